"""The summary figures of a run, read off its time series the same way for every engine.

:func:`summarize` computes what every engine's :attr:`.results.RunResult.summary` holds from the series alone:
revolutions, final displacements, peak speeds, the end of the first contraction (:func:`first_gap_minimum`),
mode switches, the weakest locked clutch's reaction, with finite grip each module's skid and the peak grip use
(:func:`grip_use`, the one definition of the ``grip_use`` column every engine writes), and the wheeled model's
wall figures (:func:`wheel_keys`). Beside them: the list of mode changes (:func:`mode_changes`) and
the words of a stall (:func:`stall_reason`).
:mod:`.results` re-exports every name here.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np

from .columns import MODE_NAMES, REST_SPEED, Mode


def mode_changes(series: dict[str, np.ndarray]) -> list[dict[str, Any]]:
    """Every change of mode: time [s], crank angle [rad] and its position in the turn [deg], from, to."""
    modes = np.asarray(series["mode"], dtype=int)
    changes = []
    for i in np.flatnonzero(np.diff(modes)):
        phi = float(series["phi"][i + 1])
        changes.append({"t": float(series["t"][i + 1]), "phi": phi,
                        "phi_deg_in_turn": math.degrees(phi % (2 * math.pi)),
                        "from": MODE_NAMES[int(modes[i])], "to": MODE_NAMES[int(modes[i + 1])]})
    return changes


def write_mode_changes(path: str | Path, series: dict[str, np.ndarray]) -> None:
    """Write :func:`mode_changes` as CSV."""
    lines = ["t,phi,phi_deg_in_turn,from,to"]
    lines += [f"{c['t']:.12g},{c['phi']:.12g},{c['phi_deg_in_turn']:.6f},{c['from']},{c['to']}"
              for c in mode_changes(series)]
    Path(path).write_text("\n".join(lines) + "\n")


def first_gap_minimum(t: np.ndarray, S_dot: np.ndarray) -> float | None:
    """Time of the first minimum of S [s]: where S first stops falling, S_dot turning from below -REST_SPEED
    to -REST_SPEED or above (rising, or at rest: a robot that stalls while contracting has its minimum where
    it comes to rest, whether its series holds an exact 0 there or the soft constraints' creep).

    Arrays of shape (n,): t [s], S_dot [m/s]. The time where S_dot reaches 0, linearly interpolated between
    the two samples (the later one if S_dot stays below 0, at rest); None if S never stops falling.
    """
    falling = S_dot[:-1] < -REST_SPEED
    stopped = S_dot[1:] >= -REST_SPEED
    hits = np.flatnonzero(falling & stopped)
    if hits.size == 0:
        return None
    i = hits[0]
    s0, s1 = S_dot[i], S_dot[i + 1]
    return float(t[i] + (t[i + 1] - t[i]) * min(1.0, -s0 / (s1 - s0)))


def min_locked_reaction(series: dict[str, np.ndarray]) -> float | None:
    """Smallest reaction of a locked clutch over the run [N]; None if none locked."""
    modes = np.asarray(series["mode"], dtype=int)
    rear = np.isin(modes, [Mode.BOTH_LOCKED, Mode.EXPANSION])
    front = np.isin(modes, [Mode.BOTH_LOCKED, Mode.CONTRACTION])
    values = np.concatenate([series["lambda1"][rear], series["lambda2"][front]])
    return float(values.min()) if values.size else None


def mode_switches(series: dict[str, np.ndarray]) -> int:
    """How often the run changes mode: the ``mode`` column, and with finite grip the module states
    ``wheels1/2`` too (a module that turns from rolling forward to skidding back changes mode where the
    kinematics, which say only which modules stand, do not)."""
    changed = np.diff(np.asarray(series["mode"], dtype=int)) != 0
    for column in ("wheels1", "wheels2"):
        if column in series:
            changed |= np.diff(np.asarray(series[column], dtype=float)) != 0
    return int(np.count_nonzero(changed))


def slip(series: dict[str, np.ndarray], module: int) -> float:
    """Backward skid [m] of module ``module`` (1 or 2) over the run, >= 0: the growth of its ``slip``
    column; 0.0 where the series has none (nothing skids: unlimited grip)."""
    column = series.get(f"slip{module}")
    return 0.0 if column is None else max(float(column[-1] - column[0]), 0.0)


def grip_use(lam, wheels, G: float) -> np.ndarray:
    """One module's ``grip_use`` column [-], the one definition every engine writes: 1 where its wheels skid
    (``wheels`` == -1), else its clutch's reaction over its grip, max(lambda, 0) / G, at most 1 (a module that
    does not skid holds within its grip by the law; what a soft engine shows beyond it, a carriage's or a
    wheel's inertia force, is not the clutch's use of the grip). G = 0 [N]: 0 unless it skids. Arrays (n,):
    ``lam`` [N] the ``lambda`` column, ``wheels`` the ``wheels`` column (+1 rolling, 0 standing, -1 skidding)."""
    lam, wheels = np.asarray(lam, dtype=float), np.asarray(wheels, dtype=float)
    use = np.minimum(np.maximum(lam, 0.0) / G, 1.0) if G > 0 else np.zeros(lam.shape)
    return np.where(wheels == -1.0, 1.0, use)


def peak_grip_use(series: dict[str, np.ndarray], grip: tuple[float, float] | None = None) -> float | None:
    """Largest grip use over the run [-] (1: a module skidded), from the columns every engine writes on finite
    grip, ``lambda1/2`` and ``wheels1/2``, by :func:`grip_use` with ``grip`` (G1, G2) [N] (a series without
    them: its ``grip_use1/2`` columns). None with unlimited grip (``grip`` None: no ratio exists)."""
    if grip is None:
        return None
    if all(c in series for c in ("lambda1", "lambda2", "wheels1", "wheels2")):
        return float(max(grip_use(series[f"lambda{k}"], series[f"wheels{k}"], G).max()
                         for k, G in zip((1, 2), grip)))
    columns = [np.asarray(series[c], dtype=float) for c in ("grip_use1", "grip_use2") if c in series]
    return float(max(c.max() for c in columns)) if columns else None


def wheel_keys(series: dict[str, np.ndarray]) -> dict[str, float]:
    """The wheeled MuJoCo model's wall figures (a run with the ``press1/2`` and ``wheels_off`` columns; {} for
    others): ``press1_n``, ``press2_n`` [N], each module's mean total wall press over the run's samples;
    ``wheel_off_s`` [s], how long any wheel was off its wall (the sample intervals that start with one off)."""
    if "press1" not in series:
        return {}
    t, off = np.asarray(series["t"], dtype=float), np.asarray(series["wheels_off"], dtype=float)
    return {"press1_n": float(np.mean(series["press1"])), "press2_n": float(np.mean(series["press2"])),
            "wheel_off_s": float(np.sum(np.diff(t)[off[:-1] > 0]))}


def summarize(series: dict[str, np.ndarray], energy: dict[str, float],
              grip: tuple[float, float] | None = None) -> dict[str, Any]:
    """The summary figures of a run, computed from its time series; ``grip`` (G1, G2) [N] of finite grip
    (:attr:`.param_table.RobotParams.grip`), None for unlimited grip."""
    t, phi = series["t"], series["phi"]
    return {
        "revolutions": float((phi[-1] - phi[0]) / (2 * math.pi)),
        "x1_final": float(series["x1"][-1] - series["x1"][0]),
        "x2_final": float(series["x2"][-1] - series["x2"][0]),
        "v1_max": float(np.max(series["v1"])),
        "v2_max": float(np.max(series["v2"])),
        "first_contraction_end_s": first_gap_minimum(t, series["S_dot"]),
        "mode_switches": mode_switches(series),
        "min_clutch_reaction_n": min_locked_reaction(series),
        "slip1_m": slip(series, 1),
        "slip2_m": slip(series, 2),
        "peak_grip_use": peak_grip_use(series, grip),
        **wheel_keys(series),
        "energy": dict(energy),
    }


def stall_reason(t: float, phi: float, torque: float, gravity: bool) -> str:
    """RunResult.stall, in the same words for every engine: the robot at rest for good from time ``t`` [s],
    the crank at ``phi`` [rad], where the drive's torque at rest ``torque`` [N m] cannot move it;
    ``gravity``: whether gravity pulls along the pipe (an incline)."""
    against = "the resistances and gravity" if gravity else "the resistances"
    return (f"at rest from t={t:.6g} s at phi={phi:.6g} rad ({math.degrees(phi) % 360:.1f} deg in its turn): the "
            f"drive's torque at rest ({torque:.6g} N m) cannot move the linkage against {against}")

