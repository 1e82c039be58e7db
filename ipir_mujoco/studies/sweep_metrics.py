"""Per-design figures of merit, from any engine's run, read the same way for every engine.

The per-revolution figures and the steady state come from :mod:`ipir_mujoco.core.cycles`
(through ``RunResult.summary`` for a full run, or ``cycle_summary`` for the series a
``mujoco.batch`` run returns): nothing here re-derives them.

=========================  ======  ==============================================================
metric                     units   meaning
=========================  ======  ==============================================================
revolutions                rev     crank turns in the run
mean_speed_m_s             m/s     forward speed of the robot (mean of the two modules) over the
                                   last whole crank revolutions (up to 3, counted back from the
                                   run's end); 0 if none was completed
steady                     0/1     1 if the run reached its periodic steady state
t_steady_s                 s       when it did (end of the settled window); empty if not steady;
                                   a revolution's resolution: two engines that agree on the steady
                                   speed may settle a revolution apart
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
accel_jump_m_s2            m/s^2   largest jump of a module's acceleration where a clutch engages or
                                   lets go (exact, at the analytic engines' event instants; empty for
                                   MuJoCo, see below)
stalled                    0/1     1 if the robot ended at rest for good (the engine's stall
                                   reason goes to the row's ``notes``); a stalled design is a
                                   result, not a failure
residual_ratio             -       MuJoCo accuracy monitor: worst energy residual / motor work
loop_gap_m                 m       MuJoCo accuracy monitor: worst loop-closure gap (both empty for
                                   the analytic engines, whose accuracy is their solver tolerance)
=========================  ======  ==============================================================

Per-revolution figures of a stalled design (a robot at rest: a partial revolution's "distance per
revolution", an efficiency of a run that did no work at the end) are left empty: ``distance_per_rev_m``,
``energy_per_metre_j_m``, ``efficiency``.

``mean_speed_mps`` and ``accel_jump_mps2`` (:data:`LEGACY`) are the first spellings of ``mean_speed_m_s``
and ``accel_jump_m_s2``, kept in every row with the same values for scripts written against them.

``accel_jump_m_s2``: the largest jump |a_after - a_before| of either module's acceleration at an
instant the engine resolves as an event (a mode switch: a clutch engages or lets go; a compliant
clutch's contact), read exactly where the run writes that instant twice, before and after, as the
analytic engines do; 0 if the run has no event. MuJoCo leaves it empty: its clutches engage over a
few steps of a soft constraint, so no instant holds a jump, and an estimate from its samples measures
the sampling: where the acceleration changes fast just before a switch, a fit through 1 ms samples on
either side cannot carry it to the event, in the equations' series as in MuJoCo's.

Peak forces from MuJoCo, left empty where they would measure the numerics. A rigid MuJoCo clutch is a
soft constraint that takes up its load within a few steps and overshoots for a step or two, by an amount
set by the step; read every 1 ms (the sweep's output), the peak is whichever step a sample hits, and
read at every step it still moves with the step. Where an engagement is hard (a light module started
from rest) its jolt reaches the rod, whose peak force then moves with the step too (tests/test_sweep.py
holds both artefacts). A compliant clutch's spring force is physical, but its peak falls between 1 ms
samples. So MuJoCo's ``peak_clutch_force_n`` and ``peak_rod_force_n`` are given only for compliant
clutches sampled at every step; the analytic engines give the rigid model's values (its reactions peak
at mode switches, which are sampled exactly), and ``clutch-study`` the engagement loads of real clutches
in both engines.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any

from ipir_mujoco.labels import SUMMARY

if TYPE_CHECKING:  # numpy and the cycles load where a metric is computed: the sweep's parser reads METRICS only
    import numpy as np

LEGACY = {"mean_speed_mps": "mean_speed_m_s", "accel_jump_mps2": "accel_jump_m_s2"}  # old spelling -> new
# metric: (in words, unit): the summary's figures as ipir_mujoco.labels names them, and the sweep's own
_SWEEP_ONLY = {
    "mean_speed_m_s": ("mean forward speed", "m/s"), "steady": ("steady state reached", "0/1"),
    "peak_rod_force_n": ("peak rod force", "N"), "accel_jump_m_s2": ("acceleration jump at a clutch switch", "m/s^2"),
    "stalled": ("stalled", "0/1"), "residual_ratio": ("MuJoCo energy residual / motor work", "-"),
    "loop_gap_m": ("MuJoCo loop gap", "m"),
}
DESCRIBED = {m: SUMMARY[m] if m in SUMMARY else _SWEEP_ONLY[m] for m in (  # in the order of the CSV's columns
    "revolutions", "mean_speed_m_s", "steady", "t_steady_s", "steady_speed_m_s", "distance_per_rev_m",
    "energy_per_metre_j_m", "efficiency", "peak_clutch_force_n", "peak_rod_force_n", "accel_jump_m_s2", "stalled",
    "residual_ratio", "loop_gap_m", "mean_omega_rad_s", "speed_ripple")}
METRICS = (*DESCRIBED, *LEGACY)  # every column a row carries per engine, the legacy spellings last
UNITS = {**{m: unit for m, (_, unit) in DESCRIBED.items()}, **{old: DESCRIBED[new][1] for old, new in LEGACY.items()}}
PER_REVOLUTION = ("distance_per_rev_m", "energy_per_metre_j_m", "efficiency")  # empty for a stalled design


def described(metric: str) -> str:
    """'mean forward speed [m/s]': a metric (or its legacy spelling) in words, with its unit."""
    words, unit = DESCRIBED[LEGACY.get(metric, metric)]
    return f"{words} [{unit}]"
LAST_CYCLES = 3


def accel_jump(series: dict[str, np.ndarray]) -> float:
    """Largest jump [m/s^2] of either module's acceleration at an event instant the series holds twice
    (before and after; module docstring); 0 if none."""
    import numpy as np

    t = np.asarray(series["t"], dtype=float)
    twins = np.flatnonzero(t[1:] == t[:-1])
    if twins.size == 0:
        return 0.0
    return float(max(np.abs(np.asarray(series[c])[twins + 1] - np.asarray(series[c])[twins]).max()
                     for c in ("a1", "a2")))


def mean_speed(series: dict[str, np.ndarray]) -> float:
    """Mean speed [m/s] over the run's last whole revolutions (up to LAST_CYCLES), counted back from its
    end: the travel since the crank stood that many turns short of its final reach, over the time since;
    0 if no revolution was completed.

    Counted from the end, not from the start's crank angle: two runs that agree to a fraction of a turn
    then average over the same strokes. Counted from the start, a run just past a whole turn and one just
    short of it average over different strokes of an accelerating crank, and their mean speeds can differ
    by far more than their revolutions do."""
    import numpy as np

    from ipir_mujoco.core.cycles import travel

    t, phi = np.asarray(series["t"], dtype=float), np.asarray(series["phi"], dtype=float)
    reach = np.maximum.accumulate(phi) - phi[0]  # the running maximum, as the revolution count
    turns = min(LAST_CYCLES, int(math.floor(reach[-1] / (2 * math.pi) + 1e-9)))
    if turns < 1:
        return 0.0
    target = reach[-1] - 2 * math.pi * turns
    i = int(np.searchsorted(reach, target, side="left"))  # the first sample at or past it
    position = travel(series)
    if i == 0 or reach[i] == reach[i - 1]:
        t_start, x_start = t[i], position[i]
    else:
        w = (target - reach[i - 1]) / (reach[i] - reach[i - 1])
        t_start = t[i - 1] + w * (t[i] - t[i - 1])
        x_start = position[i - 1] + w * (position[i] - position[i - 1])
    return float((position[-1] - x_start) / (t[-1] - t_start)) if t[-1] > t_start else 0.0


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
    stalled = bool(stalled or summary.get("stalled"))
    metrics = {
        "revolutions": float(revolutions),
        "mean_speed_m_s": float(mean_speed(series)),
        "steady": float(bool(summary.get("steady"))),
        "t_steady_s": _number(summary.get("t_steady_s")),
        "steady_speed_m_s": _number(summary.get("steady_speed_m_s")),
        "distance_per_rev_m": _number(summary.get("distance_per_rev_m")),
        "energy_per_metre_j_m": _number(summary.get("energy_per_metre_j_m")),
        "efficiency": _number(efficiency),
        "peak_clutch_force_n": _number(summary.get("peak_clutch_force_n")),
        "peak_rod_force_n": float(abs(series["rod_force"]).max()) if "rod_force" in series else math.nan,
        "accel_jump_m_s2": accel_jump(series) if len(t) > 1 else 0.0,
        "stalled": float(stalled),
        "residual_ratio": _number(accuracy.get("residual_ratio")),
        "loop_gap_m": _number(accuracy.get("loop_gap_m")),
        "mean_omega_rad_s": _number(summary.get("mean_omega_rad_s")),
        "speed_ripple": _number(summary.get("speed_ripple")),
    }
    if stalled:  # a robot at rest for good: no revolution to be per (module docstring)
        metrics.update({m: math.nan for m in PER_REVOLUTION})
    return with_legacy(metrics)


def with_legacy(metrics: dict[str, float]) -> dict[str, float]:
    """``metrics`` with each :data:`LEGACY` spelling holding its new metric's value (in place)."""
    for old, new in LEGACY.items():
        metrics[old] = metrics[new]
    return metrics


