"""DOP853 with dense output and terminal events, on the scalar kernels: scipy's algorithm without its per-step cost.

``solve_ivp(method="DOP853", events=..., dense_output=True)`` spends some
60-100 us of Python per step on arrays of 5-7 elements, plus 15 calls of a
numpy right-hand side (about 13 us each): 250-300 us a step, where the
arithmetic is a few microseconds. :func:`integrate` is the same method step
for step (scipy's tableau, error norm, step-size control, first-step guess,
dense output, event test and Brent root search with its tolerances), written
as one loop over scalars that :mod:`.accel` compiles when numba is installed.
The model's equations are the kernels' (:mod:`.kernels`), chosen by number.

:func:`solve` wraps it in what the solvers read from a solve_ivp result:
``t``, ``y``, ``status`` (0: reached t_end, 1: a terminal event, -1: failed),
``message``, ``t_events``/``y_events`` (the first event only: every event here
is terminal) and ``sol``, the dense output (:class:`.dense.DenseSolution`: no
Python per sample). Units: those of the state; times in s.
"""

from __future__ import annotations

import math
from contextlib import nullcontext

import numpy as np

from . import accel
from . import dop853_tableau as _coefficients
from .accel import jit
from .dense import DenseSolution, dense_at as _dense
from .kernels import guard, rhs

_A = np.ascontiguousarray(_coefficients.A, dtype=float)  # (16, 16): stages 0-11, the error stage 12, extra 13-15
_B = np.ascontiguousarray(_coefficients.B, dtype=float)  # (12,)
_C = np.ascontiguousarray(_coefficients.C, dtype=float)  # (16,)
_E3 = np.ascontiguousarray(_coefficients.E3, dtype=float)  # (13,)
_E5 = np.ascontiguousarray(_coefficients.E5, dtype=float)  # (13,)
_D = np.ascontiguousarray(_coefficients.D, dtype=float)  # (4, 16)
_SAFETY, _MIN_FACTOR, _MAX_FACTOR = 0.9, 0.2, 10.0
_EXPONENT = -1.0 / 8.0  # -1 / (error estimator order + 1)
_EPS4 = 4 * float(np.finfo(float).eps)  # solve_ivp's xtol and rtol of the event root search


@jit
def _spacing(t):
    """nextafter(t, +inf) - t for t >= 0 (the solver's time never runs backward)."""
    if t == 0.0:
        return 5e-324
    mantissa, exponent = math.frexp(t)
    return math.ldexp(1.0, exponent - 53)


@jit
def _event_value(model, mode, k, p, quiet, F, y_old, t_old, h, t, buf):
    _dense(F, y_old, t_old, h, t, buf)
    return guard(model, mode, k, t, buf, p, quiet)


@jit
def _root(model, mode, k, p, quiet, F, y_old, t_old, h, xa, xb, buf):
    """Brent's method on event k over [xa, xb] (scipy's brentq, xtol = rtol = 4 eps, 100 iterations)."""
    xpre, xcur = xa, xb
    xblk, fblk, spre, scur = 0.0, 0.0, 0.0, 0.0
    fpre = _event_value(model, mode, k, p, quiet, F, y_old, t_old, h, xpre, buf)
    fcur = _event_value(model, mode, k, p, quiet, F, y_old, t_old, h, xcur, buf)
    if fpre == 0.0:
        return xpre
    if fcur == 0.0:
        return xcur
    if (fpre < 0.0) == (fcur < 0.0):  # the step's end state and its interpolant there differ in the guard's sign
        return xb  # by roundoff (scipy's brentq would raise): the crossing is at the step's end
    for _ in range(100):
        if fpre != 0.0 and fcur != 0.0 and (fpre < 0.0) != (fcur < 0.0):
            xblk, fblk = xpre, fpre
            spre = scur = xcur - xpre
        if abs(fblk) < abs(fcur):
            xpre, xcur, xblk = xcur, xblk, xcur
            fpre, fcur, fblk = fcur, fblk, fcur
        delta = (_EPS4 + _EPS4 * abs(xcur)) / 2
        sbis = (xblk - xcur) / 2
        if fcur == 0.0 or abs(sbis) < delta:
            return xcur
        if abs(spre) > delta and abs(fcur) < abs(fpre):
            if xpre == xblk:  # interpolate
                stry = -fcur * (xcur - xpre) / (fcur - fpre)
            else:  # extrapolate
                dpre = (fpre - fcur) / (xpre - xcur)
                dblk = (fblk - fcur) / (xblk - xcur)
                stry = -fcur * (fblk * dblk - fpre * dpre) / (dblk * dpre * (fblk - fpre))
            if 2 * abs(stry) < min(abs(spre), 3 * abs(sbis) - delta):  # good short step
                spre, scur = scur, stry
            else:
                spre, scur = sbis, sbis
        else:
            spre, scur = sbis, sbis
        xpre, fpre = xcur, fcur
        if abs(scur) > delta:
            xcur += scur
        else:
            xcur += delta if sbis > 0 else -delta
        fcur = _event_value(model, mode, k, p, quiet, F, y_old, t_old, h, xcur, buf)
    return xcur


