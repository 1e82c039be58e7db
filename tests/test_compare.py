"""compare's metrics on synthetic runs with known offsets: each measures what it claims."""

from __future__ import annotations

import json

import numpy as np
import pytest

from ipir_mujoco.analytic import RobotParams
from ipir_mujoco.core.results import COLUMNS, Mode, RunResult
from ipir_mujoco.cli import main
from ipir_mujoco.studies.compare import compare_runs, load_run

T_END, OMEGA = 1.0, 20.0  # s, rad/s


def synthetic(shift=0.0, scale=1.0, n=20001):
    """A crank at constant speed; every quantity a smooth function of phi = OMEGA (t - shift).

    Modes follow the sign of S_dot, so mode switches sit at phi = k pi, shifted in time by ``shift``.
    """
    t = np.linspace(0.0, T_END, n)
    phi = OMEGA * (t - shift)
    series = {c: np.zeros(n) for c in COLUMNS}
    S_dot = -0.05 * np.sin(phi) * OMEGA
    series.update(t=t, phi=phi, omega=np.full(n, OMEGA), x1=scale * 0.01 * phi, x2=scale * 0.02 * phi,
                  v1=scale * (1 + np.sin(phi)), v2=scale * (1 + np.cos(phi)), S=0.2 + 0.05 * np.cos(phi),
                  S_dot=S_dot)
    series["mode"] = np.where(S_dot <= 0, int(Mode.CONTRACTION), int(Mode.EXPANSION))
    energy = {"motor_work_j": 1.0, "kinetic_j": 0.5, "friction_j": 0.5, "residual_j": 0.0}
    return RunResult("test", "exact", "kinematic", RobotParams(), T_END, series, energy)


def test_identical_runs_compare_as_identical():
    result = compare_runs(synthetic(), synthetic())
    assert all(v["max"] == 0 for v in result["time_grid"].values())
    assert all(v["relative"] in (0, None) for v in result["summary"].values())
    assert result["switches"]["max_abs_dt"] == 0 and all(v is None for v in result["first_exceedance"].values())


def test_a_time_shift_shows_at_matching_time_and_vanishes_at_matching_angle():
    delta = 1e-3  # s
    result = compare_runs(synthetic(), synthetic(shift=delta))
    # at matching time: x1 = 0.01 OMEGA t is off by 0.01 OMEGA delta everywhere
    assert result["time_grid"]["x1"]["max"] == pytest.approx(0.01 * OMEGA * delta, rel=1e-6)
    assert result["time_grid"]["x1"]["rms"] == pytest.approx(0.01 * OMEGA * delta, rel=1e-6)
    # v1 = 1 + sin(OMEGA (t - delta)): largest difference OMEGA delta (to first order)
    assert result["time_grid"]["v1"]["max"] == pytest.approx(OMEGA * delta, rel=0.01)
    # at matching crank angle the two runs are the same curves; only the time to reach phi differs, by delta
    assert result["angle_grid"]["x1"]["max"] < 1e-12 and result["angle_grid"]["v1"]["max"] < 1e-12
    assert result["angle_grid"]["t"]["max"] == pytest.approx(delta, rel=1e-9)
    # every switch moves by exactly delta; dt resolution is the sample spacing (5e-5 s)
    assert result["switches"]["matched"] >= 5 and result["switches"]["unmatched_a"] == 0
    np.testing.assert_allclose(result["switches"]["dt"], delta, atol=T_END / 20000)


def test_a_scale_error_shows_as_that_relative_error():
    epsilon = 0.02
    result = compare_runs(synthetic(), synthetic(scale=1 + epsilon))
    for key in ("x1_final", "x2_final", "v1_max", "v2_max"):
        assert result["summary"][key]["relative"] == pytest.approx(epsilon, rel=1e-9), key
    assert result["summary"]["revolutions"]["relative"] == 0
    a = synthetic().series["x1"]
    assert result["time_grid"]["x1"]["rms"] == pytest.approx(epsilon * np.sqrt(np.mean(a**2)), rel=1e-3)
    # x1 = 0.01 OMEGA t (1 + eps): |b - a| = eps x1 exceeds 1 % of max|x1| once x1 > max/2, at t = T_END / 2
    assert result["first_exceedance"]["x1"] == pytest.approx(T_END / 2, abs=1e-3)
    assert compare_runs(synthetic(), synthetic(scale=1.005))["first_exceedance"]["x1"] is None


def test_a_crank_that_does_not_turn_forward_has_no_angle_grid():
    rocking = synthetic()
    rocking.series["phi"] = np.sin(rocking.series["t"])
    rocking.series["phi"][-10:] = 0.0
    assert compare_runs(rocking, rocking)["angle_grid"] is None


