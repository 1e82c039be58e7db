"""Statistics of an uncertainty study, with their confidence intervals (95 % unless said).

Plain Monte Carlo (one engine, n independent samples; :func:`mc_statistics`):

* mean: the sample mean, interval Student's t (n - 1 degrees of freedom; the central limit theorem);
* standard deviation: the sample SD (n - 1), interval by the bias-corrected and accelerated (BCa) bootstrap
  (``scipy.stats.bootstrap``, 2000 resamples, seeded; the percentile bootstrap beyond :data:`BCA_MAX` samples):
  no normality assumed;
* quantiles (5, 50, 95 %): the sample quantile, interval distribution-free from order statistics (the ranks
  j < k with P(X_(j) <= q_p <= X_(k)) >= 95 % under Binomial(n, p), exact for any continuous metric).

Multi-fidelity (:func:`multi_fidelity`): the equations on all N samples (g), MuJoCo on the first M of them
(f, paired: the same parameter draws), the equations as a control variate of MuJoCo,

    mean = mean_M(f) + alpha (mean_N(g) - mean_M(g)),  alpha = cov(f, g) / var(g) on the M pairs,

whose variance is var(f) / M (1 - (1 - M / N) rho^2), rho the correlation of f and g on the pairs (Peherstorfer,
Willcox, Gunzburger 2016, MFMC with one low fidelity). ``variance_reduction`` is the plain MuJoCo mean's variance
over this one's, 1 / (1 - (1 - M/N) rho^2): the multi-fidelity estimate is worth that many times M plain MuJoCo
runs. Its interval: Student's t with M - 2 degrees of freedom (alpha is estimated from the pairs). The standard
deviation is estimated the same way from the second moment (control variate g^2), the quantiles by inverting the
control-variate CDF F_N^g(y) + F_M^f(y) - F_M^g(y) (coefficient 1: unbiased whatever the coefficient, and
near-optimal where f and g nearly agree; made monotone by isotonic regression, ``scipy.optimize``), both with
percentile-bootstrap intervals (the M pairs and the N - M
other equations' samples resampled separately, 2000 times).

Event probabilities (:func:`event_probability`): one engine, k of n samples: k / n with the Clopper-Pearson
interval (exact binomial; never narrower than the truth, valid at k = 0). Multi-fidelity: the MuJoCo event
probability is the equations' plus the share of samples where MuJoCo has the event and the equations not, less
the share where the equations have it and MuJoCo not; the interval bounds each of the three shares by its own
Clopper-Pearson interval at 1 - 0.05 / 3 (Bonferroni: 95 % together). With few pairs, the discrepancy shares'
upper bounds (3/M-ish at 0 of M) dominate: that is what M pairs can say. An event seen fewer than
:data:`RARE_COUNT` times is flagged: its interval is the statement, not its point estimate.
"""

from __future__ import annotations

import math
import warnings

import numpy as np

LEVEL = 0.95
BOOTSTRAP = 2000
QUANTILES = (5, 50, 95)
BCA_MAX = 5000  # samples up to which the SD's interval is BCa: its jackknife costs n^2; beyond, the percentile
# bootstrap (where the two agree: the SD's sampling distribution is close to normal by then)
RARE_COUNT = 10  # events seen fewer times than this: the probability is not resolved (its upper bound is)


def _t(dof: int) -> float:
    from scipy import stats

    return float(stats.t.ppf(0.5 + LEVEL / 2, max(dof, 1)))


def quantile_interval(x: np.ndarray, p: float) -> tuple[float, float]:
    """Distribution-free interval of the ``p`` quantile (0 < p < 1) from the sorted sample's order statistics:
    the narrowest symmetric ranks [j, k] with Binomial(n, p) probability of j <= count < k at least LEVEL;
    (-inf or +inf where the sample is too small to bound that side)."""
    from scipy import stats

    x = np.sort(x)
    n = len(x)
    alpha = (1 - LEVEL) / 2
    cdf = stats.binom.cdf(np.arange(n + 1), n, p)  # cdf[i] = P(count <= i), count ~ Binomial(n, p)
    # 1-based ranks: P(X_(j) > q_p) = P(count < j) = cdf[j - 1] <= alpha, P(X_(k) < q_p) = 1 - cdf[k - 1] <= alpha
    j = int(np.count_nonzero(cdf <= alpha))
    k = int(np.argmax(1 - cdf <= alpha)) + 1
    lo = float(x[j - 1]) if j >= 1 else -math.inf
    hi = float(x[k - 1]) if k <= n else math.inf
    return lo, hi


