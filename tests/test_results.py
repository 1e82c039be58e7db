"""The shared result container, on synthetic series with known answers."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from ipir_mujoco.analytic import ParameterError, RobotParams
from ipir_mujoco.core.results import COLUMNS, Mode, RunResult, first_gap_minimum, min_locked_reaction, read_csv, write_json


def synthetic_series(n=2001, t_end=2.0):
    """S = cos(pi t): first minimum at t = 1 s exactly; modes follow the sign of S_dot."""
    t = np.linspace(0.0, t_end, n)
    S_dot = -math.pi * np.sin(math.pi * t)
    series = {c: np.zeros(n) for c in COLUMNS}
    series.update(t=t, S=np.cos(math.pi * t), S_dot=S_dot, phi=2 * math.pi * 1.5 * t / t_end,
                  x1=0.1 * t, x2=0.2 * t, v1=np.linspace(0, 3, n), v2=np.linspace(2, 0, n))
    series["mode"] = np.where(S_dot <= 0, int(Mode.CONTRACTION), int(Mode.EXPANSION))
    series["lambda2"] = np.where(series["mode"] == Mode.CONTRACTION, 5.0 - t, -99.0)  # -99: not locked
    series["lambda1"] = np.where(series["mode"] == Mode.EXPANSION, 3.0 + t, -99.0)
    return series


def test_first_gap_minimum_interpolates_the_sign_change():
    series = synthetic_series()
    # linear interpolation of S_dot ~ pi^2 (t - 1) near the root is exact to O(dt^2)
    assert first_gap_minimum(series["t"], series["S_dot"]) == pytest.approx(1.0, abs=1e-9)
    assert first_gap_minimum(series["t"], -np.abs(series["S_dot"]) - 1) is None


def test_the_first_gap_minimum_of_a_stall_is_where_the_robot_comes_to_rest():
    """A robot that stalls while contracting: S_dot falls to rest at t = 0.36 s and stays there, as an exact
    0 (the analytic engines) or as MuJoCo's creep of a held module (-1.4e-9 m/s, which never turns >= 0): both
    series give the same minimum, the first sample at rest (S_dot reaching 0 between the samples is past it)."""
    from ipir_mujoco.core.results import REST_SPEED

    t = np.linspace(0.3, 0.4, 101)  # 1e-3 s apart
    falling = np.where(t < 0.36 - 1e-12, -0.05 * (0.36 - t), 0.0)
    for at_rest in (-0.0, -1.4e-9, 1e-12):
        S_dot = np.where(t < 0.36 - 1e-12, falling, at_rest)
        # a positive round-off moves the interpolated zero by 1e-3 s x 1e-12 / 5e-5 = 2e-11 s
        assert first_gap_minimum(t, S_dot) == pytest.approx(0.36, abs=1e-10), at_rest
    # a gap still falling at twice the rest speed has no minimum yet
    assert first_gap_minimum(t, np.where(t < 0.36, falling, -2 * REST_SPEED)) is None


def test_min_locked_reaction_ignores_clutches_that_are_not_locked():
    series = synthetic_series()
    # contraction lasts to t = 1 (lambda2 = 5 - t >= 4), expansion after (lambda1 = 3 + t >= 4)
    assert min_locked_reaction(series) == pytest.approx(4.0, abs=2e-3)


def test_summary_from_a_synthetic_run():
    run = RunResult("test", "exact", "kinematic", RobotParams(), 2.0, synthetic_series(),
                    {"motor_work_j": 1.0, "kinetic_j": 0.5, "friction_j": 0.5, "residual_j": 0.0})
    s = run.summary
    assert s["revolutions"] == pytest.approx(1.5)
    assert (s["x1_final"], s["x2_final"]) == pytest.approx((0.2, 0.4))
    assert (s["v1_max"], s["v2_max"]) == (3.0, 2.0)
    assert s["mode_switches"] == 1


def test_csv_round_trip_keeps_columns_and_values(tmp_path):
    series = synthetic_series(n=101)
    run = RunResult("test", "exact", "kinematic", RobotParams(), 2.0, series, {})
    run.write_csv(tmp_path / "ts.csv")
    back = read_csv(tmp_path / "ts.csv")
    assert list(back) == list(COLUMNS)
    for c in COLUMNS:
        np.testing.assert_allclose(back[c], series[c], rtol=1e-11, atol=1e-15)  # written with 12 digits


def test_container_refuses_missing_or_ragged_columns():
    series = synthetic_series()
    del series["lambda1"]
    with pytest.raises(ValueError, match="lambda1"):
        RunResult("test", "exact", "kinematic", RobotParams(), 2.0, series, {})
    series = synthetic_series()
    series["v1"] = series["v1"][:-1]
    with pytest.raises(ValueError, match="v1"):
        RunResult("test", "exact", "kinematic", RobotParams(), 2.0, series, {})


def test_json_writes_a_number_that_is_not_finite_as_null(tmp_path):
    """JSON has no NaN or infinity: the writer puts null (docs/cli.md says what it means per key), so that a
    valid run never ends in an internal error at its last step and strict readers take every file."""
    write_json(tmp_path / "x.json", {"a": float("nan"), "b": [float("inf"), 1.5]})
    text = (tmp_path / "x.json").read_text()
    assert json.loads(text, parse_constant=lambda name: pytest.fail(name)) == {"a": None, "b": [None, 1.5]}


def test_the_residual_ratio_is_against_the_energy_put_through_the_robot():
    """A crank coasting down from 60 rad/s with the drive off: the motor does no work, the kinetic energy
    released pays the resistances. The audit's residual is still reported, over the energy put through the
    robot (the largest of the works and energy changes, and the kinetic energy at the start, as MuJoCo's
    monitor measures it; it used to be missing with the drive off, and over the motor's small work, 30x too
    large, with a 1 mN m torque); the solver's error keeps it far below 1e-6."""
    from ipir_mujoco.analytic import simulate

    for M in (0.0, 0.001):
        run = simulate(RobotParams(M=M, omega0=60.0), "exact", "unilateral", 0.3, dt_out=1e-3)
        e = run.energy
        assert abs(e["motor_work_j"]) < 0.05 * e["friction_j"]
        ratio = run.summary["accuracy"]["residual_ratio"]
        start = run.series["kinetic"][0]  # 1.8 J at 60 rad/s: the largest energy in play
        assert ratio == pytest.approx(e["residual_j"] / max(e["friction_j"], -e["kinetic_j"], start), rel=1e-12)
        assert abs(ratio) < 1e-6


