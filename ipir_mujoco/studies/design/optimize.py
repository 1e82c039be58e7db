"""Design optimization: the best design, or the Pareto front, of bounded parameters under constraints.

Designs are evaluated in the fast engine (default ``analytic-unilateral``) by
:class:`~ipir_mujoco.studies.design_eval.Evaluator` (the sweep's per-design task and pool, streamed to
``OUT/evaluations.csv``); the optimum or every point of the front is then re-run in the verifying engine
(default ``mujoco-ratchet``), its divergence (verify - engine) / |engine| beside it in ``OUT/pareto.csv``.
A design that stalls or fails is infeasible.

One objective: a scrambled Sobol warm start (``n0`` points of the budget, run at once on the pool),
then COBYQA (scipy.optimize.minimize: derivative-free trust-region, bounds and nonlinear constraints,
a hard cap on function evaluations) from the best start, on the unit box (log axes in log space). The
metrics are smooth in the parameters but carry a steady-state detection's small noise, which rules
out finite-difference gradients; a few parameters and a budget of tens of evaluations suit a model-based
local method better than a population method such as differential evolution, whose populations alone
would spend the budget. The reported optimum is the best feasible design ever evaluated.

Several objectives: NSGA-II (pymoo 0.6), one population evaluated at once on the pool per generation.

Both are seeded, so a resumed study proposes the same designs again, finds them in evaluations.csv and
runs only the rest.

Its problem (ranges, objectives, constraints, engines, budget): :mod:`.optimize_problem`, re-exported here.
"""

from __future__ import annotations

import json
import math
import os
import warnings
from pathlib import Path

import numpy as np

from ipir_mujoco.core.errors import ParameterError, ParameterTypeError, refuse_all_failed
from ipir_mujoco.core.options import check_type
from ipir_mujoco.core.params import check_whole
from ipir_mujoco.core.results import write_json

from ..figure_errors import unusable_counts, why_unusable
from ...output import check_output_dir, study_folder
from .design_eval import Evaluator, key_value, verify_rows
from .optimize_problem import (  # noqa: F401  (re-exported: every name stays importable from here)
    DEFAULT_BUDGET, DEFAULT_ENGINE, DEFAULT_VERIFY, POPULATION, Constraint, Objective, Problem, parse_constraint,
    parse_objective)


def check_resume(out: Path, problem: Problem, resume: bool) -> None:
    meta = out / "optimize.json"
    if resume and out.is_dir() and any(out.iterdir()):
        try:
            previous = json.loads(meta.read_text(encoding="utf-8")).get("fingerprint")
        except (OSError, ValueError, UnicodeDecodeError, AttributeError):
            raise ParameterError(f"--resume --out {str(out)!r}: the folder holds no optimization (no readable "
                                 "optimize.json)") from None
        if previous != problem.fingerprint():
            raise ParameterError(f"{str(out)!r} holds another optimization (its settings differ); resume needs the "
                                 "same one")
    elif (out / "evaluations.csv").exists():
        raise ParameterError(f"{str(out / 'evaluations.csv')!r} exists; use --resume to complete it, or another --out")


def non_dominated(points: np.ndarray) -> np.ndarray:
    """Indices of the rows of ``points`` (to minimise) that no other row dominates."""
    keep = []
    for i, p in enumerate(points):
        dominated = np.any(np.all(points <= p, axis=1) & np.any(points < p, axis=1))
        if not dominated:
            keep.append(i)
    return np.asarray(keep, dtype=int)


def _single(problem: Problem, ev: Evaluator) -> None:
    from scipy.optimize import NonlinearConstraint, minimize
    from scipy.stats import qmc

    d = len(problem.axes)
    n0 = min(problem.budget, max(8, 4 * d))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # scipy's note when n0 is not a power of 2: the start stays space-filling
        unit = qmc.Sobol(d=d, scramble=True, seed=problem.seed).random(n0)
    rows = ev.evaluate([problem.design(u) for u in unit])
    left = problem.budget - n0
    if left < 2:
        return
    starts = [(problem.feasible(r), problem.objective_values(r)[0], -_violation(problem, r), k)
              for k, r in enumerate(rows)]
    feasible = [s for s in starts if s[0]]
    k0 = min(feasible, key=lambda s: s[1])[3] if feasible else max(starts, key=lambda s: s[2])[3]
    span = [float(np.nanmax([problem.objective_values(r)[0] for r in rows] + [0.0])),
            float(np.nanmin([problem.objective_values(r)[0] for r in rows] + [0.0]))]
    worst = span[0] + abs(span[0] - span[1]) + 1.0  # a stalled or failed design's objective: worse than any seen

    def row_at(u):
        return ev.evaluate([problem.design(u)])[0]

    def fun(u):
        r = row_at(u)
        v = problem.objective_values(r)[0]
        return v if math.isfinite(v) and not (r.get("error") or r.get("stalled") == 1) else worst

    def slacks(u):
        r = row_at(u)
        failed = bool(r.get("error")) or r.get("stalled") == 1
        return np.array([-1.0 if failed else _scaled(c, key_value(c.key, r, problem.base))
                         for c in problem.constraints])

    constraints = [NonlinearConstraint(slacks, 0.0, np.inf)] if problem.constraints else []
    minimize(fun, unit[k0], method="COBYQA", bounds=[(0.0, 1.0)] * d, constraints=constraints,
             options={"maxfev": left, "initial_tr_radius": 0.25, "final_tr_radius": 1e-5})


