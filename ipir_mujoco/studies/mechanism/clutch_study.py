"""The engagement-load study: what a real one-way clutch (stiffness k, backlash delta) does, in both engines.

For every clutch stiffness k [N/m] and backlash delta [m] of a grid, at each
operating point (:data:`POINTS`: the default motor's cruise, run to its
periodic steady state, and the paper's start-up, constant torque for 1 s from
rest), the analytic compliant clutch (exact geometry) and MuJoCo's compliant
ratchet run side by side, and so do the rigid clutches of both engines (the
limit k -> infinity: the analytic one-way model and MuJoCo's ratchet).

Per run (:func:`run_metrics`; cruise: over the steady window, the last
``steady_cycles`` revolutions; start-up: the whole run):

* ``peak_clutch_force_n`` [N]: the largest clutch force, with
  ``peak_sampling_bound``, the relative error the sampling may add to it.
  omega_c = sqrt(k / min(m1, m2)) is the fastest clutch oscillation [rad/s].
  The analytic model's force maxima are samples whatever the output grid:
  without damping the clutch force k d peaks where its module turns (d' = -v),
  a segment's end (bound 0); with damping the run locates each maximum on the
  solver's dense output with a bounded Brent search, to scipy's time tolerance
  sqrt(eps) t (bound (omega_c sqrt(eps) t_end)^2: 2.2e-9 for the default
  grid's stiffest clutch, 1e7 N/m, at t_end = 1 s, 2.2e-7 at the 10 s cap;
  so the peak does not depend on the output grid, as tests/test_compliant_clutch.py
  holds). MuJoCo is sampled at every step
  h <= 0.1 / omega_c: its peak lies within (omega_c h)^2 / 4 <= 2.5e-3 of the
  converged one (entering the spring between two steps, and the turning point
  between samples, each up to (omega_c h)^2 / 8; mjcf/README.md); every n-th
  step where that would keep more than STUDY_SAMPLES samples. With a finite
  grip MuJoCo's skidding carriage (1e-3 of its module's mass) rings on the
  spring ~32 times faster than omega_c, at 0.3 / its rate per step
  (:mod:`ipir_mujoco.engine.kinds.timestep`): the bound is then
  (carriage rate x n h)^2 / 4 (0.0225 at every step, at most 1) on the peak's
  excess over the grip, which is that carriage's inertia force;
  ``python bench/study_samples.py`` measures the difference every n-th step
  makes to each peak.
* ``peak_acceleration_m_s2`` [m/s^2]: the largest |a1|, |a2| (the linkage's
  own accelerations included: at start-up they set it unless an impact is
  harder).
* ``lost_per_stroke_m`` [m]: the travel the clutch costs per stroke against the
  rigid clutch of the same engine at the same operating point (MuJoCo: at the
  same timestep): cruise, half the difference of the distances per revolution;
  start-up, the distance over the first N whole revolutions both runs made,
  over 2N strokes (whole revolutions: the travel within one is not uniform).
* ``backslide_per_stroke_m`` [m]: how far the modules slide backward per stroke
  (into the play and the spring), read from the run alone.
* ``steady_speed_m_s`` [m/s], ``energy_per_metre_j_m`` [J/m], ``t_steady_s``
  [s] (cruise), ``distance_per_rev_m`` [m], ``revolutions``.
* ``engagement``: the engagement that caused the peak force: module, time [s],
  crank angle [rad] and speed [rad/s], ``speed_m_s`` (the module's backward speed when it reached
  its clutch, from the last sample inside the play with its acceleration) and
  ``accel_m_s2`` (its acceleration there: what drove it back).

Divergence: (MuJoCo - analytic) / |analytic| for every metric both have.
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
from ipir_mujoco.core.cycles import cycles, steady_window
from ipir_mujoco.core.checks import check_numbers, check_sequence
from ipir_mujoco.core.errors import ParameterError, SimulationError, refuse_all_failed
from ipir_mujoco.core.options import study_dt_out
from ipir_mujoco.core.params import (RobotParams, check_whole, refuse_idle_parameters, refuse_idle_under,
                                     require_params)

from ...engine.kinds.timestep import carriage_rate, clutch_rate
from ..pool import map_unordered


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
METRICS = (("peak_clutch_force_n", "peak clutch force", "N"),
           ("peak_acceleration_m_s2", "peak module acceleration", "m/s^2"),
           ("lost_per_stroke_m", "travel lost per stroke", "m"),
           ("backslide_per_stroke_m", "backward slide per stroke", "m"),
           ("steady_speed_m_s", "steady speed", "m/s"),
           ("energy_per_metre_j_m", "energy per metre", "J/m"),
           ("distance_per_rev_m", "distance per revolution", "m"),
           ("revolutions", "crank revolutions", "rev"))
OUTPUT_PERIODS = 500  # analytic output samples per fastest clutch period (at most)
DT_OUT_MAX = 1e-4  # s: the analytic output grid when the clutch is soft (or rigid)
# relative time tolerance to which the analytic compliant run locates a damped clutch's force maximum (scipy's
# bounded Brent search, minimize_scalar(method='bounded'): sqrt(eps) |t| + xatol / 3, xatol 1e-15 s)
PEAK_TIME_TOL = math.sqrt(np.finfo(float).eps)


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
    peak force is sampled whatever the grid, the module docstring)."""
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
    """One run's metrics (:func:`run_metrics`) with its wall time [s], or {"error": one line}."""
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