@jit
def _maximum(a, b):
    """np.maximum of two floats: a nan in either is the result."""
    if a != a or b != b:
        return math.nan
    return a if a >= b else b


@jit
def _rms_scaled(v, scale):
    total = 0.0
    for j in range(v.size):
        q = v[j] / scale[j]
        total += q * q  # as numpy's square and numba's x ** 2: Python's ** would call pow, rounding otherwise
    return math.sqrt(total) / math.sqrt(v.size)


@jit
def _first_step(model, mode, t0, y0, f0, t_bound, p, rtol, atol):
    """scipy's select_initial_step (Hairer, Norsett, Wanner II.4) for DOP853's error estimator of order 7."""
    interval = abs(t_bound - t0)
    if interval == 0.0:
        return 0.0
    n = y0.size
    scale = np.empty(n)
    for j in range(n):
        scale[j] = atol + abs(y0[j]) * rtol
    d0, d1 = _rms_scaled(y0, scale), _rms_scaled(f0, scale)
    h0 = 1e-6 if d0 < 1e-5 or d1 < 1e-5 else 0.01 * d0 / d1
    h0 = min(h0, interval)
    y1, f1, df = np.empty(n), np.empty(n), np.empty(n)
    for j in range(n):
        y1[j] = y0[j] + h0 * f0[j]
    rhs(model, mode, t0 + h0, y1, p, f1)
    for j in range(n):
        df[j] = f1[j] - f0[j]
    d2 = _rms_scaled(df, scale) / h0
    if d1 <= 1e-15 and d2 <= 1e-15:
        h1 = max(1e-6, h0 * 1e-3)
    else:
        h1 = (0.01 / max(d1, d2)) ** (1.0 / 8.0)
    return min(100 * h0, h1, interval)


@jit
def _combine(K, stages, weights, row, y, h, out):
    """out = y + h * sum_{q < stages} weights[row, q] K[q] (one Runge-Kutta stage's argument)."""
    np.dot(weights[row, :stages], K[:stages], out)
    out *= h
    out += y


