"""Helpers shared by the analytic solvers: option checks, output sampling, finiteness."""

from __future__ import annotations

import contextlib
from typing import Iterator

import numpy as np

from .errors import ParameterError, SimulationError
from .params import check_real
from .params import check_run_options as check_time_options


def check_run_options(t_end: float, dt_out: float, rtol: float = 1e-10, atol: float = 1e-12) -> tuple[float, float]:
    """(t_end, dt_out) as floats after the shared run-option check (:func:`analytic.params.check_run_options`:
    ranges, the sample budget) and the solver tolerances' own (both > 0, rtol >= 1e-13, DOP853's floor)."""
    t_end, dt_out = check_time_options(t_end, dt_out)
    check_real("atol", atol)
    if check_real("rtol", rtol) < 1e-13:
        raise ParameterError(f"rtol={rtol} is out of range; allowed: rtol >= 1e-13 (DOP853's floor)")
    return t_end, dt_out


@contextlib.contextmanager
def quiet_trial_steps() -> Iterator[None]:
    """Floating-point warnings off around ``solve_ivp``.

    An explicit Runge-Kutta step evaluates the right-hand side at trial states; a step that is far too
    long can overflow there (omega**2 at omega ~ 1e160), and scipy's error estimate then reads inf/nan
    ("invalid value encountered in dot"), rejects the step and retries a shorter one. The result is
    guarded by that rejection and by :func:`check_finite` on the output, so the warnings say nothing a
    user can act on.
    """
    with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
        yield


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
