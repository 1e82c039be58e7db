"""Helpers shared by the analytic solvers: option checks, output sampling, finiteness."""

from __future__ import annotations

import math

import numpy as np

from .errors import ParameterError, SimulationError


def check_run_options(t_end: float, dt_out: float, rtol: float, atol: float) -> None:
    for name, value in (("t_end", t_end), ("dt_out", dt_out), ("rtol", rtol), ("atol", atol)):
        if not (isinstance(value, (int, float)) and math.isfinite(value) and value > 0):
            raise ParameterError(f"{name}={value!r} is out of range; allowed: a finite number > 0")
    if dt_out > t_end:
        raise ParameterError(f"dt_out={dt_out} s is out of range; allowed: dt_out <= t_end ({t_end} s)")
    if rtol < 1e-13:
        raise ParameterError(f"rtol={rtol} is out of range; allowed: rtol >= 1e-13 (DOP853's floor)")


def sample_times(t0: float, t1: float, grid: np.ndarray) -> np.ndarray:
    """Segment [t0, t1]: its end points and the output grid strictly inside."""
    inside = grid[(grid > t0) & (grid < t1)]
    return np.concatenate([[t0], inside, [t1]]) if t1 > t0 else np.array([t0])


def check_finite(series: dict[str, np.ndarray]) -> None:
    for name, values in series.items():
        bad = np.flatnonzero(~np.isfinite(values))
        if bad.size:
            t_bad = series["t"][bad[0]]
            raise SimulationError(f"non-finite {name} at t={t_bad:.6g} s")
