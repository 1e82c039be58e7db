"""The periodic steady state of a run from its per-revolution mean speeds: the exact test and the statistical one.

Every engine's run stops (``--until-steady``) and every summary reads its steady figures through
:func:`find_steady`, so that the watch that stops a run (:class:`.steady_watch.SteadyWatch`) and the figures
read off it afterwards (:func:`.cycles.cycle_summary`) find the same revolution. Two tests, the first that
passes wins:

- **exact** (:func:`steady_at_end`): the last ``n`` means agree within ``tol`` of their mean and the
  drift their last changes extrapolate to is as small. A run whose revolutions converge to one limit cycle
  (the equations; MuJoCo without skids, whose wobble from revolution to revolution is a few 1e-5) passes
  it, and its figures are the limit extrapolated from the last revolutions (:func:`.cycles.limit_motion`).
- **statistical** (:func:`statistical_at_end`): where each revolution differs a little from the last for
  ever (MuJoCo's modules skidding every stroke: the skid's start and end fall where the steps fall, a few
  1e-4 of a revolution's speed), the exact test never passes. The last W >= :data:`STATISTICAL_MIN`
  revolutions' means u_1..u_W are fitted with a line u = m + b (k - mean k) by least squares, with the
  residuals' scatter s, the standard errors s / sqrt(W) of the mean and s / sqrt(sum (k - mean k)^2) of
  the trend b, and Student's quantile q of W - 2 degrees of freedom at :data:`CONFIDENCE`. The window is
  steady when its mean is > 0, its trend is not significant (|b| <= q SE(b): what is left of the approach
  is buried in the scatter), and the figure's uncertainty

      U = q s / sqrt(W) + |b| (W - 1) / 2        (the mean's confidence half-width + the trend's reach
                                                  from the window's centre to its end)

  is within ``target`` |m|. Of the windows ending at a revolution (every W from STATISTICAL_MIN up to all
  the revolutions so far) the longest that passes is taken (the start-up's revolutions, far off the limit,
  inflate a longer window's scatter so much that they hide their own trend: the longest window without a
  significant trend held them); its mean is the steady speed, its sums the distance per revolution and the
  energy per metre (:func:`.cycles.transit_free_energy`). Choosing among windows and stopping at the first
  revolution that passes favours windows whose scatter happens to look small, so the quantile is taken at
  :data:`CONFIDENCE` = 0.99: on revolutions scattering by 5e-4 and 1e-3 about a known limit, U then held the
  limit in 0.96 and 0.98 of runs (:data:`COVERAGE`, 0.95, is what is stated), where at 0.95 it held it in
  0.93 and 0.90 (and the window of the smallest U in 0.91 and 0.86).

The target is the accuracy each engine states for its steady figures (:data:`LIMIT_ACCURACY`, relative to the
periodic limit the engine converges to; :func:`steady_target`), or the run's ``steady_tol`` where that is
looser. A run that passes the exact test has the stated accuracy as its uncertainty (the test
``tests/test_steady_limit.py`` holds it to that); one that passes the statistical test has its own U.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from statistics import NormalDist

import numpy as np

# The accuracy the steady figures are stated to (relative to the periodic limit each engine converges to) and
# held to by tests/test_steady_limit.py against runs taken much closer to that limit: the analytic engines'
# per-revolution figures are smooth to their integration tolerance, so the extrapolation leaves a second-order
# error; MuJoCo's wobble from revolution to revolution by a few 1e-5 (where its steps fall in a revolution),
# which no extrapolation removes. The statistical test's target (:func:`steady_target`).
STEADY_TOL = 1e-4  # relative spread of the per-revolution mean speed that counts as settled
STEADY_CYCLES = 3  # revolutions the spread is measured over
LIMIT_ACCURACY = {"analytic": 2e-5, "mujoco": 3e-4}
STATISTICAL_MIN = 8  # revolutions: the fewest a statistical window fits a trend and a scatter to (6 dof)
# two-sided, of the mean's and the trend's intervals: 0.99, so that over the choice of window and the stop at the
# first revolution that passes the stated uncertainty still covers the limit in COVERAGE of runs (measured:
# tests/test_steady_statistics.py; at 0.95 the same selection covered it in only 0.90-0.93 of them)
CONFIDENCE = 0.99
COVERAGE = 0.95  # what the stated uncertainty U is held to: the share of runs whose limit lies within it


def student_quantile(p: float, dof) -> np.ndarray:
    """Student's t quantile at probability ``p`` for ``dof`` degrees of freedom (float or array, >= 1), by the
    Cornish-Fisher expansion in 1/dof to fourth order about the normal quantile z (core imports no scipy):
    3.7062 against the exact 3.7074 at 6 degrees of freedom for p = 0.995 (2.44680 against 2.44691 for
    p = 0.975), closer with more; at 1 or 2 it falls short, which the statistical test never asks for (W >= 8)."""
    z = NormalDist().inv_cdf(p)
    v = np.asarray(dof, dtype=float)
    return (z + (z**3 + z) / (4 * v) + (5 * z**5 + 16 * z**3 + 3 * z) / (96 * v**2)
            + (3 * z**7 + 19 * z**5 + 17 * z**3 - 15 * z) / (384 * v**3)
            + (79 * z**9 + 776 * z**7 + 1482 * z**5 - 1920 * z**3 - 945 * z) / (92160 * v**4))


def steady_target(engine: str, tol: float = 0.0) -> float:
    """The statistical test's target [-] for a run of ``engine`` (a :class:`.results.RunResult`'s ``engine``:
    'mujoco' or 'analytic...'): the accuracy that engine states for its steady figures, or ``tol`` (the run's
    steady_tol) where that is looser."""
    stated = LIMIT_ACCURACY["mujoco" if engine.startswith("mujoco") else "analytic"]
    return max(stated, float(tol))


@dataclass(frozen=True)
class Steady:
    """Where and how a run reached its steady state: at the end of revolution ``end`` (index into the
    per-revolution means), over the window of revolutions ``start..end``; ``test`` 'exact' or 'statistical';
    ``uncertainty`` [-]: the steady speed's, relative (exact: the stated accuracy; statistical: U / |m|)."""

    end: int
    start: int
    test: str
    uncertainty: float


