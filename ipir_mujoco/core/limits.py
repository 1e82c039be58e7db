"""The bounds of a run, in physical units, and their one-line checks (numpy-free: the command line's parsers and
bad-input checks read them without loading the numerics; :mod:`.options` builds a run's options on them)."""

from __future__ import annotations

import math
from typing import Any

from .errors import ParameterError
from .params import check_real

# the clutch rules every engine takes: the paper's (its locks switch by the sign of the gap's rate S_dot) and
# one-way clutches (they only push); here, numpy-free, for the command line's flags
CLUTCH_RULES = ("kinematic", "unilateral")
MAX_T_END = 3600.0  # s: an hour of simulated motion; a motor reaches its steady state in seconds, and a
# MuJoCo run at its 1e-4 s step already takes 3.6e7 steps for an hour
MAX_SAMPLES = 10_000_000  # samples kept per run: ~20 float64 columns -> 1.6 GB in memory, ~4 GB as CSV
SAMPLE_BYTES = 20 * 8  # bytes per kept sample (about 20 float64 columns)
MAX_STEPS = 100_000_000  # MuJoCo steps per run: ~7 min at ~4 us a step (bench/ratchet_step.py); the longest
# run the engine chooses by itself, 3600 s at its 1e-4 s step, is 3.6e7 steps, so only a tiny given timestep
# with a long t_end reaches it
# samples a study keeps per run at most (docs/cli.md, "Entry point and exit status"): a study runs many runs, each
# worker holds one at a time, and a run's figures are read with a few copies of its ~35 float64 columns: ~56 MB
# a run, ~250 MB of a worker's memory with the copies. A run that would keep more is sampled more coarsely
# (:func:`study_dt_out`); its steps stay the ones its accuracy needs
STUDY_SAMPLES = 200_000
DEFAULT_WALL_BUDGET_S = 1800.0  # s of wall time a run may take unless told otherwise: the longest default-step
# run (3600 s of MuJoCo, ~2.5 min) fits ~10 times over, and no run left alone goes on for hours


def study_dt_out(t_end: float, dt_out: float, step: float | None = None) -> float:
    """The output interval [s] of a study's run of ``t_end`` [s] wanted every ``dt_out`` [s]: ``dt_out``, or where
    that would keep more than STUDY_SAMPLES samples the interval that keeps that many, a whole number of MuJoCo's
    ``step`` [s] where given (its samples fall on steps). Bounds what every study holds in memory whatever the
    step its runs need (a finite grip's skids, a stiff clutch's spring)."""
    if t_end / dt_out + 1 <= STUDY_SAMPLES:
        return dt_out
    wanted = t_end / (STUDY_SAMPLES - 1)
    return wanted if step is None else step * math.ceil(wanted / step * (1 - 1e-12))


def check_step_count(t_end: float, timestep: float, t_end_name: str = "t_end",
                     timestep_name: str = "timestep") -> int:
    """The MuJoCo step count t_end / timestep (both [s]), or a one-line ParameterError naming both and the
    allowed maximum MAX_STEPS: bounded up front, so that a run of 1e12 steps is refused, not started."""
    steps = t_end / timestep
    if steps > MAX_STEPS:
        raise ParameterError(
            f"{t_end_name}={t_end:g} s with {timestep_name}={timestep:g} s would take {steps:.3g} MuJoCo steps "
            f"(~{steps * 4e-6 / 3600:.3g} h at ~4 us a step); allowed: at most {MAX_STEPS:.0e} steps "
            f"({timestep_name} >= {t_end / MAX_STEPS:.3g} s for this {t_end_name})")
    return int(math.ceil(steps))


def check_run_options(t_end: Any, dt_out: Any) -> tuple[float, float]:
    """(t_end [s], dt_out [s]) as floats: 0 < t_end <= MAX_T_END, 0 < dt_out <= t_end, and at most
    MAX_SAMPLES samples kept (t_end / dt_out + 1), with the size it would need named in the message."""
    t_end = check_real("t_end", t_end, high=MAX_T_END, unit="s")
    dt_out = check_real("dt_out", dt_out, unit="s")
    if dt_out > t_end:
        raise ParameterError(f"dt_out={dt_out:g} s is out of range; allowed: dt_out <= t_end ({t_end:g} s)")
    samples = t_end / dt_out + 1
    if samples > MAX_SAMPLES:
        raise ParameterError(
            f"t_end={t_end:g} s with dt_out={dt_out:g} s would keep {samples:.3g} samples "
            f"(~{samples * SAMPLE_BYTES / 1e9:.3g} GB); allowed: at most {MAX_SAMPLES:.0e} samples "
            f"(dt_out >= {t_end / (MAX_SAMPLES - 1):.3g} s for this t_end)")
    return t_end, dt_out


def refuse_steady_without_motor(drive: str, until_steady: bool) -> None:
    """A run asked to stop at its periodic steady state under the constant torque, which has none (the crank
    speeds up for ever or comes to rest): refused in one line, with what has a steady state."""
    if until_steady and drive == "torque":
        raise ParameterError("until_steady with drive=torque: a constant torque has no periodic steady state (the "
                             "crank speeds up for ever, or comes to rest); allowed: drive=motor or servo (--drive "
                             "motor), or a run of fixed length without until_steady")
