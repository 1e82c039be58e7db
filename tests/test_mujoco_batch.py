"""Batched MuJoCo runs: the serial engine's physics and its accuracy monitor, per design."""

from __future__ import annotations

import numpy as np
import pytest

from ipir_mujoco.analytic import RobotParams
from ipir_mujoco.core.errors import ParameterError
from ipir_mujoco.engine import simulate_mujoco
from ipir_mujoco.engine.run.batch import run_ratchet_batch
from ipir_mujoco.engine.builders.model import INTEGRATORS, SolverSettings


def test_batch_equals_the_serial_engine_with_motor_gravity_and_own_timesteps():
    """Each design keeps its own automatic timestep in one batch: a fast crank (J_A = 1e-4) steps finer."""
    designs = [RobotParams(drive="motor", incline=30.0), RobotParams(J_A=1e-4), RobotParams(incline=-20.0, M=0.1)]
    t_end = 0.3
    batched = run_ratchet_batch(designs, t_end, dt_out=1e-3, nthread=1)
    timesteps = [outcome["settings"]["timestep"] for outcome in batched]
    assert timesteps[1] < timesteps[0] / 1.5  # really different steps in one batch
    for params, outcome in zip(designs, batched):
        run = simulate_mujoco(params, "unilateral", "ratchet", t_end, dt_out=1e-3)
        assert outcome["settings"]["timestep"] == run.settings["timestep"]
        b, s = outcome["series"], run.series
        # the same models from the same states, stepped alike: bit for bit
        for column in ("t", "phi", "omega", "x1", "x2", "v1", "v2", "a1", "a2", "motor_work", "kinetic", "potential"):
            np.testing.assert_array_equal(b[column], s[column], err_msg=column)
        # the gap is summed in another order (a few ulps of ~1e-5 m); the batch's friction work is
        # F_r |v| dt per step, the serial engine's the frictionloss rows' work: equal while a module
        # slides at F_r, apart in the few steps where it starts or stops (below 1e-9 of the motor work)
        np.testing.assert_allclose(b["loop_gap"], s["loop_gap"], rtol=1e-12, atol=1e-20)
        np.testing.assert_allclose(b["friction_work"], s["friction_work"], rtol=0, atol=1e-8 * s["motor_work"][-1])
        assert outcome["accuracy"]["ok"] and run.accuracy["ok"]
        for figure in ("loop_gap_m", "excursion_m"):
            assert outcome["accuracy"][figure] == pytest.approx(run.accuracy[figure], rel=1e-9, abs=1e-18), figure
        # residuals differ by the friction bookkeeping only: 1e-8 of the energy scale
        assert outcome["accuracy"]["residual_ratio"] == pytest.approx(run.accuracy["residual_ratio"], abs=1e-8)


def test_a_design_failing_the_monitor_is_marked_and_the_others_kept():
    """A coarse common step (4e-4 s): the paper's design fails the energy check, a gentle motor passes."""
    designs = [RobotParams(), RobotParams(drive="motor", M_stall=0.3, omega_noload=8.0)]
    coarse = SolverSettings(timestep=4e-4)
    failed, kept = run_ratchet_batch(designs, 0.8, dt_out=4e-3, settings=coarse, nthread=1)
    assert "accuracy check failed at t=" in failed["error"] and "energy residual" in failed["error"]
    assert not failed["accuracy"]["ok"] or failed["accuracy"]["mode"] == "stop"
    assert "error" not in kept and kept["accuracy"]["ok"] and kept["series"]["phi"][-1] > 1.0
    # warn: the failing design is kept, with the crossing recorded
    recorded, _ = run_ratchet_batch(designs, 0.8, dt_out=4e-3, settings=coarse, accuracy="warn", nthread=1)
    assert "error" not in recorded and not recorded["accuracy"]["ok"]
    assert recorded["accuracy"]["violations"][0]["figure"] == "residual_ratio"


@pytest.mark.slow
def test_batch_stops_steady_and_stalled_designs():
    designs = [RobotParams(drive="motor"), RobotParams(drive="motor", M_stall=0.02)]
    # one thread: two designs are too few to gain from more, and the suite shares the machine
    steady, stalled = run_ratchet_batch(designs, 3.0, dt_out=1e-3, nthread=1, until_steady=True)
    serial = simulate_mujoco(designs[0], "unilateral", "ratchet", 3.0, dt_out=1e-3, until_steady=True)
    assert steady["steady"] and steady["stall"] is None
    # the serial run stops at the same sample, at the end of the same steady revolution
    np.testing.assert_array_equal(steady["series"]["t"], serial.series["t"])
    assert stalled["stall"] is not None and stalled["stall"].startswith("at rest from t=")
    assert not stalled["steady"] and stalled["series"]["t"][-1] < 1.0


