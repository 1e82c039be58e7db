"""The report's headline figures, each read from one place of ``metrics.json``, with its base and its text.

A headline is a number the README and the docs quote from the report: where first-order kinematics starts to cost
more than 1 %, what each idealization costs at the paper's case, the cruise speeds, the climbing limit, the speed
control's ripples. Each is read here from the one entry of the metrics record the report writes it from, and
:func:`headlines` gives it as {key: :class:`Headline`}: its value in the unit it is quoted in (per cent for a
cost) and the text the report shows. tests/test_headlines.py holds the report, the README and the docs to them.

Every cost is the report's convention: (the model with the idealization - the model without it) / |the model
without it| (:func:`ipir_mujoco.studies.compare.cost`).
"""

from __future__ import annotations

from dataclasses import dataclass

from ..studies.comparison.compare import cost
from . import control_section, cruise_section
from .document import pct


@dataclass(frozen=True)
class Headline:
    key: str
    words: str  # what the figure is, with its base
    value: float  # in the unit it is quoted in: per cent for a cost or a share, else the figure's own
    text: str  # as the report writes it


def _ladder(metrics: dict) -> dict[str, dict]:
    return {r["name"]: r["summary"] for r in metrics["ladder"]}


def headlines(metrics: dict) -> dict[str, Headline]:
    """Every headline figure of a metrics record of the paper's case (the full report or ``--quick``: each figure
    here is the same in both, to the digits quoted)."""
    out: list[Headline] = []

    def add(key: str, words: str, value: float, text: str) -> None:
        out.append(Headline(key, words, value, text))

    crossing = metrics["lr_study"]["thresholds"]["revolutions"]["1%"]
    add("lr_crossing", "L/r below which first-order kinematics costs more than 1 % in crank revolutions "
        "((first order - exact) / |exact|, narrowed by the atlas's root-finding)", crossing["crossing"],
        f"L/r = {crossing['crossing']:.3g}")
    add("lr_crossing_L", "the same crossing as a rod length L [m]", crossing["crossing_L_m"],
        f"L = {crossing['crossing_L_m']:.3g} m")
    ladder = _ladder(metrics)
    paper, exact, rod = ladder["paper model"], ladder["exact geometry"], ladder["with rod mass"]
    locks, ratchet = ladder["MuJoCo, paper's rule"], ladder["MuJoCo ratchet"]
    for key, figure, words in (("first_order_revolutions", "revolutions", "crank revolutions"),
                               ("first_order_rear_travel", "x1_final", "module 1's travel")):
        value = cost(paper[figure], exact[figure])
        add(key, f"first-order kinematics' cost at the paper's L/r = 4 in {words}, 1 s from rest", 100 * value,
            pct(value))
    agree = max(abs(cost(rod[k], locks[k])) for k in ("revolutions", "x1_final", "x2_final"))
    add("engines_same_linkage", "MuJoCo with the paper's locks against the equations of the same linkage, the "
        "largest difference in revolutions and the travels [%]", 100 * agree, f"{100 * agree:.2f} %")
    pull = metrics["clutch_pull"]
    add("pull_share", "share of the paper-model run in which a locked clutch would have to pull [%]",
        100 * pull["fraction_of_time"], f"{100 * pull['fraction_of_time']:.1f} %")
    add("pull_force", "the largest pull of the paper's lock [N]", -pull["min_reaction_n"],
        f"{-pull['min_reaction_n']:.0f} N")
    for key, figure, words in (("locks_revolutions", "revolutions", "crank revolutions"),
                               ("locks_rear_travel", "x1_final", "module 1's travel"),
                               ("locks_front_travel", "x2_final", "module 2's travel")):
        value = cost(locks[figure], ratchet[figure])
        add(key, f"the paper's locks' cost in {words} (MuJoCo with the paper's rule against MuJoCo's ratchet), "
            "1 s from rest", 100 * value, pct(value))
    cruise = metrics["sections"]["cruise"]
    rungs = {r["name"]: r for r in cruise["rungs"]}
    for key, name in (("cruise_paper", cruise_section.PAPER), ("cruise_one_way", cruise_section.ONE_WAY)):
        speed = rungs[name]["steady_speed_m_s"]
        add(key, f"steady speed under the default motor, {name} [m/s]", speed, f"{speed:.4g} m/s")
    error = cruise_section.paper_error(cruise)
    add("paper_error_cruise", "the paper's model's error in steady speed against the one-way clutch equations "
        "((paper's model - one-way clutches) / |one-way clutches|)", 100 * error, pct(error))
    locks_cost = cruise_section.locks_cost(cruise)
    add("locks_cost_cruise", "the paper's locks' cost in steady speed (with rod mass against one-way clutches, the "
        "same mechanism)", 100 * locks_cost, pct(locks_cost))
    riser = metrics["sections"]["vertical_riser"]
    study = riser["study"]
    brackets = {tuple(v["bracket"]) for v in study["steady_climb"].values() if v["incline_deg"] is not None}
    if len(brackets) == 1:  # both engines in one bracket: the README's statement
        (low, high), = brackets
        add("climb_low", "the steepest incline seen to climb to a steady state from rest, both engines [deg]", low,
            f"{low:.2f}-{high:.2f} deg")
        add("climb_high", "the least steep incline seen to stall, both engines [deg]", high,
            f"{low:.2f}-{high:.2f} deg")
    add("restart_limit", "the steepest incline at which the default motor restarts at every crank angle [deg]",
        study["restart"]["incline_deg"], f"up to {study['restart']['incline_deg']:.1f} deg")
    add("riser_torque", "the torque at rest a vertical riser needs [N m]", riser["need"]["torque_n_m"],
        f"{riser['need']['torque_n_m']:.4g} N m")
    control = metrics["sections"]["speed_control"]
    for key, controller, variant, words in (
            ("ripple_promised", "pi+paper", control_section.PROMISE, "the paper's feedforward on its own model"),
            ("ripple_delivered", "pi+paper", control_section.EXACT, "the paper's feedforward on the exact linkage"),
            ("ripple_exact", "pi+exact", control_section.EXACT, "the exact feedforward on the exact linkage")):
        run = next(r for r in control["runs"] if r["controller"] == controller and r["variant"] == variant)
        add(key, f"speed ripple at 10 rad/s, {words} [%]", 100 * run["speed_ripple"],
            control_section._ripple(control, controller, variant))
    return {h.key: h for h in out}