@jit
def integrate(model, mode, t0, t_bound, y0, p, rtol, atol, first_step, n_events, directions, quiet, max_steps,
              resumed):
    """DOP853 from (t0, y0) until t_bound or the first terminal event.

    ``first_step`` [s] > 0 is used as given (capped by the interval), else scipy's guess.
    ``directions`` (n_events,): +1 an event fires rising through zero, -1 falling, 0 either;
    ``quiet`` (n_events,): see :func:`.kernels.guard`. After ``max_steps`` steps (0: no limit) it
    returns with status 2, to be called again from its last step end with the step size it proposes
    (``resumed`` = 1: not the segment's first call); the steps are those of one call. Returns (ts (m+1,), ys (m+1, n),
    F (m, 7, n) the dense-output coefficients of each step, t_full (m,) each step's own end,
    status, event index, event time, event state (n,), right-hand-side calls).
    """
    n = y0.size
    cap = 64
    ts, ys = np.empty(cap), np.empty((cap, n))
    Fs, t_full = np.empty((cap, 7, n)), np.empty(cap)
    K = np.empty((16, n))
    y, f = y0.copy(), np.empty(n)
    y_new, f_new, tmp, buf = np.empty(n), np.empty(n), np.empty(n), np.empty(n)
    d5, d3, dD = np.empty(n), np.empty(n), np.empty((4, n))  # the products below, without a new array per step
    rhs(model, mode, t0, y, p, f)
    nfev = 1
    if first_step > 0:
        h_abs = min(first_step, abs(t_bound - t0))
    else:
        h_abs = _first_step(model, mode, t0, y, f, t_bound, p, rtol, atol)
        nfev += 1
    g = np.empty(n_events)
    g_new = np.empty(n_events)
    for k in range(n_events):
        g[k] = guard(model, mode, k, t0, y, p, quiet)
    ts[0] = t0
    ys[0, :] = y
    m, t, status, hit, t_hit = 0, t0, 0, -1, math.nan
    y_hit = y0.copy()
    if t0 >= t_bound:  # nothing to integrate: one constant piece
        ts[1], ys[1, :], t_full[0] = t0, y, t0
        Fs[0, :, :] = 0.0
        return ts[:2], ys[:2], Fs[:1], t_full[:1], 0, hit, t_hit, y_hit, nfev, h_abs
    while True:
        min_step = 10.0 * _spacing(t)
        if h_abs < min_step:
            h_abs = min_step
        rejected, failed = False, False
        while True:
            if h_abs < min_step:
                failed = True
                break
            t_new = t + h_abs
            if t_new - t_bound > 0:
                t_new = t_bound
            h = t_new - t
            h_abs = abs(h)
            K[0, :] = f
            for s in range(1, 12):
                _combine(K, s, _A, s, y, h, tmp)
                rhs(model, mode, t + _C[s] * h, tmp, p, K[s])
            np.dot(_B, K[:12], y_new)
            for j in range(n):
                y_new[j] = y[j] + h * y_new[j]
            rhs(model, mode, t + h, y_new, p, f_new)
            K[12, :] = f_new
            nfev += 12
            np.dot(_E5, K[:13], d5)
            np.dot(_E3, K[:13], d3)
            e5, e3 = 0.0, 0.0
            for j in range(n):  # the scaled error norms, element by element in numpy's order
                scale = atol + _maximum(abs(y[j]), abs(y_new[j])) * rtol
                q5, q3 = d5[j] / scale, d3[j] / scale
                e5 += q5 * q5
                e3 += q3 * q3
            if e5 == 0.0 and e3 == 0.0:
                error = 0.0
            else:
                error = abs(h) * e5 / math.sqrt((e5 + 0.01 * e3) * n)
            if error < 1.0:
                factor = _MAX_FACTOR if error == 0.0 else min(_MAX_FACTOR, _SAFETY * error ** _EXPONENT)
                if rejected:
                    factor = min(1.0, factor)
                h_abs *= factor
                break
            factor = _SAFETY * error ** _EXPONENT
            if not factor > _MIN_FACTOR:  # also for a nan error (an overflowed trial step), as max() in scipy
                factor = _MIN_FACTOR
            h_abs *= factor
            rejected = True
        if failed:
            status = -1
            break
        t_old = t
        for j in range(n):
            tmp[j] = y[j]  # y_old
        # dense output: three more stages, then the interpolant's coefficients
        for s in range(13, 16):
            _combine(K, s, _A, s, tmp, h, buf)
            rhs(model, mode, t_old + _C[s] * h, buf, p, K[s])
        nfev += 3
        if m + 1 >= cap:
            cap *= 2
            ts2, ys2, Fs2, tf2 = np.empty(cap), np.empty((cap, n)), np.empty((cap, 7, n)), np.empty(cap)
            ts2[:m + 1], ys2[:m + 1], Fs2[:m], tf2[:m] = ts[:m + 1], ys[:m + 1], Fs[:m], t_full[:m]
            ts, ys, Fs, t_full = ts2, ys2, Fs2, tf2
        F = Fs[m]
        np.dot(_D, K, dD)
        for j in range(n):
            dy = y_new[j] - tmp[j]
            F[0, j] = dy
            F[1, j] = h * K[0, j] - dy
            F[2, j] = 2 * dy - h * (f_new[j] + K[0, j])
            for i in range(4):
                F[3 + i, j] = h * dD[i, j]
        t = t_new
        for j in range(n):
            y[j] = y_new[j]
            f[j] = f_new[j]
        finished = t - t_bound >= 0
        t_stop = t
        for k in range(n_events):
            g_new[k] = guard(model, mode, k, t, y, p, quiet)
        for k in range(n_events):
            up = g[k] <= 0 and g_new[k] >= 0
            down = g[k] >= 0 and g_new[k] <= 0
            if up and directions[k] > 0 or down and directions[k] < 0 or (up or down) and directions[k] == 0:
                root = _root(model, mode, k, p, quiet, F, tmp, t_old, h, t_old, t, buf)
                if hit < 0 or root < t_hit:
                    hit, t_hit = k, root
            g[k] = g_new[k]
        if hit >= 0:
            status = 1
            t_stop = t_hit
            _dense(F, tmp, t_old, h, t_hit, y_hit)
            if (m >= 1 or resumed) and ts[m] == t_hit:  # solve_ivp drops a step whose event is at its start
                break
        m += 1
        ts[m] = t_stop
        t_full[m - 1] = t
        ys[m, :] = y_hit if status == 1 else y
        if status == 1 or finished:
            break
        if m == max_steps:
            status = 2
            break
    return ts[:m + 1], ys[:m + 1], Fs[:m], t_full[:m], status, hit, t_hit, y_hit, nfev, h_abs