def _peak_bound(params: RobotParams, task: Task, run, dt_out: float) -> float | None:
    """Relative error bound of the peak force as sampled (see the module docstring); None for rigid runs. MuJoCo's
    at its sampling interval ``dt_out`` [s] (its step, or n of them), with the fastest mode its spring takes part
    in (with a finite grip the skidding carriage's: :func:`.timestep.carriage_rate`), at most 1: past
    omega dt_out ~ 2 sampling resolves no peak."""
    if task.stiffness is None:
        return None
    if task.engine == "analytic":  # a maximum located on the dense output to the search's time tolerance
        return 0.0 if params.clutch_damping == 0 else (clutch_rate(params) * PEAK_TIME_TOL * run.t_end) ** 2
    return min(1.0, (carriage_rate(params) * max(run.settings["timestep"], dt_out)) ** 2 / 4)


def run_metrics(run, point: OperatingPoint) -> dict:
    """The study's figures of one run (see the module docstring); {"error": ...} if cruise was not reached."""
    s, summary = run.series, run.summary
    found = cycles(s)
    if point.until_steady:
        window = steady_window(found, *run.steady_test, run.steady_target)
        if window is None:
            why = run.stall or f"no periodic steady state by t_end = {point.t_end:g} s"
            return {"error": why}
        inside = (s["t"] >= window[0].t_start) & (s["t"] <= window[-1].t_end)
        revolutions = float(len(window))
    else:
        inside = np.ones(s["t"].shape, dtype=bool)
        revolutions = float(summary["revolutions"])
    force = np.maximum(s["lambda1"], s["lambda2"])
    peak = int(np.flatnonzero(inside)[np.argmax(force[inside])])
    accel = np.maximum(np.abs(s["a1"]), np.abs(s["a2"]))[inside]
    backslide = sum(float(np.maximum(-np.diff(s[x][inside]), 0.0).sum()) for x in ("x1", "x2"))
    out = {
        "peak_clutch_force_n": float(force[peak]),
        "peak_acceleration_m_s2": float(accel.max()),
        "backslide_per_stroke_m": backslide / (2 * revolutions) if revolutions > 0 else None,
        "distance_per_rev_m": summary["distance_per_rev_m"],
        "revolutions": float(summary["revolutions"]),
        "travel_per_revolution_m": [c.distance_m for c in found],
        "steady_speed_m_s": summary["steady_speed_m_s"],
        "energy_per_metre_j_m": summary["energy_per_metre_j_m"],
        "t_steady_s": summary["t_steady_s"],
        "stall": run.stall,
        "engagement": _engagement(s, peak),
    }
    return out


def _engagement(s: dict, peak: int) -> dict | None:
    """The engagement whose force peaked at sample ``peak`` (see the module docstring), or None (rigid)."""
    module = 1 if s["lambda1"][peak] >= s["lambda2"][peak] else 2
    column = f"clutch_overlap{module}"
    if column not in s:
        return None
    before = np.flatnonzero(s[column][:peak + 1] <= 0.0)
    if before.size == 0:
        return None  # engaged from the start
    i = int(before[-1])
    v, a, gap = -float(s[f"v{module}"][i]), -float(s[f"a{module}"][i]), -float(s[column][i])
    # backward speed on reaching the clutch: the remaining play crossed at the sample's acceleration
    return {"module": module, "t_s": float(s["t"][i]), "phi_rad": float(s["phi"][i]),
            "omega_rad_s": float(s["omega"][i]),
            "speed_m_s": math.sqrt(max(v * v + 2.0 * a * gap, 0.0)) if v > 0 else 0.0,
            "accel_m_s2": float(s[f"a{module}"][i])}


def _lost_per_stroke(point: OperatingPoint, run: dict, rigid: dict) -> float | None:
    """Travel lost per stroke [m] against the rigid clutch (see the module docstring)."""
    if "error" in run or rigid is None or "error" in rigid:
        return None
    if point.until_steady:
        return 0.5 * (rigid["distance_per_rev_m"] - run["distance_per_rev_m"])
    n = min(len(run["travel_per_revolution_m"]), len(rigid["travel_per_revolution_m"]))
    if n == 0:
        return None
    return (sum(rigid["travel_per_revolution_m"][:n]) - sum(run["travel_per_revolution_m"][:n])) / (2 * n)


def divergence(an: dict, mj: dict) -> dict:
    """(MuJoCo - analytic) / |analytic| per metric both have (None where either lacks it or analytic is 0)."""
    out = {}
    for key, _, _ in METRICS:
        a, m = an.get(key), mj.get(key)
        out[key] = None if a is None or m is None or a == 0 else (m - a) / abs(a)
    return out


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
    ``scaling``: :func:`scaling`; ``settings``, ``wall_s``.
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


def scaling(study: dict) -> list[dict]:
    """Log-log slope of the peak clutch force against k, per point, backlash and engine.

    ``slope_stiff``: over the stiffest decade of the grid (the asymptotic law: ~1/2 for an impact,
    -> 0 where the force tends to a finite limit); ``slope_all``: over the whole grid.
    """
    out = []
    for key in study["points"]:
        for b in study["backlash_m"]:
            rows = [r for r in study["rows"] if r["point"] == key and r["clutch_backlash_m"] == b]
            for engine in ENGINES:
                pairs = [(r["clutch_stiffness_n_m"], r[engine]["peak_clutch_force_n"]) for r in rows
                         if "error" not in r[engine] and r[engine]["peak_clutch_force_n"] > 0]
                if len(pairs) < 2:
                    continue
                k, f = np.log10(np.array(pairs)).T
                stiff = k >= k.max() - 1.0 - 1e-9
                out.append({"point": key, "clutch_backlash_m": b, "engine": engine,
                            "slope_all": float(np.polyfit(k, f, 1)[0]),
                            "slope_stiff": float(np.polyfit(k[stiff], f[stiff], 1)[0]) if stiff.sum() >= 2 else None,
                            "stiff_range_n_m": [float(10 ** k[stiff].min()), float(10 ** k.max())]})
    return out
