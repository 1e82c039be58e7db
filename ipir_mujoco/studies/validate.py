"""The validation job: the model ladder at the paper's case, checked and measured.

Each rung of the ladder removes one idealization of the paper, so the change
from one rung to the next is what that idealization costs. This version runs
the analytic rungs; the MuJoCo and one-way-clutch rungs join as their engines
land.

``metrics.json`` (schema version 1)::

    schema_version        int, 1
    verdicts              list of {question, answer, evidence}: the report's opening
    paper_checks          list of {key, label, reported, value, low, high, units,
                          why, reproduced}: the paper's model against each figure
                          the paper reports (see ipir_mujoco.studies.paper_reference)
    ladder                list of {name, engine, geometry, clutch, isolates,
                          summary, change_vs_previous}; summary as CONTRACT.md;
                          change_vs_previous maps each ladder figure to the
                          relative change (new - old) / |old| against the rung
                          before (null for the first rung or a zero reference)
    clutch_pull           {fraction_of_time, min_reaction_n, per_stroke: [{mode, t_start,
                          t_end, mean_crank_speed, pull_fraction}]}: how much of the
                          paper-model run (and of each stroke) has a locked clutch
                          that would have to pull
    lr_study              {ratios, rows: [{ratio, L, first_order, exact, mujoco,
                          divergence, mujoco_vs_exact}], thresholds: {figure: {"1%"|"5%":
                          {between: [lo, hi]} | {below_sweep} | {whole_sweep}}}}: see
                          ipir_mujoco.studies.lr_study; divergence = (first order - exact) / |exact|,
                          S_at_angle / S_dot_at_angle as fractions of 2r / max|S_dot|
    convergence           {mujoco: [rows of ipir_mujoco.studies.convergence], equations: [{rtol,
                          revolutions, x1_final, x2_final, residual_fraction}],
                          mujoco_default_error, equations_default_error}: largest
                          relative change of revolutions/x1/x2 from the default setting
                          to the finest one tried
    params                the parameter set used (SI units)
    settings              {t_end_s, quick, dt_out_s, rtol, atol, mujoco: {timestep,
                          integrator, constraint_time_constant, solimp}}
    versions              software versions
"""

from __future__ import annotations

import platform
import sys
import time
from dataclasses import dataclass
from typing import Callable

import numpy as np

from ipir_mujoco import analytic
from ipir_mujoco.analytic.params import RobotParams
from ipir_mujoco.analytic.results import MODE_NAMES, Mode, RunResult

from .. import __version__
from ..engine import simulate_mujoco
from ..engine.model import SolverSettings
from .paper_reference import check_paper_figures

LADDER_FIGURES = ("revolutions", "x1_final", "x2_final", "v1_max", "v2_max", "first_contraction_end_s",
                  "min_clutch_reaction_n")

# the rungs drawn over the paper's Fig. 2-4 (one line style each)
FIGURE_RUNGS = ("paper model", "MuJoCo, paper's rule", "MuJoCo ratchet")


@dataclass
class Rung:
    """One step of the model ladder."""

    name: str
    isolates: str  # the assumption this rung removes, in words
    run: RunResult