@pytest.mark.slow
def test_batch_halves_an_automatic_step_that_fails(monkeypatch):
    """As a serial run: an automatic step the monitor stops (4e-4 s, residual -7e-3 at the paper's
    case) is halved for that design only, and the design comes back within the tolerance."""
    from ipir_mujoco.engine.kinds import timestep

    chosen = timestep.choose_settings  # the slide kind's rule, which the batch asks for every design
    def coarse(params, *args):
        return (SolverSettings(timestep=4e-4), {}) if params.M > 0.2 else chosen(params, *args)

    monkeypatch.setattr(timestep, "choose_settings", coarse)
    fast, gentle = run_ratchet_batch([RobotParams(), RobotParams(M=0.1)], 0.8, dt_out=4e-3, nthread=1)
    assert [h["timestep"] for h in fast["settings"]["refinements"]][0] == 4e-4
    assert fast["settings"]["timestep"] < 4e-4 and fast["accuracy"]["ok"] and "error" not in fast
    assert gentle["settings"]["refinements"] == [] and gentle["accuracy"]["ok"]


@pytest.mark.parametrize("integrator", INTEGRATORS)
def test_batch_and_serial_count_the_motors_work_alike_under_every_integrator(integrator):
    """Both engines take the motor's implicit torque slope from one function: the implicit integrators
    apply the motor's velocity term at the step's final speed, Euler at its starting speed (a batch that
    added the slope under Euler was 1.4e-4 J = 8e-5 of the motor work off in 0.1 s)."""
    params, settings = RobotParams(drive="motor"), SolverSettings(timestep=1e-4, integrator=integrator)
    outcome = run_ratchet_batch([params], 0.1, dt_out=1e-3, settings=settings, nthread=1)[0]
    run = simulate_mujoco(params, "unilateral", "ratchet", 0.1, dt_out=1e-3, settings=settings)
    # the same model stepped alike, the work summed in the same order: bit for bit
    for column in ("phi", "omega", "motor_work"):
        np.testing.assert_array_equal(outcome["series"][column], run.series[column], err_msg=column)
    assert outcome["energy"]["motor_work_j"] == run.energy["motor_work_j"] > 0.1
    for column in ("kinetic", "potential"):
        np.testing.assert_array_equal(outcome["series"][column], run.series[column], err_msg=column)
    # the residual differs by the friction bookkeeping only (see the first test): 1e-8 of the energy scale
    assert outcome["accuracy"]["residual_ratio"] == pytest.approx(run.accuracy["residual_ratio"], abs=1e-8)


def test_rk4_is_refused_by_both_engines_in_one_line():
    """Under RK4 the values the engines read after mj_step (energies, drive torque, friction rows) are the
    last stage's: the serial engine's kinetic energy at t = 1 ms read 1.47e-4 J against 1.22e-4 J. Both
    engines take their settings from SolverSettings, which refuses it, naming the allowed integrators."""
    with pytest.raises(ParameterError) as refused:
        SolverSettings(integrator="rk4")
    message = str(refused.value)
    assert "\n" not in message and "'rk4'" in message and "unknown" not in message and "last stage" in message
    assert message.endswith("allowed: " + ", ".join(INTEGRATORS)) and "rk4" not in INTEGRATORS
    assert set(INTEGRATORS) == {"euler", "implicitfast", "implicit"}


def test_a_non_finite_speed_fails_the_design():
    """The health check reads the velocities too: a NaN crank speed with finite positions fails the design
    with the one-line reason, and only that design."""
    from ipir_mujoco.engine.run.batch import _Batch
    from ipir_mujoco.engine.builders.model import build_model

    designs, settings = [RobotParams(), RobotParams(M=0.1)], SolverSettings()
    models = [build_model(p, settings, ratchet=True) for p in designs]
    batch = _Batch(models, designs, [settings] * 2, 0.01, 1e-3, 1, "stop", False, 1e-4, 3)
    batch._start()
    batch.qvel[0, batch.crank_v] = np.nan
    assert np.all(np.isfinite(batch.qpos))
    batch._check_health(1, np.array([True, True]), np.zeros(2, dtype=int))
    assert batch.failed[0].startswith("MuJoCo became unstable after t=0 s") and batch.failed[1] is None
    assert not batch.running[0] and batch.running[1] and not batch.inaccurate[0]
