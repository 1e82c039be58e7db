"""The periodic steady state watched while a run goes: :class:`SteadyWatch`, fed sample by sample by every
engine's run loop, and the one check of the steady test's settings (:func:`check_steady_test`). The tests
themselves are :mod:`.steady_test`'s, the figures read off a finished run :mod:`.cycles`'."""

from __future__ import annotations

import math

import numpy as np

from .steady_test import STEADY_CYCLES, STEADY_TOL, steady_at, steady_at_end
from .errors import ParameterError
from .params import as_real


def check_steady_test(tol, n) -> tuple[float, int]:
    """(tol, n) of the steady test as (float, int), or a one-line ParameterError naming the one out of range:
    0 < steady_tol < 1 and steady_cycles a whole number >= 2."""
    number = as_real(tol)
    if number is None or isinstance(tol, bool) or not (math.isfinite(number) and 0 < number < 1):
        raise ParameterError(f"steady_tol={tol!r} is out of range; allowed: 0 < steady_tol < 1")
    if isinstance(n, bool) or not isinstance(n, (int, np.integer)) or n < 2:
        raise ParameterError(f"steady_cycles={n!r} is out of range; allowed: a whole number >= 2")
    return float(number), int(n)


class SteadyWatch:
    """Tells an engine, sample by sample, when its run has reached the periodic steady state.

    Feed it the samples as they come (:meth:`update` with arrays of t [s], phi
    [rad] and robot travel [m]); it returns True once the per-revolution mean speeds
    are steady (:func:`.steady_test.steady_at`: the exact test on the last ``n``, or with a ``target``
    [-], the engine's :func:`.steady_test.steady_target`, the statistical one). Cheap: work only where a
    revolution ends. ``found``: the :class:`.steady_test.Steady` once steady.
    """

    def __init__(self, phi0: float, tol: float = STEADY_TOL, n: int = STEADY_CYCLES, target: float | None = None):
        tol, n = check_steady_test(tol, n)
        self.phi0, self.tol, self.n, self.target = float(phi0), tol, n, target
        self.found = None
        self.reach = 0.0  # running maximum of phi - phi0
        self.last = None  # (t, reach, travel) of the previous sample
        self.boundary = None  # (t, travel) where the current revolution began
        self.speeds: list[float] = []
        self.turns = 0  # revolutions ended so far (a turn of no duration ends too, but has no speed)
        self.steady_at: float | None = None

    def update(self, t, phi, position) -> bool:
        t, phi, position = (np.atleast_1d(np.asarray(a, dtype=float)) for a in (t, phi, position))
        if self.last is None:
            self.last = (t[0], np.maximum(phi[0] - self.phi0, self.reach), position[0])
            self.boundary = (t[0], position[0])
        target = 2 * math.pi * (self.turns + 1)
        top = np.maximum((phi - self.phi0).max(), self.reach)  # the running maximum's last value (nan wins)
        if top < target:  # no revolution ends in these samples: the common case
            self.reach, self.last = float(top), (t[-1], top, position[-1])
            return self.steady_at is not None
        reach = np.maximum.accumulate(np.maximum(phi - self.phi0, self.reach))
        prev_t, prev_r, prev_x = self.last
        for ti, ri, xi in zip(t, reach, position):
            while ri >= target:
                w = 1.0 if ri == prev_r else (target - prev_r) / (ri - prev_r)
                tb, xb = prev_t + w * (ti - prev_t), prev_x + w * (xi - prev_x)
                if tb > self.boundary[0]:
                    self.speeds.append((xb - self.boundary[1]) / (tb - self.boundary[0]))
                self.boundary = (tb, xb)
                if self.steady_at is None and self.speeds:
                    self.found = steady_at(np.asarray(self.speeds), self.tol, self.n, self.target, steady_at_end)
                    if self.found is not None:
                        self.steady_at = tb
                self.turns += 1  # counted apart from the speeds, or a turn of no duration would loop forever
                target = 2 * math.pi * (self.turns + 1)
            prev_t, prev_r, prev_x = ti, ri, xi
        self.reach, self.last = float(reach[-1]), (t[-1], reach[-1], position[-1])
        return self.steady_at is not None
