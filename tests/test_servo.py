"""drive = servo: the speed controller (core/control.py) on both engines, its summary keys and its bad input."""

from __future__ import annotations

import copy
import math

import mujoco
import numpy as np
import pytest

from ipir_mujoco import registry
from ipir_mujoco.core.control import FeedforwardTable, SpeedController, default_gains, tick_step
from ipir_mujoco.core.errors import ParameterError
from ipir_mujoco.core.params import RobotParams
from ipir_mujoco.engine.loop import servo_drive

from cli_run import run_cli

SERVO = RobotParams(drive="servo", omega_target=10.0, feedforward="exact")
PAIR = ("analytic-unilateral", "mujoco-ratchet")  # the exact one-way equations and MuJoCo's ratchet


@pytest.fixture(scope="module")
def steady():
    """Both engines to the periodic steady state under the exact feedforward at 10 rad/s."""
    return {v: registry.run(v, SERVO, 10.0, dt_out=1e-3, until_steady=True) for v in PAIR}


@pytest.mark.slow
def test_exact_feedforward_holds_the_target_speed_in_both_engines(steady):
    # the acceptance: mean within 1 % of the target, ripple <= 0.05 (the open-loop motor's is ~0.47)
    for run in steady.values():
        s = run.summary
        assert s["steady"]
        assert abs(s["mean_omega_rad_s"] - SERVO.omega_target) <= 0.01 * SERVO.omega_target
        assert s["speed_ripple"] <= 0.05
        assert s["peak_drive_u"] <= 1.0
    a, m = (steady[v].summary for v in PAIR)
    # the engines agree on the steady speed within 0.3 % (crank and robot)
    assert m["mean_omega_rad_s"] == pytest.approx(a["mean_omega_rad_s"], rel=3e-3)
    assert m["steady_speed_m_s"] == pytest.approx(a["steady_speed_m_s"], rel=3e-3)


@pytest.mark.slow
def test_the_summary_window_is_the_steady_revolutions(steady):
    run = steady["analytic-unilateral"]
    s, series = run.summary, run.series
    # the window --until-steady stops on: the last steady_cycles revolutions, ending at t_steady_s
    n = run.settings["steady_cycles"]
    t, phi, omega = series["t"], series["phi"], series["omega"]
    # the run ends on a revolution's end (an exact sample); the window starts on the sample n turns before
    start = t[np.searchsorted(np.maximum.accumulate(phi), phi[-1] - 2 * math.pi * n * (1 + 1e-12))]
    inside = t >= start
    assert s["t_steady_s"] == pytest.approx(t[-1])
    assert s["mean_omega_rad_s"] == pytest.approx(2 * math.pi * n / (t[-1] - start), rel=1e-9)
    assert s["speed_ripple"] == pytest.approx(np.ptp(omega[inside]) / s["mean_omega_rad_s"], rel=1e-9)


def _band(series, params):
    """(low, high) [N m]: the motor's torque at |u| = 1 at each sample's crank speed."""
    back = series["omega"] / params.omega_noload
    return params.M_stall * (-1.0 - back), params.M_stall * (1.0 - back)


# a start far above the target (omega0 25 rad/s, target 5) drives u to -1, the start from rest to +1
SATURATING = RobotParams(drive="servo", omega_target=5.0, omega0=25.0)


def test_the_analytic_torque_column_stays_in_the_motor_band():
    for params in (SATURATING, SATURATING.replace(omega0=0.0)):
        run = registry.run("analytic-unilateral", params, 0.3, dt_out=1e-4)
        s = run.series
        low, high = _band(s, params)
        u = s["drive_u"]
        assert u.max() <= 1.0 and u.min() >= -1.0
        # roundoff of M_stall (u - omega / omega_noload): a few ulps of the torque's size
        slack = 1e-12 * params.M_stall
        assert np.all(s["motor_torque"] >= low - slack) and np.all(s["motor_torque"] <= high + slack)
    assert u.max() == 1.0  # from rest: the controller asks for full voltage


