"""The validation report's section "Under a real motor": every rung of the ladder at its steady state.

:func:`compute` runs :func:`ipir_mujoco.studies.cruise.cruise_study` (each rung under the parameter set's
DC gearmotor until its periodic steady state, and MuJoCo cross-checked against the equations of the same
mechanism); :func:`render` draws the time histories of the first seconds and writes the tables and the
text; :func:`verdict` answers what the paper's model gets wrong at cruise. Registered in
:mod:`ipir_mujoco.report.sections`.
"""

from __future__ import annotations

import math
from pathlib import Path

from ipir_mujoco.core.params import RobotParams

from ..labels import signed_percent, summary_label
from .document import Heading, Image, Paragraph, Table, fmt, pct
from ..core.figures import new_figure

FIGURE = "cruise_histories.png"
PAPER, EXACT, ROD, ONE_WAY, RATCHET, LOCKS = ("paper model", "exact geometry", "with rod mass", "one-way clutches",
                                              "MuJoCo ratchet", "MuJoCo, paper's rule")
# one colour per rung; MuJoCo dashed over the equations of its mechanism
STYLE = {PAPER: ("tab:blue", "-"), EXACT: ("tab:orange", "-"), ROD: ("tab:green", "-"),
         LOCKS: ("black", "--"), ONE_WAY: ("tab:red", "-"), RATCHET: ("tab:purple", "--")}
# line widths: rungs that agree to the width of a line lie on each other, so each is drawn thinner than the
# one under it (the paper's model widest, underneath): every curve shows at least as a rim or between dashes
WIDTH = {PAPER: 3.4, EXACT: 2.4, ROD: 1.1, LOCKS: 0.8, ONE_WAY: 2.6, RATCHET: 1.1}
DEFAULT_MOTOR = RobotParams(drive="motor")


def compute(params: RobotParams, quick: bool, progress) -> dict:
    from ..studies.validation.cruise import cruise_study

    return cruise_study(params, quick=quick, progress=progress)


def fine_pct(value) -> str:
    """A fraction as a signed percentage to 4 decimals (the engines agree to far less than the 0.01 % two
    decimals show); 'n/a' for None."""
    return "n/a" if value is None else signed_percent(value, 4)


def _rungs(metrics: dict) -> dict[str, dict]:
    return {r["name"]: r for r in metrics["rungs"]}


def _ok(record: dict | None) -> bool:
    return record is not None and "error" not in record and bool(record.get("steady"))


def figure_histories(metrics: dict, path: Path) -> None:
    """Crank speed, robot speed and per-revolution mean speed against time, every rung, to its steady state."""
    history_figure(metrics).savefig(path, dpi=110)


def history_figure(metrics: dict):
    """The figure of :func:`figure_histories` (a matplotlib Figure, for tests to read)."""
    fig, (ax_crank, ax_speed, ax_rev) = new_figure(3, height=2.4)
    for record in metrics["rungs"]:
        if "error" in record:
            continue
        colour, style = STYLE.get(record["name"], ("grey", "-"))
        lw = WIDTH.get(record["name"], 1.0)
        h, ends = record["history"], record["revolutions_end"]
        ax_crank.plot(h["t"], h["omega"], style, color=colour, lw=lw, label=record["name"])
        ax_speed.plot(h["t"], h["speed"], style, color=colour, lw=lw)
        ax_rev.plot(ends["t"], ends["speed"], "o" + style, color=colour, ms=1.5 + 1.5 * lw, lw=lw)
        if record.get("steady_speed_m_s") is not None:
            ax_rev.axhline(record["steady_speed_m_s"], color=colour, lw=0.6, ls=":")
    params = metrics["params"]
    ax_crank.axhline(params["omega_noload"], color="grey", lw=0.8, ls="-.", label="motor's no-load speed")
    ax_crank.set(ylabel="crank speed [rad/s]", title="(a) crank speed", ylim=(0, None))
    ax_speed.set(ylabel="robot speed [m/s]", title="(b) robot speed (mean of the two modules' speeds)")
    ax_rev.set(xlabel="time t [s]", ylabel="mean speed [m/s]",
               title="(c) mean speed of each crank revolution (dotted: the steady speed)")
    for ax in (ax_crank, ax_speed, ax_rev):
        ax.grid(alpha=0.3)
        ax.set_xlim(0, max(ax.dataLim.x1 for ax in (ax_crank, ax_speed, ax_rev)))  # one time axis for all three
    fig.legend(*ax_crank.get_legend_handles_labels(), loc="outside lower center", ncols=4, fontsize="small")
    return fig