def run_ladder(params: RobotParams, t_end: float, dt_out: float, rtol: float, atol: float,
               progress: Callable[[str], None]) -> list[Rung]:
    """Run the rungs that exist, from the paper's model up to MuJoCo's ratchet."""
    massless = params.replace(rod_mass=0.0, rod_inertia=0.0)

    def equations(rung_params, geometry, clutch="kinematic"):
        return lambda: analytic.simulate(rung_params, geometry, clutch, t_end, dt_out=dt_out,
                                         rtol=rtol, atol=atol)

    def physics(rule, implementation):
        return lambda: simulate_mujoco(params, rule, implementation, t_end, dt_out=dt_out)

    plan = (
        ("paper model", "nothing: first-order kinematics (L >> r), massless rod, ideal locks",
         equations(massless, "approx")),
        ("exact geometry", "L >> r: the exact slider-crank", equations(massless, "exact")),
        ("with rod mass", f"the massless rod: rod of {params.rod_mass:g} kg", equations(params, "exact")),
        ("MuJoCo, paper's rule", "the equations: MuJoCo physics of the same linkage, locks by the paper's rule",
         physics("kinematic", "lock")),
        ("one-way clutches", "ideal locks: clutches that can only push (equations, complementarity)",
         equations(params, "exact", "unilateral")),
        ("MuJoCo ratchet", "the equations again: MuJoCo physics with one-way clutches (joint-limit ratchet)",
         physics("unilateral", "ratchet")),
    )
    rungs = []
    for i, (name, isolates, simulate) in enumerate(plan, start=1):
        started = time.perf_counter()
        progress(f"[{i}/{len(plan)}] {name} ...")
        run = simulate()
        progress(f"[{i}/{len(plan)}] {name}: {run.summary['revolutions']:.3f} rev "
                 f"({time.perf_counter() - started:.2f} s)")
        rungs.append(Rung(name, isolates, run))
    return rungs


def relative_change(new: float | None, old: float | None) -> float | None:
    """(new - old) / |old|, or None where either is missing or old is zero."""
    if new is None or old is None or old == 0:
        return None
    return (new - old) / abs(old)


def locked_reaction(s: dict[str, np.ndarray]) -> np.ndarray:
    """Reaction of the clutch the paper's rule locks at each sample [N] (inf where none is locked)."""
    return np.where(s["mode"] == Mode.CONTRACTION, s["lambda2"],
                    np.where(s["mode"] == Mode.EXPANSION, s["lambda1"], np.inf))


def clutch_pull(run: RunResult) -> dict:
    """How much of the run has a locked clutch whose reaction is negative (would have to pull)."""
    s = run.series
    pulling = locked_reaction(s) < 0
    dt = np.diff(s["t"])
    fraction = float(np.sum(dt * pulling[:-1]) / np.sum(dt))
    return {"fraction_of_time": fraction, "min_reaction_n": run.summary["min_clutch_reaction_n"]}


def software_versions() -> dict[str, str]:
    import matplotlib
    import mujoco
    import scipy

    return {"ipir_mujoco": __version__, "python": sys.version.split()[0], "numpy": np.__version__,
            "scipy": scipy.__version__, "matplotlib": matplotlib.__version__, "mujoco": mujoco.__version__,
            "platform": platform.platform()}


def _percent(x: float | None) -> str:
    return "n/a" if x is None else f"{100 * x:+.2f} %"