def line_fit(values: np.ndarray) -> tuple[float, float, float, float, int]:
    """(mean, trend per revolution, SE of the mean, SE of the trend, degrees of freedom) of ``values`` (W,) fitted
    by u = m + b (k - mean k), W >= 3 (module docstring)."""
    u = np.asarray(values, dtype=float)
    w = u.size
    k = np.arange(w) - 0.5 * (w - 1)
    mean = float(u.mean())
    sxx = float(k @ k)
    slope = float(k @ (u - mean)) / sxx
    residual = u - mean - slope * k
    s = math.sqrt(float(residual @ residual) / (w - 2))
    return mean, slope, s / math.sqrt(w), s / math.sqrt(sxx), w - 2


def window_uncertainty(values) -> float:
    """U = q SE(mean) + |b| (W - 1) / 2 of ``values`` (W,), W >= 3 (module docstring), in their unit."""
    _, slope, se_mean, _, dof = line_fit(values)
    return float(student_quantile(0.5 + 0.5 * CONFIDENCE, dof)) * se_mean + abs(slope) * (len(values) - 1) / 2


def _windows(u: np.ndarray) -> tuple[np.ndarray, ...]:
    """For every window of the last W of ``u`` (K,), W = 3..K: (W, mean, trend, SE mean, SE trend), arrays
    (K - 2,), from running sums over the values taken from the end (centred on the last value, so that the
    scatter's squares do not cancel against the mean's)."""
    rev = u[::-1] - u[-1]  # j = 0 is the last revolution
    j = np.arange(rev.size, dtype=float)
    s1, sj, s2 = np.cumsum(rev), np.cumsum(j * rev), np.cumsum(rev * rev)
    w = np.arange(1, rev.size + 1, dtype=float)
    keep = slice(2, None)
    w, s1, sj, s2 = w[keep], s1[keep], sj[keep], s2[keep]
    mean_dev = s1 / w
    # positions from the window's start x = W - 1 - j; centred: x - (W - 1) / 2 = (W - 1) / 2 - j
    sxx = w * (w * w - 1.0) / 12.0
    sxu = 0.5 * (w - 1.0) * s1 - sj  # sum ((W - 1)/2 - j) u_j, the centred positions against the values
    slope = sxu / sxx
    ss = np.maximum(s2 - s1 * mean_dev - slope * sxu, 0.0)
    s = np.sqrt(ss / (w - 2.0))
    return w, mean_dev + u[-1], slope, s / np.sqrt(w), s / np.sqrt(sxx)


def _trend_free(u: np.ndarray) -> tuple[np.ndarray, ...] | None:
    """(W, mean, U) of every window of the last W >= STATISTICAL_MIN of ``u`` (K,) whose mean is > 0 and whose
    trend is not significant (module docstring), arrays in the order of W; None where the last
    STATISTICAL_MIN are not all finite."""
    if u.size < STATISTICAL_MIN or not np.all(np.isfinite(u[-STATISTICAL_MIN:])):
        return None
    w, mean, slope, se_mean, se_slope = _windows(u)
    ok = w >= STATISTICAL_MIN
    w, mean, slope, se_mean, se_slope = w[ok], mean[ok], slope[ok], se_mean[ok], se_slope[ok]
    q = student_quantile(0.5 + 0.5 * CONFIDENCE, w - 2.0)
    spread = q * se_mean + np.abs(slope) * (w - 1.0) / 2.0
    with np.errstate(invalid="ignore"):
        good = (np.abs(slope) <= q * se_slope) & (mean > 0)
    return w[good], mean[good], spread[good]