def _motor_text(metrics: dict) -> str:
    p = metrics["params"]
    given = (p["M_stall"], p["omega_noload"]) != (DEFAULT_MOTOR.M_stall, DEFAULT_MOTOR.omega_noload)
    head = (f"Every rung of the ladder is driven by the same DC gearmotor at constant voltage, seen at the crank: "
            f"torque M_stall (1 - omega / omega_noload), with M_stall = {p['M_stall']:g} N m and omega_noload = "
            f"{p['omega_noload']:g} rad/s ({60 * p['omega_noload'] / (2 * math.pi):.0f} rpm)")
    if given:
        return head + " as given. Each run starts from rest and stops at its periodic steady state."
    return head + (
        ", the defaults. Why these: a small brushed gearmotor (a DC motor of a few centimetres behind a "
        "reduction of a few tens) gives a few tenths of a N m at stall and a few hundred rpm at no load; its stall "
        f"torque is twice the paper's constant M = {DEFAULT_MOTOR.M:g} N m, so it starts the robot at least as "
        "briskly as the paper, and ten times the F_r1 r = "
        f"{DEFAULT_MOTOR.F_r1 * DEFAULT_MOTOR.r:g} N m the crank needs at rest mid-stroke to push module 1 against "
        "its resistance, so it cannot stall. Where the paper's constant torque speeds the crank up without bound, "
        "this motor holds it below its no-load speed: the robot reaches a periodic steady "
        "state, the cruise a designer sizes the robot for. Each run starts from rest and stops at the end of the "
        "revolution where the last 3 per-revolution mean speeds agree within 1e-4.")


def _rung_table(metrics: dict) -> Table:
    header = ["rung", "removes", summary_label("t_steady_s"),
              summary_label("steady_speed_m_s") + " (the paper's model against it)",
              summary_label("distance_per_rev_m"), summary_label("energy_per_metre_j_m"), "efficiency [-]",
              "mean crank speed [rad/s]", "mean crank torque [N m] (the paper's model against it)",
              "peak clutch reaction [N]"]
    rows = []
    for r in metrics["rungs"]:
        if "error" in r:
            rows.append([r["name"], r["isolates"], "failed: " + r["error"]] + [""] * 7)
            continue
        if not r["steady"]:
            why = r["stall_reason"] or f"not steady by {metrics['t_cap_s']:g} s"
            rows.append([r["name"], r["isolates"], why] + [""] * 7)
            continue
        rungs = _rungs(metrics)

        def vs(key):  # the report's convention: (the paper's model - this rung) / |this rung|
            error = _change(rungs, PAPER, key, r["name"])
            return f" ({pct(error)})" if error and r["name"] != PAPER else ""

        rows.append([r["name"], r["isolates"], fmt(r["t_steady_s"], 4), fmt(r["steady_speed_m_s"], 5) + vs(
            "steady_speed_m_s"), fmt(r["distance_per_rev_m"], 5), fmt(r["energy_per_metre_j_m"], 5),
            fmt(r["efficiency"], 5), fmt(r["crank_speed_rad_s"], 4),
            fmt(r["crank_torque_n_m"], 4) + vs("crank_torque_n_m"), fmt(r["peak_clutch_force_n"], 4)])
    return Table(header, rows)


def _cross_table(metrics: dict) -> Table:
    header = ["MuJoCo rung (b)", "against the equations (a)", "figure", "a", "b", "(b - a) / |a|",
              "(b - a) / |a| at half MuJoCo's step", f"within {100 * metrics['cross_check_tol']:.2g} %"]
    rows = []
    for check in metrics["cross_checks"]:
        if "error" in check:
            rows.append([check["mujoco"], check["equations"], check["error"]] + [""] * 5)
            continue
        halved = check.get("halved_step", {})
        for key, v in check["figures"].items():
            if key == "peak_clutch_force_n":  # not an agreement figure: its own table (_peak_table)
                continue
            finer = halved.get("figures", {}).get(key, {}).get("relative")
            held = key in metrics["checked"]
            rows.append([check["mujoco"], check["equations"], summary_label(key), fmt(v["a"], 6), fmt(v["b"], 6),
                         fine_pct(v["relative"]),
                         fine_pct(finer) if finer is not None else ("n/a" if "error" in halved else "(quick run)"),
                         ("yes" if v["relative"] is not None and abs(v["relative"]) <= metrics["cross_check_tol"]
                          else "NO") if held else "shown"])
    return Table(header, rows)


