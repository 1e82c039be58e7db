"""The engagement-load study: what a real one-way clutch (stiffness k, backlash delta) does, in both engines.

For every clutch stiffness k [N/m] and backlash delta [m] of a grid, at each
operating point (:data:`POINTS`: the default motor's cruise, run to its
periodic steady state, and the paper's start-up, constant torque for 1 s from
rest), the analytic compliant clutch (exact geometry) and MuJoCo's compliant
ratchet run side by side, and so do the rigid clutches of both engines (the
limit k -> infinity: the analytic one-way model and MuJoCo's ratchet).

What each run measures (the peak clutch force and how finely it is sampled,
the peak acceleration, the travel lost and slid back per stroke, the
engagement behind the peak), the divergence between the engines and the
scaling with k are :mod:`.clutch_metrics`'s; this module plans the runs
(:func:`plan`: each run's design and MuJoCo timestep, checked before any
runs), runs them (:func:`run_tasks`) and puts the study together
(:func:`run_study`).
"""

from __future__ import annotations

import functools
import math
import os
import time
from dataclasses import asdict, dataclass
from typing import Callable, Sequence

import numpy as np

from ipir_mujoco import registry
from ipir_mujoco.registry import ENGINES
from ipir_mujoco.core.checks import check_numbers, check_sequence
from ipir_mujoco.core.errors import ParameterError, SimulationError, refuse_all_failed
from ipir_mujoco.core.options import study_dt_out
from ipir_mujoco.core.params import (RobotParams, check_whole, refuse_idle_parameters, refuse_idle_under,
                                     require_params)

from ...engine.kinds.timestep import clutch_rate
from ..pool import map_unordered
from .clutch_metrics import (METRICS, PEAK_TIME_TOL, _lost_per_stroke, _peak_bound, divergence,  # noqa: F401
                             run_metrics, scaling)  # (re-exported: their home was here)


@dataclass(frozen=True)
class OperatingPoint:
    """Where the clutches are loaded: the drive, how long [s] (the cap, with ``until_steady``)."""

    key: str
    label: str
    drive: str
    t_end: float
    until_steady: bool


POINTS = {
    "cruise": OperatingPoint("cruise", "cruise: the default motor at its periodic steady state", "motor", 10.0, True),
    "startup": OperatingPoint("startup", "the paper's start-up: constant torque M, 1 s from rest", "torque", 1.0,
                              False),
}
# the variant each engine of the study runs (ipir_mujoco.registry): the exact one-way clutches, compliant where
# the design has a finite clutch_stiffness
VARIANTS = {"analytic": "analytic-unilateral", "mujoco": "mujoco-ratchet"}
STIFFNESS = tuple(float(k) for k in np.geomspace(1e3, 1e7, 9))  # N/m: two per decade
BACKLASH = (0.0, 5e-4, 1e-3, 2e-3)  # m
STIFFNESS_QUICK, BACKLASH_QUICK = (1e4, 1e5, 1e6), (0.0, 1e-3)
MAX_VALUES = 50  # per axis: a 50 x 50 grid at both points is ~10,000 runs
OUTPUT_PERIODS = 500  # analytic output samples per fastest clutch period (at most)
DT_OUT_MAX = 1e-4  # s: the analytic output grid when the clutch is soft (or rigid)


@dataclass(frozen=True)
class Task:
    """One run: an engine at an operating point with one clutch (``stiffness`` None: rigid).

    ``timestep`` [s]: MuJoCo's step (a compliant run's chosen from its motion, a rigid one's that of
    the compliant runs it is the limit of); None for the analytic engine.
    """

    point: str
    engine: str
    stiffness: float | None
    backlash: float
    timestep: float | None = None


