"""The analytic models under a real motor and gravity along the pipe: torque law, energy, steady state, stall."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from ipir_mujoco import analytic
from ipir_mujoco.analytic import RobotParams, SimulationError
from ipir_mujoco.core.cycles import cycles
from ipir_mujoco.analytic.dynamics import OneDofDynamics
from ipir_mujoco.analytic.kinematic_clutch import mode_rhs
from ipir_mujoco.core.results import Mode
from ipir_mujoco.analytic.unilateral_model import UnilateralModel
from ipir_mujoco.cli import main

MOTOR = RobotParams(drive="motor")  # the default gearmotor: M_stall 0.5 N m, no-load 30 rad/s
RTOL = 1e-10  # the solvers' default relative tolerance


def motor_line(params, omega):
    """The motor's torque at the crank [N m], written from its definition (not from analytic.forces)."""
    return params.M_stall * (1.0 - omega / params.omega_noload)


@pytest.mark.parametrize("omega", [-20.0, 0.0, 12.0, 30.0, 45.0])  # backward, stall, mid, no-load, overspeed
@pytest.mark.parametrize("geometry", ["approx", "exact"])
def test_the_right_hand_sides_apply_the_motor_line(geometry, omega):
    dyn = OneDofDynamics(MOTOR, geometry)
    phi = 1.1
    torque = motor_line(MOTOR, omega)
    # driven backward it gives more than M_stall; above no-load it brakes
    assert (torque > MOTOR.M_stall) == (omega < 0) and (torque < 0) == (omega > MOTOR.omega_noload)
    for mode in (Mode.CONTRACTION, Mode.EXPANSION):
        expected = dyn.acceleration(phi, omega, mode, M=torque)  # the same equations, the torque given
        paper_rule = mode_rhs(dyn, mode)(0.0, [phi, omega, 0.0, 0.0, 0.0])
        one_way = UnilateralModel(MOTOR, geometry).rhs(mode)(0.0, [phi, omega, 0.0, 0.0, 0.0, 0.0])
        for rhs in (paper_rule, one_way):
            # the same floating-point operations on the same numbers: equal to roundoff
            assert rhs[1] == pytest.approx(expected, rel=1e-14, abs=1e-12)
            assert rhs[-1] == pytest.approx(torque * omega, rel=1e-14, abs=1e-14)  # motor power [W]
    x1dd, alpha = dyn.both_moving(phi, omega, M=torque)
    rhs = UnilateralModel(MOTOR, geometry).rhs(Mode.BOTH_MOVING)(0.0, [phi, omega, 0.0, 0.0, 0.3, 0.0])
    assert rhs[1] == pytest.approx(alpha, rel=1e-14) and rhs[4] == pytest.approx(x1dd, rel=1e-14)
    assert rhs[-1] == pytest.approx(torque * omega, rel=1e-14, abs=1e-14)


@pytest.fixture(scope="module")
def steady_runs():
    """The default motor to steady state: the paper's model and the one-way clutches."""
    return {clutch: analytic.simulate(MOTOR, geometry, clutch, 5.0, dt_out=1e-3, until_steady=True)
            for geometry, clutch in (("approx", "kinematic"), ("exact", "unilateral"))}