def _peak_table(metrics: dict) -> Table | None:
    """The peak clutch reaction of each MuJoCo rung against the equations: shown apart from the agreement
    figures, since it measures MuJoCo's step where a rigid clutch engages, not the mechanism."""
    rows = []
    for check in metrics["cross_checks"]:
        v = check.get("figures", {}).get("peak_clutch_force_n")
        if v is None:
            continue
        finer = check.get("halved_step", {}).get("figures", {}).get("peak_clutch_force_n", {}).get("relative")
        rows.append([check["mujoco"], check["equations"], fmt(v["a"], 4), fmt(v["b"], 4), fine_pct(v["relative"]),
                     fine_pct(finer) if finer is not None else "(quick run)"])
    if not rows:
        return None
    return Table(["MuJoCo rung (b)", "against the equations (a)", "peak clutch reaction a [N]", "b [N]",
                  "(b - a) / |a|", "at half MuJoCo's step"], rows)


def _change(rungs: dict, name: str, key: str, against: str = PAPER) -> float | None:
    """(rung ``name`` - rung ``against``) / |``against``| of a figure; None where either did not settle."""
    a, b = rungs.get(against), rungs.get(name)
    if not (_ok(a) and _ok(b)) or not a[key]:
        return None
    return (b[key] - a[key]) / abs(a[key])


def paper_error(metrics: dict) -> float | None:
    """The paper's model's error in cruise speed: (paper's model - one-way clutches) / |one-way clutches|, every
    idealization at once (the section's verdict, and the README's)."""
    return _change(_rungs(metrics), PAPER, "steady_speed_m_s", ONE_WAY)


def locks_cost(metrics: dict) -> float | None:
    """The paper's locks' cost in cruise speed: (with rod mass - one-way clutches) / |one-way clutches|, the same
    mechanism with and without them (the opening figure's bar, report/overview.py)."""
    return _change(_rungs(metrics), ROD, "steady_speed_m_s", ONE_WAY)


def paper_error_text(metrics: dict) -> str:
    return pct(paper_error(metrics))


def locks_cost_text(metrics: dict) -> str:
    return pct(locks_cost(metrics)) + " in steady speed"


