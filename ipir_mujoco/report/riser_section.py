"""The validation report's section "Vertical riser": the design in a vertical pipe under its motor.

Both exact models (analytic one-way clutches and MuJoCo's ratchet) under the design's motor (by
default the gearmotor M_stall = 0.5 N m, 30 rad/s no-load) in a vertical pipe; whether they stall,
where and why (the torque a revolution needs at rest, :mod:`ipir_mujoco.studies.climbing`), with
the clutch reactions that then hold the weight against statics; the smallest stall torque that
restarts the robot at every crank angle in the riser, and with it the steady climb, the clutch
loads and whether the paper's rule (first order or exact) still gives the right answer, with the
share of the run its lock would have to pull; the climbing-ability figure over the inclines.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from ipir_mujoco.analytic.dynamics import OneDofDynamics
from ipir_mujoco.core.params import RobotParams

from ..labels import signed_percent
from .. import registry
from ..studies.climb import climbing
from .climb_figure import write_climb_figure
from .document import Heading, Image, Paragraph, Table, fmt

EXACT = ("analytic-unilateral", "mujoco-ratchet")  # the two exact models with one-way clutches
PAPER_RULE = ("analytic-exact", "analytic-approx")  # the paper's rule: exact geometry, and the paper's own model
INCLINES = {False: (0, 10, 20, 30, 40, 50, 60, 70, 75, 80, 90), True: (0, 30, 60, 90)}  # the figure's inclines [deg], full / quick
# bracket of the steady-climb limit [deg], full / quick: ``climb``'s own (climbing.TOLERANCE_DEG), so that the report
# and ``ipir-mujoco climb`` bisect to the same bracket (three more runs per engine than a 0.5 deg bracket)
TOLERANCE = {False: climbing.TOLERANCE_DEG, True: climbing.TOLERANCE_DEG}
TORQUE_STEP = 0.01  # N m: the stronger motor is the torque needed at rest rounded up to this (a catalogue step)


def _statics(params: RobotParams, metrics: dict) -> dict:
    """Where a run stalled: the clutch reactions and static resistances statics gives at its crank angle
    (exact geometry; a hold pulling a module back is its resistance's, up to F_r), beside the run's own."""
    if "error" in metrics or not metrics["stalled"]:
        return metrics
    lambda1, lambda2, res1, res2 = OneDofDynamics(params, "exact").stalled_reactions(metrics["stall_phi_rad"])
    return {**metrics, "statics_n": [float(lambda1), float(lambda2)], "statics_resistance_n": [float(res1), float(res2)]}


def compute(params: RobotParams, quick: bool, progress) -> dict:
    """The riser runs and the climbing-ability study (``quick``: four inclines, a 2 deg bracket)."""
    motor = params.replace(drive="motor")
    riser = motor.replace(incline=90.0)
    need = climbing.torque_needed(riser)
    contraction = climbing.torque_needed(riser, stroke="contraction")
    # where a crank started from rest at phi0 first meets a torque it cannot give at rest
    ahead = params.phi0 + np.linspace(0.0, 2 * math.pi, 7201)
    short = ahead[climbing.required_torque(riser, ahead) > riser.M_stall]
    default = {}
    for engine in EXACT + PAPER_RULE:
        default[engine] = _statics(riser, climbing.measure(engine, riser))
        progress(f"default motor, vertical, {engine}: " + _state(default[engine]))
    stronger = math.ceil(need["torque_n_m"] / TORQUE_STEP - 1e-9) * TORQUE_STEP
    strong_riser = riser.replace(M_stall=stronger)
    strong = {}
    for engine in EXACT + PAPER_RULE:
        strong[engine] = climbing.measure(engine, strong_riser, every_step=True)  # its mean clutch force is shown
        progress(f"M_stall {stronger:g} N m, vertical, {engine}: " + _state(strong[engine]))
    flat = climbing.measure("analytic-approx", strong_riser.replace(incline=0.0))
    study = climbing.climb_study(motor, INCLINES[quick], EXACT, TOLERANCE[quick], progress=progress)
    return {"quick": quick, "motor": {"M_stall_n_m": motor.M_stall, "omega_noload_rad_s": motor.omega_noload},
            "weight_n": (params.m1 + params.m2 + params.rod_mass) * params.g,
            "need": need, "need_contraction": contraction,
            "need_paper": climbing.torque_needed(riser.replace(rod_mass=0.0, rod_inertia=0.0), "approx"),
            "first_short_phi_rad": float(short[0]) if short.size else None,
            "default": default, "stronger_n_m": stronger, "strong": strong, "paper_flat": flat,
            "study": study, "params": params.as_dict()}


def _state(m: dict) -> str:
    if "error" in m:
        return f"failed: {m['error']}"
    if m["stalled"]:
        return f"stalled at {math.degrees(m['stall_phi_rad']) % 360:.1f} deg"
    return f"{m['steady_speed_m_s']:.4g} m/s" if m["steady"] else "no steady state"


def _deg(phi: float | None) -> str:
    return "n/a" if phi is None else f"{math.degrees(phi) % 360:.1f} deg"


def _relative(a, b) -> str:
    return "n/a" if a is None or b is None or a == 0 else signed_percent((b - a) / abs(a), 3)


def render(metrics: dict, figures_dir: Path) -> list:
    params = RobotParams(**{k: v for k, v in metrics["params"].items()})
    motor = params.replace(drive="motor")
    study, default, strong = metrics["study"], metrics["default"], metrics["strong"]
    write_climb_figure(study, motor, figures_dir / "climbing_ability.png")
    m_stall = metrics["motor"]["M_stall_n_m"]
    blocks: list = [Heading("Vertical riser"), Paragraph(
        "The paper names vertical sections as future work. Here the design climbs a vertical pipe under its motor "
        f"(M_stall {m_stall:g} N m, no-load {metrics['motor']['omega_noload_rad_s']:g} rad/s), from rest at phi0, "
        "in both exact models (analytic one-way clutches, exact geometry with the rod; MuJoCo's ratchet), and under "
        "the paper's rule. Gravity pulls every body back along the pipe; the resistances F_r1, F_r2 stay the "
        "wall-press rolling resistance, which does not depend on it.")]
    blocks.append(Paragraph(_stall_text(metrics)))
    header = ["model", "outcome", "at rest from [s]", "crank angle", "clutch reaction, module 1 [N]",
              "clutch reaction, module 2 [N]", "statics: clutch reactions, modules 1, 2 [N]",
              "statics: resistance holding module 1, 2 [N]"]
    rows = []
    for engine, m in default.items():
        if "error" in m:
            rows.append([registry.variant(engine).label, f"failed: {m['error']}", "", "", "", "", "", ""])
        elif m["stalled"]:
            statics = m.get("statics_n")
            rows.append([registry.variant(engine).label, "stalls", fmt(m['stall_t_s'], 4), _deg(m["stall_phi_rad"]),
                         fmt(m["lambda1_at_rest_n"], 5), fmt(m["lambda2_at_rest_n"], 5),
                         f"{statics[0]:.5g}, {statics[1]:.5g}",
                         ", ".join(f"{v:.4g}" for v in m["statics_resistance_n"])])
        else:
            rows.append([registry.variant(engine).label, f"climbs at {fmt(m['steady_speed_m_s'], 4)} m/s"
                         if m["steady"] else "no steady state", "", "", "", "", "", ""])
    blocks.append(Table(header, rows))
    blocks.append(Paragraph(_stronger_text(metrics)))
    header = ["model", "steady speed [m/s]", "vs analytic one-way", "peak clutch reaction [N]",
              "mean clutch reaction, steady window [N]", "climbing efficiency [-]", "lock would pull [% of run]"]
    reference = strong["analytic-unilateral"].get("steady_speed_m_s")
    rows = []
    for engine, m in strong.items():
        if "error" in m or not m["steady"]:
            rows.append([registry.variant(engine).label, _state(m), "", "", "", "", ""])
            continue
        rows.append([registry.variant(engine).label, fmt(m["steady_speed_m_s"], 5), _relative(reference, m["steady_speed_m_s"]),
                     fmt(m["peak_clutch_force_n"], 4), fmt(m["mean_clutch_force_n"], 4),
                     fmt(m["efficiency"], 6),
                     "" if m["pull_share"] is None else f"{100 * m['pull_share']:.1f}"])
    blocks.append(Table(header, rows))
    blocks.append(Paragraph(_paper_rule_text(metrics)))
    blocks.append(Image("figures/climbing_ability.png", _caption(metrics)))
    blocks.append(Paragraph(_limits_text(study)))
    return blocks


def _stall_text(metrics: dict) -> str:
    need, contraction, default = metrics["need"], metrics["need_contraction"], metrics["default"]
    m_stall = metrics["motor"]["M_stall_n_m"]
    exact = [default[e] for e in EXACT]
    stalls = all("error" not in m and m["stalled"] for m in exact)
    paper = default["analytic-approx"]
    head = ("**It stalls.**" if stalls else "**It climbs.**") + (
        f" The torque a revolution needs at rest in a vertical pipe (lifting one module and its share of the rod "
        f"against its resistance, the other held by its clutch) peaks at {need['torque_n_m']:.4g} N m at "
        f"{_deg(need['phi_rad'])} ({need['stroke']}, module {1 if need['stroke'] == 'contraction' else 2} moving) "
        f"and at {contraction['torque_n_m']:.4g} N m at {_deg(contraction['phi_rad'])} in contraction (module 1 "
        f"moving); the motor gives at most M_stall = {m_stall:g} N m. ")
    if stalls:
        times = [f"{registry.variant(e).label} at t = {default[e]['stall_t_s']:.4g} s, crank at "
                 f"{_deg(default[e]['stall_phi_rad'])}" for e in EXACT]
        head += (f"Started from rest at phi0, the crank passes {_deg(metrics['first_short_phi_rad'])}, where the "
                 "torque at rest first falls short, on its kinetic energy and stops for good where that is spent: "
                 + "; ".join(times) + ". There both clutches hold the robot, and their reactions are those of "
                 "statics (table; the weight is "
                 f"{metrics['weight_n']:.4g} N).")
    if "error" not in paper and not paper["stalled"] and paper["steady"]:
        head += (f" The paper's own model (first-order kinematics, massless rod) climbs instead, at "
                 f"{fmt(paper['steady_speed_m_s'], 3)} m/s: its requirement, r sin(phi) (F_r + m g), peaks at only "
                 f"{metrics['need_paper']['torque_n_m']:.4g} N m, and its crank carries over it. It gets the answer wrong.")
    return head


def _stronger_text(metrics: dict) -> str:
    need, stronger = metrics["need"], metrics["stronger_n_m"]
    return (f"**The smallest motor for the riser.** A stall torque of {need['torque_n_m']:.4g} N m is what lets "
            "the robot restart from rest at every crank angle in the riser; below it a robot that stops at the "
            f"hardest angle ({_deg(need['phi_rad'])}), after a power cut or at an obstacle, stays there (a weaker "
            "motor may still climb from a favourable start by carrying the crank over that angle, but cannot be "
            f"relied on). Rounded up to a catalogue step of {TORQUE_STEP:g} N m: M_stall = {stronger:g} N m, the same "
            "no-load speed. With it, in the vertical pipe:")


def _paper_rule_text(metrics: dict) -> str:
    strong, flat = metrics["strong"], metrics["paper_flat"]
    one_way = strong["analytic-unilateral"].get("steady_speed_m_s")
    paper, exact = strong["analytic-approx"], strong["analytic-exact"]
    parts = []
    if "error" not in paper and paper["steady"] and one_way:
        parts.append(f"The paper's model climbs at {paper['steady_speed_m_s']:.4g} m/s, "
                     f"{_relative(one_way, paper['steady_speed_m_s'])} from the one-way clutches' "
                     f"{one_way:.4g} m/s")
    if "error" not in exact and exact["steady"] and one_way:
        parts.append(f"its rule on the exact linkage at {exact['steady_speed_m_s']:.4g} m/s "
                     f"({_relative(one_way, exact['steady_speed_m_s'])})")
    text = "; ".join(parts) + ". " if parts else ""
    if paper.get("pull_share") is not None and flat.get("pull_share") is not None:
        riser, level = 100 * paper["pull_share"], 100 * flat["pull_share"]
        text += (f"Its locked clutch would have to pull during {riser:.2g} % of the run in the riser, against "
                 f"{level:.3g} % with the same motor in a horizontal pipe: the weight presses the held module onto "
                 "its clutch, so its reaction changes sign " + ("nowhere: in the riser the rule locks exactly the "
                 "clutches one-way clutches engage, and what remains is the geometry. " if riser == 0 else
                 "at other places and less often. "))
    weight = metrics["weight_n"]
    text += (f"On average over a steady revolution the clutches carry the weight ({weight:.4g} N) and the moving "
             "module's resistance (the mean reactions above); the peaks come where a module is stopped. MuJoCo's "
             "peak is not shown (n/a): its rigid ratchet engages through a soft constraint that overshoots the "
             "rigid model's peak by an amount set by the step, up to twice the load it takes up (see the "
             "real-clutch section); its mean reaction is the robot's.")
    return text


def _caption(metrics: dict) -> str:
    return ("Climbing ability under the motor against the pipe's incline: steady speed (top; crosses: stalled) "
            "and clutch reactions (bottom: peak and mean over the steady window, with the weight along the pipe); "
            "analytic one-way clutches (line) and MuJoCo's ratchet (open circles); the restart limit (dashed) and "
            "the steady-climb limit from rest (dotted; black where both engines find it in the same bracket)"
            + (" (quick run: four inclines)." if metrics["quick"] else "."))


def _limits_text(study: dict) -> str:
    restart, bound = study["restart"], study["energy_bound"]
    limits = [f"{registry.variant(e).label} {lim['bracket'][0]:.2f}-{lim['bracket'][1]:.2f} deg"
              for e, lim in study["steady_climb"].items() if lim["incline_deg"] is not None]
    where = ("at no incline" if restart["incline_deg"] is None else f"up to {restart['incline_deg']:.1f} deg")
    return (f"Limits of the motor: it restarts from rest at every crank angle {where} "
            f"(quasi-static: the hardest angle is {_deg(restart['phi_rad'])}); from rest at phi0 it reaches a steady "
            "climb up to " + ("; ".join(limits) or "n/a") + " (bisection on runs to steady state: the last incline "
            "seen to climb, and the first seen to stall); between the two, a robot that stops at the hardest angle "
            "does not get going again. The steady speed does not fall to zero at the limit: what fails is the "
            "first revolution from rest, and beyond the limit the robot stalls in its first turn. "
            + ("By energy alone (2 pi M_stall per revolution against a stroke 2r of lifting and resistance) it "
               "could climb any incline." if bound["sin"] >= 1 else
               f"By energy alone it cannot hold a climb steeper than {bound['incline_deg']:.1f} deg."))


def verdict(metrics: dict) -> dict:
    default, need = metrics["default"], metrics["need"]
    exact = [default[e] for e in EXACT]
    stalls = all("error" not in m and m["stalled"] for m in exact)
    paper = default["analytic-approx"]
    strong = [metrics["strong"][e] for e in EXACT]
    speeds = [m.get("steady_speed_m_s") for m in strong]
    answer = (("No, not" if stalls else "Yes,") + f" with the motor of M_stall {metrics['motor']['M_stall_n_m']:g} N m: "
              + ("both exact models stall in the first turn (" + "; ".join(
                  f"{registry.variant(e).label} at {_deg(default[e]['stall_phi_rad'])}" for e in EXACT)
                 + f"), since lifting a module needs up to {need['torque_n_m']:.4g} N m at rest"
                 if stalls else "both exact models climb")
              + ((f"; the paper's model wrongly says it climbs, at {fmt(paper['steady_speed_m_s'], 3)} m/s")
                 if "error" not in paper and paper["steady"] and stalls else "")
              + f". A motor of {metrics['stronger_n_m']:g} N m (the torque needed at rest, rounded up) climbs at "
              + " and ".join(f"{fmt(s, 4)} m/s" for s in speeds) + " (analytic, MuJoCo" + (
                  f": {_relative(speeds[0], speeds[1])})" if None not in speeds else ")") + ".")
    return {"question": "Can the robot climb a vertical riser with its motor, and does the paper's model tell?",
            "answer": answer, "evidence": "sections.vertical_riser",
            "short": ("No, not" if stalls else "Yes,") + f" with M_stall {metrics['motor']['M_stall_n_m']:g} N m",
            "key": f"{need['torque_n_m']:.4g} N m needed at rest"}
