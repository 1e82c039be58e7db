"""Uncertainty propagation: distributions, estimators and their intervals, the command's files and refusals."""

from __future__ import annotations

import csv
import json
import math

import numpy as np
import pytest
from scipy import stats

from cli_run import run_cli
from ipir_mujoco.core.cycles import STEADY_TOL
from ipir_mujoco.core.errors import ParameterError
from ipir_mujoco.studies import uq_stats
from ipir_mujoco.studies.uncertainty import engine_pair, parse_event
from ipir_mujoco.studies.uq_dists import outside_mass, parse_dist, read_dist_file, sample

REPEATS = 400
# a 95 % interval's coverage over REPEATS independent repeats: Binomial(REPEATS, 0.95) / REPEATS, whose SD is
# sqrt(0.95 * 0.05 / REPEATS) = 0.011; 4 SDs below 0.95 is what a correct interval stays above (a fixed seed,
# so the test is deterministic; a wrong interval, e.g. the plain-MC one for the control variate, misses by far more)
COVERAGE_FLOOR = 0.95 - 4 * math.sqrt(0.95 * 0.05 / REPEATS)


def test_distributions_parse_check_their_range_and_sample_their_moments():
    d = parse_dist("F_r1=normal:1:0.1")
    assert d.kind == "normal" and d.args == (1.0, 0.1)
    assert outside_mass(d) == pytest.approx(stats.norm.cdf(-10), rel=1e-6)
    n = 20000
    x = sample([d, parse_dist("m2=uniform:0.5:1.5"), parse_dist("J_A=lognormal:-7:0.3"),
                parse_dist("mu_wall=truncnormal:0.5:0.2:0.3:0.6")], n, seed=3)
    assert x.shape == (n, 4)
    # sample means within 5 standard errors of the distributions' (sd / sqrt(n))
    for k, frozen in enumerate([stats.norm(1, 0.1), stats.uniform(0.5, 1.0), stats.lognorm(0.3, scale=math.exp(-7)),
                                stats.truncnorm((0.3 - 0.5) / 0.2, (0.6 - 0.5) / 0.2, loc=0.5, scale=0.2)]):
        assert abs(x[:, k].mean() - frozen.mean()) < 5 * frozen.std() / math.sqrt(n)
    assert x[:, 3].min() >= 0.3 and x[:, 3].max() <= 0.6
    # nested draws: the first m of n are the draw of m (the MuJoCo samples are the equations' first ones)
    assert np.array_equal(sample([d], 50, seed=3), sample([d], 200, seed=3)[:50])


@pytest.mark.parametrize("spec, words", [
    ("F_r1=normal:0.1:0.1", "outside F_r1's allowed range"),
    ("m2=uniform:-1:2", "outside m2's allowed range"),
    ("mu_wall=truncnormal:0.5:0.1:-0.5:1", "outside mu_wall's allowed range"),
    ("F_r1=gauss:1:0.1", "unknown distribution"),
    ("F_r1=normal:1", "takes 2 numbers"),
    ("F_r1=normal:1:-0.1", "must be > 0"),
    ("nope=normal:1:0.1", "unknown parameter"),
    ("drive=normal:1:0.1", "a choice"),
])
def test_bad_distributions_are_refused_in_one_line(spec, words):
    with pytest.raises(ParameterError, match=words):
        parse_dist(spec)


def test_dist_file_with_correlation_gives_correlated_draws(tmp_path):
    path = tmp_path / "d.toml"
    path.write_text('[dist]\nF_r1 = "normal:1.3:0.05"\nF_r2 = "normal:0.8:0.05"\n'
                    '[correlation]\nnames = ["F_r1", "F_r2"]\nmatrix = [[1.0, -0.9], [-0.9, 1.0]]\n')
    dists, correlation = read_dist_file(path)
    x = sample(dists, 20000, seed=1, correlation=correlation)
    # the sample correlation's standard error is (1 - rho^2) / sqrt(n) = 0.0013; 5 of them
    assert np.corrcoef(x.T)[0, 1] == pytest.approx(-0.9, abs=5 * 0.19 / math.sqrt(20000))
    path.write_text('[dist]\nF_r1 = "normal:1.3:0.05"\n[correlation]\nnames = ["F_r1"]\nmatrix = [[2.0]]\n')
    with pytest.raises(ParameterError, match="ones on its diagonal"):
        read_dist_file(path)