def _findings(metrics: dict) -> list[str]:
    """What the paper's idealizations change at cruise, in words with numbers (the section's core)."""
    rungs = _rungs(metrics)
    paper, exact, rod, one_way = (rungs.get(n) for n in (PAPER, EXACT, ROD, ONE_WAY))
    if not all(_ok(r) for r in (paper, exact, rod, one_way)):
        return ["Not every equation rung reached its steady state (see the table), so the idealizations' cost at "
                "cruise is not stated for this design."]
    p = metrics["params"]
    load = p["F_r1"] + p["F_r2"]
    level = p["incline"] == 0
    lift = (p["m1"] + p["m2"]) * p["g"] * math.sin(math.radians(p["incline"]))
    energies = [r["energy_per_metre_j_m"] for r in metrics["rungs"] if _ok(r)]
    spread = max(abs(e / load - 1) for e in energies)
    low, high = paper["crank_speed_range_rad_s"]
    # under the paper's rule the resting module is started at each dead centre with the crank pin's
    # acceleration r omega^2 (first order) while the other module's clutch holds: m r omega^2 + F_r
    started = min(p["m1"], p["m2"]) * p["r"] * high**2 + min(p["F_r1"], p["F_r2"])
    return [
        f"**Steady speed.** The paper's model cruises at {paper['steady_speed_m_s']:.4g} m/s, reached after "
        f"{paper['t_steady_s']:.3g} s. Each cost here is (the model with the idealization - the model without it) "
        "/ |the model without it|. First-order kinematics costs "
        f"{pct(_change(rungs, PAPER, 'steady_speed_m_s', EXACT))} in steady speed, the massless rod a further "
        f"{pct(_change(rungs, EXACT, 'steady_speed_m_s', ROD))}: under the paper's rule each revolution advances the "
        f"robot exactly 2r = {2 * p['r']:g} m whatever the geometry, so these change only the crank speed. The "
        f"paper's locks cost {locks_cost_text(metrics)} against one-way clutches on the same mechanism (with the "
        f"rod), which cruise at {one_way['steady_speed_m_s']:.4g} m/s (reached after "
        f"{one_way['t_steady_s']:.3g} s): a module that is no longer pushed coasts on against its resistance instead "
        f"of being stopped by its lock, so each revolution carries the robot {fmt(one_way['distance_per_rev_m'])} m "
        f"instead of {fmt(rod['distance_per_rev_m'])} m, while the crank turns at nearly the same mean speed "
        f"({one_way['crank_speed_rad_s']:.4g} against {rod['crank_speed_rad_s']:.4g} rad/s). Altogether the "
        f"paper's model is {paper_error_text(metrics)} off the cruising speed of the robot with one-way clutches "
        "((paper's model - one-way clutches) / |one-way clutches|).",
        (f"**Energy per metre.** {min(energies):.4f} to {max(energies):.4f} J/m in every rung: F_r1 + F_r2 = "
         f"{load:g} N to within {100 * spread:.2g} % (the kinetic energy still gained over the steady window). Rigid "
         "clutches engage at zero relative speed and dissipate nothing, so at cruise all the work the motor does at "
         "the crank goes into the resistances (efficiency ~1), whatever the model: the idealizations do not change "
         "the energy per metre. " if level else
         f"**Energy per metre.** {min(energies):.4f} to {max(energies):.4f} J/m in every rung: in this pipe, "
         f"inclined {p['incline']:g} deg, the motor's work per metre goes into the resistances, F_r1 + F_r2 = "
         f"{load:g} N, and into the climb, (m1 + m2) g sin(incline) = {lift:.4g} N and the rod's share where it has "
         "mass. Rigid clutches engage at zero relative speed and dissipate nothing, so the idealizations change the "
         "energy per metre only by the rod's weight. ")
        + "They change the mean crank torque the motor must give, "
        f"{paper['crank_torque_n_m']:.3g} N m in the paper's model against {one_way['crank_torque_n_m']:.3g} N m "
        f"with one-way clutches ({pct(_change(rungs, PAPER, 'crank_torque_n_m', ONE_WAY))}: the same work per metre "
        "over a shorter distance per revolution), and with it the motor's current.",
        f"**Clutch loads.** The peak clutch reaction at cruise is {paper['peak_clutch_force_n']:.4g} N in the "
        f"paper's model, {exact['peak_clutch_force_n']:.4g} N with the exact geometry and "
        f"{one_way['peak_clutch_force_n']:.4g} N with one-way clutches: the paper's lock carries "
        f"{paper['peak_clutch_force_n'] / one_way['peak_clutch_force_n']:.2g} times the load. At each dead centre its "
        "rule stops the moving module and starts the resting one with the crank pin's full acceleration r "
        f"omega^2, at the crank's fastest (it swings between {low:.3g} and {high:.3g} rad/s at cruise, fastest where "
        "the linkage takes no torque), while the other clutch holds: m r omega^2 + F_r = "
        f"{started:.4g} N. With one-way clutches both modules coast through each dead centre, and a clutch takes load "
        "only where its module comes to rest, mid-stroke: no module is thrown from rest at r omega^2.",
    ]