def run_metrics(run) -> dict[str, float]:
    """Metrics of a :class:`~ipir_mujoco.core.results.RunResult`; the analytic engines' accuracy figures
    (a solver residual, not a monitor) are left empty, and so are MuJoCo's peak forces where they would
    measure the step or the sampling rather than the robot, and its acceleration jump (module docstring)."""
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
        metrics["accel_jump_m_s2"] = math.nan  # no instant of a soft engagement holds a jump (module docstring)
    return with_legacy(metrics)


def batch_metrics(outcome: dict, steady_tol: float | None = None, steady_cycles: int | None = None) -> dict[str, float]:
    """Metrics of one design of :func:`ipir_mujoco.engine.kinds.slides.batch.run_ratchet_batch` (its ``series``,
    ``motor_work_j``, ``friction_work_j`` and, where the batch gives them, ``accuracy`` and ``stall``)."""
    from ipir_mujoco.core.cycles import cycle_summary

    series = outcome["series"]
    options = {k: v for k, v in (("tol", steady_tol), ("n", steady_cycles)) if v is not None}
    summary = cycle_summary(series, **options)
    summary["accuracy"] = outcome.get("accuracy") or {}
    stalled = outcome.get("stall") is not None if "stall" in outcome else _at_rest(series)
    energy = {"motor_work_j": outcome["motor_work_j"], "friction_j": outcome["friction_work_j"]}
    metrics = design_metrics(series, summary, energy, stalled=stalled)
    metrics["accel_jump_m_s2"] = math.nan  # MuJoCo: no instant of a soft engagement holds a jump
    return with_legacy(metrics)


def _at_rest(series: dict[str, np.ndarray]) -> bool:
    # until the batch reports its stalls: crank and both modules at rest at the end (under a
    # constant torque a robot at rest stays at rest)
    return all(abs(float(series[c][-1])) < 1e-9 for c in ("omega", "v1", "v2"))