def _scaled(c: Constraint, value) -> float:
    s = c.slack(value)
    return max(s / max(abs(c.value), 1e-12), -1.0) if math.isfinite(s) else -1.0


def _violation(problem: Problem, row: dict) -> float:
    if row.get("error") or row.get("stalled") == 1:
        return math.inf
    return sum(max(0.0, -_scaled(c, key_value(c.key, row, problem.base))) for c in problem.constraints)


def _multi(problem: Problem, ev: Evaluator) -> None:
    try:
        from pymoo.algorithms.moo.nsga2 import NSGA2
        from pymoo.core.problem import Problem as PymooProblem
        from pymoo.optimize import minimize
    except ImportError:
        raise ParameterError("several objectives need pymoo: pip install 'ipir-mujoco[optimize]'") from None
    pop = min(POPULATION, problem.budget)
    generations = max(1, problem.budget // pop)
    n_obj, n_con = len(problem.objectives), len(problem.constraints)

    class _P(PymooProblem):
        def _evaluate(self, X, out, *args, **kwargs):
            rows = ev.evaluate([problem.design(x) for x in X])
            F, G = [], []
            for r in rows:
                failed = bool(r.get("error")) or r.get("stalled") == 1
                f = problem.objective_values(r)
                F.append([1e30 if failed or not math.isfinite(v) else v for v in f])
                G.append([1.0 if failed else -_scaled(c, key_value(c.key, r, problem.base))
                          for c in problem.constraints] + ([1.0 if failed else -1.0] if not n_con else []))
            out["F"], out["G"] = np.array(F), np.array(G)

    minimize(_P(n_var=len(problem.axes), n_obj=n_obj, n_ieq_constr=max(1, n_con), xl=0.0, xu=1.0),
             NSGA2(pop_size=pop), ("n_gen", generations), seed=problem.seed, verbose=False)


OUTPUT_FILES = ("evaluations.csv", "pareto.csv", "optimize.json", "pareto.png")


def run_optimize(problem: Problem, out: str | Path, *, resume: bool = False, workers: int | None = None,
                 progress: bool = True, executor=None, figure=None) -> dict:
    """Run ``problem``; write OUT/evaluations.csv, pareto.csv, optimize.json; return optimize.json's record.

    ``executor``: any ``concurrent.futures.Executor`` (a Dask client's, ``--scheduler``) instead of the pool.
    ``figure``: a function of the folder that draws into it (the command line's pareto.png), called before
    optimize.json says ``"status": "done"``, which it says last. Every argument, the folder and the file to
    resume are checked before the first design; the folder is locked while the study runs (a second run on it
    is refused). Ctrl-C raises :class:`~ipir_mujoco.core.errors.StudyInterrupted` with every evaluation kept.
    """
    check_type("problem", problem, Problem, "an optimize.Problem")
    check_type("out", out, (str, os.PathLike), "the path of the results folder")
    check_type("resume", resume, bool, "True or False")
    check_type("progress", progress, bool, "True or False")
    if workers is not None:
        check_whole("workers", workers, low=1, high=1024)
    if figure is not None and not callable(figure):
        raise ParameterTypeError(f"figure={figure!r} is not callable; allowed: a function of the results folder, "
                                 "or None")
    out = check_output_dir(out, files=OUTPUT_FILES)
    check_resume(out, problem, resume)
    if len(problem.objectives) > 1:
        try:
            import pymoo  # noqa: F401
        except ImportError:
            raise ParameterError("several objectives need pymoo: pip install 'ipir-mujoco[optimize]'") from None
    with study_folder(out):
        check_resume(out, problem, resume)  # again, under the lock: what another run may have left
        return _run_locked(problem, out, resume, workers, progress, executor, figure)


def _run_locked(problem: Problem, out: Path, resume: bool, workers, progress: bool, executor, figure) -> dict:
    settings = problem.to_json()
    options = {"until_steady": problem.until_steady}
    # progress against the budget: the most the search may ask for (COBYQA may converge before it)
    ev = Evaluator(out / "evaluations.csv", problem.names, problem.base, problem.engine, problem.t_end,
                   problem.study.dt_out, options, resume, workers, progress, total=problem.budget,
                   executor=executor, axes=problem.axes)
    if not (resume and (out / "optimize.json").is_file()):  # resumed: the same study's (check_resume), left as it is
        write_json(out / "optimize.json", {"fingerprint": problem.fingerprint(), "settings": settings,
                                           "status": "running"})
    with ev:
        (_single if len(problem.objectives) == 1 else _multi)(problem, ev)
        rows = list(ev.cache.values())
        reused = ev.reused
    rows.sort(key=lambda r: r["eval_id"])
    refuse_all_failed([r.get("error") for r in rows], "designs", str(out / "evaluations.csv"))
    feasible = [r for r in rows if problem.feasible(r)]
    if feasible:
        points = np.array([problem.objective_values(r) for r in feasible])
        front = [feasible[i] for i in non_dominated(points)]
        front.sort(key=lambda r: problem.objective_values(r))
        if len(problem.objectives) == 1:
            front = front[:1]
    else:
        front = []
    keys = list(dict.fromkeys([o.key for o in problem.objectives] + [c.key for c in problem.constraints]
                              + ["steady_speed_m_s" if problem.until_steady else "mean_speed_m_s"]))
    if problem.verify and front:
        front = verify_rows(front, problem.names, problem.base, problem.engine, problem.verify, keys,
                            problem.t_end, problem.study.dt_out, options, workers, executor)
    _write_front(out / "pareto.csv", front, problem, keys)
    record = {"fingerprint": problem.fingerprint(), "settings": settings, "status": "done",
              "evaluations": len(rows), "feasible": len(feasible), "reused_on_resume": reused,
              "flat_objectives": flat_objectives(problem, feasible),
              # the runs that gave nothing, by why (a MuJoCo figure with its error bar is used, its bar in notes)
              "unusable": unusable_counts(why_unusable(r["error"]) for r in rows if r.get("error"))}
    summary = [_summary(r, problem, keys) for r in front]
    if len(problem.objectives) == 1:
        record["best"] = summary[0] if summary else None
    else:
        record["front"] = summary
    if figure is not None:
        figure(out)
    write_json(out / "optimize.json", _finite(record))  # last: "done" only once every file is written
    return record


def flat_objectives(problem: Problem, feasible: list[dict]) -> list[str]:
    """The objectives whose value is the same in every feasible design (of two or more): a search that
    cannot tell its designs apart, which the command line says rather than naming an arbitrary best (the
    usual cause: a run too short to complete a revolution, whose per-revolution figures read 0 or empty)."""
    if len(feasible) < 2:
        return []
    columns = np.array([problem.objective_values(r) for r in feasible])
    return [o.key for o, column in zip(problem.objectives, columns.T) if np.all(column == column[0])]


def _finite(data):
    """JSON has no NaN or infinity: those become null."""
    if isinstance(data, dict):
        return {k: _finite(v) for k, v in data.items()}
    if isinstance(data, list):
        return [_finite(v) for v in data]
    return None if isinstance(data, float) and not math.isfinite(data) else data


def _summary(row: dict, problem: Problem, keys: list[str]) -> dict:
    """A design of the result: its parameters and metrics at the top level, its verification beside."""
    from ..sweeps.sweep_metrics import DESCRIBED

    item = {n: row[n] for n in problem.names}
    item.update({m: row.get(m) for m in DESCRIBED})
    item["eval_id"] = row["eval_id"]
    if problem.verify:
        item["verify"] = {k: row.get(k) for k in row if k.startswith((f"{problem.verify}:", "divergence:"))
                          or k == "verify_error"}
    return item


def _write_front(path: Path, front: list[dict], problem: Problem, keys: list[str]) -> None:
    import csv

    from ..sweeps.sweep_metrics import METRICS

    header = ["eval_id", *problem.names, *METRICS]
    if problem.verify:
        header += [f"{problem.verify}:{k}" for k in keys if k in METRICS] + [f"divergence:{k}" for k in keys
                                                                            if k in METRICS] + ["verify_error"]
    staged = path.with_name(f".{path.name}.tmp")
    with staged.open("w", newline="", encoding="utf-8") as fh:
        writer = csv.writer(fh)
        writer.writerow(header)
        for row in front:
            writer.writerow(["" if row.get(c) is None else (repr(row[c]) if isinstance(row[c], float) else row[c])
                             for c in header])
    staged.replace(path)
