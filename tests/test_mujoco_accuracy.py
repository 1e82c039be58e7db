"""MuJoCo numbers a user can trust with default options: the accuracy monitor and the automatic timestep."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from ipir_mujoco import analytic
from ipir_mujoco.analytic import ParameterError, RobotParams, SimulationError
from ipir_mujoco.core.cycles import travel
from ipir_mujoco.core.options import RepeatProgress
from ipir_mujoco.cli import main
from ipir_mujoco.engine import simulate_mujoco
from ipir_mujoco.engine import kinds
from ipir_mujoco.engine.kinds import timestep
from ipir_mujoco.engine.run import simulate as engine_simulate
from ipir_mujoco.engine.builders.model import SolverSettings
from ipir_mujoco.engine.loop.monitor import RESIDUAL_TOL
from ipir_mujoco.engine.modelkinds.timestep import DT_MAX, DT_MAX_CLUTCH

TARGET = 1e-3  # MuJoCo within 0.1 % of the analytic model of the same mechanism


def relative_errors(mj, reference) -> dict[str, float]:
    moved = lambda run: travel(run.series)[-1] - travel(run.series)[0]  # noqa: E731
    return {"revolutions": mj.summary["revolutions"] / reference.summary["revolutions"] - 1,
            "travel": moved(mj) / moved(reference) - 1}


def test_a_fast_crank_with_default_options_stays_within_0_1_percent_or_stops():
    """A crank spun up fast (J_A = 3e-4 kg m^2: 12 revolutions in 1 s, 340 rad/s at the end).

    The former fixed 1e-4 s step gave +0.17 % revolutions here with a residual of
    -0.5 % of the motor work, silently; the same step now stops on the monitor,
    and the default (automatic) settings land within the 0.1 % target.
    """
    params = RobotParams(J_A=3e-4)
    reference = analytic.simulate(params, "exact", "unilateral", 1.0)
    with pytest.raises(SimulationError, match=r"accuracy check failed at t=.*energy residual"):
        simulate_mujoco(params, "unilateral", "ratchet", 1.0, settings=SolverSettings(timestep=1e-4))
    run = simulate_mujoco(params, "unilateral", "ratchet", 1.0)
    assert run.settings["timestep_source"] == "auto" and run.settings["timestep"] < 1e-4
    for figure, error in relative_errors(run, reference).items():
        assert abs(error) < TARGET, figure
    assert abs(run.accuracy["residual_ratio"]) < RESIDUAL_TOL and run.accuracy["ok"]


def test_a_light_rod_with_default_options_stays_within_0_1_percent():
    """rod_mass = 1e-4 kg (1 % of the default): the soft loop's leak, (1 - d) of the rod end's free
    acceleration, cost -0.29 % revolutions at impedance 0.99; at 0.9999 it is within the target."""
    params = RobotParams(rod_mass=1e-4)
    reference = analytic.simulate(params, "exact", "unilateral", 1.0)
    run = simulate_mujoco(params, "unilateral", "ratchet", 1.0)
    for figure, error in relative_errors(run, reference).items():
        assert abs(error) < TARGET, figure
    # the loop gap tells the leak: 3e-4 m at impedance 0.99; its tolerance is 1e-3 r
    assert run.accuracy["loop_gap_m"] < run.accuracy["tolerances"]["loop_gap_m"] == pytest.approx(1e-3 * params.r)


def test_the_locks_need_their_own_smaller_largest_step():
    """DT_MAX_CLUTCH: under the paper's rule a lock stops its module within one step at every engagement,
    so at the paper's 1 s case the locks' energy residual crosses the monitor's tolerance at the ratchet's
    largest step and stays inside it at their own."""
    assert DT_MAX_CLUTCH["lock"] < DT_MAX == DT_MAX_CLUTCH["ratchet"]
    worst = {}
    for step in (DT_MAX, DT_MAX_CLUTCH["lock"]):
        run = simulate_mujoco(RobotParams(), "kinematic", "lock", 1.0, dt_out=1e-3,
                              settings=SolverSettings(timestep=step), accuracy="warn")
        worst[step] = abs(run.accuracy["residual_ratio"])
    assert worst[DT_MAX] > RESIDUAL_TOL > worst[DT_MAX_CLUTCH["lock"]], worst


def test_the_monitor_stops_a_coarse_run_and_warn_records_it(capsys, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    coarse = ["simulate", "--engine", "mujoco", "--clutch", "unilateral", "--t-end", "0.5",
              "--timestep", "5e-4", "--dt-out", "5e-4"]
    assert main(coarse) == 1
    err = capsys.readouterr().err
    # one line naming the time, the figure, its value, the tolerance and the remedies
    assert err.count("\n") == 1
    for fragment in ("t=", "energy residual", "tolerance 0.001", "--timestep", "--accuracy warn"):
        assert fragment in err, fragment
    assert main(coarse + ["--accuracy", "warn", "--json"]) == 0
    accuracy = json.loads(capsys.readouterr().out)["summary"]["accuracy"]
    assert accuracy["mode"] == "warn" and not accuracy["ok"]
    first = accuracy["violations"][0]
    assert first["figure"] == "residual_ratio" and abs(first["value"]) > first["tolerance"] == RESIDUAL_TOL
    assert 0 < first["t_s"] <= 0.5 and abs(accuracy["residual_ratio"]) >= abs(first["value"])
    assert list(tmp_path.iterdir()) == []  # no MUJOCO_LOG.TXT


def test_an_automatic_step_that_fails_the_monitor_is_halved(monkeypatch):
    """Whatever the motion bounds miss is caught: a step of 4e-4 s (residual -5e-3 at the paper's case)
    fails, and the engine repeats the run at half the step until it passes."""
    chosen = timestep.choose_settings  # the slide kind's timestep rule, which every run asks
    monkeypatch.setattr(timestep, "choose_settings",
                        lambda *args: (SolverSettings(timestep=4e-4), chosen(*args)[1]))
    run = simulate_mujoco(RobotParams(), "unilateral", "ratchet", 0.8, dt_out=4e-4)
    failed = run.settings["refinements"]
    assert failed and failed[0]["timestep"] == 4e-4 and "accuracy check failed" in failed[0]["reason"]
    assert run.settings["timestep"] == 4e-4 / 2 ** len(failed) and run.accuracy["ok"]


def test_the_run_never_goes_past_t_end(capsys):
    run = simulate_mujoco(RobotParams(), "unilateral", "ratchet", 0.15, dt_out=0.1)
    np.testing.assert_allclose(run.series["t"], [0.0, 0.1, 0.15], rtol=0, atol=1e-12)
    assert run.t_end == pytest.approx(0.15, abs=1e-12)
    with pytest.raises(ParameterError, match=r"dt_out=0.2 s is out of range; allowed: dt_out <= t_end"):
        simulate_mujoco(RobotParams(), "unilateral", "ratchet", 0.1, dt_out=0.2)
    assert main(["simulate", "--engine", "mujoco", "--t-end", "0.1", "--dt-out", "0.2"]) == 2
    assert capsys.readouterr().err.count("\n") == 1


def test_a_motor_too_weak_for_the_load_is_a_stall_not_an_error():
    """M_stall = 0.02 N m: the crank turns a tenth of a revolution and stops for good."""
    run = simulate_mujoco(RobotParams(drive="motor", M_stall=0.02), "unilateral", "ratchet", 3.0, dt_out=1e-3)
    assert run.stall is not None and run.stall.startswith("at rest from t=")
    assert run.t_end < 1.0 and run.summary["stalled"] and run.summary["stall_reason"] == run.stall
    # at rest over the last 0.1 s: the crank pin and the modules slower than 1e-6 m/s
    last = run.series["t"] >= run.t_end - 0.1
    assert np.abs(run.series["omega"][last]).max() * run.params.r < 1e-6
    assert np.abs(run.series["v1"][last]).max() < 1e-6 and np.abs(run.series["v2"][last]).max() < 1e-6


def test_both_engines_put_the_first_minimum_of_s_of_a_stall_where_the_robot_comes_to_rest():
    """The default motor up a vertical pipe stalls while contracting (at rest from t = 0.3602 s in the
    equations). The equations' S_dot rests at an exact 0, MuJoCo's held module creeps (S_dot about
    -1.4e-9 m/s, never >= 0; this summary said 'none'): one summary function reads both as the minimum of S.
    Within one output interval (1e-3 s): MuJoCo's rest is known to its samples, and the first at rest is its
    minimum; the engines' motions agree far closer (the stall times differ by < 1e-3 s)."""
    params, dt_out = RobotParams(drive="motor", incline=90.0), 1e-3
    equations = analytic.simulate(params, "exact", "unilateral", 0.6, dt_out=dt_out)
    mujoco = simulate_mujoco(params, "unilateral", "ratchet", 0.6, dt_out=dt_out)
    assert equations.stall is not None and mujoco.stall is not None
    first = equations.summary["first_contraction_end_s"]
    assert first == pytest.approx(0.3602, abs=1e-4)
    assert mujoco.summary["first_contraction_end_s"] == pytest.approx(first, abs=dt_out)


def test_until_steady_stops_at_the_end_of_the_steady_revolution():
    """The default motor reaches its periodic steady state in about 2 s."""
    run = simulate_mujoco(RobotParams(drive="motor"), "unilateral", "ratchet", 10.0, dt_out=1e-3, until_steady=True)
    s = run.summary
    assert s["steady"] and run.settings["steady_tol"] == 1e-4 and run.settings["steady_cycles"] == 3
    # the run ends on the first sample at or after the end of the steady revolution
    assert 0 <= run.t_end - s["t_steady_s"] < 1e-3 + 1e-9 and run.t_end < 10.0
    # energy columns: the audit closes per revolution as well as the monitor holds the run's:
    # a revolution's residual is the difference of two cumulative ones, each within 1e-3 of the
    # energy put through the robot by then (the motor work)
    assert s["cycle_energy_residual_j"] <= 2 * RESIDUAL_TOL * run.series["motor_work"][-1]
    assert 0.9 < s["efficiency"] <= 1.0  # little kinetic energy is gained at cruise: most work goes to friction


def test_the_engine_models_drive_and_incline():
    # (compliant clutches, and what stays refused with them: tests/test_mujoco_compliant.py)
    run = simulate_mujoco(RobotParams(drive="motor", incline=30.0), "unilateral", "ratchet", 0.3, dt_out=1e-3)
    # climbing 30 deg: the potential energy MuJoCo reports is g sin(30 deg) times the mass-weighted climb
    # of the modules and of the rod's centre (at L/2 along the rod from the crank pin)
    p, s = run.params, run.series
    beta = np.arcsin(-p.r * np.sin(s["phi"]) / p.L)
    rod_x = s["x1"] + p.r * np.cos(s["phi"]) + 0.5 * p.L * np.cos(beta)
    climb = p.m1 * s["x1"] + p.m2 * s["x2"] + p.rod_mass * (rod_x - rod_x[0])
    assert climb[-1] > 0.01
    # the rod's centre is off by at most the loop gap (< 5e-5 m): 1e-6 J of the ~0.1 J bounds it
    np.testing.assert_allclose(s["potential"], p.g * 0.5 * climb, rtol=0, atol=1e-6)
    assert run.accuracy["ok"]


def test_static_clutch_reactions_in_a_vertical_pipe_carry_the_weights():
    """Crank held by the two clutches (both modules held fix the gap, so the crank angle), vertical pipe.

    Statics with gravity -g along x, no resistance (so each clutch alone holds its
    module), crank torque M: rod force on the crank P at B, module 2's pin force
    on the rod Q at C, rod weight w at its centre G. Rod: P + Q + (-w, 0) = 0 and
    moments about B: d x Q + (d/2) x (-w, 0) = 0, d = C - B. Crank (balanced, its
    weight on A): b x (-P) + M = 0, b = B - A. Modules: lambda1 = m1 g + P_x,
    lambda2 = m2 g + Q_x... with the rod's force on module 2 = -Q: lambda2 = m2 g + Q_x.
    """
    for phi, torque in ((1.0, 0.0), (2.2, 0.0), (4.1, 0.0), (5.3, 0.0), (1.0, 0.1), (4.1, -0.1)):
        params = RobotParams(incline=90.0, F_r1=0.0, F_r2=0.0, M=torque, phi0=phi, rod_mass=0.05)
        run = simulate_mujoco(params, "unilateral", "ratchet", 0.3)
        assert run.stall is not None, phi  # held at rest: the run ends as a stall
        p, g = params, params.g
        b = p.r * np.array([math.cos(phi), math.sin(phi)])
        beta = math.asin(-p.r * math.sin(phi) / p.L)
        d = p.L * np.array([math.cos(beta), math.sin(beta)])
        w = p.rod_mass * g
        # unknowns Q = (Qx, Qy): -b_x Qy + b_y Qx = M + b_y w (crank), d_x Qy - d_y Qx = -d_y w / 2 (rod)
        qx, qy = np.linalg.solve([[b[1], -b[0]], [-d[1], d[0]]], [torque + b[1] * w, -d[1] * w / 2])
        lambda1, lambda2 = p.m1 * g + w - qx, p.m2 * g + qx
        # MuJoCo's soft rows settle to the static load exactly; what remains is the geometry moved by
        # the clutches' give, (1 - d) g tc^2 ~ 1e-4 * 10 * (2e-4)^2 = 4e-11 m, which changes the
        # angles by ~1e-9 rad: 1e-7 of the weights bounds both with margin
        scale = (p.m1 + p.m2 + p.rod_mass) * g
        assert run.series["lambda1"][-1] == pytest.approx(lambda1, abs=1e-7 * scale), (phi, torque)
        assert run.series["lambda2"][-1] == pytest.approx(lambda2, abs=1e-7 * scale), (phi, torque)
        assert min(lambda1, lambda2) > 0.5 * min(p.m1, p.m2) * g  # both clutches really carry weight


def test_progress_every_tenth_of_a_second_and_the_wall_budget():
    seen: list[float] = []
    simulate_mujoco(RobotParams(), "unilateral", "ratchet", 0.5, dt_out=1e-3, progress=seen.append)
    # reported at the first output sample at or after each 0.1 s (checks run every 0.05 s of simulated time)
    np.testing.assert_allclose(seen, [0.1, 0.2, 0.3, 0.4, 0.5], atol=0.05 + 1e-9)
    assert all(b - a > 0.05 for a, b in zip(seen, seen[1:]))
    # the budget covers building the model too, so a budget of 1 ns is spent before the first step
    with pytest.raises(SimulationError, match=r"wall-time budget of 1e-09 s while building its model"):
        simulate_mujoco(RobotParams(), "unilateral", "ratchet", 0.5, dt_out=1e-3, wall_budget_s=1e-9)


def test_a_run_slower_than_its_progress_wall_time_reports_at_every_check(monkeypatch):
    """Where 0.1 s of simulated time takes longer than PROGRESS_WALL_S of wall time (a wheeled run at a fine
    step), progress comes at every check (every BLOCK_TIME of simulated time) past it: here, with the wall time
    set to 0, at every check."""
    from ipir_mujoco.engine.modelkinds.common import BLOCK_TIME
    from ipir_mujoco.engine.run import block_checks

    monkeypatch.setattr(block_checks, "PROGRESS_WALL_S", 0.0)
    seen: list[float] = []
    simulate_mujoco(RobotParams(), "unilateral", "ratchet", 0.3, dt_out=1e-3, progress=seen.append)
    # a check at each output sample at or after every BLOCK_TIME (0.05 s), the last at the end
    np.testing.assert_allclose(seen, BLOCK_TIME * np.arange(1, 7), atol=1e-3 + 1e-9)


def test_progress_never_goes_back_across_a_halved_step_and_the_repeat_says_where_it_is(monkeypatch):
    """The first attempt at 4e-4 s reports progress until the monitor stops it; the repeat at half the step
    reports all along, as RepeatProgress values that never go below what was reported (a user's progress never
    goes back) and carry the repeat's own time, step and attempt; it still reaches the end."""
    chosen = timestep.choose_settings  # the slide kind's timestep rule, which every run asks
    monkeypatch.setattr(timestep, "choose_settings",
                        lambda *args: (SolverSettings(timestep=4e-4), chosen(*args)[1]))
    attempts, seen = [], []
    real = engine_simulate._Run

    class Counted(real):  # counts the attempts, to prove the retry happened after progress was reported
        def __init__(self, *args, **kwargs):
            attempts.append(len(seen))
            super().__init__(*args, **kwargs)

    monkeypatch.setattr(engine_simulate, "_Run", Counted)
    run = simulate_mujoco(RobotParams(), "unilateral", "ratchet", 0.8, dt_out=4e-4, progress=seen.append)
    assert run.settings["refinements"] and len(attempts) >= 2 and attempts[1] >= 2  # reported, then repeated
    assert all(b >= a for a, b in zip(seen, seen[1:])), seen
    first, repeat = seen[:attempts[1]], seen[attempts[1]:]
    assert all(b > a for a, b in zip(first, first[1:])) and not any(isinstance(t, RepeatProgress) for t in first)
    assert repeat and all(isinstance(t, RepeatProgress) and t.attempt == 2 and t.timestep == 2e-4 for t in repeat)
    own = [t.t for t in repeat]
    # the repeat's own time from its start (every 0.1 s of it, within one output interval), not from the first
    # attempt's last report: it is heard from before it passes that point
    assert own[0] < first[-1] and all(b > a for a, b in zip(own, own[1:]))
    assert all(float(t) == max(first[-1], t.t) for t in repeat)
    assert seen[-1] == pytest.approx(0.8, abs=4e-4) and repeat[-1].t == pytest.approx(0.8, abs=4e-4)


@pytest.mark.parametrize("params, servo, t_end, named", [
    (RobotParams(rod_mass=1e-10), None, 0.1, r"^rod_mass=1e-10 kg: the module-to-rod mass ratio 1e\+10 "),
    (RobotParams(), engine_simulate.CrankServo(lambda t: 0.0, lambda t: 0.0, kp=1e12), 0.1,
     r"^crank servo kp=1e\+12 N m/rad"),
    (RobotParams(J_A=1e-6, M=10.0), None, 60.0, r"^t_end=60 s: the crank can reach"),
])
def test_a_timestep_below_the_floor_names_the_limit_that_set_it(params, servo, t_end, named):
    """The refusal names what demanded the step (a light rod, a stiff servo, the crank speed), not always
    the crank speed, and the timestep it would need, in one line."""
    from ipir_mujoco.engine.modelkinds.timestep import DT_MIN, choose_settings

    with pytest.raises(ParameterError, match=named) as refused:
        choose_settings(params, t_end, 1e-3, servo)
    message = str(refused.value)
    assert "MuJoCo would need a timestep of" in message and f">= {DT_MIN:g} s" in message and "\n" not in message
    assert ("crank can reach" in message) == named.startswith("^t_end")


def _fed_in_turn(values, times, worst, tolerance, mode, rows=None):
    """The monitor's loop-gap record (or its error) after feeding ``values`` at ``times``: each in turn as the
    per-sample loop did (a value that beats the worst), or only ``rows``."""
    from ipir_mujoco.engine.loop.monitor import AccuracyError, AccuracyMonitor, Tolerances

    monitor = AccuracyMonitor(Tolerances(1.0, tolerance, 1.0), mode)
    monitor.worst["loop_gap_m"] = worst
    try:
        for i in (range(len(values)) if rows is None else rows):
            if values[i] > monitor.worst["loop_gap_m"]:
                monitor.loop_gap(times[i], values[i])
    except AccuracyError as exc:
        return str(exc)
    return monitor.record()


@pytest.mark.parametrize("mode", ["stop", "warn"])
def test_a_block_feeds_the_monitor_what_feeding_every_sample_would(mode):
    """The engine feeds the monitor a block's first crossing of the tolerance and its worst only: the record
    (worst, when, violations) and any error equal those of feeding every sample in turn, on blocks with
    ties, NaN, crossings before, at and after the worst, and a worst already past the tolerance."""
    rng = np.random.default_rng(7)
    for _ in range(400):
        n = int(rng.integers(1, 60))
        values = np.round(rng.uniform(0, 2, n), 1)  # rounded: ties
        values[rng.random(n) < 0.05] = np.nan
        times = np.arange(n) * 1e-3
        worst, tolerance = float(rng.choice([0.0, 0.5, 1.2, 1.9])), float(rng.choice([0.7, 1.0, 1.5]))
        rows = engine_simulate._rising(values, worst, tolerance, 0)
        assert _fed_in_turn(values, times, worst, tolerance, mode, rows) == \
            _fed_in_turn(values, times, worst, tolerance, mode)
