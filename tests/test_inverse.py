"""Inverse kinetostatics, checked by the forward models and by MuJoCo."""

from __future__ import annotations

import re

import numpy as np
import pytest

from ipir_mujoco import analytic
from ipir_mujoco.analytic import ParameterError, RobotParams
from ipir_mujoco.analytic.inverse import CrankMotion, inverse_kinetostatics
from ipir_mujoco.analytic.unilateral_run import simulate_unilateral
from ipir_mujoco.cli import main
from ipir_mujoco.engine import CrankServo, simulate_mujoco

OMEGA = 30.0  # rad/s
MOTION = CrankMotion.constant_speed(OMEGA, revolutions=3)
PARAMS = RobotParams()
FORWARD = {"kinematic": lambda p, t_end, torque: analytic.simulate_kinematic(p, "exact", t_end, torque=torque),
           "unilateral": lambda p, t_end, torque: simulate_unilateral(p, "exact", t_end, torque=torque)}


@pytest.fixture(scope="module", params=["kinematic", "unilateral"])
def inverse_run(request):
    return inverse_kinetostatics(PARAMS, MOTION, "exact", request.param, dt_out=1e-5)


def test_inverse_energy_balances(inverse_run):
    e = inverse_run.summary["energy"]
    assert abs(e["residual_j"]) < 1e-8 * e["motor_work_j"]


def test_feeding_the_torque_forward_reproduces_the_prescribed_motion(inverse_run):
    s = inverse_run.series
    torque = lambda t, phi, omega: np.interp(t, s["t"], s["motor_torque"])  # noqa: E731
    forward = FORWARD[inverse_run.clutch](PARAMS.replace(omega0=OMEGA), inverse_run.t_end, torque).series
    # The torque jumps at mode switches; linear interpolation smears each jump dM (< 3 N m)
    # over one sample interval h = 1e-5 s, moving the crank by at most dM h^2 / J_A = 3e-7 rad
    # per jump; a dozen jumps bound the drift by ~4e-6 rad: 1e-5 rad leaves margin.
    assert np.max(np.abs(forward["phi"] - OMEGA * forward["t"])) < 1e-5
    for column in ("x1", "x2"):
        assert forward[column][-1] == pytest.approx(s[column][-1], rel=1e-4, abs=1e-9)


def test_mujoco_servo_needs_the_same_torque(inverse_run):
    implementation = "lock" if inverse_run.clutch == "kinematic" else "ratchet"
    servo = CrankServo(MOTION.phi, MOTION.omega)
    mj = simulate_mujoco(PARAMS.replace(omega0=OMEGA), inverse_run.clutch, implementation, MOTION.t_end,
                         servo=servo).series
    expected = np.interp(mj["phi"], inverse_run.series["phi"], inverse_run.series["motor_torque"])
    difference = np.abs(mj["motor_torque"] - expected)
    # A PD servo without feedforward lags by e = M / kp (1.5e-3 rad here); its torque then
    # differs from the need by the inertia times that lag's acceleration, J_eff * M'' / kp with
    # J_eff <= J_A + m r^2 and M'' ~ (2 omega)^2 max|M|. Switches make brief transients, so
    # the bound holds for the median and the 90th percentile, not the maximum.
    J_eff = PARAMS.J_A + max(PARAMS.m1, PARAMS.m2) * PARAMS.r**2
    bound = J_eff * (2 * OMEGA) ** 2 * np.abs(expected).max() / servo.kp
    assert np.median(difference) < bound and np.percentile(difference, 90) < 2 * bound
    assert np.max(np.abs(mj["phi"] - OMEGA * mj["t"])) < 2 * np.abs(expected).max() / servo.kp


@pytest.mark.slow
def test_sampled_motion_of_a_forward_run_needs_its_constant_torque():
    """Round trip: a forward run's phi(t), given as samples, must need the run's own torque M."""
    forward = analytic.simulate(PARAMS, "exact", "kinematic", 0.3, dt_out=1e-4).series
    keep = np.concatenate([[True], np.diff(forward["t"]) > 0])  # samples need distinct times
    motion = CrankMotion.from_samples(forward["t"][keep], forward["phi"][keep])
    inverse = inverse_kinetostatics(PARAMS, motion, "exact", "kinematic", dt_out=1e-4).series
    inside = (inverse["t"] > 0.01) & (inverse["t"] < 0.29)
    # the spline's alpha is exact to O(h^2 phi'''') away from the switches, where alpha jumps
    assert np.median(np.abs(inverse["motor_torque"][inside] - PARAMS.M)) < 1e-3 * PARAMS.M


def test_prescribed_motion_is_validated():
    with pytest.raises(ParameterError, match="omega=0"):
        CrankMotion.constant_speed(0.0)
    with pytest.raises(ParameterError, match="increase strictly"):
        CrankMotion.from_samples([0, 1, 1, 2], [0, 1, 2, 3])
    with pytest.raises(ParameterError, match="at least 4"):
        CrankMotion.from_samples([0, 1], [0, 1])


