"""Per-design figures of merit, from any engine's run, read the same way for every engine.

The per-revolution figures and the steady state come from :mod:`ipir_mujoco.analytic.cycles`
(through ``RunResult.summary`` for a full run, or ``cycle_summary`` for the series a
``mujoco.batch`` run returns): nothing here re-derives them.

=========================  ======  ==============================================================
metric                     units   meaning
=========================  ======  ==============================================================
revolutions                rev     crank turns in the run
mean_speed_mps             m/s     forward speed of the robot (mean of the two modules) over the
                                   last whole crank revolutions (up to 3); 0 if none was completed
steady                     0/1     1 if the run reached its periodic steady state
t_steady_s                 s       when it did (end of the settled window); empty if not steady
steady_speed_m_s           m/s     mean speed over the settled window; empty if not steady
distance_per_rev_m         m       distance per crank revolution: settled window, else whole run
energy_per_metre_j_m       J/m     motor work per metre over the settled window; empty if not steady
efficiency                 -       work against the resistances / motor work (settled window, else
                                   whole run)
peak_clutch_force_n        N       largest clutch reaction (settled window, else whole run; empty
                                   where the engine cannot say: batched MuJoCo, and MuJoCo's rigid
                                   clutches or any MuJoCo run not sampled at every step, see below)
peak_rod_force_n           N       largest |rod force| (empty where the engine cannot say: as
                                   peak_clutch_force_n, see below)
accel_jump_mps2            m/s^2   largest jump of a module's acceleration where a clutch engages or
                                   lets go (see below)
stalled                    0/1     1 if the robot ended at rest for good (the engine's stall
                                   reason goes to the row's ``notes``); a stalled design is a
                                   result, not a failure
residual_ratio             -       MuJoCo accuracy monitor: worst energy residual / motor work
loop_gap_m                 m       MuJoCo accuracy monitor: worst loop-closure gap (both empty for
                                   the analytic engines, whose accuracy is their solver tolerance)
=========================  ======  ==============================================================

``accel_jump_mps2``, defined so that it means the same in a rigid and a soft engine. Where a
module starts or stops (its speed crosses HELD_SPEED = 1e-6 m/s), the jump is |a_after - a_before|,
each side's acceleration at the event extrapolated from a parabola fitted to the module's velocity
over a window of JUMP_WINDOW_S = 3 ms that begins JUMP_GUARD_S = 2 ms after (ends 2 ms before) the
event. Why: the rigid equations jump within one instant, while MuJoCo's clutches are soft
constraints that engage over a few timesteps and a ratchet that catches a module lets it recoil
briefly; an acceleration read over one step, (v_n+1 - v_n) / dt, then reads a velocity impulse over
the timestep. The former metric (the largest change of a between two samples where a module starts
or stops) differed 4-80x between the engines (median 10x) over the 20 x 20 sweep of L and m2 at
1 s, whose revolutions agree to 0.02 %: a property of the solver, not of the robot. The guard puts
the transient outside both windows; the parabola removes most of the smooth change of a across
them. Measured on five designs (L 0.06-0.5 m, m2 0.2-3 kg, 1 s, 1 ms samples), the analytic
engine's value lies within 0.84-1.14 of its exact jump (read at its duplicated event instants),
and MuJoCo's within 0.92-1.01 of the analytic value; ``divergence:ENGINE:accel_jump_mps2`` in the
sweep's rows shows it for every design. Output sampled at most every 1 ms (the sweep's) resolves it.

Peak forces from MuJoCo, left empty where they would measure the numerics. A rigid MuJoCo clutch is a
soft constraint that takes up its load within a few steps and overshoots for a step or two, by an
amount set by the step; read every 1 ms (the sweep's output), the peak is whichever step a sample
hits. At the default motor's cruise the ratchet's peak reaction reads 11.84 N every 1 ms, 16.34 N at
its 0.1 ms steps and 12.09 N at 0.05 ms (the equations: 12.13 N); the lock's 96.0, 141.3 and 110.9 N
(equations 97.5 N), and the clutch's jolt reaches the rod: the lock's peak rod force reads 96.0,
119.4 and 139.7 N at 0.05 ms read every 1 ms, at every step, and at 0.025 ms. The ratchet's holds at
that cruise (36.67-36.68 N) but not where an engagement is hard: starting from rest at L = 0.3742 m,
m2 = 0.2 kg its peak rod force reads 226.5, 217.6, 197.1 and 162.1 N read at every step of 1e-4,
5e-5, 2.5e-5 and 1.25e-5 s (the equations: 127.6 N); over the 20 x 20 sweep of L and m2 the ratchet's
1 ms peak differed from the equations' by -16 % to +78 %. A compliant clutch's spring force is
physical, but its peak falls between 1 ms samples. So MuJoCo's ``peak_clutch_force_n`` and
``peak_rod_force_n`` are given only for compliant clutches sampled at every step; the analytic engines
give the rigid model's values (its reactions peak at mode switches, which are sampled exactly), and
``clutch-study`` the engagement loads of real clutches in both engines.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from ipir_mujoco.analytic.cycles import cycle_summary, cycles

METRICS = ("revolutions", "mean_speed_mps", "steady", "t_steady_s", "steady_speed_m_s", "distance_per_rev_m",
           "energy_per_metre_j_m", "efficiency", "peak_clutch_force_n", "peak_rod_force_n", "accel_jump_mps2",
           "stalled", "residual_ratio", "loop_gap_m")
UNITS = {"revolutions": "rev", "mean_speed_mps": "m/s", "steady": "0/1", "t_steady_s": "s", "steady_speed_m_s": "m/s",
         "distance_per_rev_m": "m", "energy_per_metre_j_m": "J/m", "efficiency": "-", "peak_clutch_force_n": "N",
         "peak_rod_force_n": "N", "accel_jump_mps2": "m/s^2", "stalled": "0/1", "residual_ratio": "-",
         "loop_gap_m": "m"}
LAST_CYCLES = 3
HELD_SPEED = 1e-6  # m/s
JUMP_WINDOW_S = 3e-3  # s: width of the windows the accelerations are read from
JUMP_GUARD_S = 2e-3  # s: gap between an event and each window, longer than a soft clutch's engagement
JUMP_POINTS = 7  # velocities read per window (interpolated between samples)


def _slope_weights(x: np.ndarray) -> np.ndarray:
    """Weights w (len(x),) such that w @ y is the slope at 0 of the least-squares parabola through (x, y)."""
    return np.linalg.pinv(np.vander(x, 3))[1]


_OFFSETS = np.linspace(JUMP_GUARD_S, JUMP_GUARD_S + JUMP_WINDOW_S, JUMP_POINTS)  # s, after an event
_BEFORE, _AFTER = _slope_weights(-_OFFSETS), _slope_weights(_OFFSETS)


def accel_jump(series: dict[str, np.ndarray]) -> float:
    """Largest acceleration jump [m/s^2] of either module at a clutch event (module docstring); 0 if none."""
    t = np.asarray(series["t"], dtype=float)
    keep = np.concatenate([np.diff(t) > 0, [True]])  # of a duplicated instant, the later sample
    t_unique = t[keep]
    reach = JUMP_GUARD_S + JUMP_WINDOW_S
    largest = 0.0
    for column in ("v1", "v2"):
        v = np.asarray(series[column], dtype=float)
        held = v <= HELD_SPEED
        events = t[1:][held[1:] != held[:-1]]
        events = events[(events - reach >= t[0]) & (events + reach <= t[-1])]
        if events.size == 0:
            continue
        # slope at the event of a parabola through v over each window: exact for a linear a(t)
        before = np.interp(events[:, None] - _OFFSETS, t_unique, v[keep]) @ _BEFORE
        after = np.interp(events[:, None] + _OFFSETS, t_unique, v[keep]) @ _AFTER
        largest = max(largest, float(np.abs(after - before).max()))
    return largest


def mean_speed(series: dict[str, np.ndarray]) -> float:
    """Mean speed [m/s] over the last whole revolutions (up to LAST_CYCLES); 0 if none completed."""
    found = cycles(series)[-LAST_CYCLES:]
    time = sum(c.period_s for c in found)
    return sum(c.distance_m for c in found) / time if time > 0 else 0.0


def _number(value: Any) -> float:
    if value is None:
        return math.nan
    return float(value)


def design_metrics(series: dict[str, np.ndarray], summary: dict[str, Any], energy: dict[str, float] | None = None,
                   stalled: bool = False) -> dict[str, float]:
    """Metrics of one run (see the module docstring).

    ``summary``: the run's ``RunResult.summary``, or for a batched run its ``cycle_summary`` with
    ``accuracy`` added; ``energy``: the whole run's audit (motor_work_j, friction_j), used for the
    efficiency when the series lacks the cumulative energy columns. Missing figures are NaN.
    """
    t, phi = series["t"], series["phi"]
    revolutions = (phi[-1] - phi[0]) / (2 * math.pi)
    efficiency = summary.get("efficiency")
    if efficiency is None and energy and energy.get("motor_work_j", 0) > 0 and "friction_j" in energy:
        efficiency = energy["friction_j"] / energy["motor_work_j"]
    accuracy = summary.get("accuracy") or {}
    return {
        "revolutions": float(revolutions),
        "mean_speed_mps": float(mean_speed(series)),
        "steady": float(bool(summary.get("steady"))),
        "t_steady_s": _number(summary.get("t_steady_s")),
        "steady_speed_m_s": _number(summary.get("steady_speed_m_s")),
        "distance_per_rev_m": _number(summary.get("distance_per_rev_m")),
        "energy_per_metre_j_m": _number(summary.get("energy_per_metre_j_m")),
        "efficiency": _number(efficiency),
        "peak_clutch_force_n": _number(summary.get("peak_clutch_force_n")),
        "peak_rod_force_n": float(np.abs(series["rod_force"]).max()) if "rod_force" in series else math.nan,
        "accel_jump_mps2": accel_jump(series) if len(t) > 1 else 0.0,
        "stalled": float(bool(stalled or summary.get("stalled"))),
        "residual_ratio": _number(accuracy.get("residual_ratio")),
        "loop_gap_m": _number(accuracy.get("loop_gap_m")),
    }


def run_metrics(run) -> dict[str, float]:
    """Metrics of a :class:`~ipir_mujoco.analytic.results.RunResult`; the analytic engines' accuracy figures
    (a solver residual, not a monitor) are left empty, and so are MuJoCo's peak forces where they would
    measure the step or the sampling rather than the robot (module docstring)."""
    summary = dict(run.summary)
    if run.engine != "mujoco":
        summary["accuracy"] = {}
    metrics = design_metrics(run.series, summary, {"motor_work_j": run.energy.get("motor_work_j", 0.0),
                                                   "friction_j": run.energy.get("friction_j", math.nan)})
    if run.engine == "mujoco":
        settings = run.settings
        every_step = settings.get("dt_out") == settings.get("timestep")
        if settings.get("clutch_model") != "compliant" or not every_step:
            metrics["peak_clutch_force_n"] = metrics["peak_rod_force_n"] = math.nan
    return metrics


def batch_metrics(outcome: dict, steady_tol: float | None = None, steady_cycles: int | None = None) -> dict[str, float]:
    """Metrics of one design of :func:`ipir_mujoco.engine.batch.run_ratchet_batch` (its ``series``,
    ``motor_work_j``, ``friction_work_j`` and, where the batch gives them, ``accuracy`` and ``stall``)."""
    series = outcome["series"]
    options = {k: v for k, v in (("tol", steady_tol), ("n", steady_cycles)) if v is not None}
    summary = cycle_summary(series, **options)
    summary["accuracy"] = outcome.get("accuracy") or {}
    stalled = outcome.get("stall") is not None if "stall" in outcome else _at_rest(series)
    energy = {"motor_work_j": outcome["motor_work_j"], "friction_j": outcome["friction_work_j"]}
    return design_metrics(series, summary, energy, stalled=stalled)


def _at_rest(series: dict[str, np.ndarray]) -> bool:
    # until the batch reports its stalls: crank and both modules at rest at the end (under a
    # constant torque a robot at rest stays at rest)
    return all(abs(float(series[c][-1])) < 1e-9 for c in ("omega", "v1", "v2"))
