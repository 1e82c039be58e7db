"""The statistical steady test (ipir_mujoco.core.steady_test): per-revolution means that scatter for ever are
steady once their trend is buried in the scatter and their mean is known to the target; the figure's stated
uncertainty covers the true limit; a run that settles exactly keeps the exact test's answer."""

from __future__ import annotations

import math
import re

import numpy as np
import pytest

from ipir_mujoco.core.cycles import cycle_summary, steady_at_end, steady_index
from ipir_mujoco.core.steady_test import (COVERAGE, LIMIT_ACCURACY, STATISTICAL_MIN, find_steady, line_fit,
                                          speed_estimate, statistical_at_end, steady_target, student_quantile)
from ipir_mujoco.core.steady_watch import SteadyWatch

PERIOD = 0.2  # s per revolution of the synthetic runs


def run_of(speeds, per_rev=200):
    """A synthetic run whose k-th revolution takes PERIOD and moves speeds[k] * PERIOD (both modules alike),
    sampled ``per_rev`` times per revolution, with the cumulative energy columns of a robot that spends
    10 J per metre (no kinetic energy): every revolution's energy per metre is exactly 10 J/m."""
    u = np.asarray(speeds, dtype=float)
    t = np.linspace(0.0, PERIOD * u.size, u.size * per_rev + 1)
    phi = 2 * math.pi * t / PERIOD
    ends = np.concatenate([[0.0], np.cumsum(u * PERIOD)])
    x = np.interp(t, PERIOD * np.arange(u.size + 1), ends)
    return {"t": t, "phi": phi, "x1": x, "x2": x, "motor_work": 10.0 * x, "friction_work": 10.0 * x,
            "kinetic": 0 * t, "potential": 0 * t}


def noisy(n, mean=0.2, rel=5e-4, seed=0):
    return mean * (1 + rel * np.random.default_rng(seed).standard_normal(n))


def test_the_quantile_is_students_where_the_test_uses_it():
    from scipy.stats import t

    dof = np.arange(STATISTICAL_MIN - 2, 400)
    # the expansion's error at 6 dof, 1.3e-3 (its docstring), falls as dof^-5 beyond
    np.testing.assert_allclose(student_quantile(0.995, dof), t.ppf(0.995, dof), atol=1.3e-3)


def test_the_fit_recovers_a_line_and_its_scatter():
    k = np.arange(20)
    mean, slope, se_mean, se_slope, dof = line_fit(0.3 + 0.01 * (k - 9.5))
    # an exact line: the mean, the slope and no scatter, to round-off of values near 0.3 (1e-16 relative)
    assert (mean, slope) == pytest.approx((0.3, 0.01), rel=1e-12) and se_mean < 1e-14 and dof == 18


def test_scatter_for_ever_never_passes_the_exact_test_but_passes_the_statistical_one():
    u = noisy(60)
    assert steady_index(u, 1e-4, 3) is None  # 5e-4 scatter: three revolutions never agree within 1e-4
    found = find_steady(u, 1e-4, 3, 3e-4, steady_at_end)
    assert found is not None and found.test == "statistical"
    assert found.end - found.start + 1 >= STATISTICAL_MIN and found.uncertainty <= 3e-4


def test_the_stated_uncertainty_covers_the_true_mean_at_its_confidence():
    # 300 runs scattering about a known limit, each stopped by the statistical test at its first pass: the
    # window's mean +- U holds the limit in at least COVERAGE of them (300 runs resolve a coverage of 0.95 to
    # +-0.025 at two standard deviations, hence the bound COVERAGE - 0.03). The exact test is left out here: three
    # revolutions that scatter by 1e-3 agree within 1e-4 by chance now and then, and it then states the
    # engine's accuracy, not the window's
    never = lambda u, tol, n: False  # noqa: E731
    for rel in (5e-4, 1e-3):
        covered, runs = 0, 300
        for seed in range(runs):
            u = noisy(300, rel=rel, seed=seed)
            found = find_steady(u, 1e-4, 3, 3e-4, never)
            mean = u[found.start:found.end + 1].mean()
            covered += abs(mean / 0.2 - 1) <= found.uncertainty
        assert covered / runs >= COVERAGE - 0.03


