"""The validation report's verdicts: its opening questions, answered in words from the metrics.

:func:`verdicts` reads what :func:`.validate.build_metrics` has gathered (the paper's figures checked, the
ladder's rungs and changes, the clutches' pull, the L/r study, the convergence) and states each answer with the
numbers behind it; the rest here words those numbers (a relative change as a signed percentage, an agreement's
size, the wheels' press beside the slides').
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from ..comparison.compare import cost, relative_change
from .lr_study import describe_threshold
from .paper_reference import PAPER_CASE, describe_differences

if TYPE_CHECKING:  # annotations only (validate imports this module)
    from .validate import LadderRun


def _percent(x: float | None) -> str:
    return "n/a" if x is None else f"{100 * x:+.2f} %"


def _magnitude(x: float | None) -> str:
    """An agreement's size, without a sign: '0.02 %'."""
    return "n/a" if x is None else f"{100 * abs(x):.2f} %"


def _paper_verdict(checks: list[dict], identities: list[dict], case: dict) -> dict:
    question = "Does the paper's model, as implemented here, give the figures the paper reports?"
    if not case["is_paper_case"]:
        return {"question": question, "evidence": "paper_case", "section": "Not the paper's case",
                "answer": "Not checked: this is not the paper's case (" + describe_differences(case["differences"])
                          + "), and the paper prints figures for its own case only. Every rung below is "
                          "compared with the paper's model at this design instead (the ladder's first rung).",
                "short": "not checked: not the paper's case", "key": ""}
    inside = [c for c in checks if c["status"] == "inside"]
    edge = [c for c in checks if c["status"] == "edge"]
    outside = [c for c in checks if c["status"] == "outside"]
    head = "No" if outside else "Yes, to the precision the paper states them"
    answer = (f"{head}: {len(inside)} of the {len(checks)} figures the paper states in numbers land inside the "
              "interval their wording allows (a number stated to 0.1 m covers +-0.05 m)")
    if edge:
        answer += "; " + "; ".join(
            f"{c['label']}, {c['value']:.6g} {c['units']}, sits exactly on the edge of "
            f"[{c['low']:.6g}, {c['high']:.6g}] {c['units']}" for c in edge)
        if any(c["key"] == "x2_absolute" for c in edge):
            answer += (" (module 2 advances in whole strokes of 2r, so its position is quantised: it rounds to "
                       "the paper's 1.0 m or to 1.1 m depending on the rounding rule)")
    if outside:
        answer += "; outside: " + "; ".join(f"{c['label']} {c['value']:.6g} {c['units']} (paper: {c['reported']})"
                                           for c in outside)
    close = [c for c in inside if c["margin_precisions"] < 0.1]
    if close:
        answer += ". Close to an edge: " + "; ".join(
            f"{c['label']}, {c['value']:.5g} {c['units']}, lies {c['margin_precisions'] * c['precision']:.2g} "
            f"{c['units']} inside [{c['low']:.6g}, {c['high']:.6g}]" for c in close)
    held = all(i["holds"] for i in identities)
    answer += (". The paper's S_min = L - r and S_max = L + r " + ("hold" if held else "do NOT hold")
               + " by construction of the slider-crank and are not counted as reproduced figures.")
    return {"question": question, "answer": answer, "evidence": "paper_checks, identities",
            "section": "The paper's figures, reproduced", "short": head,
            "key": f"{len(inside)} of the {len(checks)} figures"}