def test_monte_carlo_intervals_cover_the_truth_at_their_level():
    """Mean (Student t) and quantiles (order statistics) of a skewed metric, n = 60, REPEATS times."""
    rng = np.random.default_rng(11)
    truth = stats.lognorm(0.5)
    hits = {"mean": 0, "5": 0, "50": 0, "95": 0}
    for _ in range(REPEATS):
        x = truth.rvs(size=200, random_state=rng)
        lo, hi = uq_stats.quantile_interval(x, 0.5)
        hits["50"] += lo <= truth.median() <= hi
        for q in ("5", "95"):
            lo, hi = uq_stats.quantile_interval(x, int(q) / 100)
            hits[q] += lo <= truth.ppf(int(q) / 100) <= hi
        half = stats.t.ppf(0.975, len(x) - 1) * x.std(ddof=1) / math.sqrt(len(x))
        hits["mean"] += abs(x.mean() - truth.mean()) <= half
    for key, count in hits.items():
        assert count / REPEATS >= COVERAGE_FLOOR, key


def test_order_statistic_interval_says_when_the_sample_cannot_bound_a_tail():
    # with 20 samples P(all above the 5 % quantile) = 0.95^20 = 0.36 > 0.025: no order statistic bounds it below
    lo, hi = uq_stats.quantile_interval(np.arange(20.0), 0.05)
    assert lo == -math.inf and math.isfinite(hi)


def test_multi_fidelity_mean_has_the_variance_and_coverage_it_states():
    """f = g + small independent noise (correlation ~0.995): over REPEATS studies the estimator's spread matches
    the stated variance reduction, and its interval covers the true mean of f."""
    rng = np.random.default_rng(5)
    n, m = 400, 20
    estimates, plain, covered, reductions = [], [], 0, []
    for k in range(REPEATS):
        g = rng.normal(1.0, 0.1, n)
        f = g + 0.01 + rng.normal(0, 0.01, n)  # true mean of f: 1.01
        e = uq_stats.multi_fidelity(f[:m], g[:m], g[m:], seed=k) if k < 10 else None
        mean, _, _ = uq_stats.cv_moments(f[:m], g[:m], g[m:])
        estimates.append(mean)
        plain.append(f[:m].mean())
        if e is not None:
            covered += e["mean_interval"][0] <= 1.01 <= e["mean_interval"][1]
            reductions.append(e["variance_reduction"])
    rho2 = 0.1 ** 2 / (0.1 ** 2 + 0.01 ** 2)
    predicted = 1 / (1 - (1 - m / n) * rho2)
    measured = np.var(plain) / np.var(estimates)
    # the ratio of two sample variances of REPEATS values each has a relative SD of about sqrt(2 / REPEATS) x 2
    # (both vary) = 0.14, and the estimated coefficient costs a little (a factor (M - 2) / (M - 3) here): 4 SDs
    assert measured == pytest.approx(predicted, rel=4 * 2 * math.sqrt(2 / REPEATS))
    assert np.median(reductions) == pytest.approx(predicted, rel=0.5)  # from 20 pairs each: a rough estimate
    assert covered >= 7  # 10 intervals at 95 %: P(6 or fewer cover) = 1e-4


