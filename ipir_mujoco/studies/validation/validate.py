"""The validation job: the model ladder, checked and measured.

Each rung of the ladder removes one idealization of the paper, so the change
from one rung to the next is what that idealization costs.

At the paper's own design the paper's model is also checked against the
figures the paper reports; at any other design (``validate --set L=0.3``) the
report says so, checks nothing against the paper's printed figures, and
compares every rung with the paper's model at that design (the first rung).

``metrics.json`` (schema version 2; version 1 had no ``paper_case``,
``identities`` or ``parameter_table``, counted the two identities among
``paper_checks`` and had no ``status``, ``precision`` or ``note`` in them)::

    schema_version        int, 2
    verdicts              list of {question, answer, evidence}: the report's opening
    paper_case            {is_paper_case, differences: [{name, value, paper}]}: whether
                          the parameters are the paper's simulation case
    paper_checks          list of {key, label, reported, reported_value, precision,
                          value, low, high, units, why, note, status, margin_precisions,
                          reproduced}: the paper's model against each figure the paper
                          reports; [low, high] = reported_value -+ precision / 2;
                          status 'inside' | 'edge' | 'outside'; reproduced = not
                          outside; margin_precisions = distance to the nearer bound
                          in units of precision (see ipir_mujoco.studies.paper_reference).
                          Empty when not the paper's case.
    identities            list of {key, label, reported, expected, value, units, holds}:
                          S_min = L - r and S_max = L + r, true by construction
    ladder                list of {name, engine, geometry, clutch, isolates, params,
                          summary, change_vs_previous, cost_vs_previous}; summary as in
                          docs/cli.md; change_vs_previous maps each ladder figure to the
                          relative change (new - old) / |old| against the rung
                          before (null for the first rung or a zero reference);
                          cost_vs_previous to the cost of the idealization the rung
                          removes, (old - new) / |new| (the model with it against the
                          model without it: the report's convention, which it shows)
    clutch_pull           {fraction_of_time, min_reaction_n, per_stroke: [{mode, t_start,
                          t_end, mean_crank_speed, pull_fraction, complete}]}: how much of the
                          paper-model run (and of each stroke) has a locked clutch
                          that would have to pull
    lr_study              {ratios, rows: [{ratio, L, first_order, exact, exact_with_rod, mujoco,
                          divergence, mujoco_vs_exact}], thresholds: {figure: {"1%"|"5%":
                          {between: [lo, hi]} | {below_sweep} | {whole_sweep}}}}: see
                          ipir_mujoco.studies.lr_study; divergence = (first order - exact) / |exact|,
                          S_at_angle / S_dot_at_angle as fractions of 2r / max|S_dot|
    convergence           {mujoco: [rows of ipir_mujoco.studies.convergence], equations: [{rtol,
                          revolutions, x1_final, x2_final, residual_fraction}],
                          mujoco_default_error, mujoco_auto_timestep: {clutch: s},
                          equations_default_error, envelope}: largest relative change of
                          revolutions/x1/x2 among the default setting (for MuJoCo, each
                          clutch's automatic step) and the finer ones tried; envelope: ipir_mujoco.studies.convergence.
                          envelope_study over the envelope's corners (two of them with --quick)
    sections              {key: metrics} of each further study the report runs
                          (see ipir_mujoco.report.sections)
    params                the parameter set used (SI units; rod_inertia resolved)
    parameter_table       list of {name, value, text, units, meaning}: text shows
                          'rigid' / 'uniform' where the value was left to its default rule
    settings              {t_end_s, quick, dt_out_s, rtol, atol, mujoco: {timestep,
                          integrator, constraint_time_constant, solimp} (the largest step the
                          engine chooses by itself), mujoco_runs: {rung name: the same four, as
                          chosen from the motion for that run}}
    versions              software versions
"""

from __future__ import annotations

import platform
import sys
import time
from dataclasses import dataclass
from typing import Callable, Sequence

import numpy as np

from ipir_mujoco import registry
from ipir_mujoco.core.options import (HEARTBEAT_S, LIVE_HEARTBEAT_S, Status, heartbeat, progress_text,
                                      throttled)
