"""The atlas's surrogate of one cost over the design box: where |cost| < threshold, with its uncertainty.

A cost c(x) = (idealized - real) / |real| (signed) is modelled as z = asinh(c / s) by a Gaussian process
(:mod:`.gp`) on the unit box: asinh is linear near 0 and logarithmic far from it, so costs from 0.01 % to
50 % sit on one smooth scale, and the threshold T maps to +-asinh(T / s) (s: the smallest threshold asked).
A MuJoCo cost is modelled on top of the equations' surrogate of the same idealization where there is one
(a two-level co-kriging: the equations' posterior, mean and covariance, plus a GP of the difference, which for
one mechanism in two engines is small and smooth; :class:`CostSurrogate`); otherwise on a constant mean.

At a design x the posterior z ~ N(m, sd^2) gives p(x) = P(|c| < T) = Phi((a - m) / sd) - Phi((-a - m) / sd),
a = asinh(T / s). A design is *safe* where p >= 0.975, *unsafe* where p <= 0.025, on the *boundary* (its side
not known at 95 %) otherwise. Over a quasi-random set of designs filling the box: the safe fraction is the
share with p > 0.5, its interval [share with p >= 0.975, share with p > 0.025] widened by the set's own
binomial standard error; the boundary is known to a tolerance when the boundary share is below it.
"""

from __future__ import annotations

import math

import numpy as np
from scipy.special import ndtr

from .gp import GaussianProcess, one_blas_thread

CONFIDENT = 0.975  # p beyond which a design's side of the threshold is known (two-sided 95 %)
MAX_POINTS = 128  # points an equations' surrogate is fitted on (the first of its dense sample): the fit is O(n^3)
REFIT_GROWTH = 1.25  # hyper-parameters are fitted again once the points have grown by this factor