@pytest.mark.slow
def test_kinetostatics_command(tmp_path, capsys):
    out = tmp_path / "k"
    assert main(["kinetostatics", "--omega", "30", "--clutch", "unilateral", "--out", str(out)]) == 0
    printed = capsys.readouterr().out
    assert "motor torque" in printed
    # every bound keeps 4 significant digits and its sign ('-16.00 .. +26.02 N', not '-16 .. +26.02')
    bounds = re.findall(r"([-+]?[0-9.]+) \.\. ([-+]?[0-9.]+)", printed)
    assert len(bounds) == 4, printed
    for value in (v for pair in bounds for v in pair):
        assert len(value.lstrip("+-").replace(".", "").lstrip("0")) == 4 or float(value) == 0, printed
        assert value[0] in "+-" or float(value) == 0, printed
    assert (out / "kinetostatics.png").read_bytes()[:4] == b"\x89PNG"
    header = (out / "kinetostatics.csv").read_text().splitlines()[0].split(",")
    assert {"motor_torque", "lambda1", "lambda2", "rod_force", "phi"} <= set(header)
    samples = tmp_path / "phi.csv"
    samples.write_text("t,phi\n" + "\n".join(f"{t:.3f},{20 * t + 5 * t * t:.6f}" for t in np.linspace(0, 0.5, 51)))
    assert main(["kinetostatics", "--samples", str(samples), "--out", str(tmp_path / "s")]) == 0
    bad = tmp_path / "bad.csv"
    bad.write_text("time,angle\n0,0\n1,1\n")
    for argv, fragment in ((["--omega", "0"], "omega=0"), (["--samples", str(tmp_path / "none.csv")], "none.csv"),
                           (["--samples", str(bad)], "columns t and phi")):
        assert main(["kinetostatics", *argv, "--out", str(tmp_path / "never")]) == 2
        assert fragment in capsys.readouterr().err
    assert not (tmp_path / "never").exists()


@pytest.mark.parametrize("clutch", ["kinematic", "unilateral"])
def test_on_a_slope_the_inverse_torque_drives_the_forward_model_the_same_way(clutch):
    """Gravity enters the inverse (torque, holds) and the forward models alike: uphill, one turn at 30 rad/s."""
    params = PARAMS.replace(incline=25.0)
    motion = CrankMotion.constant_speed(OMEGA, revolutions=1)
    inverse = inverse_kinetostatics(params, motion, "exact", clutch, dt_out=1e-5)
    e, s = inverse.summary["energy"], inverse.series
    assert e["potential_j"] > 0  # it climbed
    assert abs(e["residual_j"]) < 1e-8 * e["motor_work_j"]
    torque = lambda t, phi, omega: np.interp(t, s["t"], s["motor_torque"])  # noqa: E731
    forward = FORWARD[clutch](params.replace(omega0=OMEGA), inverse.t_end, torque).series
    # the same interpolation bound as on the level (test above): a few switches, 1e-5 rad
    assert np.max(np.abs(forward["phi"] - OMEGA * forward["t"])) < 1e-5
    for column in ("x1", "x2"):
        assert forward[column][-1] == pytest.approx(s[column][-1], rel=1e-4, abs=1e-9)


def test_progress_reports_the_simulated_time_up_to_the_end():
    """progress(t) at every clutch-mode change: increasing simulated times [s], the last the run's end, so
    that the command line can say where a long prescribed motion is (kinetostatics --samples)."""
    reached = []
    run = inverse_kinetostatics(RobotParams(), CrankMotion.constant_speed(20.0, 0.0, 2.0), "exact", "unilateral",
                                progress=reached.append)
    assert len(reached) >= 4 and np.all(np.diff(reached) > 0)  # two mode changes a revolution at least
    assert reached[-1] == pytest.approx(run.t_end, rel=1e-12)


def test_a_throttled_progress_passes_the_time_on_at_most_once_per_period():
    """core.options.throttled: the studies' heartbeat inside a long run (validate's rungs, the convergence
    runs): with no period every call goes through; with a period longer than the test, none (the first only
    after a whole period)."""
    from ipir_mujoco.core.options import throttled

    seen = []
    every = throttled(seen.append, every_s=0.0)
    for t in (0.1, 0.2, 0.3):
        every(t)
    assert seen == [0.1, 0.2, 0.3]
    quiet = throttled(seen.append, every_s=1e9)
    quiet(0.4)
    assert seen == [0.1, 0.2, 0.3]
    run = analytic.simulate(RobotParams(), "exact", "unilateral", 0.3,
                            progress=throttled(seen.append, every_s=0.0))
    assert seen[3:] and seen[-1] <= run.t_end + 1e-12 and np.all(np.diff(seen[3:]) >= 0)