def statistical_at_end(speeds, target: float) -> tuple[int, float] | None:
    """(W, U [m/s]) of the statistical window (module docstring) ending at the last of ``speeds`` [m/s] if its
    uncertainty U is within ``target`` of its mean, else None."""
    windows = _trend_free(np.asarray(speeds, dtype=float))
    if windows is None:
        return None
    w, mean, spread = windows
    good = np.flatnonzero(spread <= target * mean)
    if good.size == 0:
        return None
    i = good[-1]  # the longest window that passes
    return int(w[i]), float(spread[i])


def speed_estimate(speeds) -> tuple[int, float, float] | None:
    """(W, mean [m/s], U [m/s]) of a run that never became steady: of the windows ending at its last
    revolution (``speeds`` [m/s], per-revolution means in order) with no significant trend and W >=
    STATISTICAL_MIN, the one of the smallest U (module docstring), whatever U is; None where there is none.

    Why: a run whose revolutions differ by more than any target allows (a wheeled module that tips as its
    wheels lift and land every stroke) still has a mean speed, known to U; the start-up's revolutions, far
    off it, raise a window's U, so the window of the smallest U leaves them out. Chosen for the smallest U, U
    covers the limit less often than :data:`COVERAGE` (0.86-0.91 of runs in the module docstring's
    measurements): an estimate, not a steady figure."""
    windows = _trend_free(np.asarray(speeds, dtype=float))
    if windows is None or windows[0].size == 0:
        return None
    w, mean, spread = windows
    i = int(np.argmin(spread))
    return int(w[i]), float(mean[i]), float(spread[i])


_DRIFT_FLOOR = 1e-3  # of tol: a change per revolution this small counts as settled whatever its trend


def remaining_drift(speeds: list[float] | np.ndarray) -> float:
    """How far [m/s] the per-revolution mean speed still moves after its last value, extrapolated from its
    last two changes d1, d2 as a geometric approach (ratio d2 / d1): |d2| rho / (1 - rho).

    0 where the changes alternate in sign or one is zero (an oscillation the spread bounds); inf where they
    do not shrink (a drift that does not die out, e.g. a constant torque accelerating for ever); inf with
    fewer than three speeds.
    """
    if len(speeds) < 3:
        return math.inf
    d1, d2 = float(speeds[-2] - speeds[-3]), float(speeds[-1] - speeds[-2])
    if d1 * d2 <= 0:
        return 0.0
    rho = d2 / d1
    return abs(d2) * rho / (1.0 - rho) if rho < 1 else math.inf


def steady_at_end(speeds: list[float] | np.ndarray, tol: float = STEADY_TOL, n: int = STEADY_CYCLES) -> bool:
    """Whether the last ``n`` per-revolution mean speeds [m/s] (of ``speeds``, in order) are the periodic
    steady state: their mean > 0, their spread <= tol * mean, and the :func:`remaining_drift` <= tol * mean
    (or the last change below _DRIFT_FLOOR * tol * mean, settled whatever its trend)."""
    u = np.asarray(speeds, dtype=float)
    if u.size < n:
        return False
    window = u[-n:]
    mean = float(window.mean())
    if not (mean > 0 and float(window.max() - window.min()) <= tol * mean):
        return False
    return abs(float(u[-1] - u[-2])) <= _DRIFT_FLOOR * tol * mean or remaining_drift(u) <= tol * mean


def steady_index(speeds: list[float] | np.ndarray, tol: float = STEADY_TOL, n: int = STEADY_CYCLES) -> int | None:
    """Index of the first revolution at whose end the run is at steady state (:func:`steady_at_end`); or None."""
    u = np.asarray(speeds, dtype=float)
    for k in range(n - 1, u.size):
        if steady_at_end(u[:k + 1], tol, n):
            return k
    return None


def find_steady(speeds, tol: float, n: int, target: float | None, exact) -> Steady | None:
    """The first revolution of ``speeds`` [m/s] (per-revolution means, in order) at whose end the run is
    steady, by the exact test ``exact(speeds_so_far, tol, n)`` (:func:`steady_at_end`) or, with a
    ``target``, the statistical one; None where neither passes. The exact one wins a revolution both pass."""
    u = np.asarray(speeds, dtype=float)
    for k in range(n - 1, u.size):
        found = steady_at(u[:k + 1], tol, n, target, exact)
        if found is not None:
            return found
    return None


def steady_at(u: np.ndarray, tol: float, n: int, target: float | None, exact) -> Steady | None:
    """Whether the run is steady at the end of the last of ``u`` (:func:`find_steady`'s test at one
    revolution)."""
    k = u.size - 1
    if exact(u, tol, n):
        return Steady(k, k - n + 1, "exact", float(target if target is not None else tol))
    if target is None:
        return None
    found = statistical_at_end(u, target)
    if found is None:
        return None
    w, spread = found
    return Steady(k, k - w + 1, "statistical", spread / float(np.mean(u[k - w + 1:])))