def test_mujoco_actuator_force_stays_in_the_motor_band(monkeypatch):
    """MuJoCo's own data.actuator_force at every tick's state, with the ctrl the controller wrote."""
    seen = []
    original = servo_drive.TickedDrive.run

    def run_and_look(self, nstep, row=-1):
        original(self, nstep, row)
        probe = copy.copy(self.data)
        mujoco.mj_forward(self.steps.model, probe)  # MuJoCo's actuator force at this state and ctrl
        seen.append((probe.ctrl[self.motor], probe.actuator_force[self.motor], probe.qvel[self.crank_v]))

    monkeypatch.setattr(servo_drive.TickedDrive, "run", run_and_look)
    for params in (SATURATING, SATURATING.replace(omega0=0.0)):
        seen.clear()
        registry.run("mujoco-ratchet", params, 0.3, dt_out=1e-3)
        ctrl, force, omega = np.array(seen).T
        assert ctrl.min() >= -1.0 and ctrl.max() <= 1.0
        back = omega / params.omega_noload
        slack = 1e-12 * params.M_stall  # MuJoCo's gain * ctrl + bias, a few ulps
        assert np.all(force >= params.M_stall * (-1 - back) - slack)
        assert np.all(force <= params.M_stall * (1 - back) + slack)
        assert np.allclose(force, params.M_stall * (ctrl - back), rtol=0, atol=slack)
        if params.omega0 > params.omega_target:
            assert ctrl.min() == -1.0  # the band's lower edge is reached, and held


def test_mujoco_ticks_fall_on_the_controller_period():
    params = RobotParams(drive="servo", control_rate=500.0)
    run = registry.run("mujoco-ratchet", params, 0.05, dt_out=1e-3)
    dt = run.settings["timestep"]
    period = 1 / params.control_rate
    steps = round(period / dt)
    assert steps * dt == pytest.approx(period, rel=1e-12)  # the automatic timestep divides the period
    # u changes only at ticks: constant over each period's samples
    u, t = run.series["drive_u"], run.series["t"]
    tick = np.ceil(t[1:] / period - 1e-6)  # the tick whose u the step ending at t used
    for k in np.unique(tick):
        assert np.ptp(u[1:][tick == k]) == 0.0
    assert [tick_step(k, period, dt) for k in range(4)] == [0, steps, 2 * steps, 3 * steps]


def test_anti_windup_does_not_integrate_into_the_clip():
    controller = SpeedController(RobotParams(drive="servo"))
    for _ in range(50):
        assert controller.tick(0.0, 0.0) == 1.0  # far below the target: full voltage
    assert controller.integral == 0.0  # no ticks integrated while clipped (the error pushed further in)
    kp, ki = default_gains(RobotParams(drive="servo"))
    # close to the target u leaves the clip at once: kp e + ki I with I unwound
    assert controller.tick(0.0, 10.0 - 0.1) == pytest.approx(kp * 0.1 + ki * 0.1 * controller.period)


def test_feedforward_tables_are_data_and_fit_their_run():
    table = registry.feedforward_table(SERVO)
    assert isinstance(table, FeedforwardTable) and table.model == "exact" and table.omega == 10.0
    assert registry.feedforward_table(SERVO.replace(feedforward="none")) is None
    assert table.at(table.phi0) == table.torque[0] and table.at(table.phi0 + 2 * math.pi) == table.torque[0]
    with pytest.raises(ParameterError, match="needs its table"):
        SpeedController(SERVO)
    with pytest.raises(ParameterError, match="not omega_target"):
        SpeedController(SERVO.replace(omega_target=12.0), table)
    from ipir_mujoco.engine import simulate_mujoco

    with pytest.raises(ParameterError, match="drive='motor'"):
        simulate_mujoco(RobotParams(drive="motor"), t_end=0.01, feedforward=table)


@pytest.mark.parametrize("argv,fragment", [
    (["--drive", "servo", "--set", "omega_target=0"], "omega_target=0.0 is out of range"),
    (["--drive", "servo", "--set", "omega_target=-2"], "omega_target=-2.0 is out of range"),
    (["--drive", "servo", "--set", "omega_target=30"], "omega_target=30 rad/s is out of range"),
    (["--drive", "servo", "--set", "omega_target=45"], "omega_target=45 rad/s is out of range"),
    (["--drive", "motor", "--feedforward", "exact"], "--feedforward exact applies only to --drive servo"),
    (["--feedforward", "paper"], "--feedforward paper applies only to --drive servo"),
    (["--drive", "motor", "--set", "omega_target=5"], "omega_target=5.0 sets the speed controller"),
    (["--drive", "servo", "--clutch", "unilateral", "--set", "mu_wall=0.5"], "drive='servo' runs on rigid clutches"),
])
def test_bad_servo_input_exits_2_with_one_line(capsys, argv, fragment):
    code, out, err = run_cli(capsys, "simulate", "--t-end", "0.01", *argv)
    assert code == 2 and out == ""
    assert fragment in err and err.count("\n") == 1


