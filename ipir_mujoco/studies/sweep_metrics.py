"""Per-design figures of merit, from any engine's time series.

=========================  ======  ==============================================================
metric                     units   meaning
=========================  ======  ==============================================================
revolutions                rev     crank turns in the run
mean_speed_mps             m/s     forward speed of the robot (mean of the two modules) over the
                                   last whole crank revolutions (up to 3); 0 if none was completed
distance_per_rev_m         m       distance the robot made per crank revolution, whole run
efficiency                 -       work against the resistances / motor work
peak_clutch_reaction_n     N       largest clutch reaction (empty where the engine cannot say)
peak_rod_force_n           N       largest |rod force| (empty where the engine cannot say)
accel_jump_mps2            m/s^2   largest jump of a module's acceleration between two samples
                                   where a module starts or stops (held: speed <= 1e-6 m/s, read
                                   the same way for every engine)
stalled                    0/1     1 if the crank and both modules are at rest at the end: under a
                                   constant torque a robot at rest stays at rest
=========================  ======  ==============================================================
"""

from __future__ import annotations

import math

import numpy as np

METRICS = ("revolutions", "mean_speed_mps", "distance_per_rev_m", "efficiency", "peak_clutch_reaction_n",
           "peak_rod_force_n", "accel_jump_mps2", "stalled")
LAST_CYCLES = 3
HELD_SPEED = 1e-6  # m/s


def design_metrics(series: dict[str, np.ndarray], motor_work: float, friction_work: float) -> dict[str, float]:
    """Metrics of one run (see the module docstring); a missing force column gives NaN."""
    t, phi = series["t"], series["phi"]
    revolutions = (phi[-1] - phi[0]) / (2 * math.pi)
    travel = 0.5 * (series["x1"] + series["x2"])
    whole = int(math.floor(revolutions))
    if whole >= 1:
        cycles = min(LAST_CYCLES, whole)
        start_angle = phi[0] + 2 * math.pi * (whole - cycles)
        end_angle = phi[0] + 2 * math.pi * whole
        # first samples where the crank reaches each angle (its running maximum, as it may rock)
        i0, i1 = np.searchsorted(np.maximum.accumulate(phi), [start_angle, end_angle])
        i1 = min(i1, len(t) - 1)
        t0, t1, x0, x1 = t[i0], t[i1], travel[i0], travel[i1]
        mean_speed = (x1 - x0) / (t1 - t0) if t1 > t0 else 0.0
    else:
        mean_speed = 0.0
    held = (series["v1"] <= HELD_SPEED).astype(int) + 2 * (series["v2"] <= HELD_SPEED)
    changes = np.flatnonzero(np.diff(held) != 0)
    jumps = [max(abs(series["a1"][i + 1] - series["a1"][i]), abs(series["a2"][i + 1] - series["a2"][i]))
             for i in changes]
    reactions = [series[c] for c in ("lambda1", "lambda2") if c in series]
    stopped = abs(series["omega"][-1]) < 1e-9 and abs(series["v1"][-1]) < 1e-9 and abs(series["v2"][-1]) < 1e-9
    return {
        "revolutions": float(revolutions),
        "mean_speed_mps": float(mean_speed),
        "distance_per_rev_m": float(travel[-1] / revolutions) if revolutions > 1e-9 else 0.0,
        "efficiency": float(friction_work / motor_work) if motor_work > 0 else math.nan,
        "peak_clutch_reaction_n": float(max(r.max() for r in reactions)) if reactions else math.nan,
        "peak_rod_force_n": float(np.abs(series["rod_force"]).max()) if "rod_force" in series else math.nan,
        "accel_jump_mps2": float(max(jumps)) if jumps else 0.0,
        "stalled": float(stopped),
    }
