"""A segment's dense output (the DOP853 interpolants of its steps) and the scans the event loop runs over it.

:class:`DenseSolution` is what a :class:`.dop853.Segment` offers as ``sol``:
the state at any time of the segment, for one time or many. Over many times
the interpolants are summed in one compiled loop (:func:`dense_table`); the
graze scan of :func:`.solver_support.missed_crossing` (every guard at each
step's start and interior points, and where each is first clearly negative)
is one more (:func:`graze_scan`). Without numba (:mod:`.accel`) the same
numbers come from numpy: the same operations in the same order, so the two
paths agree bit for bit (``tests/test_dense_output.py``). Units: those of the
state; times in s.
"""

from __future__ import annotations

import bisect
import math

import numpy as np

from . import accel
from .accel import jit
from .kernels import guards_at

GRAZE_POINTS = 8  # interior points checked per accepted step for a guard that dipped below zero and came back
CLEAR = 1e-9  # "clearly" positive or negative: beyond this fraction of the guard's largest value in the segment


@jit
def dense_at(F, y_old, t_old, h, t, out):
    """The step's DOP853 interpolant at time t, into ``out`` (scipy's Dop853DenseOutput)."""
    x = (t - t_old) / h
    for j in range(out.size):
        acc = 0.0
        for i in range(7):
            acc += F[6 - i, j]
            if i % 2 == 0:
                acc *= x
            else:
                acc *= 1.0 - x
        out[j] = acc + y_old[j]


@jit
def _step_of(ts, t, steps):
    """np.searchsorted(ts, t, side="left") - 1, clipped to [0, steps - 1]: the step serving time t."""
    if t != t:
        return steps - 1  # numpy sorts nan last
    lo, hi = 0, ts.size
    while lo < hi:
        mid = (lo + hi) // 2
        if ts[mid] < t:
            lo = mid + 1
        else:
            hi = mid
    return min(max(lo - 1, 0), steps - 1)


@jit
def _interpolate(ts, t_old, y_old, F, h_safe, t, out):
    """The state at time t into ``out`` (n,), as :meth:`DenseSolution.evaluate` computes it (its Horner order)."""
    step = _step_of(ts, t, h_safe.size)
    x = (t - t_old[step]) / h_safe[step]
    rest = 1 - x
    for j in range(out.size):
        y = F[step, 6, j] * x
        for i in range(1, 7):
            y += F[step, 6 - i, j]
            y *= x if i % 2 == 0 else rest
        out[j] = y + y_old[step, j]


@jit
def component_at(ts, t_old, y_old, F, h, j, t):
    """State component j at time t as :meth:`DenseSolution.__call__` computes it for one time (its bisection,
    a constant piece's value, :func:`dense_at`'s order), without a Python call per evaluation."""
    step = 0 if t != t else _step_of(ts, t, h.size)  # bisect_left puts a nan first
    if h[step] == 0:
        return y_old[step, j]
    x = (t - t_old[step]) / h[step]
    acc = 0.0
    for i in range(7):
        acc += F[step, 6 - i, j]
        if i % 2 == 0:
            acc *= x
        else:
            acc *= 1.0 - x
    return acc + y_old[step, j]


@jit
def dense_table(ts, t_old, y_old, F, h_safe, times, out):
    """The state at each of ``times`` (k,) into ``out`` (n, k)."""
    buf = np.empty(out.shape[0])
    for i in range(times.size):
        _interpolate(ts, t_old, y_old, F, h_safe, times[i], buf)
        for j in range(buf.size):
            out[j, i] = buf[j]


@jit
def graze_scan(model, mode, n_events, p, ts, t_old, y_old, F, h_safe, times, negative, positive):
    """Every guard of ``mode`` at each step's start, its GRAZE_POINTS interior points and the last end.

    Fills ``times`` ((ts.size - 1) (GRAZE_POINTS + 1) + 1,) with those times and, per event k,
    ``negative[k]`` with the first index where the guard is clearly negative (-1: never) and
    ``positive[k]`` with the last index before it where it is clearly positive (-1: none).
    """
    per = GRAZE_POINTS + 1
    for i in range(ts.size - 1):
        width = ts[i + 1] - ts[i]
        for j in range(per):
            times[i * per + j] = ts[i] + width * (j / per)
    times[times.size - 1] = ts[ts.size - 1]
    values = np.empty((n_events, times.size))
    state, at = np.empty(y_old.shape[1]), np.empty(max(n_events, 1))
    never = np.full(max(n_events, 1), -math.inf)
    for i in range(times.size):
        _interpolate(ts, t_old, y_old, F, h_safe, times[i], state)
        guards_at(model, mode, n_events, times[i], state, p, never, at)
        for k in range(n_events):
            values[k, i] = at[k]
    for k in range(n_events):
        scale = 0.0
        for i in range(times.size):
            size = abs(values[k, i])
            if size != size or scale != scale:
                scale = math.nan  # as numpy's max: a nan wins, and then no sample is clearly anything
            elif size > scale:
                scale = size
        if scale < 1e-300:
            scale = 1e-300
        negative[k], positive[k] = -1, -1
        for i in range(times.size):
            if values[k, i] < -CLEAR * scale:
                negative[k] = i
                break
        for i in range(negative[k] - 1, -1, -1):
            if values[k, i] > CLEAR * scale:
                positive[k] = i
                break