def verdicts(checks: list[dict], identities: list[dict], case: dict, rungs: list[LadderRun], pull: dict, study: dict,
             ladder: list[dict], convergence: dict) -> list[dict]:
    """The report's opening: plain questions, plain answers, the numbers behind them."""
    paper, exact, rod, locks, one_way, ratchet = (r.run.summary for r in rungs[:6])
    modelling = {r["name"]: max(abs(r["change_vs_previous"][k]) for k in ("revolutions", "x1_final", "x2_final")
                                if r["change_vs_previous"][k] is not None)
                 for r in ladder if r["name"] in ("exact geometry", "with rod mass", "one-way clutches")}
    smallest_name = min(modelling, key=modelling.get)
    smallest = modelling[smallest_name]
    worst = max(abs(relative_change(locks[k], rod[k])) for k in ("revolutions", "x1_final", "x2_final"))
    # "agree" = the engines differ by less than a fifth of the smallest modelling effect the ladder measures:
    # then no conclusion about an idealization can come from the engine instead
    engine = {
        "question": "Do MuJoCo and the equations agree when both describe the same linkage under the paper's "
                    "clutch rule?",
        "answer": ("Yes" if worst < 0.2 * smallest else "No") + ": with locks switched by the paper's rule, "
                  "MuJoCo's linkage (exact geometry, the same rod) and the exact-geometry equations agree to "
                  f"{_magnitude(cost(rod['revolutions'], locks['revolutions']))} in crank revolutions, "
                  f"{_magnitude(cost(rod['x1_final'], locks['x1_final']))} and "
                  f"{_magnitude(cost(rod['x2_final'], locks['x2_final']))} in the module travels "
                  f"(halving MuJoCo's timestep moves them by up to {100 * convergence['mujoco_default_error']:.3f} %; "
                  f"the smallest modelling effect in the ladder, {smallest_name}, is {100 * smallest:.2f} %). "
                  "The paper's first-order equations differ from MuJoCo by "
                  f"{_percent(cost(paper['revolutions'], locks['revolutions']))} in revolutions ((paper - MuJoCo) / "
                  "|MuJoCo|): the cost of L >> r and of the rod, not of the engine.",
        "evidence": "ladder, convergence", "section": "The model ladder",
        "short": "Yes" if worst < 0.2 * smallest else "No",
        "key": f"{_magnitude(cost(rod['revolutions'], locks['revolutions']))} in revolutions",
    }
    p = rungs[0].run.params
    ratio = (f"At the paper's L/r = {p.L / p.r:g}" if case["is_paper_case"]
             else f"At this design's L/r = {p.L / p.r:g} (the paper's case has {PAPER_CASE['L'] / PAPER_CASE['r']:g})")
    costs = {
        "question": "What do the idealizations cost?",
        "answer": (
            "Each cost below is (the model with the idealization - the model without it) / |the model without "
            "it|. "
            f"First-order kinematics is off by more than 1 % in crank revolutions "
            f"{describe_threshold(study['thresholds']['revolutions']['1%'])} and by more than 5 % "
            f"{describe_threshold(study['thresholds']['revolutions']['5%'])}; module 1's travel is more sensitive "
            f"(1 % {describe_threshold(study['thresholds']['x1_final']['1%'])}). "
            f"{ratio} first-order kinematics costs "
            f"{_percent(cost(paper['revolutions'], exact['revolutions']))} in crank revolutions, "
            f"{_percent(cost(paper['x1_final'], exact['x1_final']))} in module 1's travel and "
            f"{_percent(cost(paper['first_contraction_end_s'], exact['first_contraction_end_s']))} in the end of "
            "the first contraction. "
            f"The massless rod (against a rod of {rungs[2].run.params.rod_mass:g} kg) costs a further "
            f"{_percent(cost(exact['revolutions'], rod['revolutions']))} in revolutions. "
            f"Ideal locks: in {100 * pull['fraction_of_time']:.1f} % of the paper-model run a locked clutch would "
            f"have to pull, with up to {-pull['min_reaction_n']:.0f} N; a one-way clutch cannot. The paper's locks "
            f"(MuJoCo with the paper's rule against MuJoCo's ratchet) cost "
            f"{_percent(cost(locks['revolutions'], ratchet['revolutions']))} in crank revolutions and "
            f"{_percent(cost(locks['x1_final'], ratchet['x1_final']))} (rear) and "
            f"{_percent(cost(locks['x2_final'], ratchet['x2_final']))} (front) in the modules' travel. The "
            "one-way-clutch equations and that physics agree to "
            f"{_magnitude(cost(one_way['revolutions'], ratchet['revolutions']))} in revolutions."
            + _contact_sentence(rungs)
        ),
        "evidence": "ladder, clutch_pull, lr_study", "section": "Where L >> r breaks down",
        "short": "first-order kinematics off by > 1 % in revolutions "
                 + describe_threshold(study["thresholds"]["revolutions"]["1%"]).split(" (")[0],
        "key": f"{_percent(cost(paper['revolutions'], exact['revolutions']))} at this L/r",
    }
    numerical = max(convergence["mujoco_default_error"], convergence["equations_default_error"])
    trust = {
        "question": "Is the numerical error small against the modelling differences?",
        "answer": ("Yes" if numerical < 0.2 * smallest else "No") + ": halving MuJoCo's timestep from its default "
                  f"moves the summary figures by at most {100 * convergence['mujoco_default_error']:.3f} %, and "
                  f"tightening the equations' tolerance 100-fold by {100 * convergence['equations_default_error']:.1e} %; the "
                  f"smallest modelling effect in the ladder ({smallest_name}) changes them by up to "
                  f"{100 * smallest:.2f} %.",
        "evidence": "convergence", "section": "Numerical convergence",
        "short": "Yes" if numerical < 0.2 * smallest else "No",
        "key": f"{100 * convergence['mujoco_default_error']:.3f} % (MuJoCo, timestep halved)",
    }
    return [_paper_verdict(checks, identities, case), engine, costs, trust]


def _contact_sentence(rungs: list[LadderRun]) -> str:
    """The costs verdict's words on the last rung, the robot on wheels in contact (empty without it)."""
    named = {r.name: r.run.summary for r in rungs}
    if "wheels in contact" not in named:
        return ""
    wheels, ratchet = named["wheels in contact"], named["MuJoCo ratchet"]
    return (" The slides (against wheels pressed on the pipe's walls: MuJoCo's contacts, a ratchet in every hub) "
            f"cost {_percent(cost(ratchet['revolutions'], wheels['revolutions']))} in crank revolutions and "
            f"{_percent(cost(ratchet['x1_final'], wheels['x1_final']))} in module 1's travel ({_press(wheels)}; "
            f"MuJoCo's energy residual {_residual(named['wheels in contact'])}).")


def _press(summary: dict) -> str:
    """The wheels' press and grip as MuJoCo has them, beside the slides' constant press (the constant-press
    idealization's measure): mean press per module, wheels off their wall, grip mu_wall x press where finite."""
    text = (f"the wheels pressed {summary['press1_n']:.4g} / {summary['press2_n']:.4g} N on the mean, a wheel off its "
            f"wall {summary['wheel_off_s']:.3g} s")
    if summary.get("grip1_n") is not None:
        text += f", a grip of {summary['grip1_n']:.4g} / {summary['grip2_n']:.4g} N (mu_wall x press)"
    return text


def _residual(summary: dict) -> str:
    accuracy = summary.get("accuracy") or {}
    ratio = accuracy.get("residual_ratio")
    return "unknown" if ratio is None else f"{ratio:.1e} of the energy put through"