@pytest.mark.parametrize("clutch", ["kinematic", "unilateral"])
@pytest.mark.slow
def test_the_default_motor_reaches_steady_state_and_stops_there(steady_runs, clutch):
    run = steady_runs[clutch]
    s, summary = run.series, run.summary
    assert summary["steady"] and not summary["stalled"]
    assert run.settings["until_steady"] and run.settings["steady_tol"] == 1e-4 and run.settings["steady_cycles"] == 3
    # stopped at the end of the revolution where the watch found it steady: that end is a sample, exact to
    # the root finder's tolerance (dt ~ 1e-15 s, phi' dt ~ 1e-13 rad), and it is the last one
    assert s["t"][-1] == pytest.approx(summary["t_steady_s"], abs=1e-13) and s["t"][-1] < 5.0
    turns = (s["phi"][-1] - s["phi"][0]) / (2 * math.pi)
    assert turns == pytest.approx(round(turns), abs=1e-12) and round(turns) == summary["cycles"]
    # the motor holds the mean crank speed below its no-load speed, where its torque is positive
    assert 0 < 2 * math.pi * summary["steady_speed_m_s"] / summary["distance_per_rev_m"] < MOTOR.omega_noload
    # rigid clutches lose nothing in impacts: over whole revolutions the gap returns, both modules
    # travel the same distance, and the motor's work per metre is F_r1 + F_r2 plus the kinetic energy
    # gained, which at a speed settled to 1e-4 is ~1e-4 of the work: 1e-3 leaves margin
    assert summary["energy_per_metre_j_m"] == pytest.approx(MOTOR.F_r1 + MOTOR.F_r2, rel=1e-3)
    assert summary["efficiency"] == pytest.approx(1.0, rel=1e-3)
    if clutch == "kinematic":  # under the paper's rule each module moves exactly 2r per revolution
        assert summary["distance_per_rev_m"] == pytest.approx(2 * MOTOR.r, rel=1e-9)


@pytest.mark.parametrize("clutch", ["kinematic", "unilateral"])
@pytest.mark.slow
def test_each_revolution_closes_its_energy_audit(steady_runs, clutch):
    """Motor work = friction work + kinetic energy gained, per revolution (core.cycles)."""
    run = steady_runs[clutch]
    found = cycles(run.series)
    assert len(found) == run.summary["cycles"] >= 3
    total = run.series["motor_work"][-1]
    for c in found:
        assert c.potential_change_j == 0.0  # a horizontal pipe
        # work, positions and speeds are integrated states, each step within rtol of its size: the
        # cumulative work (<= total) carries at most ~rtol * total per step over the ~100 steps of a
        # revolution; 1e3 rtol * total bounds it with margin
        assert abs(c.residual_j) < 1e3 * RTOL * total
        assert c.motor_work_j == pytest.approx(c.friction_work_j + c.kinetic_change_j, abs=1e3 * RTOL * total)


def test_per_revolution_steady_options_are_used_and_recorded():
    run = analytic.simulate(MOTOR, "approx", "kinematic", 5.0, dt_out=1e-3, until_steady=True,
                            steady_tol=1e-3, steady_cycles=4)
    assert run.settings["steady_tol"] == 1e-3 and run.settings["steady_cycles"] == 4
    speeds = [c.mean_speed_m_s for c in cycles(run.series)[-4:]]
    assert run.summary["steady"] and max(speeds) - min(speeds) <= 1e-3 * np.mean(speeds)


def potential_from_positions(params, series, rod):
    """Potential energy gained [J], from the bodies' heights: g sin(incline) (m1 x1 + m2 x2 + m_rod G_x)."""
    phi = series["phi"]
    S = params.r * np.cos(phi) + np.sqrt(params.L**2 - (params.r * np.sin(phi)) ** 2)
    rod_x = series["x1"] + (params.r * np.cos(phi) + S) / 2  # rod centre: mid-point of B and C
    height = params.m1 * series["x1"] + params.m2 * series["x2"] + (params.rod_mass * (rod_x - rod_x[0]) if rod else 0)
    return params.g * math.sin(math.radians(params.incline)) * height


@pytest.mark.parametrize("incline", [30.0, -20.0])
@pytest.mark.parametrize("geometry,clutch", [("approx", "kinematic"), ("exact", "unilateral")])
def test_energy_audit_closes_uphill_and_downhill(geometry, clutch, incline):
    params = MOTOR.replace(incline=incline)
    run = analytic.simulate(params, geometry, clutch, 1.0, dt_out=1e-3)
    e, s = run.energy, run.series
    np.testing.assert_allclose(s["potential"], potential_from_positions(params, s, geometry == "exact"),
                               rtol=1e-12, atol=1e-12)
    assert (e["potential_j"] > 0) == (incline > 0)  # the robot went up, or down
    assert e["potential_j"] == pytest.approx(s["potential"][-1])
    # every term is an integrated state or a function of states, each within ~rtol of its size
    flow = max(abs(e["motor_work_j"]), e["friction_j"], abs(e["potential_j"]), abs(e["kinetic_j"]))
    assert abs(e["residual_j"]) < 1e-6 * flow
    # the per-revolution audit includes gravity too
    assert all(abs(c.residual_j) < 1e-6 * flow for c in cycles(s))