def _agreement(metrics: dict) -> str:
    parts, peaks = [], []
    for check in metrics["cross_checks"]:
        if "error" in check:
            parts.append(f"{check['mujoco']}: {check['error']}")
            continue
        finer = check.get("halved_step", {}).get("worst_checked")
        parts.append(f"{check['mujoco']} against {check['equations']} within {100 * check['worst_checked']:.2g} %"
                     + ("" if finer is None else f" ({100 * finer:.2g} % at half MuJoCo's step)"))
        peak = check["figures"]["peak_clutch_force_n"]["relative"]
        if peak is not None:
            peaks.append(f"{pct(peak)} ({check['mujoco']})")
    text = ("**MuJoCo against the equations of the same mechanism**, in steady speed, distance per revolution and "
            "energy per metre: " + "; ".join(parts) + f". Tolerance {100 * metrics['cross_check_tol']:.2g} %: MuJoCo's "
            "accuracy monitor (energy residual 1e-3, which keeps revolutions and travel within 0.1 %; ratchet "
            "excursion 1e-4 of the travel) plus twice the steady-state test's 1e-4 (each engine stops within it of "
            "its limit cycle).")
    if peaks:
        text += (" The peak clutch reaction is not held to it (" + ", ".join(peaks) + "): a rigid clutch's reaction "
                 "jumps where it engages, which MuJoCo's soft constraint resolves over a few steps, overshooting for a "
                 "step or two by an amount set by the step (MuJoCo is read at every step here; see the column at half "
                 "its step). A real clutch's engagement load is set by its stiffness and play (the "
                 "section on real clutches).")
    return text


def render(metrics: dict, figures_dir: Path) -> list:
    figure_histories(metrics, figures_dir / FIGURE)
    return [Heading("Under a real motor"), Paragraph(_motor_text(metrics)), _rung_table(metrics),
            Image(f"figures/{FIGURE}", "The first seconds from rest under the motor, every rung until its steady "
                                       "state (MuJoCo dashed): (a) crank speed, (b) robot speed, (c) mean speed of "
                                       "each crank revolution and the steady speed."),
            *(Paragraph(text) for text in _findings(metrics)), Paragraph(_agreement(metrics)),
            _cross_table(metrics), *_peak_blocks(metrics)]


def _peak_blocks(metrics: dict) -> list:
    table = _peak_table(metrics)
    if table is None:
        return []
    return [Paragraph("**Not an agreement figure: the peak clutch reaction.** A rigid clutch's reaction jumps where "
                      "it engages; MuJoCo's soft constraint takes the load up over a few steps and overshoots by an "
                      "amount its step sets, so the difference below follows the step (see the last column), not "
                      "the mechanism. The engagement loads of real clutches, stiffness and play included, are the "
                      "section on real clutches."), table]


def verdict(metrics: dict) -> dict | None:
    rungs = _rungs(metrics)
    paper, one_way, ratchet = (rungs.get(n) for n in (PAPER, ONE_WAY, RATCHET))
    if not (_ok(paper) and _ok(one_way)):
        return None
    mj = (f" (MuJoCo's ratchet: {ratchet['steady_speed_m_s']:.4g} m/s, {ratchet['energy_per_metre_j_m']:.4f} J/m)"
          if _ok(ratchet) else "")
    answer = (
        f"Under a gearmotor of {metrics['params']['M_stall']:g} N m stall torque and "
        f"{metrics['params']['omega_noload']:g} rad/s no-load speed, the paper's model cruises at "
        f"{paper['steady_speed_m_s']:.4g} m/s where the robot with one-way clutches cruises at "
        f"{one_way['steady_speed_m_s']:.4g} m/s{mj}: {paper_error_text(metrics)} ((paper's model - one-way "
        f"clutches) / |one-way clutches|), because its "
        f"locks stop each module instead of letting it coast ({fmt(paper['distance_per_rev_m'])} against "
        f"{fmt(one_way['distance_per_rev_m'])} m per revolution). Energy per metre is set by the load, not by the "
        "model: "
        f"{paper['energy_per_metre_j_m']:.4f} against {one_way['energy_per_metre_j_m']:.4f} J/m ("
        + ("= F_r1 + F_r2" if metrics["params"]["incline"] == 0 else "the resistances and the climb")
        + ": rigid clutches dissipate nothing); the peak clutch reaction at cruise is "
        f"{paper['peak_clutch_force_n']:.3g} N "
        f"against {one_way['peak_clutch_force_n']:.3g} N.")
    return {"question": "What does the paper's model get wrong at cruise, under a real motor?", "answer": answer,
            "evidence": "sections.cruise", "short": "its cruise speed; energy per metre it gets right",
            "key": f"{paper_error_text(metrics)} in steady speed (paper's model against one-way clutches)"}