from ipir_mujoco.core.params import RobotParams
from ipir_mujoco.core.results import MODE_NAMES, Mode, RunResult

from ... import __version__
from ..comparison.compare import cost, relative_change
from .convergence import convergence_evidence
from .ladder import VALIDATION_LADDER
from .lr_study import RATIOS_FULL, RATIOS_QUICK, lr_study
from .paper_reference import check_identities, check_paper_figures, differences_from_paper
from .verdicts import _press, verdicts  # noqa: F401  (re-exported: tests read the wheels' press words here)

LADDER_FIGURES = ("revolutions", "x1_final", "x2_final", "v1_max", "v2_max", "first_contraction_end_s",
                  "min_clutch_reaction_n")

# the rungs drawn over the paper's Fig. 2-4 (one line style each)
FIGURE_RUNGS = ("paper model", "MuJoCo, paper's rule", "MuJoCo ratchet")


@dataclass
class LadderRun:
    """One rung of the model ladder (:data:`.ladder.LADDER`) and its run."""

    name: str
    isolates: str  # the assumption this rung removes, in words
    run: RunResult


def run_ladder(params: RobotParams, t_end: float, dt_out: float, rtol: float, atol: float,
               progress: Callable[[str], None]) -> list[LadderRun]:
    """Every rung of the ladder for ``t_end`` [s], from the paper's model up to MuJoCo's ratchet: the
    equations at the solver tolerances ``rtol``/``atol``, MuJoCo with its automatic settings."""
    rungs = []
    for i, rung in enumerate(VALIDATION_LADDER, start=1):
        started = time.perf_counter()
        progress(f"[{i}/{len(VALIDATION_LADDER)}] {rung.name} ...")
        tolerances = ({"accuracy": rung.accuracy} if registry.variant(rung.variant).is_mujoco
                      else {"rtol": rtol, "atol": atol})
        # the run's time as the command line's status line (every second, in place on a terminal), else every 5 s
        beat = throttled(lambda t, i=i, rung=rung: progress(Status(f"[{i}/{len(VALIDATION_LADDER)}] {rung.name}: "
                                                                   + progress_text(t, t_end))),
                         LIVE_HEARTBEAT_S if getattr(progress, "live", False) else HEARTBEAT_S)
        run = registry.run(rung.variant, rung.params(params), t_end, dt_out=dt_out, progress=beat, **tolerances)
        progress(f"[{i}/{len(VALIDATION_LADDER)}] {rung.name}: {run.summary['revolutions']:.3f} rev "
                 f"({time.perf_counter() - started:.2f} s)")
        rungs.append(LadderRun(rung.name, rung.describe(params), run))
    return rungs


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


def parameter_table(params: RobotParams) -> list[dict]:
    """Each parameter with its value in words: 'rigid' / 'uniform' where the default rule applies."""
    from ipir_mujoco.core.params import describe_parameters

    rows = []
    values = params.as_dict()
    for row in describe_parameters():
        name, given = row["name"], getattr(params, row["name"])
        value = values[name]
        if name == "rod_inertia" and given is None:
            text = f"{value:.6g} (uniform rod, rod_mass L^2 / 12)"
        elif given is None:
            text = row["default_text"]  # the word of a None default, e.g. 'rigid'
        else:
            text = value if isinstance(value, str) else f"{value:.6g}"
        rows.append({"name": name, "value": value, "text": text, "units": row["units"], "meaning": row["meaning"]})
    return rows


def build_metrics(params: RobotParams, rungs: list[LadderRun], settings: dict, study: dict, convergence: dict) -> dict:
    differences = differences_from_paper(params)
    case = {"is_paper_case": not differences, "differences": differences}
    checks = check_paper_figures(rungs[0].run) if case["is_paper_case"] else []
    identities = check_identities(rungs[0].run)
    pull = clutch_pull(rungs[0].run)
    pull["per_stroke"] = pull_per_stroke(rungs[0].run)
    ladder, previous = [], None
    for rung in rungs:
        summary = rung.run.summary
        change = {k: (None if previous is None else relative_change(summary[k], previous[k])) for k in LADDER_FIGURES}
        costs = {k: (None if previous is None else cost(previous[k], summary[k])) for k in LADDER_FIGURES}
        ladder.append({"name": rung.name, "engine": rung.run.engine, "geometry": rung.run.geometry,
                       "clutch": rung.run.clutch, "isolates": rung.isolates, "params": rung.run.params.as_dict(),
                       "summary": summary, "change_vs_previous": change, "cost_vs_previous": costs})
        previous = summary
    return {
        "schema_version": 2,
        "verdicts": verdicts(checks, identities, case, rungs, pull, study, ladder, convergence),
        "paper_case": case,
        "paper_checks": checks,
        "identities": identities,
        "ladder": ladder,
        "clutch_pull": pull,
        "lr_study": study,
        "convergence": convergence,
        "params": params.as_dict(),
        "parameter_table": parameter_table(params),
        "settings": settings,
        "versions": software_versions(),
    }