def verdicts(checks: list[dict], rungs: list[Rung], pull: dict, study: dict, ladder: list[dict],
             convergence: dict) -> list[dict]:
    """The report's opening: plain questions, plain answers, the numbers behind them."""
    from .lr_study import describe_threshold
    n_ok = sum(c["reproduced"] for c in checks)
    missed = [c["label"] for c in checks if not c["reproduced"]]
    reproduce = {
        "question": "Does the paper's model reproduce the paper's own figures?",
        "answer": ("Yes" if not missed else "No") + f": {n_ok} of {len(checks)} reported figures land within "
                  "the reading precision of the paper's plots" + ("" if not missed else f"; missed: {', '.join(missed)}"),
        "evidence": "paper_checks",
    }
    paper, exact, rod, locks, one_way, ratchet = (r.run.summary for r in rungs[:6])
    worst = max(abs(relative_change(locks[k], rod[k])) for k in ("revolutions", "x1_final", "x2_final"))
    engine = {
        "question": "Does MuJoCo reproduce the paper's model when given the paper's assumptions?",
        "answer": ("Yes" if worst < 0.003 else "No") + ": with locks that follow the paper's rule, MuJoCo's "
                  f"real linkage matches the equations of the same linkage (exact geometry, same rod) to "
                  f"{_percent(relative_change(locks['revolutions'], rod['revolutions']))} in crank revolutions, "
                  f"{_percent(relative_change(locks['x1_final'], rod['x1_final']))} and "
                  f"{_percent(relative_change(locks['x2_final'], rod['x2_final']))} in the module displacements; "
                  "against the paper's first-order equations it differs by "
                  f"{_percent(relative_change(locks['revolutions'], paper['revolutions']))} in revolutions, "
                  "which is the cost of L >> r, not of the engine.",
        "evidence": "ladder",
    }
    costs = {
        "question": "What do the idealizations cost?",
        "answer": (
            f"First-order kinematics is off by more than 1 % in crank revolutions "
            f"{describe_threshold(study['thresholds']['revolutions']['1%'])} and by more than 5 % "
            f"{describe_threshold(study['thresholds']['revolutions']['5%'])}; module 1's travel is more sensitive "
            f"(1 % {describe_threshold(study['thresholds']['x1_final']['1%'])}). "
            f"At the paper's L/r = {rungs[0].run.params.L / rungs[0].run.params.r:g} the exact "
            f"slider-crank changes crank revolutions by {_percent(relative_change(exact['revolutions'], paper['revolutions']))}, "
            f"module 1 displacement by {_percent(relative_change(exact['x1_final'], paper['x1_final']))} and the "
            f"end of the first contraction by {_percent(relative_change(exact['first_contraction_end_s'], paper['first_contraction_end_s']))}. "
            f"The rod's mass changes revolutions by a further {_percent(relative_change(rod['revolutions'], exact['revolutions']))}. "
            f"Ideal locks: in {100 * pull['fraction_of_time']:.1f} % of the paper-model run a locked clutch would "
            f"have to pull, with up to {-pull['min_reaction_n']:.0f} N; a one-way clutch cannot. One-way "
            f"clutches (MuJoCo's ratchet) change crank revolutions by {_percent(relative_change(ratchet['revolutions'], locks['revolutions']))} "
            f"and the modules' travel by {_percent(relative_change(ratchet['x1_final'], locks['x1_final']))} "
            f"(rear) and {_percent(relative_change(ratchet['x2_final'], locks['x2_final']))} (front) against the "
            "same physics with the paper's locks: the largest idealization cost. The one-way-clutch equations "
            f"agree with that physics to {_percent(relative_change(ratchet['revolutions'], one_way['revolutions']))} "
            "in revolutions."
        ),
        "evidence": "ladder, clutch_pull",
    }
    modelling = {r["name"]: max(abs(r["change_vs_previous"][k]) for k in ("revolutions", "x1_final", "x2_final")
                                if r["change_vs_previous"][k] is not None)
                 for r in ladder if r["name"] in ("exact geometry", "with rod mass", "one-way clutches")}
    smallest_name = min(modelling, key=modelling.get)
    smallest = modelling[smallest_name]
    numerical = max(convergence["mujoco_default_error"], convergence["equations_default_error"])
    trust = {
        "question": "Is the numerical error small against the modelling differences?",
        "answer": ("Yes" if numerical < 0.2 * smallest else "No") + ": halving MuJoCo's timestep from its default "
                  f"moves the summary figures by at most {100 * convergence['mujoco_default_error']:.3f} %, and "
                  f"tightening the equations' tolerance 100-fold by {100 * convergence['equations_default_error']:.1e} %; the "
                  f"smallest modelling effect in the ladder ({smallest_name}) changes them by up to "
                  f"{100 * smallest:.2f} %.",
        "evidence": "convergence",
    }
    return [reproduce, engine, costs, trust]


def build_metrics(params: RobotParams, rungs: list[Rung], settings: dict, study: dict, convergence: dict) -> dict:
    checks = check_paper_figures(rungs[0].run)
    pull = clutch_pull(rungs[0].run)
    pull["per_stroke"] = pull_per_stroke(rungs[0].run)
    ladder, previous = [], None
    for rung in rungs:
        summary = rung.run.summary
        change = {k: (None if previous is None else relative_change(summary[k], previous[k])) for k in LADDER_FIGURES}
        ladder.append({"name": rung.name, "engine": rung.run.engine, "geometry": rung.run.geometry,
                       "clutch": rung.run.clutch, "isolates": rung.isolates, "params": rung.run.params.as_dict(),
                       "summary": summary, "change_vs_previous": change})
        previous = summary
    return {
        "schema_version": 1,
        "verdicts": verdicts(checks, rungs, pull, study, ladder, convergence),
        "paper_checks": checks,
        "ladder": ladder,
        "clutch_pull": pull,
        "lr_study": study,
        "convergence": convergence,
        "params": params.as_dict(),
        "settings": settings,
        "versions": software_versions(),
    }