def parse_values(option: str, text: str, log: bool) -> tuple[float, ...]:
    """``A,B,C`` (a list) or ``START:STOP:N`` (N values, log-spaced if ``log``) as floats, or a ParameterError."""
    spaced = "START:STOP:N, log-spaced" if log else "START:STOP:N"
    allowed = f"allowed: a comma-separated list of numbers or {spaced}"
    parts = [p.strip() for p in str(text).split(":")]
    try:
        if len(parts) == 3:
            lo, hi = float(parts[0]), float(parts[1])
            count = check_whole(f"{option} N", float(parts[2]), low=1, high=MAX_VALUES)
            if not (math.isfinite(lo) and math.isfinite(hi) and (lo > 0 and hi > 0 or not log)):
                raise ParameterError(f"{option} {text!r}: the bounds must be finite{' and > 0' if log else ''}; "
                                     f"{allowed}")
            values = (np.geomspace if log else np.linspace)(lo, hi, count)
        elif len(parts) == 1:
            values = [float(v) for v in parts[0].split(",") if v.strip()]
        else:
            raise ValueError
    except ParameterError:
        raise
    except ValueError:
        raise ParameterError(f"{option} {text!r} is malformed; {allowed}") from None
    values = tuple(sorted({float(v) for v in values}))
    if not values or len(values) > MAX_VALUES:
        raise ParameterError(f"{option} {text!r} gives {len(values)} values; allowed: 1 to {MAX_VALUES}")
    return values


def parse_points(text: str) -> tuple[str, ...]:
    names = tuple(dict.fromkeys(p.strip() for p in str(text).split(",") if p.strip()))
    unknown = [n for n in names if n not in POINTS]
    if not names or unknown:
        raise ParameterError(f"--points {text!r}: unknown operating point {', '.join(unknown) or '(none)'}; "
                             f"allowed: a comma-separated list from {', '.join(POINTS)}")
    return names


def design(base: RobotParams, point: OperatingPoint, stiffness: float | None, backlash: float) -> RobotParams:
    """The parameter set of one run (the shared input checks apply: one line naming a bad value)."""
    return base.replace(drive=point.drive, clutch_stiffness=stiffness, clutch_backlash=backlash)


def analytic_dt_out(params: RobotParams, t_end: float | None = None) -> float:
    """Output interval [s]: at most 1/500 of the clutch spring's period (:func:`.timestep.clutch_rate`: the analytic
    anchor has no mass, so that is its clutch's rate whatever the grip), at most 1e-4 s, and
    with ``t_end`` [s] coarse enough to keep at most STUDY_SAMPLES samples (:func:`.options.study_dt_out`: the
    peak force is sampled whatever the grid, :mod:`.clutch_metrics`)."""
    rate = clutch_rate(params)
    wanted = DT_OUT_MAX if rate == 0 else min(DT_OUT_MAX, 2 * math.pi / rate / OUTPUT_PERIODS)
    return wanted if t_end is None else study_dt_out(t_end, wanted)


def mujoco_dt_out(t_end: float, timestep: float) -> float:
    """MuJoCo's output interval [s] for a run of ``t_end`` [s] at ``timestep`` [s]: every step, or every n-th where
    that would keep more than STUDY_SAMPLES samples (:func:`.options.study_dt_out`)."""
    return study_dt_out(t_end, timestep, timestep)


def plan(base: RobotParams, designs: Sequence[tuple[float, float]], points: Sequence[str],
         points_table: dict[str, OperatingPoint] = POINTS) -> list[Task]:
    """Every run of the study for ``designs`` [(k [N/m], backlash [m])], checked before any runs: a bad
    value raises a one-line ParameterError (the shared input checks, and MuJoCo's timestep rule)."""
    tasks, rigid_steps = [], {}
    try:  # a parameter no run of the study can use (the servo's, where the study sets each point's drive)
        refuse_idle_under(base, (points_table[key].drive for key in points))
    except ParameterError as exc:
        first = points_table[points[0]]
        raise ParameterError(f"the {points[0]} point runs drive={first.drive} (the study sets it): {exc}") from None
    for key in points:
        point = points_table[key]
        rigid = design(base, point, None, 0.0)
        refuse_idle_parameters(rigid)  # (the clutch's own: damping and backlash with a spring)
        rigid_steps[key] = {registry.timestep(VARIANTS["mujoco"], rigid, point.t_end, DT_OUT_MAX)}
        for k, b in designs:
            params = design(base, point, k, b)
            h = registry.timestep(VARIANTS["mujoco"], params, point.t_end, DT_OUT_MAX)  # refuses an unresolvable k
            tasks += [Task(key, "analytic", k, b), Task(key, "mujoco", k, b, h)]
            rigid_steps[key].add(h)
        tasks.append(Task(key, "analytic", None, 0.0))
        tasks += [Task(key, "mujoco", None, 0.0, h) for h in sorted(rigid_steps[key])]
    return tasks