def validate(params: RobotParams, quick: bool = False, progress: Callable[[str], None] = lambda _m: None,
             sections: Sequence = ()):
    """Run everything the report needs and return (metrics, rungs).

    ``quick`` samples outputs 10x coarser and sweeps L/r, timesteps and
    tolerances on coarser grids (for tests and CI). ``sections``
    (:class:`ipir_mujoco.report.sections.Section`) are further studies: each
    one's metrics go to ``metrics["sections"][key]`` and its verdict, if it
    gives one, joins the verdicts.
    """
    settings = {"t_end_s": 1.0, "quick": quick, "dt_out_s": 1e-3 if quick else 1e-4, "rtol": 1e-10, "atol": 1e-12,
                "mujoco": registry.mujoco_defaults()}
    # the ladder's runs under the design's drive, without another drive's parameters (the motor's, given for the
    # sections that run the motor: each names its drive): a run refuses what its drive does not use
    own = params.replace(drive=params.drive)
    rungs = run_ladder(own, settings["t_end_s"], settings["dt_out_s"], settings["rtol"], settings["atol"], progress)
    # MuJoCo's settings are chosen per run from the motion: record what each MuJoCo rung used
    settings["mujoco_runs"] = {r.name: {k: r.run.settings[k] for k in ("timestep", "integrator",
                                                                         "constraint_time_constant", "solimp")}
                               for r in rungs if r.run.engine == "mujoco"}
    study = lr_study(own, RATIOS_QUICK if quick else RATIOS_FULL, settings["t_end_s"], 1e-3, progress)
    convergence = convergence_evidence(own, quick, lambda m: progress(f"convergence: {m}"))
    metrics = build_metrics(params, rungs, settings, study, convergence)
    run_sections(metrics, params, quick, progress, sections)
    return metrics, rungs


VERDICT_KEYS = ("question", "answer", "evidence", "short", "key")  # what every verdict states


def run_sections(metrics: dict, params: RobotParams, quick: bool, progress: Callable[[str], None],
                 sections: Sequence) -> None:
    """Compute each section into ``metrics["sections"]`` and add its verdict, if any (in place)."""
    metrics.setdefault("sections", {})
    for section in sections:
        started = time.perf_counter()
        progress(f"{section.title} ...")
        with heartbeat(progress, section.title) as beat:  # a line at least every 5 s whatever the section does
            result = section.compute(params, quick, lambda m, s=section: beat.say(f"{s.title}: {m}"))
        metrics["sections"][section.key] = result
        if section.verdict is not None and (verdict := section.verdict(result)) is not None:
            missing = [k for k in VERDICT_KEYS if k not in verdict]
            if missing:  # a section written without them: a programming error, said where it is
                raise ValueError(f"the verdict of section {section.key!r} lacks {', '.join(missing)}")
            metrics["verdicts"].append({**verdict, "section": section.title})
        progress(f"{section.title}: done ({time.perf_counter() - started:.1f} s)")


def pull_per_stroke(run: RunResult) -> list[dict]:
    """Per stroke of the paper's model: mean crank speed and the fraction of its time a lock would pull.

    ``complete`` is False for the last stroke, which the end of the run cuts
    short: its figures describe part of a stroke only.
    """
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
                            "pull_fraction": float(np.sum(dt * (reaction[:-1] < 0)) / np.sum(dt)),
                            "complete": bool(end < len(s["t"]))})
        start = end
    return strokes