def validate(params: RobotParams, quick: bool = False, progress: Callable[[str], None] = lambda _m: None):
    """Run everything the report needs and return (metrics, rungs).

    ``quick`` samples outputs 10x coarser and sweeps L/r, timesteps and
    tolerances on coarser grids (for tests and CI).
    """
    from .lr_study import RATIOS_FULL, RATIOS_QUICK, lr_study

    settings = {"t_end_s": 1.0, "quick": quick, "dt_out_s": 1e-3 if quick else 1e-4, "rtol": 1e-10, "atol": 1e-12,
                "mujoco": SolverSettings().as_dict()}
    rungs = run_ladder(params, settings["t_end_s"], settings["dt_out_s"], settings["rtol"], settings["atol"], progress)
    study = lr_study(params, RATIOS_QUICK if quick else RATIOS_FULL, settings["t_end_s"], 1e-3, progress)
    convergence = convergence_evidence(params, quick, lambda m: progress(f"convergence: {m}"))
    return build_metrics(params, rungs, settings, study, convergence), rungs


def pull_per_stroke(run: RunResult) -> list[dict]:
    """Per stroke of the paper's model: mean crank speed and the fraction of its time a lock would pull."""
    s = run.series
    locked = locked_reaction(s)
    strokes, start = [], 0
    changes = np.flatnonzero(np.diff(s["mode"]) != 0)
    for end in list(changes + 1) + [len(s["t"])]:
        t, reaction = s["t"][start:end], locked[start:end]
        if end - start > 2 and t[-1] > t[0]:
            dt = np.diff(t)
            strokes.append({"mode": MODE_NAMES[int(s["mode"][start])], "t_start": float(t[0]), "t_end": float(t[-1]),
                            "mean_crank_speed": float((s["phi"][end - 1] - s["phi"][start]) / (t[-1] - t[0])),
                            "pull_fraction": float(np.sum(dt * (reaction[:-1] < 0)) / np.sum(dt))})
        start = end
    return strokes


def convergence_evidence(params: RobotParams, quick: bool, progress: Callable[[str], None]) -> dict:
    """MuJoCo's figures against its timestep, the equations' against their tolerance (paper's case)."""
    from .convergence import timestep_study

    timesteps = (1e-4, 5e-5) if quick else (4e-4, 2e-4, 1e-4, 5e-5)
    rows = timestep_study({"paper's case": params}, timesteps, progress=progress)
    equations = []
    for rtol in ((1e-10, 1e-12) if quick else (1e-6, 1e-8, 1e-10, 1e-12)):
        run = analytic.simulate(params, "exact", "unilateral", 1.0, rtol=rtol, atol=rtol * 1e-2, dt_out=1e-3)
        equations.append({"rtol": rtol, **{k: run.summary[k] for k in ("revolutions", "x1_final", "x2_final")},
                          "residual_fraction": run.summary["energy"]["residual_j"] / run.summary["energy"]["motor_work_j"]})
    default = SolverSettings().timestep

    def spread(items, key_filter):
        chosen = [r for r in items if key_filter(r)]
        return max(abs(a[k] - b[k]) / abs(b[k]) for a in chosen for b in chosen
                   for k in ("revolutions", "x1_final", "x2_final"))

    # numerical error of the defaults: change from the default setting to the finest one tried
    mj_error = max(spread(rows, lambda r, c=c: r["clutch"] == c and r["timestep"] <= default)
                   for c in ("lock", "ratchet"))
    eq_error = spread(equations, lambda r: r["rtol"] <= 1e-10)
    return {"mujoco": rows, "equations": equations, "mujoco_default_error": mj_error,
            "equations_default_error": eq_error}
