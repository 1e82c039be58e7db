"""A small Gaussian-process regressor on numpy and scipy: the atlas's surrogate of a cost over a design box.

Why our own: the atlas needs one model, a GP with a Matern 5/2 kernel of one length scale per parameter
(automatic relevance), a constant mean and a noise term, fitted by maximum marginal likelihood, and its
posterior mean and standard deviation, on at most a few hundred points in a few dimensions. That is ~100
lines on numpy and scipy (Rasmussen & Williams, *Gaussian Processes for Machine Learning*, 2006, alg. 2.1
and eq. 5.9), which the package's core dependencies already bring; scikit-learn's GaussianProcessRegressor
does the same and more, but would add scikit-learn, joblib and threadpoolctl (tens of MB) to the
installation for this one use. tests/test_gp.py holds this one to known functions, to its own calibration
(the truth inside mean +- 2 sd) and the likelihood's gradient to finite differences.

Inputs are points of the unit box [0, 1]^d (the atlas maps each parameter's range onto [0, 1], log ranges in
log space); outputs are standardised inside.

Kernel: k(x, x') = s2 (1 + sqrt5 q + 5 q^2 / 3) exp(-sqrt5 q), q^2 = sum_k ((x_k - x'_k) / l_k)^2, plus
n2 on the diagonal (noise). Hyper-parameters (log l_1..l_d, log s2, log n2) maximise the log marginal
likelihood (L-BFGS-B with its exact gradient, a few deterministic starts) within :data:`BOUNDS`.
"""

from __future__ import annotations

import ctypes
import functools
import math
from contextlib import contextmanager

import numpy as np
from scipy.linalg import cho_factor, cho_solve, solve_triangular
from scipy.optimize import minimize

SQRT5 = math.sqrt(5.0)
# bounds of the hyper-parameters on the standardised outputs over the unit box: a length scale shorter than
# 1/100 of the box cannot be resolved by the few hundred points a GP here gets; longer than 30 boxes is a
# parameter the output does not depend on (the bound keeps the kernel matrix well conditioned); the noise
# variance from 1e-8 (the analytic engines' outputs: deterministic to their tolerance) to 0.5 (half the
# outputs' variance: anything noisier is not a surrogate worth having)
BOUNDS = {"length": (0.01, 30.0), "signal": (1e-3, 1e3), "noise": (1e-8, 0.5)}
STARTS = (0.3, 1.0)  # initial length scales (all parameters alike) of the likelihood's maximisation


@functools.lru_cache(maxsize=1)
def _openblas_setters() -> tuple:
    """``openblas_set_num_threads_local`` of every OpenBLAS loaded (numpy's and scipy's: Linux, where
    /proc/self/maps lists them), or () where there is none to find."""
    try:
        with open("/proc/self/maps", encoding="utf-8") as fh:
            paths = sorted({line.split()[-1] for line in fh if "openblas" in line and line.split()[-1].startswith("/")})
    except OSError:
        return ()
    setters = []
    for path in paths:
        try:
            setter = ctypes.CDLL(path).openblas_set_num_threads_local
        except (OSError, AttributeError):
            continue
        setter.restype, setter.argtypes = ctypes.c_int, [ctypes.c_int]
        setters.append(setter)
    return tuple(setters)


@contextmanager
def one_blas_thread():
    """OpenBLAS on one thread here (restored on leaving). The GP's matrices are at most a few hundred wide,
    where OpenBLAS's threads cost more than they give, and on a machine whose cores are busy each of its
    synchronisations waits for a core: measured on 2 busy cores (load 14), a 40-point fit took 9.5 s with
    OpenBLAS's threads and 0.29 s on one."""
    setters = _openblas_setters()
    previous = [setter(1) for setter in setters]
    try:
        yield
    finally:
        for setter, count in zip(setters, previous):
            setter(count)


