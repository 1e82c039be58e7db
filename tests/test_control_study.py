"""The control study: open loop against PI and feedforward, the dead-centre profile; its files and bad input."""

from __future__ import annotations

import csv
import math

import pytest

from ipir_mujoco.cli.control_study import FILES, format_table, write_csv
from ipir_mujoco.core.params import RobotParams
from ipir_mujoco.report.control_figure import study_figure
from ipir_mujoco.studies import control_study as cs

import figure_checks
from cli_run import run_cli


@pytest.fixture(scope="module")
def study():
    return cs.run_study(RobotParams(), speeds=(10.0,), dips=(0.0, 0.1), workers=1)


def _row(study, controller, variant):
    return next(r for r in study["rows"] if r["controller"] == controller and r["variant"] == variant)


@pytest.mark.slow
def test_every_run_settles_and_the_open_loop_matches_the_speed(study):
    for r in study["rows"] + study["profile"]["rows"]:
        assert "error" not in r and r["steady"], r
    # the voltage search's own tolerance, on the variant it searched
    open_loop = _row(study, "open-loop", "analytic-unilateral")
    assert open_loop["mean_omega_rad_s"] == pytest.approx(10.0, rel=10 * cs.SEARCH_TOL)
    for r in study["rows"]:
        if r["controller"] != "open-loop":
            assert r["mean_omega_rad_s"] == pytest.approx(10.0, rel=0.01)  # the servo holds its target


@pytest.mark.slow
def test_feedback_and_the_exact_feedforward_shrink_the_ripple_on_the_real_linkage(study):
    for variant in ("analytic-unilateral", "mujoco-ratchet"):
        ripple = {c: _row(study, c, variant)["speed_ripple"] for c in cs.CONTROLLERS}
        assert ripple["pi+exact"] < ripple["pi"] < ripple["open-loop"]
        assert ripple["pi+exact"] < ripple["pi+paper"]


@pytest.mark.slow
def test_the_paper_feedforward_delivers_less_than_it_promised(study):
    promised = _row(study, "pi+paper", "analytic-approx-unilateral")["speed_ripple"]
    for variant in ("analytic-unilateral", "mujoco-ratchet"):
        assert _row(study, "pi+paper", variant)["speed_ripple"] > 2 * promised


@pytest.mark.slow
def test_the_engines_agree_on_every_servo_run(study):
    # both engines hold the same speed; their ripples agree to the sampling of MuJoCo's 1 ms output and the
    # controller's ticks landing on its steps (a tenth of the ripple at most)
    for c in ("pi", "pi+paper", "pi+exact"):
        a, m = _row(study, c, "analytic-unilateral"), _row(study, c, "mujoco-ratchet")
        assert m["mean_omega_rad_s"] == pytest.approx(a["mean_omega_rad_s"], rel=3e-3)
        assert m["speed_ripple"] == pytest.approx(a["speed_ripple"], rel=0.1)
        assert m["electrical_energy_per_metre_j_m"] == pytest.approx(a["electrical_energy_per_metre_j_m"], rel=3e-3)


@pytest.mark.slow
def test_mujoco_leaves_its_rigid_ratchets_peaks_out(study):
    for r in study["rows"] + study["profile"]["rows"]:
        missing = r["peak_clutch_force_n"] is None and r["peak_module_accel_m_s2"] is None
        assert missing == (r["variant"] == "mujoco-ratchet")


@pytest.mark.slow
def test_the_energy_drawn_covers_the_work_at_the_crank(study):
    # the winding's loss tau^2 omega_noload / M_stall >= 0: what the motor draws is at least its work
    for r in study["rows"] + study["profile"]["rows"]:
        assert r["electrical_energy_per_metre_j_m"] >= r["energy_per_metre_j_m"] * (1 - 1e-3)


@pytest.mark.slow
def test_files_and_figure(study, tmp_path):
    write_csv(tmp_path / FILES[0], study)
    with open(tmp_path / FILES[0], newline="") as handle:
        rows = list(csv.DictReader(handle))
    assert len(rows) == len(study["rows"]) + len(study["profile"]["rows"])
    assert {r["part"] for r in rows} == {"controllers", "profile"}
    assert all(math.isfinite(float(r["speed_ripple"])) for r in rows)
    fig = study_figure(study)
    gids = {a.get_gid() for ax in fig.axes for a in ax.get_children()}
    assert {"trace:pi", "trace:pi+exact", "ripple:mujoco-ratchet", "force:analytic-unilateral",
            "profile-force:analytic-unilateral", "profile-energy:mujoco-ratchet"} <= gids
    assert all(ax.get_ylabel() for ax in fig.axes)
    # legends off the data (a legend used to cover the bars), every entry drawn, axes with units
    figure_checks.assert_reads_right(fig)
    text = format_table(study)
    assert "ripple [-]" in text and "dead-centre profile" in text


@pytest.mark.parametrize("argv,fragment", [
    (["--speeds", "30"], "omega_target=30 rad/s is out of range"),
    (["--speeds", "0"], "--speeds=0.0 is out of range"),
    (["--dips", "0.95"], "--dips=0.95 is out of range"),
    (["--speeds", "x"], "--speeds 'x' is not a number"),
    (["--set", "drive=motor"], "drive='motor' in --set or --config: the control study sets it"),
    (["--set", "speed_dip=0.2"], "speed_dip=0.2 in --set or --config: the control study sets it"),
    (["--profile-speed", "20", "--dips", "0.5"], "speed_dip=0.5 with omega_target=20 rad/s is out of range"),
])
def test_bad_study_input_exits_2_with_one_line(capsys, tmp_path, argv, fragment):
    code, out, err = run_cli(capsys, "control-study", "--out", str(tmp_path / "out"), *argv)
    assert code == 2 and out == ""
    assert fragment in err and err.count("\n") == 1
    assert not (tmp_path / "out").exists()