def _cost(task: Task, points_table: dict[str, OperatingPoint]) -> float:
    """A rough relative cost (to start the longest runs first): steps of the clutch's oscillation."""
    rate = 0.0 if task.stiffness is None else math.sqrt(task.stiffness)
    return min(points_table[task.point].t_end, 3.0) * (1.0 + rate / 300.0) * (2.0 if task.backlash == 0 else 1.0)


def run_task(base: RobotParams, point: OperatingPoint, task: Task) -> dict:
    """One run's metrics (:func:`.clutch_metrics.run_metrics`) with its wall time [s], or {"error": one line}."""
    params = design(base, point, task.stiffness, task.backlash)
    steady = {"until_steady": True} if point.until_steady else {}
    started = time.perf_counter()
    try:
        if task.engine == "analytic":
            dt_out = analytic_dt_out(params, point.t_end)
            run = registry.run(VARIANTS["analytic"], params, point.t_end, dt_out=dt_out, **steady)
        else:
            # sampled at every step (an impact peaks between coarser samples), or every n-th step where the run
            # would keep more than STUDY_SAMPLES samples (peak_sampling_bound says what that costs)
            dt_out = mujoco_dt_out(point.t_end, task.timestep)
            # compliant: the engine's own step rule (it halves the step if its accuracy monitor fails);
            # rigid: the step of the compliant runs it is compared with
            step = None if task.stiffness is not None else task.timestep
            run = registry.run(VARIANTS["mujoco"], params, point.t_end, dt_out=dt_out, timestep=step, **steady)
    except (ParameterError, SimulationError) as exc:
        return {"error": " ".join(str(exc).split())}
    metrics = run_metrics(run, point)
    metrics.update(wall_s=time.perf_counter() - started, dt_out_s=dt_out,
                   timestep_s=run.settings.get("timestep"), peak_sampling_bound=_peak_bound(params, task, run, dt_out))
    if run.accuracy is not None:
        metrics["residual_ratio"] = run.accuracy.get("residual_ratio")
    return metrics


def run_tasks(base: RobotParams, tasks: list[Task], points_table: dict[str, OperatingPoint], workers: int,
              progress: Callable[[str], None]) -> dict[Task, dict]:
    """Every task's metrics: in a process pool of ``workers`` (1: here, one by one), longest first."""
    order = sorted(tasks, key=lambda t: -_cost(t, points_table))
    results: dict[Task, dict] = {}

    def done(task: Task, result: dict) -> None:
        results[task] = result
        what = "rigid" if task.stiffness is None else f"k={task.stiffness:.3g} N/m, backlash={1e3 * task.backlash:g} mm"
        if task.stiffness is None and task.timestep is not None:  # one rigid MuJoCo run per compliant step
            what += f" at step {task.timestep:.3g} s"
        status = result["error"] if "error" in result else f"{result['wall_s']:.2f} s"
        progress(f"[{len(results)}/{len(tasks)}] {task.point} {task.engine} {what}: {status}")

    map_unordered(functools.partial(_run_task_item, base, points_table), order, workers, done)
    return results


def _run_task_item(base: RobotParams, points_table: dict[str, OperatingPoint], task: Task) -> dict:
    """One task in a worker; a surprise inside an engine (r = 1e-300 m divides by zero) ends the study as a
    SimulationError naming the task, one line, rather than a bare exception from the pool."""
    try:
        return run_task(base, points_table[task.point], task)
    except (ParameterError, SimulationError):
        raise
    except Exception as exc:  # noqa: BLE001
        raise SimulationError(f"{task}: {type(exc).__name__}: {' '.join(str(exc).split())[:200]}") from None