def test_event_intervals_are_exact_and_the_multi_fidelity_one_bounds_the_truth():
    assert uq_stats.clopper_pearson(7, 20) == pytest.approx(
        tuple(stats.binomtest(7, 20).proportion_ci(method="exact")), rel=1e-9)  # scipy's own, slower
    e = uq_stats.event_probability(np.zeros(100, dtype=bool))
    assert e["probability"] == 0 and e["interval"][0] == 0
    assert e["interval"][1] == pytest.approx(1 - 0.025 ** (1 / 100))  # Clopper-Pearson at 0 of n
    assert not e["resolved"]
    rng = np.random.default_rng(2)
    covered = 0
    for _ in range(200):
        g = rng.uniform(size=2000) < 0.2
        f = g.copy()
        flip = rng.uniform(size=2000) < 0.02  # MuJoCo disagrees on 2 %: P(f) = 0.2 + 0.02 (0.8 - 0.2) = 0.212
        f[flip] = ~f[flip]
        e = uq_stats.multi_fidelity_event(f[:50], g[:50], g)
        covered += e["interval"][0] <= 0.212 <= e["interval"][1]
    assert covered / 200 >= 0.95 - 4 * math.sqrt(0.95 * 0.05 / 200)


def test_events_and_engines_parse():
    assert parse_event("stall").key == "stalled"
    e = parse_event("skid_m>=0.01")
    assert (e.key, e.op, e.value) == ("skid_m", ">=", 0.01)
    assert list(e.hits(np.array([0.0, 0.01, np.nan, 0.2]))) == [False, True, False, True]
    with pytest.raises(ParameterError, match="unknown key"):
        parse_event("nope>1")
    with pytest.raises(ParameterError, match="malformed"):
        parse_event("skid_m")
    assert engine_pair(None) == ("analytic-unilateral", "mujoco-ratchet")
    assert engine_pair("mujoco-lock") == ("analytic-exact", "mujoco-lock")
    assert engine_pair("analytic-unilateral") == ("analytic-unilateral", "mujoco-ratchet")


@pytest.mark.slow
def test_energy_per_metre_is_the_sum_of_the_resistances_sample_by_sample(capsys, tmp_path):
    """With rigid clutches the motor's work per metre at steady state is F_r1 + F_r2 (each module slides the whole
    distance; the kinetic energy repeats over the settled window to the steady test's tolerance, STEADY_TOL)."""
    out = tmp_path / "u"
    code, stdout, err = run_cli(capsys, "uncertainty", "--dist", "F_r1=normal:1:0.1", "--dist", "F_r2=normal:1:0.1",
                                "--metric", "energy_per_metre_j_m", "--event", "energy_per_metre_j_m>2.1",
                                "--drive", "motor", "--until-steady", "--samples", "12", "--workers", "1",
                                "--out", out)
    assert code == 0, err
    with (out / "samples.csv").open() as fh:
        rows = list(csv.DictReader(fh))
    energy = np.array([float(r["analytic-unilateral:energy_per_metre_j_m"]) for r in rows])
    resistance = np.array([float(r["F_r1"]) + float(r["F_r2"]) for r in rows])
    np.testing.assert_allclose(energy, resistance, rtol=STEADY_TOL)
    result = json.loads((out / "uncertainty.json").read_text())
    metric = result["metrics"]["energy_per_metre_j_m"]
    assert metric["estimator"] == "mc" and metric["variance_reduction"] is None
    assert metric["mean"] == pytest.approx(resistance.mean(), rel=STEADY_TOL)
    assert metric["std"] == pytest.approx(resistance.std(ddof=1), rel=10 * STEADY_TOL)
    assert metric["mean_interval"][0] < metric["mean"] < metric["mean_interval"][1]
    event = result["events"]["energy_per_metre_j_m>2.1"]
    assert event["count"] == int((resistance > 2.1).sum())
    assert (out / "uncertainty.png").stat().st_size > 10_000
    assert "mean" in stdout and "uncertainty.png" in stdout