@pytest.mark.slow
def test_compare_command_on_two_run_folders(tmp_path, capsys):
    for name, extra in (("a", []), ("b", ["--geometry", "exact"])):
        assert main(["simulate", "--t-end", "0.5", "--out", str(tmp_path / name), *extra]) == 0
    capsys.readouterr()
    assert main(["compare", str(tmp_path / "a"), str(tmp_path / "b"), "--json"]) == 0
    result = json.loads(capsys.readouterr().out)
    run_a, run_b = load_run(tmp_path / "a"), load_run(tmp_path / "b")
    expected = (run_b.summary["revolutions"] - run_a.summary["revolutions"]) / run_a.summary["revolutions"]
    assert result["summary"]["revolutions"]["relative"] == pytest.approx(expected, rel=1e-9)
    # exact against first order at the same crank angle: the gap differs by r^2 sin^2 / (2L) at most
    r, L = run_a.params.r, run_a.params.L
    assert result["angle_grid"]["S"]["max"] == pytest.approx(r**2 / (2 * L), rel=0.05)
    assert main(["compare", str(tmp_path / "a"), str(tmp_path / "missing")]) == 2
    assert "missing" in capsys.readouterr().err


def test_format_comparison_names_units_tolerance_and_aligns_columns():
    from ipir_mujoco.studies.compare import format_comparison

    text = format_comparison(compare_runs(synthetic(), synthetic(scale=1.02), tolerance=0.005))
    lines = text.splitlines()
    # readable names with units instead of code names, and the tolerance stated
    assert "module 1 (rear) travel" in text and "end of first contraction" in text and "x1_final" not in text
    assert "tolerance 0.005 = 0.5 %" in text
    row = next(line for line in lines if line.strip().startswith("module 1 velocity"))
    assert row.split()[3] == "m/s"
    # each table: header, a rule of dashes, rows; the right-aligned last column ends where the rule does
    rules = [i for i, line in enumerate(lines) if set(line.strip()) <= {"-", " "} and line.strip()]
    assert len(rules) == 2
    for i in rules:
        block = [lines[i - 1]]
        j = i + 1
        while j < len(lines) and lines[j].strip():
            block.append(lines[j])
            j += 1
        assert len(block) > 2 and {len(line) for line in block[1:]} == {len(lines[i])}, block


def test_runs_of_different_length_are_compared_at_the_shorter_ones_end(capsys):
    """Two runs to steady state stop at their own times; their revolutions and travels, each at its own end,
    differed by the extra time (the paper's model, 1.75 s, against one-way clutches, 2.22 s: +28.6 % in
    revolutions), not by the models. The same robot run for 1 s and for 0.6 s compares as identical."""
    long = synthetic()
    short = synthetic()
    keep = long.series["t"] <= 0.6
    short.series = {k: v[keep] for k, v in long.series.items()}
    for a, b in ((long, short), (short, long)):
        result = compare_runs(a, b)
        assert result["t_compared_s"] == pytest.approx(0.6) and {result["t_end_a_s"], result["t_end_b_s"]} == {0.6, 1.0}
        for key in ("revolutions", "x1_final", "x2_final", "v1_max", "v2_max"):
            assert result["summary"][key]["relative"] == pytest.approx(0.0, abs=1e-12), key
        # and the figures are those of the shorter run (its summary, at its end)
        assert result["summary"]["revolutions"]["a"] == pytest.approx(short.summary["revolutions"], rel=1e-12)
    from ipir_mujoco.studies.compare import format_comparison

    assert "compared at 0.6 s, the shorter run's end" in format_comparison(compare_runs(long, short))


def test_the_summary_rows_show_each_figure_to_six_digits():
    """The paper's model's 2 r = 0.1 m per revolution printed as '0.1' where its neighbours show six digits: every
    figure of the summary table shows six significant digits, counts stay whole numbers."""
    from ipir_mujoco import analytic
    from ipir_mujoco.studies.compare import format_comparison

    paper = analytic.simulate(RobotParams(drive="motor"), "approx", "kinematic", 3.0, until_steady=True)
    exact = analytic.simulate(RobotParams(drive="motor"), "exact", "kinematic", 3.0, until_steady=True)
    lines = format_comparison(compare_runs(paper, exact)).splitlines()
    row = next(line for line in lines if line.strip().startswith("distance per revolution"))
    assert row.split()[4] == "0.100000", row
    switches = next(line for line in lines if line.strip().startswith("mode switches"))
    assert "." not in switches.split()[2], switches


def test_a_quantity_held_at_zero_is_judged_against_the_mechanisms_scale():
    """Module 2 held still in run a (a vertical pipe where the robot stalls): its largest |a| is 0, and b's
    round-off (58 nm in MuJoCo's ratchet) was reported as first exceeding 1 % at t = 0.00025 s. The scale is at
    least the stroke 2r for a position and r x the largest crank speed for a speed."""
    from ipir_mujoco.studies.compare import format_comparison

    a, b = synthetic(), synthetic()
    for run in (a, b):
        run.series["x2"] = np.zeros_like(run.series["t"])
        run.series["v2"] = np.full_like(run.series["t"], -0.0)
    b.series["x2"] = b.series["x2"] + 6e-8
    b.series["v2"] = b.series["v2"] + 2e-4
    result = compare_runs(a, b)
    r = a.params.r
    assert result["time_grid"]["x2"]["scale"] == pytest.approx(2 * r)
    assert result["time_grid"]["v2"]["scale"] == pytest.approx(r * OMEGA)
    assert result["first_exceedance"]["x2"] is None and result["first_exceedance"]["v2"] is None
    # a real difference still shows: 2 mm is 2 % of the stroke
    b.series["x2"] = b.series["x2"] + 2e-3
    assert compare_runs(a, b)["first_exceedance"]["x2"] == 0.0
    assert " -0 " not in format_comparison(result)
