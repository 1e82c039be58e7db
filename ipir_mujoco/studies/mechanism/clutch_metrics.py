"""The engagement-load study's figures: what one run of it measures, and how the engines and the stiffnesses
compare (:mod:`.clutch_study` plans and runs the study, and re-exports every name here).

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

Scaling (:func:`scaling`): the log-log slope of the peak clutch force against
k, per operating point, backlash and engine.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np

from ipir_mujoco.registry import ENGINES
from ipir_mujoco.core.cycles import cycles, steady_window
from ipir_mujoco.core.params import RobotParams

from ...engine.kinds.timestep import carriage_rate, clutch_rate

if TYPE_CHECKING:
    from .clutch_study import OperatingPoint, Task

METRICS = (("peak_clutch_force_n", "peak clutch force", "N"),
           ("peak_acceleration_m_s2", "peak module acceleration", "m/s^2"),
           ("lost_per_stroke_m", "travel lost per stroke", "m"),
           ("backslide_per_stroke_m", "backward slide per stroke", "m"),
           ("steady_speed_m_s", "steady speed", "m/s"),
           ("energy_per_metre_j_m", "energy per metre", "J/m"),
           ("distance_per_rev_m", "distance per revolution", "m"),
           ("revolutions", "crank revolutions", "rev"))
# relative time tolerance to which the analytic compliant run locates a damped clutch's force maximum (scipy's
# bounded Brent search, minimize_scalar(method='bounded'): sqrt(eps) |t| + xatol / 3, xatol 1e-15 s)
PEAK_TIME_TOL = math.sqrt(np.finfo(float).eps)


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