@pytest.mark.parametrize("argv, words", [
    (["--dist", "F_r1=normal:0.1:0.1", "--metric", "revolutions"], "outside F_r1's allowed range"),
    (["--dist", "F_r1=normal:1:0.1", "--metric", "nope"], "--metric 'nope' is unknown"),
    (["--dist", "F_r1=normal:1:0.1", "--event", "revolutions"], "malformed"),
    (["--metric", "revolutions"], "at least one --dist"),
    (["--dist", "F_r1=normal:1:0.1", "--metric", "revolutions", "--mujoco-samples", "2"], "--mujoco-samples 2"),
])
def test_bad_input_exits_2_with_one_line(capsys, tmp_path, argv, words):
    code, out, err = run_cli(capsys, "uncertainty", *argv, "--samples", "10", "--out", tmp_path / "u")
    assert code == 2
    assert words in err and len(err.strip().splitlines()) == 1
    assert not (tmp_path / "u").exists()


@pytest.mark.slow
def test_multi_fidelity_study_runs_mujoco_on_the_first_samples(capsys, tmp_path):
    """Equations and MuJoCo on the same draws: the pairs agree to the engines' known cruise difference (0.01 %),
    the correlation is near 1, and the multi-fidelity interval is narrower than MuJoCo's alone."""
    out = tmp_path / "u"
    code, _, err = run_cli(capsys, "uncertainty", "--dist", "m2=normal:1:0.2", "--metric", "steady_speed_m_s",
                           "--drive", "motor", "--until-steady", "--samples", "40", "--mujoco-samples", "6",
                           "--workers", "2", "--out", out)
    assert code == 0, err
    result = json.loads((out / "uncertainty.json").read_text())
    e = result["metrics"]["steady_speed_m_s"]
    assert e["estimator"] == "multi-fidelity" and e["correlation"] > 0.99
    width = e["mean_interval"][1] - e["mean_interval"][0]
    assert width < e["mujoco_mc"]["mean_interval"][1] - e["mujoco_mc"]["mean_interval"][0]
    with (out / "samples.csv").open() as fh:
        rows = list(csv.DictReader(fh))
    pairs = [(float(r["analytic-unilateral:steady_speed_m_s"]), float(r["mujoco-ratchet:steady_speed_m_s"]))
             for r in rows if r.get("mujoco-ratchet:steady_speed_m_s")]
    assert len(pairs) == 6
    for a, m in pairs:
        assert m == pytest.approx(a, rel=1e-3)  # the engines' cruise speeds agree to 0.01 % (docs): 10x margin


def test_every_numeric_parameter_takes_a_distribution_inside_its_range_or_is_refused_by_name():
    """Across the whole parameter table: a normal about each default (SD 10 %) is accepted and drawn inside the
    allowed range, or refused naming the parameter and its range (a default at a bound, e.g. incline = 0 is not
    one; omega0 = 0 and phi0 = 0 are inside open ranges)."""
    from ipir_mujoco.core.params import describe_parameters
    from ipir_mujoco.studies.uq_dists import inside

    for row in describe_parameters():
        name, default = row["name"], row["default"]
        if not isinstance(default, float):
            continue
        spec = f"{name}=normal:{default!r}:{max(abs(default) * 0.1, 1e-3)!r}"
        try:
            d = parse_dist(spec)
        except ParameterError as exc:
            assert f"outside {name}'s allowed range" in str(exc), spec
            continue
        x = sample([d], 2000, seed=4)[:, 0]
        assert all(inside(name, v) for v in x), spec


@pytest.mark.parametrize("argv, words", [
    (["--dist", "F_r1=normal:1:0.1", "--metric", "revolutions", "--until-steady"], "no periodic steady state"),
    (["--dist", "F_r1=normal:1:0.1", "--metric", "revolutions", "--t-end", "-1"], "t_end"),
])
def test_options_no_run_could_take_are_refused_before_any_run(capsys, tmp_path, argv, words):
    code, out, err = run_cli(capsys, "uncertainty", *argv, "--samples", "10", "--out", tmp_path / "u")
    assert code == 2 and words in err and len(err.strip().splitlines()) == 1


