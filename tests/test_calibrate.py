"""Calibration to a measured run, and compare with a measured CSV."""

from __future__ import annotations

import json

import numpy as np
import pytest

from cli_run import run_cli
from ipir_mujoco import registry
from ipir_mujoco.core.errors import ParameterError
from ipir_mujoco.core.params import RobotParams
from ipir_mujoco.studies.calibrate import parse_fit
from ipir_mujoco.studies.measured import compare_measured, read_measured
from ipir_mujoco.studies.uq_dists import read_dist_file

NOISE = {"x1": 2e-4, "x2": 2e-4, "phi": 1e-2}  # m, m, rad: an encoder and two position sensors


def _measure(params: RobotParams, t_end: float, path, points: int = 200, seed: int = 7, noise=NOISE) -> None:
    """A synthetic measured run: the equations' run at irregular times, with Gaussian noise."""
    run = registry.run("analytic-unilateral", params, t_end, dt_out=1e-3)
    s = run.series
    keep = np.concatenate([[True], np.diff(s["t"]) > 0])
    rng = np.random.default_rng(seed)
    t = np.sort(rng.uniform(0.0, t_end, points))
    cols = {c: np.interp(t, s["t"][keep], s[c][keep]) + rng.normal(0, sd, t.size) for c, sd in noise.items()}
    np.savetxt(path, np.column_stack([t, *cols.values()]), delimiter=",", header="t," + ",".join(cols), comments="")


def test_fit_ranges_inside_the_allowed_ones():
    assert parse_fit("F_r1=0.5:2").low == 0.5
    with pytest.raises(ParameterError, match="outside F_r1's allowed range"):
        parse_fit("F_r1=-1:2")
    with pytest.raises(ParameterError, match="LO < HI"):
        parse_fit("F_r1=2:1")


@pytest.mark.parametrize("text, words", [
    ("x1,x2\n0,0\n1,1\n", "no column 't'"),
    ("t,y\n0,0\n1,1\n", "none of the columns"),
    ("t,x1\n0,0\n1,1\n0.5,1\n", "never decrease"),
    ("t,x1\n0,0\n1,abc\n", "line 3: x1='abc' is not a number"),
])
def test_measured_csv_faults_are_one_line_and_exit_2(capsys, tmp_path, text, words):
    path = tmp_path / "m.csv"
    path.write_text(text)
    with pytest.raises(ParameterError, match=words):
        read_measured(path)
    code, _, err = run_cli(capsys, "calibrate", "--data", path, "--fit", "F_r1=0.5:2", "--out", tmp_path / "c")
    assert code == 2 and words in err and len(err.strip().splitlines()) == 1
    assert not (tmp_path / "c").exists()


def test_fit_range_outside_the_allowed_one_exits_2(capsys, tmp_path):
    path = tmp_path / "m.csv"
    path.write_text("t,x1\n0,0\n1,1\n")
    code, _, err = run_cli(capsys, "calibrate", "--data", path, "--fit", "J_A=0:1", "--out", tmp_path / "c")
    assert code == 2 and "outside J_A's allowed range" in err and len(err.strip().splitlines()) == 1


def test_a_run_compared_with_its_own_samples_differs_by_nothing(capsys, tmp_path):
    """simulate's timeseries.csv read as a measured run: the same samples, so the interpolated run is exact."""
    code, _, err = run_cli(capsys, "simulate", "--t-end", "0.3", "--out", tmp_path / "run")
    assert code == 0, err
    measured = read_measured(tmp_path / "run" / "timeseries.csv")
    assert set(measured.columns) == {"x1", "x2", "phi", "omega", "v1", "v2"} and "mode" in measured.ignored
    code, out, err = run_cli(capsys, "compare", tmp_path / "run" / "timeseries.csv", tmp_path / "run", "--json")
    assert code == 0, err
    result = json.loads(out)
    # an event instant is written twice (before and after a switch): the interpolation keeps the first, so the
    # velocities may differ there by the jump itself; positions and angles are continuous and match to round-off
    for c in ("x1", "x2", "phi"):
        assert result["columns"][c]["max"] <= 1e-9 * result["columns"][c]["scale"]
    code, _, err = run_cli(capsys, "compare", tmp_path / "run" / "timeseries.csv",
                           tmp_path / "run" / "timeseries.csv")
    assert code == 2 and "both files" in err


