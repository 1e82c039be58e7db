"""The atlas's Gaussian process (ipir_mujoco.studies.gp) and its surrogate of a cost (atlas_surrogate)."""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest
from scipy.stats import qmc

from ipir_mujoco.studies.atlas_surrogate import CostSurrogate, crossings_1d, safe_fraction
from ipir_mujoco.studies.gp import GaussianProcess


def _sobol(n, d, seed):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # scipy's note when n is not a power of 2
        return qmc.Sobol(d=d, scramble=True, seed=seed).random(n)


def test_likelihood_gradient_matches_finite_differences():
    rng = np.random.default_rng(1)
    X = rng.random((25, 2))
    y = np.sin(4 * X[:, 0]) + X[:, 1] ** 2
    y = (y - y.mean()) / y.std()
    gp = GaussianProcess()
    theta = np.log(np.array([0.3, 0.8, 1.2, 1e-3]))
    f0, grad = gp._nll(theta, X, y)
    for k in range(theta.size):
        h = 1e-6
        step = np.zeros_like(theta)
        step[k] = h
        numeric = (gp._nll(theta + step, X, y)[0] - gp._nll(theta - step, X, y)[0]) / (2 * h)
        # central differences of a smooth function: error O(h^2 f''') plus rounding ~1e-16 |f| / h ~ 1e-9
        assert grad[k] == pytest.approx(numeric, rel=1e-5, abs=1e-6)


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_gp_interpolates_a_smooth_function_and_its_band_covers_the_truth(seed):
    def truth(U):
        return np.sin(3 * U[:, 0]) * np.exp(U[:, 1]) + 0.5 * U[:, 0] * U[:, 1]

    X = _sobol(40, 2, seed)
    gp = GaussianProcess().fit(X, truth(X))
    test = np.random.default_rng(seed + 10).random((400, 2))
    mean, sd = gp.predict(test)
    error = np.abs(mean - truth(test))
    spread = truth(test).std()
    # 40 points of a smooth 2-D function: the interpolant is far better than the function's own spread
    assert np.sqrt(np.mean(error ** 2)) < 0.02 * spread
    # calibration: a 95 % band (+-2 sd) holds the truth at most test points (an honest GP: >= 90 %)
    assert np.mean(error <= 2 * sd + 1e-9) >= 0.9


def test_gp_is_exact_at_its_points_without_noise_and_finds_an_irrelevant_parameter():
    X = _sobol(32, 2, 3)
    y = np.cos(5 * X[:, 0])  # the second parameter plays no part
    gp = GaussianProcess().fit(X, y)
    mean, sd = gp.predict(X)
    assert np.max(np.abs(mean - y)) < 1e-3 * y.std()
    assert np.max(sd) < 1e-2 * y.std()
    lengths = gp.lengths
    assert lengths[1] > 5 * lengths[0]  # automatic relevance: a long length scale for the unused parameter


def test_refit_false_keeps_the_hyperparameters():
    X = _sobol(16, 1, 0)
    gp = GaussianProcess().fit(X, np.sin(6 * X[:, 0]))
    theta = gp.theta.copy()
    gp.fit(np.vstack([X, [[0.5]]]), np.append(np.sin(6 * X[:, 0]), math.sin(3.0)), refit=False)
    assert np.array_equal(gp.theta, theta)


def test_surrogate_finds_a_known_crossing_within_its_interval():
    # cost 0.2 (u - 0.3): |cost| = 0.01 at u = 0.25 and u = 0.35
    U = np.linspace(0, 1, 15)[:, None]
    s = CostSurrogate(0.01).update(U, 0.2 * (U[:, 0] - 0.3))
    found = crossings_1d(s, 0.01)
    assert len(found) == 2
    for (x, lo, hi), true in zip(found, (0.25, 0.35)):
        assert lo <= true <= hi
        assert abs(x - true) < 0.01
    frac, (lo, hi) = safe_fraction(s.p_safe(np.linspace(0, 1, 4001)[:, None], 0.01))
    assert lo <= 0.1 <= hi and abs(frac - 0.1) < 0.01


def test_prior_mean_carries_the_shape_and_the_residual_model_learns_the_offset():
    # a "MuJoCo" cost = the "equations'" cost + 0.002: on the equations' surrogate as its trend, six MuJoCo
    # points give the cost far better than the same six points without it
    def equations(U):
        return 0.05 * np.sin(4 * U[:, 0]) * (1 + U[:, 1])

    dense = _sobol(128, 2, 0)
    prior = CostSurrogate(0.01).update(dense, equations(dense))
    few = _sobol(6, 2, 5)
    with_prior = CostSurrogate(0.01, prior).update(few, equations(few) + 0.002)
    alone = CostSurrogate(0.01).update(few, equations(few) + 0.002)
    test = _sobol(256, 2, 9)
    truth = np.arcsinh((equations(test) + 0.002) / 0.01)
    rms = {k: np.sqrt(np.mean((s.predict(test)[0] - truth) ** 2)) for k, s in (("prior", with_prior), ("alone", alone))}
    assert rms["prior"] < 0.05 * truth.std()
    assert rms["prior"] < 0.2 * rms["alone"]