def test_a_metric_mujoco_leaves_empty_falls_back_to_the_equations_with_a_note():
    """MuJoCo gives no peak force of a rigid clutch: that metric is the equations' Monte Carlo, said in a note,
    while a metric both give is multi-fidelity."""
    from ipir_mujoco.studies.uncertainty import estimate

    rng = np.random.default_rng(0)
    g = rng.normal(1.0, 0.1, 50)
    cheap = [{"peak_clutch_force_n": 10 * v, "revolutions": v} for v in g]
    faithful = [{"peak_clutch_force_n": math.nan, "revolutions": v * 1.0001} for v in g[:5]]
    out = estimate(cheap, faithful, ("peak_clutch_force_n", "revolutions"), ())
    peak, rev = out["metrics"]["peak_clutch_force_n"], out["metrics"]["revolutions"]
    assert peak["estimator"] == "mc" and "only 0 of the 5 MuJoCo runs" in peak["note"]
    assert peak["mean"] == pytest.approx(10 * g.mean(), rel=1e-12)
    assert rev["estimator"] == "multi-fidelity" and rev["correlation"] == pytest.approx(1.0, abs=1e-9)
    # f = 1.0001 g exactly: the control variate recovers 1.0001 x the mean of all 50 equations' samples
    assert rev["mean"] == pytest.approx(1.0001 * g.mean(), rel=1e-12)


def test_mujocos_figures_come_with_their_error_bars_and_its_unused_runs_with_why():
    """A MuJoCo run on finite grip gives each figure with its error bar (its rigid limit's): the study uses it,
    widens the means' intervals by the bars' mean (each MuJoCo value may be off by its bar, so their mean, which
    the estimators take with weight 1, by at most the bars' mean), and counts the runs it could not use by why."""
    from ipir_mujoco.studies.uncertainty import estimate

    rng = np.random.default_rng(1)
    g = rng.normal(1.0, 0.1, 50)
    cheap = [{"revolutions": v} for v in g]
    bars = [1e-3, 3e-3, 2e-3, 2e-3]
    faithful = [{"revolutions": v, "revolutions_error": e} for v, e in zip(g[:4], bars)]
    faithful.append({"error": "MuJoCo accuracy check failed at t=1 s: the modules skid, and the rigid limit of "
                              "x1_final is not trustworthy: the runs' differences disagree in sign"})
    without = [{"revolutions": v} for v in g[:4]] + [faithful[-1]]  # the same runs, no error bars
    plain = estimate(cheap, without, ("revolutions",), ())["metrics"]["revolutions"]
    out = estimate(cheap, faithful, ("revolutions",), ())
    rev = out["metrics"]["revolutions"]
    assert rev["mujoco_error_bar"] == pytest.approx(np.mean(bars), rel=1e-12)
    assert rev["mean_interval"] == pytest.approx([plain["mean_interval"][0] - np.mean(bars),
                                                  plain["mean_interval"][1] + np.mean(bars)], rel=1e-12)
    assert out["failures"]["mujoco_used"] == 4
    assert out["failures"]["mujoco_reasons"] == {"rigid limit not trustworthy (finite grip)": 1}


def test_a_study_reads_a_figures_error_bar_and_a_mean_of_figures_gets_their_mean():
    from ipir_mujoco.studies.figure_errors import figure_error, why_unusable

    summary = {"x1_final": 0.2, "x2_final": 0.3, "figure_errors": {"x1_final": 1e-4, "x2_final": 3e-4}}
    assert figure_error(summary, "x1_final") == 1e-4
    assert figure_error(summary, "travel_m") == pytest.approx(2e-4)
    assert figure_error(summary, "revolutions") is None and figure_error({"x1_final": 0.2}, "x1_final") is None
    assert why_unusable("MuJoCo accuracy check failed at t=0.5 s: the energy residual ...") == "accuracy monitor"
    assert why_unusable("mu_wall=-1 is out of range", bad_input=True) == "refused its parameters"