def test_downhill_one_way_clutches_let_gravity_run_the_robot():
    """Steeper than the resistances hold: both modules slide, never backward, and Newton holds for the robot."""
    params = MOTOR.replace(incline=-30.0)
    run = analytic.simulate(params, "approx", "unilateral", 1.0, dt_out=1e-3)
    s = run.series
    assert s["v1"].min() > -1e-9 and s["v2"].min() > -1e-9
    both = s["mode"] == Mode.BOTH_MOVING
    assert both.mean() > 0.5  # after the start, gravity keeps both modules running
    a_g = -params.g * math.sin(math.radians(params.incline))
    # while both slide (no clutch holds): (m1 + m2) a_cm = (m1 + m2) a_g - F_r1 - F_r2, rod ignored (approx)
    newton = params.m1 * s["a1"][both] + params.m2 * s["a2"][both]
    np.testing.assert_allclose(newton, (params.m1 + params.m2) * a_g - params.F_r1 - params.F_r2, rtol=1e-9)


def test_the_papers_rule_refuses_a_downhill_start_it_cannot_decide():
    """Crank at rest mid-stroke where gravity alone moves either module: the paper's rule has no answer."""
    params = RobotParams(incline=-60.0, phi0=math.pi / 2)  # a_g = 8.5 m/s^2 > (F_r1 + F_r2) / mass ~ 1
    with pytest.raises(SimulationError, match="cannot choose a module.*unilateral"):
        analytic.simulate(params, "approx", "kinematic", 0.2)


# --- statics in a vertical pipe ----------------------------------------------------------------

def free_body_holds(params, phi, M, geometry):
    """Holds (R1, R2) [N] on the modules and the rod's axial force [N] of the robot at rest, from free bodies.

    Exact geometry: unknown pin forces on the rod at B (crank) and C (module 2); equations: the rod's two
    force balances and moment about B (its weight m_rod a_g at its centre), and the balanced crank's torque
    balance about A. Then module 2: R2 + m2 a_g + (rod on module 2 = -C) = 0; module 1 carries the crank
    axle: R1 + m1 a_g - B_x = 0. The paper's geometry: a massless rod along x with push P, M = -K P by
    virtual work (K = -r sin phi).
    """
    a_g = -params.g * math.sin(math.radians(params.incline))
    r, L, s, c = params.r, params.L, math.sin(phi), math.cos(phi)
    if geometry == "approx":
        push = -M / (-r * s)  # the rod pushes module 2 forward with P and module 1 back with P
        return -push - params.m1 * a_g, push - params.m2 * a_g, None
    D = math.sqrt(L**2 - (r * s) ** 2)
    cb = np.array([D, -r * s])  # C - B
    mr = params.rod_mass
    # unknowns [Bx, By, Cx, Cy]
    A = np.array([[1, 0, 1, 0], [0, 1, 0, 1], [0, 0, -cb[1], cb[0]], [r * s, -r * c, 0, 0]], dtype=float)
    rhs = np.array([-mr * a_g, 0.0, 0.5 * cb[1] * mr * a_g, -M])  # moment: (C-B) x F_C + (G-B) x W = 0
    Bx, By, Cx, Cy = np.linalg.solve(A, rhs)
    return Bx - params.m1 * a_g, Cx - params.m2 * a_g, (Cx * cb[0] + Cy * cb[1]) / L