def run_study(base: RobotParams, stiffness: Sequence[float] = STIFFNESS, backlash: Sequence[float] = BACKLASH,
              points: Sequence[str] = tuple(POINTS), *, designs: Sequence[tuple[float, float]] | None = None,
              workers: int | None = None, progress: Callable[[str], None] = lambda _m: None,
              points_table: dict[str, OperatingPoint] = POINTS) -> dict:
    """Run the study over the grid ``stiffness`` x ``backlash`` (or the (k, backlash) pairs ``designs``)
    at ``points``; a JSON-ready dict.

    ``rows``: [{point, clutch_stiffness_n_m, clutch_backlash_m, analytic, mujoco, divergence}] with each
    engine's metrics (or {"error": ...}); ``rigid``: {point: {analytic, mujoco}} the limit k -> infinity
    (MuJoCo's at its automatic step; ``mujoco_by_timestep`` at every step the compliant runs used);
    ``scaling``: :func:`.clutch_metrics.scaling`; ``settings``, ``wall_s``.
    """
    started = time.perf_counter()
    base = require_params(base)
    workers = check_whole("workers", (os.cpu_count() or 1) if workers is None else workers, low=1, high=1024)
    if not check_sequence("points", points) or not all(isinstance(p, str) and p in points_table for p in points):
        raise ParameterError(f"points={tuple(points)!r}; allowed: one or more of {', '.join(points_table)}")
    if designs is None:
        designs = [(k, b) for k in check_numbers("stiffness", stiffness) for b in check_numbers("backlash", backlash)]
    if not all(len(check_numbers("designs' pair", d)) == 2 for d in check_sequence("designs", designs)):
        raise ParameterError(f"designs={designs!r}; allowed: a list of (stiffness [N/m], backlash [m]) pairs")
    designs = list(dict.fromkeys((float(k), float(b)) for k, b in designs))
    tasks = plan(base, designs, points, points_table)
    progress(f"{len(tasks)} runs on {workers} process{'es' if workers > 1 else ''}")
    results = run_tasks(base, tasks, points_table, workers, progress)
    refuse_all_failed([results[t].get("error") for t in tasks], "runs")
    rigid = {}
    for key in points:
        point = points_table[key]
        auto = registry.timestep(VARIANTS["mujoco"], design(base, point, None, 0.0), point.t_end, DT_OUT_MAX)
        by_step = {t.timestep: results[t] for t in tasks if t.point == key and t.engine == "mujoco"
                   and t.stiffness is None}
        rigid[key] = {"analytic": results[Task(key, "analytic", None, 0.0)], "mujoco": by_step[auto],
                      "mujoco_by_timestep": [{"timestep_s": h, **m} for h, m in sorted(by_step.items())]}
    rows = []
    for task in tasks:
        if task.engine != "mujoco" or task.stiffness is None:
            continue
        point = points_table[task.point]
        an = dict(results[Task(task.point, "analytic", task.stiffness, task.backlash)])
        mj = dict(results[task])
        for engine, run, reference in (("analytic", an, rigid[task.point]["analytic"]),
                                       ("mujoco", mj, results[Task(task.point, "mujoco", None, 0.0, task.timestep)])):
            if "error" not in run:
                run["lost_per_stroke_m"] = _lost_per_stroke(point, run, reference)
        rows.append({"point": task.point, "clutch_stiffness_n_m": task.stiffness, "clutch_backlash_m": task.backlash,
                     "analytic": an, "mujoco": mj, "divergence": divergence(an, mj)})
    study = {"points": {key: asdict(points_table[key]) for key in points},
             "stiffness_n_m": sorted({k for k, _ in designs}),
             "backlash_m": sorted({b for _, b in designs}), "rows": rows, "rigid": rigid, "params": base.as_dict(),
             "settings": {"analytic": {"geometry": "exact", "clutch": "unilateral", "rtol": 1e-10,
                                       "dt_out": f"min({DT_OUT_MAX:g} s, clutch period / {OUTPUT_PERIODS})"},
                          "mujoco": {"clutch": "ratchet", "timestep": "automatic, sampled every step"},
                          "workers": workers}}
    for key in rigid:
        for engine in ENGINES:
            ref = rigid[key][engine]
            if "error" not in ref:
                ref["lost_per_stroke_m"] = 0.0
    study["scaling"] = scaling(study)
    study["wall_s"] = time.perf_counter() - started
    return study