def mc_statistics(x: np.ndarray, seed: int = 0) -> dict:
    """Plain Monte Carlo statistics of the finite values ``x`` (module docstring)."""
    from scipy import stats

    x = np.asarray(x, dtype=float)
    n = len(x)
    mean = float(np.mean(x))
    std = float(np.std(x, ddof=1)) if n > 1 else math.nan
    half = _t(n - 1) * std / math.sqrt(n) if n > 1 else math.inf
    if 2 < n <= BCA_MAX and std > 0:
        with warnings.catch_warnings(), np.errstate(all="ignore"):
            warnings.simplefilter("ignore")
            boot = stats.bootstrap((x,), lambda s, axis: np.std(s, ddof=1, axis=axis), n_resamples=BOOTSTRAP,
                                   confidence_level=LEVEL, method="BCa", rng=np.random.default_rng(seed),
                                   batch=max(1, int(4e6 // n)))  # resamples at once: bounded memory
        std_interval = [float(boot.confidence_interval.low), float(boot.confidence_interval.high)]
        if not all(math.isfinite(v) for v in std_interval):
            std_interval = _percentile_std(x, seed)
    elif n > BCA_MAX and std > 0:
        std_interval = _percentile_std(x, seed)
    else:
        std_interval = [std, std] if n > 1 else [math.nan, math.nan]
    quantiles = {str(q): float(np.quantile(x, q / 100)) for q in QUANTILES}
    intervals = {str(q): list(quantile_interval(x, q / 100)) for q in QUANTILES}
    return {"mean": mean, "mean_interval": [mean - half, mean + half], "std": std, "std_interval": std_interval,
            "quantiles": quantiles, "quantile_intervals": intervals, "samples": n}


def _percentile_std(x: np.ndarray, seed: int) -> list[float]:
    rng = np.random.default_rng(seed)
    stds = np.array([np.std(x[rng.integers(0, len(x), len(x))], ddof=1) for _ in range(BOOTSTRAP)])
    return [float(np.quantile(stds, (1 - LEVEL) / 2)), float(np.quantile(stds, (1 + LEVEL) / 2))]


def cv_moments(f: np.ndarray, g_pair: np.ndarray, g_rest: np.ndarray, w_pair: np.ndarray | None = None,
               w_rest: np.ndarray | None = None):
    """(mean, std, alpha) by control variates: f and g on the M pairs, g alone on the other N - M; with weights
    (multiplicities of shape (B, M) and (B, N - M): B bootstrap resamples at once) arrays of shape (B,)."""
    single = w_pair is None
    if single:
        w_pair, w_rest = np.ones((1, len(f))), np.ones((1, len(g_rest)))
    m, n = len(f), len(f) + len(g_rest)
    results = []
    for power in (1, 2):
        fp, gp, gr = f ** power, g_pair ** power, g_rest ** power
        f_bar, g_bar = w_pair @ fp / m, w_pair @ gp / m
        g_all = (w_pair @ gp + w_rest @ gr) / n
        cov = (w_pair * (fp - f_bar[:, None]) * (gp - g_bar[:, None])).sum(1) / (m - 1)
        var = (w_pair * (gp - g_bar[:, None]) ** 2).sum(1) / (m - 1)
        with np.errstate(invalid="ignore", divide="ignore"):
            alpha = np.where(var > 0, cov / np.where(var > 0, var, 1.0), 0.0)
        results.append((f_bar + alpha * (g_all - g_bar), alpha))
    (m1, alpha), (m2, _) = results
    std = np.sqrt(np.clip(m2 - m1 * m1, 0.0, None) * m / max(m - 1, 1))
    if single:
        return float(m1[0]), float(std[0]), float(alpha[0])
    return m1, std, alpha


def cv_quantiles(f: np.ndarray, g_pair: np.ndarray, g_rest: np.ndarray, w_pair: np.ndarray | None = None,
                 w_rest: np.ndarray | None = None) -> np.ndarray:
    """Quantiles :data:`QUANTILES` of the control-variate CDF F_N^g(y) + F_M^f(y) - F_M^g(y), made monotone
    (running maximum), on the grid of every sampled value: shape (len(QUANTILES),), or (B, len(QUANTILES)) with
    bootstrap multiplicities as in :func:`cv_moments`."""
    from scipy.optimize import isotonic_regression

    single = w_pair is None
    if single:
        w_pair, w_rest = np.ones((1, len(f))), np.ones((1, len(g_rest)))
    m, n = len(f), len(f) + len(g_rest)
    g_all = np.concatenate([g_pair, g_rest])
    w_all = np.concatenate([w_pair, w_rest], axis=1)
    grid = np.sort(np.concatenate([f, g_all]))

    def counts(values, weights):  # weighted count of values <= each grid point: shape (B, len(grid))
        order = np.argsort(values, kind="stable")
        cum = np.concatenate([np.zeros((weights.shape[0], 1)), np.cumsum(weights[:, order], axis=1)], axis=1)
        return cum[:, np.searchsorted(values[order], grid, side="right")]

    cdf = counts(g_all, w_all) / n + (counts(f, w_pair) - counts(g_pair, w_pair)) / m
    # made monotone by isotonic regression weighted by the grid's spacing (a measure in y): where a pair's two
    # engines straddle y the difference term spikes by +-1/M over the gap between them, and a running maximum
    # would keep every upward spike; the isotonic fit spreads each over its width
    gaps = np.diff(grid)
    weights = np.concatenate([gaps, [gaps.mean() if gaps.size else 1.0]])
    weights = np.maximum(weights, 1e-12 * max(weights.max(), 1e-300))
    cdf = np.array([isotonic_regression(row, weights=weights).x for row in cdf])
    out = np.empty((cdf.shape[0], len(QUANTILES)))
    for k, q in enumerate(QUANTILES):
        reached = cdf >= q / 100 - 1e-12
        index = np.where(reached.any(axis=1), np.argmax(reached, axis=1), len(grid) - 1)
        out[:, k] = grid[index]
    return out[0] if single else out


def _multiplicities(rng, size: int, draws: int) -> np.ndarray:
    """Bootstrap multiplicities of ``size`` items, ``draws`` resamples: shape (draws, size), rows summing to size."""
    if size == 0:
        return np.zeros((draws, 0))
    picks = rng.integers(0, size, (draws, size)) + size * np.arange(draws)[:, None]
    return np.bincount(picks.ravel(), minlength=draws * size).reshape(draws, size).astype(float)


def multi_fidelity(f: np.ndarray, g_pair: np.ndarray, g_rest: np.ndarray, seed: int = 0) -> dict:
    """The multi-fidelity statistics (module docstring): ``f`` MuJoCo on the M pairs, ``g_pair`` the equations
    on the same samples, ``g_rest`` the equations on the other N - M. Needs M >= 3."""
    f, g_pair, g_rest = (np.asarray(a, dtype=float) for a in (f, g_pair, g_rest))
    m, n = len(f), len(f) + len(g_rest)
    mean, std, alpha = cv_moments(f, g_pair, g_rest)
    sf, sg = np.std(f, ddof=1), np.std(g_pair, ddof=1)
    rho = float(np.corrcoef(f, g_pair)[0, 1]) if sf > 0 and sg > 0 else 0.0
    rho = 0.0 if not math.isfinite(rho) else rho
    factor = 1 - (1 - m / n) * rho * rho
    half = _t(m - 2) * sf * math.sqrt(max(factor, 0.0) / m)
    quantiles = cv_quantiles(f, g_pair, g_rest)
    rng = np.random.default_rng(seed)
    block = max(1, min(BOOTSTRAP, int(4e6 // (n + m))))  # resamples at once: bounded memory
    stds, qs = [], []
    for start in range(0, BOOTSTRAP, block):
        b = min(block, BOOTSTRAP - start)
        w_pair, w_rest = _multiplicities(rng, m, b), _multiplicities(rng, n - m, b)
        stds.append(cv_moments(f, g_pair, g_rest, w_pair, w_rest)[1])
        qs.append(cv_quantiles(f, g_pair, g_rest, w_pair, w_rest))
    stds, qs = np.concatenate(stds), np.concatenate(qs)
    lo, hi = (1 - LEVEL) / 2, (1 + LEVEL) / 2
    return {"mean": mean, "mean_interval": [mean - half, mean + half], "std": std,
            "std_interval": [float(np.quantile(stds, lo)), float(np.quantile(stds, hi))],
            "quantiles": {str(q): float(v) for q, v in zip(QUANTILES, quantiles)},
            "quantile_intervals": {str(q): [float(np.quantile(qs[:, k], lo)), float(np.quantile(qs[:, k], hi))]
                                   for k, q in enumerate(QUANTILES)},
            "variance_reduction": 1.0 / factor if factor > 0 else math.inf, "correlation": rho,
            "coefficient": alpha, "samples": n, "mujoco_samples": m}


def clopper_pearson(k: int, n: int, level: float = LEVEL) -> tuple[float, float]:
    """The exact (Clopper-Pearson) interval of a binomial proportion, k of n: the beta quantiles
    B(a/2; k, n - k + 1) and B(1 - a/2; k + 1, n - k), 0 and 1 at the ends."""
    from scipy import stats

    if n == 0:
        return 0.0, 1.0
    a = 1 - level
    lo = float(stats.beta.ppf(a / 2, k, n - k + 1)) if k > 0 else 0.0
    hi = float(stats.beta.ppf(1 - a / 2, k + 1, n - k)) if k < n else 1.0
    return lo, hi


def event_probability(hits: np.ndarray) -> dict:
    """One engine: k of n samples had the event (``hits``: booleans of shape (n,))."""
    hits = np.asarray(hits, dtype=bool)
    k, n = int(hits.sum()), len(hits)
    lo, hi = clopper_pearson(k, n)
    return {"probability": k / n if n else math.nan, "interval": [lo, hi], "count": k, "samples": n,
            "estimator": "mc", **_rare_note(k, n, hi)}


def multi_fidelity_event(f_hits: np.ndarray, g_pair_hits: np.ndarray, g_all_hits: np.ndarray) -> dict:
    """MuJoCo's event probability from the equations' on all N samples and the M pairs' disagreements
    (module docstring)."""
    f, gp, ga = (np.asarray(a, dtype=bool) for a in (f_hits, g_pair_hits, g_all_hits))
    m, n = len(f), len(ga)
    level = 1 - (1 - LEVEL) / 3
    k_g = int(ga.sum())
    only_f, only_g = int(np.sum(f & ~gp)), int(np.sum(gp & ~f))
    g_lo, g_hi = clopper_pearson(k_g, n, level)
    _, up_f = clopper_pearson(only_f, m, level)
    _, up_g = clopper_pearson(only_g, m, level)
    p = k_g / n + (only_f - only_g) / m
    lo, hi = max(0.0, g_lo - up_g), min(1.0, g_hi + up_f)
    k_f = int(f.sum())
    return {"probability": min(max(p, 0.0), 1.0), "interval": [lo, hi], "count": k_g, "samples": n,
            "mujoco_count": k_f, "mujoco_samples": m, "disagreements": [only_f, only_g],
            "estimator": "multi-fidelity", **_rare_note(k_g + k_f, n, hi)}


def _rare_note(count: int, n: int, hi: float) -> dict:
    if count == 0:
        return {"resolved": False, "note": f"never seen in {n} samples: the probability is below {hi:.2g} (95 %); "
                                           "more samples resolve smaller ones"}
    if count < RARE_COUNT:
        return {"resolved": False, "note": f"seen {count} times only: the interval, not the point estimate, is what "
                                           "the samples say"}
    return {"resolved": True}