def test_a_trend_under_the_scatter_is_not_steady_while_it_shows():
    # speeds still climbing by 2e-4 per revolution under 1e-4 of scatter: the trend is significant in every
    # window, so no window passes however long the run
    k = np.arange(100)
    u = 0.2 * (1 + 2e-4 * k + 1e-4 * np.random.default_rng(1).standard_normal(k.size))
    assert find_steady(u, 1e-4, 3, 3e-4, steady_at_end) is None


def test_a_run_that_settles_exactly_keeps_the_exact_tests_revolution():
    # a geometric approach without scatter: the exact test passes first, as it did without the statistical one
    u = 0.2 * (1 - 0.5 * 0.6 ** np.arange(40))
    found = find_steady(u, 1e-4, 3, 3e-4, steady_at_end)
    assert found.test == "exact" and found.end == steady_index(u, 1e-4, 3)


def test_statistical_windows_need_enough_revolutions():
    assert statistical_at_end(noisy(STATISTICAL_MIN - 1), 1.0) is None
    assert statistical_at_end(noisy(STATISTICAL_MIN), 1.0) is not None


def test_the_watch_and_the_summary_agree_and_the_summary_states_the_uncertainty():
    u = noisy(60, seed=4)
    series = run_of(u)
    summary = cycle_summary(series, 1e-4, 3, target=3e-4)
    watch = SteadyWatch(0.0, 1e-4, 3, target=3e-4)
    for lo in range(0, series["t"].size, 997):  # fed in uneven blocks, as an engine's loop feeds it
        hi = min(lo + 997, series["t"].size)
        watch.update(series["t"][lo:hi], series["phi"][lo:hi], series["x1"][lo:hi])
    assert summary["steady"] and summary["steady_test"] == "statistical"
    assert watch.steady_at == pytest.approx(summary["t_steady_s"], abs=1e-9)
    window = u[watch.found.start:watch.found.end + 1]
    assert summary["steady_revolutions"] == window.size
    assert summary["steady_speed_m_s"] == pytest.approx(window.mean(), rel=1e-9)  # equal periods: the plain mean
    assert summary["steady_speed_uncertainty_m_s"] == pytest.approx(watch.found.uncertainty * window.mean(), rel=1e-6)
    # every revolution spends exactly 10 J/m: no scatter, no uncertainty beyond round-off
    assert summary["energy_per_metre_j_m"] == pytest.approx(10.0, rel=1e-9)
    assert summary["energy_per_metre_uncertainty_j_m"] < 1e-6


def test_an_exact_steady_states_the_engines_accuracy_as_its_uncertainty():
    u = 0.2 * (1 - 0.5 * 0.6 ** np.arange(40))
    target = steady_target("analytic", 1e-4)
    summary = cycle_summary(run_of(u), 1e-4, 3, target=target)
    assert summary["steady_test"] == "exact" and target == 1e-4  # the run's steady_tol is looser than 2e-5
    assert summary["steady_speed_uncertainty_m_s"] == pytest.approx(target * summary["steady_speed_m_s"])
    assert steady_target("mujoco", 1e-4) == LIMIT_ACCURACY["mujoco"]


def test_without_a_target_the_summary_is_the_exact_tests_alone():
    summary = cycle_summary(run_of(noisy(60)), 1e-4, 3)
    assert not summary["steady"] and "steady_test" not in summary