def test_a_run_as_a_dataframe_keeps_every_column_its_units_and_summary():
    import pandas

    from ipir_mujoco import registry
    from ipir_mujoco.core.results import SERIES_UNITS

    run = registry.run("analytic-unilateral", RobotParams(drive="motor"), 0.3, dt_out=1e-3)
    frame = run.to_pandas()
    assert isinstance(frame, pandas.DataFrame) and list(frame.columns) == list(run.series)
    assert all(np.array_equal(frame[c].to_numpy(), run.series[c]) for c in run.series)
    assert frame.attrs["units"]["x1"] == "m" and frame.attrs["units"]["omega"] == "rad/s"
    assert set(frame.attrs["units"]) == set(run.series) and all(frame.attrs["units"][c] for c in run.series)
    assert frame.attrs["summary"]["revolutions"] == run.summary["revolutions"]
    # every column either engine writes has its unit in the one table
    physics = registry.run("mujoco-ratchet", RobotParams(clutch_stiffness=1e6), 0.05, dt_out=1e-3)
    assert set(physics.series) <= set(SERIES_UNITS)


@pytest.mark.slow
def test_a_run_draws_the_papers_figures_and_a_sweep_reads_as_one_frame(tmp_path):
    from ipir_mujoco import registry
    from ipir_mujoco.studies.frames import read_sweep
    from ipir_mujoco.studies.sweep import run_sweep
    from ipir_mujoco.studies.sweep_space import Study, parse_vary

    one, other = (registry.run(v, RobotParams(), 0.2, dt_out=1e-3) for v in ("analytic-approx", "mujoco-lock"))
    figures = one.plot(other, path=tmp_path / "figs")
    assert len(figures) == 3 and all(len(f.axes[0].get_lines()) >= 2 for f in figures)  # both runs drawn
    assert sorted(p.name for p in (tmp_path / "figs").iterdir()) == ["fig2_crank.png", "fig3_modules.png",
                                                                     "fig4_gap.png"]
    study = Study((parse_vary("L=0.1,0.2"),), engines=("analytic-approx",), t_end=0.2)
    run_sweep(study, tmp_path / "sweep", progress=False, workers=1)
    frame = read_sweep(tmp_path / "sweep")
    assert list(frame["L"]) == [0.1, 0.2] and frame.attrs["units"]["L"] == "m"
    assert frame.attrs["units"]["analytic-approx:steady_speed_m_s"] == "m/s"
    with pytest.raises(ParameterError, match="holds no sweep results"):
        read_sweep(tmp_path / "figs")