class CostSurrogate:
    """The surrogate of one cost (module docstring): ``update(U, costs)`` then ``predict``, ``p_safe``.

    With a ``prior`` (the equations' surrogate of the same idealization and metric) the cost is modelled as
    z = g + delta: g the prior's posterior (its mean and its covariance: its interpolation error, which this
    surrogate's own runs reduce too), delta a GP of its own whose hyper-parameters are fitted on the residuals
    z - mean(g) (a two-level co-kriging in the manner of Kennedy & O'Hagan, 2000, with the levels' scale 1).
    """

    def __init__(self, scale: float, prior: "CostSurrogate | None" = None):
        self.scale, self.prior = scale, prior
        self.gp = GaussianProcess()
        self.fitted_at = 0
        self.U = np.zeros((0, 0))
        self.residual = np.zeros(0)
        self._cache: dict = {}  # the prior's mean, variance and whitened kernel at designs asked for before

    def update(self, U: np.ndarray, costs) -> "CostSurrogate":
        """Condition on designs U (n, d) of the unit box and their signed costs (None/nan: left out)."""
        costs = np.array([np.nan if c is None else c for c in costs], dtype=float)
        ok = np.isfinite(costs)
        U, z = np.asarray(U, dtype=float)[ok], np.arcsinh(costs[ok] / self.scale)
        if len(z) == 0:
            raise ValueError("no design gave this cost")
        base = self._prior(U)[0] if self.prior is not None else 0.0
        self.U, self.residual = U, z - base
        refit = self.fitted_at == 0 or len(z) >= REFIT_GROWTH * self.fitted_at
        self.gp.fit(U, self.residual, refit=refit)
        if refit:
            self.fitted_at = len(z)
        self._condition()
        return self

    def believe(self, u: np.ndarray) -> None:
        """Add the design u with the surrogate's own mean there (kriging believer): the uncertainty shrinks
        around it, so the next design of a batch goes elsewhere. Hyper-parameters kept."""
        m = self.predict(u[None, :])[0] - (self._prior(u[None, :])[0] if self.prior is not None else 0.0)
        self.U, self.residual = np.vstack([self.U, u]), np.append(self.residual, m)
        self.gp.fit(self.U, self.residual, refit=False)
        self._condition()

    def _prior(self, U: np.ndarray):
        """(mean, variance, whitened kernel) of the prior at U, cached (the prior is fitted once)."""
        U = np.asarray(U, dtype=float)
        key = (U.shape, hash(U.tobytes()))
        if key not in self._cache:
            if len(self._cache) > 8:
                self._cache.clear()
            mean, sd = self.prior.predict(U)
            self._cache[key] = (mean, sd * sd, self.prior.gp.whitened(U))
        return self._cache[key]

    def _prior_cov(self, A: np.ndarray, B: np.ndarray) -> np.ndarray:
        """The prior's posterior covariance between A and B (z units squared)."""
        return self.prior.gp.prior_cov(A, B) - self._prior(A)[2].T @ self._prior(B)[2]

    def _condition(self) -> None:
        if self.prior is None:
            return
        with one_blas_thread():
            self._condition_here()

    def _condition_here(self) -> None:
        gp, U = self.gp, self.U
        K = self._prior_cov(U, U) + gp.prior_cov(U, U) + gp.noise * np.eye(len(U))
        self._chol = np.linalg.cholesky(K + 1e-12 * np.trace(K) / len(U) * np.eye(len(U)))
        self._alpha = np.linalg.solve(self._chol.T, np.linalg.solve(self._chol, self.residual - gp.offset))

    def predict(self, U) -> tuple[np.ndarray, np.ndarray]:
        """Posterior mean and sd of z = asinh(cost / scale) at U (m, d)."""
        if self.prior is None:
            return self.gp.predict(U)
        with one_blas_thread():
            return self._predict_here(np.asarray(U, dtype=float))

    def _predict_here(self, U: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        mean_g, var_g, _ = self._prior(U)
        kx = self._prior_cov(U, self.U) + self.gp.prior_cov(U, self.U)
        v = np.linalg.solve(self._chol, kx.T)
        var = np.maximum(var_g + self.gp.scale ** 2 * self.gp.s2 - np.sum(v * v, axis=0), 0.0)
        return mean_g + self.gp.offset + kx @ self._alpha, np.sqrt(var)

    def cost(self, U) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """|cost| at U: the surrogate's mean, and its 95 % band [lo, hi] (of |cost|)."""
        m, sd = self.predict(U)
        lo, hi = m - 1.96 * sd, m + 1.96 * sd
        low = np.where((lo < 0) & (hi > 0), 0.0, np.minimum(np.abs(lo), np.abs(hi)))
        return (np.abs(np.sinh(m)) * self.scale, np.sinh(low) * self.scale,
                np.sinh(np.maximum(np.abs(lo), np.abs(hi))) * self.scale)

    def p_safe(self, U, threshold: float) -> np.ndarray:
        m, sd = self.predict(U)
        a = math.asinh(threshold / self.scale)
        sd = np.maximum(sd, 1e-12)
        return ndtr((a - m) / sd) - ndtr((-a - m) / sd)


def regions(p: np.ndarray) -> dict[str, int]:
    return {"safe": int(np.sum(p >= CONFIDENT)), "unsafe": int(np.sum(p <= 1 - CONFIDENT)),
            "boundary": int(np.sum((p > 1 - CONFIDENT) & (p < CONFIDENT)))}


def safe_fraction(p: np.ndarray) -> tuple[float, list[float]]:
    """(share of designs with p > 0.5, [lo, hi]) over a space-filling set (module docstring)."""
    n = len(p)
    frac = float(np.mean(p > 0.5))
    se = math.sqrt(max(frac * (1 - frac), 0.25 / n) / n)
    lo, hi = float(np.mean(p >= CONFIDENT)), float(np.mean(p > 1 - CONFIDENT))
    return frac, [max(0.0, min(lo, frac) - se), min(1.0, max(hi, frac) + se)]


def boundary_share(p: np.ndarray) -> float:
    return float(np.mean((p > 1 - CONFIDENT) & (p < CONFIDENT)))


def crossings_1d(surrogate: CostSurrogate, threshold: float, points: int = 2001) -> list[list[float]]:
    """Where |cost| crosses ``threshold`` along the one varied parameter (unit coordinate): [[u, lo, hi]], u
    where the mean crosses, [lo, hi] the stretch around it whose side is not known at 95 %."""
    u = np.linspace(0.0, 1.0, points)
    p = surrogate.p_safe(u[:, None], threshold)
    side = p > 0.5
    found = []
    for k in np.flatnonzero(side[1:] != side[:-1]):
        # the crossing between u[k] and u[k+1], linear in p
        x = u[k] + (0.5 - p[k]) / (p[k + 1] - p[k]) * (u[k + 1] - u[k]) if p[k + 1] != p[k] else u[k]
        lo = k
        while lo > 0 and 1 - CONFIDENT < p[lo] < CONFIDENT:
            lo -= 1
        hi = k + 1
        while hi < points - 1 and 1 - CONFIDENT < p[hi] < CONFIDENT:
            hi += 1
        found.append([float(x), float(u[lo]), float(u[hi])])
    return found