def test_a_run_too_scattered_to_be_steady_still_estimates_its_speed_without_its_start_up():
    # 1 % scatter (a tipping wheeled module's) after a five-revolution start-up: never steady to 3e-4, but the
    # summary's estimate leaves the start-up out (a window holding it has a larger U) and its U is the window's
    u = noisy(120, rel=1e-2, seed=3)
    u[:5] = 0.2 * np.array([0.2, 0.5, 0.7, 0.85, 0.93])
    summary = cycle_summary(run_of(u), 1e-4, 3, target=3e-4)
    assert not summary["steady"]
    w = summary["speed_estimate_revolutions"]
    assert STATISTICAL_MIN <= w <= u.size - 5
    window = u[-w:]
    assert summary["speed_estimate_m_s"] == pytest.approx(window.mean(), rel=1e-9)  # equal periods: the plain mean
    _, slope, se_mean, _, dof = line_fit(window)
    spread = float(student_quantile(0.995, dof)) * se_mean + abs(slope) * (w - 1) / 2
    assert summary["speed_estimate_uncertainty_m_s"] == pytest.approx(spread, rel=1e-9)
    # 1 % scatter over about 100 revolutions: U about 2.6 x 1e-2 / sqrt(100) of the speed, far above 3e-4
    assert 3e-4 < summary["speed_estimate_uncertainty_m_s"] / 0.2 < 1e-2
    assert abs(summary["speed_estimate_m_s"] / 0.2 - 1) <= summary["speed_estimate_uncertainty_m_s"] / 0.2


def test_the_estimate_is_left_out_where_steady_and_where_no_window_fits():
    steady = cycle_summary(run_of(noisy(60)), 1e-4, 3, target=3e-4)
    assert steady["steady"] and steady["speed_estimate_m_s"] is None
    short = cycle_summary(run_of(noisy(STATISTICAL_MIN - 1, rel=1e-2)), 1e-4, 3, target=3e-4)
    assert not short["steady"] and short["speed_estimate_m_s"] is None
    # a speed still climbing by 1 % per revolution: every window's trend is significant
    assert speed_estimate(0.2 * (1 + 1e-2 * np.arange(40))) is None


def test_simulate_says_what_a_run_that_never_became_steady_averaged():
    from ipir_mujoco.cli.simulate import format_summary
    from ipir_mujoco.core.params import RobotParams
    from ipir_mujoco.core.results import RunResult

    u = noisy(120, rel=1e-2, seed=3)
    series = run_of(u)
    n = series["t"].size
    for column in ("omega", "alpha", "v1", "v2", "a1", "a2", "S", "S_dot", "lambda1", "lambda2", "mode"):
        series.setdefault(column, np.zeros(n))
    series["omega"] = np.full(n, 2 * math.pi / PERIOD)
    run = RunResult("mujoco", "exact", "unilateral", RobotParams(), float(series["t"][-1]), series,
                    {"motor_work_j": 0.0, "kinetic_j": 0.0, "friction_j": 0.0, "residual_j": 0.0},
                    settings={"steady_tol": 1e-4, "steady_cycles": 3})
    s = run.summary
    assert not s["steady"] and s["speed_estimate_m_s"] is not None
    line = next(x for x in format_summary(run, until_steady=True).splitlines() if "not reached" in x)
    assert f"its last {s['speed_estimate_revolutions']} revolutions average" in line
    shown = re.search(r"average ([0-9.]+) \+- ([0-9.e-]+) m/s \(([0-9.]+) %; steady asks ([0-9.]+) %\)", line)
    assert shown, line
    mean, spread, share, asked = map(float, shown.groups())
    # printed to 5 and 2 significant figures and the shares to 2: equal to the keys within that rounding
    assert mean == pytest.approx(s["speed_estimate_m_s"], rel=1e-4)
    assert spread == pytest.approx(s["speed_estimate_uncertainty_m_s"], rel=5e-2)
    assert share == pytest.approx(100 * s["speed_estimate_uncertainty_m_s"] / s["speed_estimate_m_s"], rel=5e-2)
    assert asked == pytest.approx(100 * LIMIT_ACCURACY["mujoco"])