class DenseSolution:
    """The run's dense output over one segment: ``sol(t)`` for a float (-> (n,)) or an array (k,) (-> (n, k)).

    Each step's interpolant serves the times from its start up to and including its end (scipy's
    OdeSolution: a time on a step end takes the step that ends there); times outside extrapolate
    the first or last step. ``ts`` (m+1,) the step ends from the segment's start (the last cut at an
    event), ``ys`` (m+1, n) the states there, ``F`` (m, 7, n) each step's interpolant coefficients,
    ``t_full`` (m,) each step's own end.
    """

    def __init__(self, ts, ys, F, t_full):
        self.ts, self.F, self.t_full = ts, F, t_full
        self.t_old, self.y_old = ts[:-1], ys[:-1]
        self.h = t_full - self.t_old
        self._h_safe = np.where(self.h != 0, self.h, 1.0)  # a constant piece (h = 0) has F = 0: any x will do
        self._ends = None  # ts as a list, for the scalar calls' bisection (made on the first)

    def __call__(self, t):
        if isinstance(t, float) or np.ndim(t) == 0:  # one time (root searches): no array machinery
            t = float(t)
            if self._ends is None:
                self._ends = self.ts.tolist()
            step = min(max(bisect.bisect_left(self._ends, t) - 1, 0), self.h.size - 1)
            out = np.empty(self.y_old.shape[1])
            if self.h[step] == 0:
                out[:] = self.y_old[step]
            else:
                dense_at(self.F[step], self.y_old[step], self.t_old[step], self.h[step], t, out)
            return out
        times = np.asarray(t, dtype=float)
        if accel.ACCELERATED:
            out = np.empty((self.y_old.shape[1], times.size))
            dense_table(self.ts, self.t_old, self.y_old, self.F, self._h_safe, times, out)
            return out
        step = np.searchsorted(self.ts, times, side="left")
        step -= 1
        np.minimum(np.maximum(step, 0, out=step), self.h.size - 1, out=step)
        return self.evaluate(step, times).T

    def phi_at(self, t: float) -> float:
        """The first state component (the crank angle, rad) at one time t [s]: ``self(t)[0]``, compiled."""
        if not accel.ACCELERATED:
            return float(self(t)[0])
        return component_at(self.ts, self.t_old, self.y_old, self.F, self.h, 0, float(t))

    def evaluate(self, step: np.ndarray, times: np.ndarray) -> np.ndarray:
        """Step ``step[i]``'s interpolant at ``times[i]``: array (k, n) (scipy's Horner order)."""
        x = ((times - self.t_old[step]) / self._h_safe[step])[:, None]
        rest = 1 - x
        y = self.F[step, 6]
        y *= x
        for i in range(1, 7):
            y += self.F[step, 6 - i]
            y *= x if i % 2 == 0 else rest
        y += self.y_old[step]
        return y

    def graze_scan(self, model: int, mode: int, n_events: int, p: np.ndarray):
        """(times, negative, positive) of :func:`graze_scan` for the kernels' ``model``/``mode``, constants ``p``."""
        times = np.empty((self.ts.size - 1) * (GRAZE_POINTS + 1) + 1)
        negative, positive = np.empty(n_events, dtype=np.int64), np.empty(n_events, dtype=np.int64)
        graze_scan(model, mode, n_events, p, self.ts, self.t_old, self.y_old, self.F, self._h_safe, times, negative,
                   positive)
        return times, negative, positive

    @property
    def interpolants(self):
        """Step views with ``t_old``, ``t`` (the step's own end, also where an event cut it short) and a call."""
        return [_Step(self, i) for i in range(self.h.size)]


class _Step:
    def __init__(self, dense: DenseSolution, i: int):
        self.dense, self.i = dense, i
        self.t_old, self.t = float(dense.t_old[i]), float(dense.t_full[i])

    def __call__(self, t):
        times = np.asarray(t, dtype=float)
        y = self.dense.evaluate(np.full(max(times.size, 1), self.i), np.atleast_1d(times))
        return y[0] if times.ndim == 0 else y.T