def matern52(X1: np.ndarray, X2: np.ndarray, lengths: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Matern 5/2 correlation (unit variance) between the rows of X1 (n1, d) and X2 (n2, d), and the scaled
    squared differences (n1, n2, d) the gradient needs."""
    diff2 = ((X1[:, None, :] - X2[None, :, :]) / lengths) ** 2
    q = np.sqrt(diff2.sum(axis=2))
    return (1.0 + SQRT5 * q + 5.0 / 3.0 * q * q) * np.exp(-SQRT5 * q), diff2


class GaussianProcess:
    """GP regression on the unit box (module docstring). ``fit`` then ``predict``; ``refit=False`` keeps the
    hyper-parameters of the last fit (new data, same kernel: the atlas's cheap updates between full fits)."""

    def __init__(self) -> None:
        self.theta: np.ndarray | None = None  # log l_1..l_d, log s2, log n2

    @property
    def lengths(self) -> np.ndarray:
        return np.exp(self.theta[:-2])

    def _nll(self, theta: np.ndarray, X: np.ndarray, y: np.ndarray) -> tuple[float, np.ndarray]:
        """Negative log marginal likelihood of the standardised y, and its gradient in theta."""
        n, d = X.shape
        lengths, s2, n2 = np.exp(theta[:d]), math.exp(theta[d]), math.exp(theta[d + 1])
        corr, diff2 = matern52(X, X, lengths)
        K = s2 * corr + n2 * np.eye(n)
        try:
            factor = cho_factor(K, lower=True)
        except np.linalg.LinAlgError:
            return 1e25, np.zeros_like(theta)
        alpha = cho_solve(factor, y)
        nll = 0.5 * y @ alpha + np.log(np.diag(factor[0])).sum() + 0.5 * n * math.log(2 * math.pi)
        W = cho_solve(factor, np.eye(n)) - np.outer(alpha, alpha)  # dNLL/dK = W / 2
        q = np.sqrt(diff2.sum(axis=2))
        radial = s2 * 5.0 / 3.0 * (1.0 + SQRT5 * q) * np.exp(-SQRT5 * q)  # dK/dlog l_k = radial * diff2_k
        grad = np.empty_like(theta)
        for k in range(d):
            grad[k] = 0.5 * np.sum(W * radial * diff2[:, :, k])
        grad[d] = 0.5 * np.sum(W * s2 * corr)
        grad[d + 1] = 0.5 * n2 * np.trace(W)
        return float(nll), grad

    def fit(self, X, y, refit: bool = True) -> "GaussianProcess":
        with one_blas_thread():
            return self._fit(X, y, refit)

    def _fit(self, X, y, refit: bool) -> "GaussianProcess":
        """Condition on the points X (n, d) in [0, 1]^d and outputs y (n,); ``refit``: maximise the likelihood
        again (else keep the last hyper-parameters, which a first fit must have set)."""
        X, y = np.atleast_2d(np.asarray(X, dtype=float)), np.asarray(y, dtype=float).ravel()
        n, d = X.shape
        if n != y.size or n < 1:
            raise ValueError(f"GaussianProcess.fit: {n} points and {y.size} outputs; need as many, at least one")
        self.X, self.offset = X, float(y.mean())
        spread = float(y.std())
        self.scale = spread if spread > 1e-12 * max(1.0, abs(self.offset)) else 1.0
        ys = (y - self.offset) / self.scale
        bounds = ([tuple(map(math.log, BOUNDS["length"]))] * d + [tuple(map(math.log, BOUNDS["signal"]))]
                  + [tuple(map(math.log, BOUNDS["noise"]))])
        if refit or self.theta is None or self.theta.size != d + 2:
            starts = [np.array([math.log(l0)] * d + [0.0, math.log(1e-4)]) for l0 in STARTS]
            if self.theta is not None and self.theta.size == d + 2:
                starts.insert(0, self.theta.copy())
            best = None
            for start in starts:
                result = minimize(self._nll, start, args=(X, ys), jac=True, method="L-BFGS-B", bounds=bounds,
                                  options={"maxiter": 200})
                if best is None or result.fun < best.fun:
                    best = result
            self.theta = best.x
        d_ = d
        lengths, s2, n2 = self.lengths, math.exp(self.theta[d_]), math.exp(self.theta[d_ + 1])
        self.s2 = s2
        K = s2 * matern52(X, X, lengths)[0] + n2 * np.eye(n)
        jitter = 0.0
        while True:  # a nugget only if the factorisation fails (points that coincide)
            try:
                self.chol = np.linalg.cholesky(K + jitter * np.eye(n))
                break
            except np.linalg.LinAlgError:
                jitter = max(1e-10, 10 * jitter) * s2
        self.alpha = cho_solve((self.chol, True), ys)
        self.y = y
        return self

    @property
    def noise(self) -> float:
        """The fitted noise variance, in the outputs' units squared."""
        return math.exp(self.theta[-1]) * self.scale ** 2

    def prior_cov(self, A, B) -> np.ndarray:
        """The kernel's covariance (outputs' units squared) between the rows of A and B, before any data."""
        with one_blas_thread():
            return self.scale ** 2 * self.s2 * matern52(np.atleast_2d(A), np.atleast_2d(B), self.lengths)[0]

    def whitened(self, A) -> np.ndarray:
        """L^-1 k(X, A) (n, m), in output units: the posterior covariance is prior_cov(A, B) - whitened(A).T @
        whitened(B)."""
        with one_blas_thread():
            ks = self.scale * self.s2 * matern52(self.X, np.atleast_2d(np.asarray(A, dtype=float)), self.lengths)[0]
            return solve_triangular(self.chol, ks, lower=True)

    def predict(self, Xs) -> tuple[np.ndarray, np.ndarray]:
        """Posterior mean and standard deviation (of the latent function, the noise left out) at Xs (m, d)."""
        with one_blas_thread():
            return self._predict(Xs)

    def _predict(self, Xs) -> tuple[np.ndarray, np.ndarray]:
        Xs = np.atleast_2d(np.asarray(Xs, dtype=float))
        ks = self.s2 * matern52(Xs, self.X, self.lengths)[0]
        mean = ks @ self.alpha
        v = solve_triangular(self.chol, ks.T, lower=True)
        var = np.maximum(self.s2 - np.sum(v * v, axis=0), 0.0)
        return self.offset + self.scale * mean, self.scale * np.sqrt(var)