def test_the_dead_centre_profile_keeps_the_mean_crank_speed():
    from ipir_mujoco.core.control import reference_motion, reference_speed

    for dip in (0.0, 0.3, 0.6):
        t, phi = reference_motion(8.0, dip, 0.4, 2)
        # two turns at a mean of 8 rad/s take 4 pi / 8 s; the closed form to roundoff
        assert t[-1] == pytest.approx(4 * math.pi / 8.0, rel=1e-12)
        # and it follows omega_ref: its slope, by central differences, to their O(h^2) error (h = 2 pi / 4000)
        slope = (phi[2:] - phi[:-2]) / (t[2:] - t[:-2])
        assert np.allclose(slope, reference_speed(8.0, dip, phi[1:-1]), rtol=1e-4)
    # slowest at the dead centres (phi = 0, pi), fastest mid-stroke
    assert reference_speed(8.0, 0.3, 0.0) < 8.0 < reference_speed(8.0, 0.3, math.pi / 2)


def test_climb_refuses_the_servo_in_one_line(capsys, tmp_path):
    code, out, err = run_cli(capsys, "climb", "--drive", "servo", "--out", str(tmp_path / "c"))
    assert code == 2 and "drive='servo' in climb" in err and err.count("\n") == 1


def test_a_given_timestep_longer_than_the_controller_period_is_refused():
    with pytest.raises(ParameterError, match="longer than the speed controller's period"):
        registry.run("mujoco-ratchet", RobotParams(drive="servo", control_rate=5000.0), 0.01, dt_out=1e-3,
                     timestep=5e-4)


def test_leaving_the_servo_drive_drops_its_controller_settings():
    servo = RobotParams(drive="servo", omega_target=12.0, feedforward="paper", speed_kp=1.0)
    motor = servo.replace(drive="motor")
    assert (motor.omega_target, motor.feedforward, motor.speed_kp) == (10.0, "none", None)
    assert servo.replace(M_stall=0.6).omega_target == 12.0  # kept while the drive stays the servo


def test_a_servo_that_cannot_climb_stalls_as_the_motor_does():
    # a vertical riser under M_stall 0.3 N m: from rest the controller asks for full voltage and keeps it,
    # so the drive is the motor line and both engines must report the motor's stall, word for word
    riser = RobotParams(drive="servo", incline=90.0, M_stall=0.3)
    for variant in PAIR:
        servo = registry.run(variant, riser, 5.0, dt_out=1e-3)
        motor = registry.run(variant, riser.replace(drive="motor"), 5.0, dt_out=1e-3)
        assert servo.stall is not None and servo.stall == motor.stall
        assert np.all(servo.series["drive_u"] == 1.0)


@pytest.mark.slow
def test_a_sweep_row_carries_the_runs_crank_speed_figures(tmp_path, capsys):
    """sweep (and so optimize and sensitivity) reads the servo's figures: each design's speed_ripple and
    mean_omega_rad_s columns are the registry run's summary values (written with 10 significant digits)."""
    import csv

    code, _, err = run_cli(capsys, "sweep", "--vary", "control_rate=500,1000", "--variants", "analytic-unilateral",
                           "--drive", "servo", "--set", "omega_target=10", "--t-end", "0.3", "--workers", "1",
                           "--out", tmp_path / "s")
    assert code == 0, err
    with (tmp_path / "s" / "results.csv").open() as fh:
        rows = list(csv.DictReader(fh))
    for row in rows:
        rate = float(row["control_rate"])
        summary = registry.run("analytic-unilateral", RobotParams(drive="servo", omega_target=10.0,
                                                                  control_rate=rate), 0.3).summary
        for key in ("speed_ripple", "mean_omega_rad_s"):
            assert float(row[f"analytic-unilateral:{key}"]) == pytest.approx(summary[key], rel=1e-9), (rate, key)