@pytest.mark.parametrize("geometry,clutch", [("approx", "kinematic"), ("exact", "kinematic"), ("exact", "unilateral")])
@pytest.mark.parametrize("M", [0.0, 0.05])
def test_vertical_pipe_the_clutches_hold_the_weight_statics_gives(geometry, clutch, M):
    for phi in (0.4, 1.3, 2.2, 3.5, 4.4, 5.6):
        params = RobotParams(incline=90.0, M=M, phi0=phi, rod_mass=0.2)
        run = analytic.simulate(params, geometry, clutch, 0.01, dt_out=0.005)
        s = run.series
        assert np.all(s["mode"] == Mode.BOTH_LOCKED) and run.stall is not None
        R1, R2, rod = free_body_holds(params, phi, M, geometry)
        assert min(R1, R2) > 0  # both clutches push up: the hold is all theirs, not the resistance's
        # closed forms against a linear solve of the same statics: roundoff of forces ~ weight
        weight = (params.m1 + params.m2 + params.rod_mass) * params.g
        assert s["lambda1"][0] == pytest.approx(R1, abs=1e-12 * weight)
        assert s["lambda2"][0] == pytest.approx(R2, abs=1e-12 * weight)
        if M == 0.0 or geometry == "exact":  # the clutches carry the whole weight between them
            assert s["lambda1"][0] + s["lambda2"][0] == pytest.approx(
                weight if geometry == "exact" else (params.m1 + params.m2) * params.g, rel=1e-12)
        if rod is not None:
            assert s["rod_force"][0] == pytest.approx(rod, abs=1e-12 * weight)


# --- stalls --------------------------------------------------------------------------------------

@pytest.mark.parametrize("geometry,clutch", [("approx", "kinematic"), ("exact", "unilateral")])
def test_a_motor_too_weak_to_reach_the_next_dead_centre_stalls(geometry, clutch):
    params = MOTOR.replace(M_stall=0.02)  # below F_r1 r = 0.05 N m, what mid-stroke needs at rest
    run = analytic.simulate(params, geometry, clutch, 30.0, dt_out=1e-2, until_steady=True)
    s, summary = run.series, run.summary
    assert summary["stalled"] and summary["stall_reason"] == run.stall and not summary["steady"]
    at_rest = s["mode"] == Mode.BOTH_LOCKED
    t_stall, phi_stall = s["t"][at_rest][0], s["phi"][at_rest][0]
    assert run.stall.startswith(f"at rest from t={t_stall:.6g} s at phi={phi_stall:.6g} rad")
    assert "(0.02 N m)" in run.stall and 0 < phi_stall < math.pi  # before the first dead centre at pi
    assert np.all(at_rest[np.argmax(at_rest):]) and np.ptp(s["phi"][at_rest]) == 0
    # statics: the torque at rest, M_stall, cannot lift the rear module against F_r1 through the
    # linkage: M_stall <= F_r1 |K|, to the sign tests' tolerance
    K = OneDofDynamics(params, geometry).linkage.transfer(phi_stall).K
    assert params.M_stall <= params.F_r1 * abs(K) * (1 + 1e-6)


def test_a_constant_torque_too_small_is_a_stall_from_the_start():
    run = analytic.simulate(RobotParams(M=0.005, phi0=0.4), "exact", "unilateral", 0.2)
    assert run.stall == ("at rest from t=0 s at phi=0.4 rad (22.9 deg in its turn): the drive's torque at rest "
                         "(0.005 N m) cannot move the linkage against the resistances")
    up = analytic.simulate(RobotParams(M=0.005, phi0=0.4, incline=10.0), "approx", "kinematic", 0.2)
    assert up.stall.endswith("against the resistances and gravity")


def test_simulate_command_reports_steady_state_and_stall(capsys):
    assert main(["simulate", "--drive", "motor", "--until-steady", "--t-end", "5", "--dt-out", "1e-3",
                 "--json"]) == 0
    summary = json.loads(capsys.readouterr().out)["summary"]
    assert summary["steady"] and not summary["stalled"] and summary["t_steady_s"] < 5
    assert main(["simulate", "--drive", "motor", "--set", "M_stall=0.02", "--until-steady", "--t-end", "5",
                 "--dt-out", "1e-2", "--json"]) == 0
    summary = json.loads(capsys.readouterr().out)["summary"]
    assert summary["stalled"] and summary["stall_reason"].startswith("at rest from t=")