@pytest.mark.slow
def test_calibrate_recovers_the_resistances_within_their_intervals(capsys, tmp_path):
    _measure(RobotParams(F_r1=1.3, F_r2=0.8), 1.0, tmp_path / "m.csv")
    code, out, err = run_cli(capsys, "calibrate", "--data", tmp_path / "m.csv", "--fit", "F_r1=0.5:2",
                             "--fit", "F_r2=0.5:2", "--out", tmp_path / "c")
    assert code == 0, err
    result = json.loads((tmp_path / "c" / "calibration.json").read_text())
    for name, truth in (("F_r1", 1.3), ("F_r2", 0.8)):
        lo, hi = result["estimates"][name]["interval"]
        assert lo <= truth <= hi
        assert hi - lo < 0.1 * truth  # 300 noisy points pin them to a few per cent
    assert result["not_identifiable"] == []
    # the noise each column's residuals show is the noise added (a sample SD of 200 points: 10 % is 5 SEs of it)
    for c, sd in NOISE.items():
        assert result["residual_rms"][c] == pytest.approx(sd, rel=0.1)
    dists, correlation = read_dist_file(tmp_path / "c" / "posterior.toml")
    assert [d.name for d in dists] == ["F_r1", "F_r2"] and correlation is not None
    assert (tmp_path / "c" / "calibration.png").stat().st_size > 10_000


@pytest.mark.slow
def test_calibrate_names_the_inertia_a_run_at_constant_crank_speed_cannot_identify(capsys, tmp_path):
    """A stiff gearmotor started at its speed: the crank never accelerates more than 0.3 %, so J_A x alpha is
    lost in the noise while the resistances still set the speed (and so the motion)."""
    stiff = dict(drive="motor", M_stall=50.0, omega_noload=10.0, omega0=9.99)
    _measure(RobotParams(F_r1=1.3, F_r2=0.8, **stiff), 2.0, tmp_path / "m.csv", points=400,
             noise={"x1": 2e-4, "x2": 2e-4, "phi": 1e-3})
    code, out, err = run_cli(capsys, "calibrate", "--data", tmp_path / "m.csv", "--fit", "F_r1=0.5:2",
                             "--fit", "F_r2=0.5:2", "--fit", "J_A=0.0001:0.01", "--drive", "motor",
                             "--set", "M_stall=50", "--set", "omega_noload=10", "--set", "omega0=9.99",
                             "--out", tmp_path / "c")
    assert code == 0, err
    result = json.loads((tmp_path / "c" / "calibration.json").read_text())
    assert result["not_identifiable"] == ["J_A"]
    assert "J_A is not identifiable" in err
    for name, truth in (("F_r1", 1.3), ("F_r2", 0.8)):
        lo, hi = result["estimates"][name]["interval"]
        assert lo <= truth <= hi


@pytest.mark.slow
def test_calibrate_recovers_random_designs_across_the_envelope(capsys, tmp_path):
    """Random resistances (0.5-2 N), torque (0.2-0.5 N m, enough to move any of them) and front mass: each fitted value lies within 4 standard errors of the truth (a
    Gaussian estimate misses that by chance 6e-5 of the time), the noise is read back from the residuals."""
    rng = np.random.default_rng(2026)
    for k in range(3):
        truth = {"F_r1": rng.uniform(0.5, 2.0), "F_r2": rng.uniform(0.5, 2.0)}
        base = {"M": float(rng.uniform(0.2, 0.5)), "m2": float(rng.uniform(0.5, 2.0))}
        params = RobotParams(**truth, **base)
        _measure(params, 1.0, tmp_path / f"m{k}.csv", points=150, seed=k)
        code, _, err = run_cli(capsys, "calibrate", "--data", tmp_path / f"m{k}.csv", "--fit", "F_r1=0.2:3",
                               "--fit", "F_r2=0.2:3", "--set", f"M={base['M']!r}", "--set", f"m2={base['m2']!r}",
                               "--out", tmp_path / f"c{k}")
        assert code == 0, err
        result = json.loads((tmp_path / f"c{k}" / "calibration.json").read_text())
        for name, value in truth.items():
            e = result["estimates"][name]
            assert abs(e["value"] - value) <= 4 * e["standard_error"], (k, name, e, value)