class Segment:
    """What :func:`solve` returns: the fields of a solve_ivp result that the solvers read."""

    def __init__(self, ts, ys, F, t_full, status, hit, t_hit, y_hit, n_events, nfev):
        self.t, self.y, self.status, self.nfev = ts, ys.T, status, nfev
        self.sol = DenseSolution(ts, ys, F, t_full)
        self.t_events = [np.array([t_hit]) if k == hit else np.zeros(0) for k in range(n_events)]
        self.y_events = [y_hit[None, :] if k == hit else np.zeros((0, ys.shape[1])) for k in range(n_events)]
        self.message = {0: "The solver successfully reached the end of the integration interval.",
                        1: "A termination event occurred.",
                        -1: "Required step size is less than spacing between numbers."}[status]


def solve(model: int, mode: int, t0: float, t_end: float, y0, p: np.ndarray, rtol: float, atol: float,
          first_step: float | None, directions, quiet=None, max_steps: int | None = None, pause=None) -> Segment:
    """Integrate ``mode`` of ``model`` (kernel numbers) from t0 to t_end [s] or its first event.

    ``directions``: one per event (see :func:`integrate`); ``quiet``: per event, the time [s] until
    which it reads at least +tiny (None: never). ``pause(t)`` is called every ``max_steps`` steps
    (e.g. a wall-clock budget that raises); the result is the same as without pauses.
    """
    directions = np.asarray(directions, dtype=float)
    n_events = directions.size
    quiet = np.full(n_events, -math.inf) if quiet is None else np.asarray(quiet, dtype=float)
    y0, h = np.array(y0, dtype=float), float(first_step or 0.0)
    parts, resumed = [], 0
    while True:
        with nullcontext() if accel.ACCELERATED else np.errstate(over="ignore", invalid="ignore", divide="ignore"):
            # as Python (no numba; compiled, numpy's warnings never fire), trial steps of a fast crank can overflow;
            # the step controller rejects them, and the output is checked finite
            out = integrate(int(model), int(mode), float(t0), float(t_end), y0, p, float(rtol), float(atol), h,
                            n_events, directions, quiet, int(max_steps or 0), resumed)
        ts, ys, F, t_full, status, hit, t_hit, y_hit, nfev, h = out
        parts.append(out)
        if status != 2:
            break
        t0, y0, resumed = float(ts[-1]), ys[-1].copy(), 1
        pause(t0)
    if len(parts) > 1:  # one segment: each part starts where the last one ended
        ts = np.concatenate([parts[0][0]] + [part[0][1:] for part in parts[1:]])
        ys = np.concatenate([parts[0][1]] + [part[1][1:] for part in parts[1:]])
        F, t_full = (np.concatenate([part[i] for part in parts]) for i in (2, 3))
        nfev = sum(part[8] for part in parts)
    return Segment(ts, ys, F, t_full, int(status), int(hit), float(t_hit), y_hit, n_events, int(nfev))
