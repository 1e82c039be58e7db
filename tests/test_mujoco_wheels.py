"""The wheeled MuJoCo model, a 3-D robot on sprung wheel legs in a round pipe (``--mujoco-model wheels``):
MuJoCo's own arrays say the legs press the wall with F_n as the weight sags the modules, the wheels roll
against F_r and never pull outside their friction cone; the closed-form lift-off check matches MuJoCo's legs
under weight; in a straight pipe it crawls as the analytic finite-grip model does and skids in a riser as it
does; unlimited grip never skids.

Tolerances are derived where they are used: linear springs on evenly spaced legs (their outward directions sum
to zero), the friction cone's own bound, the wheels' rolling inertia (the one mass term the analytic model
lacks) plus the MuJoCo monitor's 0.1 % target, and MuJoCo's discretization error bounded by the change on
halving its step.
"""

from __future__ import annotations

import json
import math

import mujoco
import numpy as np
import pytest

from ipir_mujoco import registry
from ipir_mujoco.analytic import ParameterError, RobotParams
from ipir_mujoco.core.pipe import ARM_SHARE, SCRUB_FLOOR, WHEEL_SHARE, leg_direction, lift_check
from ipir_mujoco.core.route import route_from_tables
from ipir_mujoco.engine.builders.model import MOTOR, SolverSettings, dof_address, drive_control, qpos_address
from ipir_mujoco.engine.loop.monitor import RESIDUAL_TOL
from ipir_mujoco.engine.builders.wheels_model import (ROW_TIMES, STEER_STOP, build_wheels_model, leg_names,
                                                      leg_preload, leg_stiffness, sag, set_wheels_state, trail,
                                                      wheels_timestep)
from ipir_mujoco.engine.controllers.wheels import WheelRatchet, leg_press
from ipir_mujoco.engine.run.wheel_skids import TOLERANCE, estimate, skid_floor, skid_resolution

from cli_run import run_cli

CRUISE = RobotParams(drive="motor", mu_wall=0.5)  # F_n = 50 N, grip 25 N per module
RISER = RobotParams(drive="motor", mu_wall=0.18, incline=90.0)  # grip 9 N per module against a weight of 9.81 N


def by_hand(p: RobotParams, dt: float | None = None):
    model = build_wheels_model(p, None if dt is None else SolverSettings(timestep=dt))
    data = mujoco.MjData(model)
    set_wheels_state(model, data, p)
    data.ctrl[model.actuator(MOTOR).id] = drive_control(p)
    mujoco.mj_forward(model, data)
    return model, data, WheelRatchet(model, data, p)


def contact_forces(model, data, p) -> np.ndarray:
    """Each leg's wheel's contact normal force [N] (mj_contactForce), shape (2, 2 wheel_legs), rear first."""
    legs = leg_names(p)
    where = {model.geom(n + "_wheel").id: (i, j) for i, names in enumerate(legs) for j, n in enumerate(names)}
    out = np.zeros((2, len(legs[0])))
    force = np.zeros(6)
    for c in range(data.ncon):
        g = data.contact.geom[c]
        key = where.get(int(g[0]), where.get(int(g[1])))
        if key is not None:
            mujoco.mj_contactForce(model, data, c, force)
            out[key] += force[0]
    return out


def test_the_compiled_model_holds_the_parameters():
    p = RobotParams(F_n1=40.0, F_n2=60.0, F_r1=1.0, F_r2=2.0, mu_wall=0.6, wheel_radius=0.02, pipe_diameter=0.2,
                    wheel_legs=4, suspension_travel=0.004, ring_spacing=0.12)
    m = build_wheels_model(p)
    legs = leg_names(p)
    for i, names in enumerate(legs):
        assert len(names) == 2 * 4  # two rings of wheel_legs
        arms = [m.joint(n + "_arm").id for n in names]
        # each leg's spring on the wall (slide at 0): stiffness * springref = its preload; together the module's F_n
        preload = [m.jnt_stiffness[j] * m.qpos_spring[m.jnt_qposadr[j]] for j in arms]
        assert sum(preload) == pytest.approx((p.F_n1, p.F_n2)[i], rel=1e-12)
        assert all(m.qpos_spring[m.jnt_qposadr[j]] == pytest.approx(p.suspension_travel) for j in arms)
        hubs = [dof_address(m, n + "_hub") for n in names]
        assert sum(m.dof_frictionloss[h] for h in hubs) / p.wheel_radius == pytest.approx((p.F_r1, p.F_r2)[i],
                                                                                             rel=1e-12)
        xs = sorted({round(float(m.body(n + "_arm").pos[0]), 12) for n in names})
        assert xs == pytest.approx([-0.06, 0.06])  # the two rings, ring_spacing apart about the module's joint
        for n in names:
            g = m.geom(n + "_wheel")
            assert g.size[0] == p.wheel_radius and g.friction[0] == p.mu_wall and g.condim[0] == 3
            # the steer hinge: about the leg, its axis meeting the wall the trail e ahead of the wheel's contact,
            # its spring C e with C = cornering_coefficient x the leg's preload (the side force C alpha at the trail)
            steer, arm = m.joint(n + "_steer"), m.joint(n + "_arm")
            e, P = trail(p), (p.F_n1, p.F_n2)[i] / 8
            assert m.jnt_stiffness[steer.id] == pytest.approx(p.cornering_coefficient * P * e, rel=1e-12)
            assert m.jnt_axis[steer.id] == pytest.approx(m.jnt_axis[arm.id], abs=1e-12)
            assert m.jnt_pos[steer.id] == pytest.approx(np.array([e, 0, 0]) + p.wheel_radius * m.jnt_axis[arm.id],
                                                        abs=1e-12)
            assert m.dof_damping[steer.dofadr[0]] == 0.0 and m.jnt_range[steer.id][1] == STEER_STOP
    # rigid wheels, or unlimited grip: no steer hinges (the model before them, joint for joint)
    for rigid in (p.replace(cornering_coefficient=None), p.replace(mu_wall=None)):
        fixed = build_wheels_model(rigid)
        assert not any(fixed.joint(j).name.endswith("_steer") for j in range(fixed.njnt))
        assert fixed.nv == m.nv - 2 * len(legs[0])
    # the legs are part of their module's mass: module 1 + crank + rod, module 2
    assert m.body_subtreemass[m.body("rear_module").id] == pytest.approx(p.m1 + p.rod_mass, rel=1e-12)
    assert m.body_subtreemass[m.body("front_module").id] == pytest.approx(p.m2, rel=1e-12)
    assert m.opt.cone == mujoco.mjtCone.mjCONE_ELLIPTIC
    # the contacts' and limits' time constants are seconds of the model, the same whatever the step; the loop's
    # pin, a rigid joint, follows the step (2 steps, the slide model's rule)
    for dt in (ROW_TIMES.shortest() / 2, ROW_TIMES.shortest() / 8):
        m = build_wheels_model(p, SolverSettings(timestep=dt))
        assert m.eq_solref[m.equality("rod_to_front").id][0] == pytest.approx(2 * dt, rel=1e-12)
        assert m.jnt_solref[m.joint(legs[0][0] + "_hub").id][0] == ROW_TIMES.limit
        assert m.geom_solref[m.geom(legs[0][0] + "_wheel").id][0] == ROW_TIMES.contact
    with pytest.raises(ParameterError, match="timestep"):  # MuJoCo's floor: two steps per time constant
        build_wheels_model(p, SolverSettings(timestep=ROW_TIMES.shortest()))
    # only the hubs have friction
    assert set(np.flatnonzero(m.dof_frictionloss)) == {dof_address(m, n + "_hub") for names in legs for n in names}


@pytest.mark.parametrize("bad,word", [
    (dict(pipe_diameter=0.09), "pipe_diameter"), (dict(wheel_radius=0.041), "wheel_radius"),
    (dict(wheel_legs=2), "wheel_legs"), (dict(wheel_legs=3.5), "wheel_legs"),
    (dict(suspension_travel=0.02), "suspension_travel"), (dict(F_n1=0.0), "F_n1"),
])
def test_a_robot_that_does_not_fit_its_pipe_is_refused(bad, word):
    with pytest.raises(ParameterError, match=word) as caught:
        build_wheels_model(RobotParams(**bad))
    assert "\n" not in str(caught.value)


@pytest.mark.parametrize("legs", [3, 4])
def test_weight_sags_the_module_and_its_press_stays_F_n(legs):
    """A robot at rest in a horizontal pipe: its weight sags each module on its legs' springs by the closed
    form's m g / (n k), the legs under it press harder and those above less, and the module's legs together
    still press with F_n (read from MuJoCo's contact forces): the outward directions of evenly spaced legs sum
    to zero, so a linear spring's gain below is another's loss above. The least-pressed leg's force is the
    closed-form lift-off check's under weight alone. (Equal modules on equal springs: the loop, which holds both
    modules' ends level, then shares no weight between them but the rod's, 1 % of a module's.)"""
    p = RobotParams(M=0.0, m1=1.5, m2=1.5, F_n1=40.0, F_n2=40.0, wheel_legs=legs)
    m, d, ctl = by_hand(p)
    for _ in range(int(0.1 / m.opt.timestep)):  # 0.1 s: hundreds of the contacts' time constants
        ctl.before_step()
        mujoco.mj_step(m, d)
    forces = contact_forces(m, d, p)
    press, _ = leg_press(m, p, d.qpos[None, :])
    check = lift_check(p)
    for i in (0, 1):
        F_n = (p.F_n1, p.F_n2)[i]
        # to first order in the sag delta; to second, a wheel on the round wall reaches delta^2 (1 - u_z^2) /
        # (2 rho) less far out than its leg's line (rho the wheel centre's radius), which adds delta^2 / (4 rho
        # travel) of F_n whatever the number of legs: 1 % here, held to 1e-3 of F_n
        delta, rho = sag(p, i), 0.5 * p.pipe_diameter - p.wheel_radius
        expected = F_n * (1 + delta ** 2 / (4 * rho * p.suspension_travel))
        assert expected > 1.005 * F_n
        assert forces[i].sum() == pytest.approx(expected, rel=1e-3)
        assert press[0, i].sum() == pytest.approx(expected, rel=1e-3)  # the springs' press is the contacts'
        # each leg's: its spring's press plus its arm's and wheel's weight along its line (16.5 g each here:
        # core.wheel_legs.ARM_SHARE, WHEEL_SHARE; leg 0 down), the wall's normal off that line by delta / rho at most
        legs_down = np.array([-leg_direction(k, legs)[2] for k in range(legs)] * 2)
        own = (ARM_SHARE + WHEEL_SHARE) * (p.m1, p.m2)[i] * p.g * legs_down
        assert np.allclose(press[0, i] + own, forces[i], rtol=delta / rho, atol=1e-3 * F_n)
        assert forces[i].max() > 1.2 * leg_preload(p, i)  # the weight really is on the lower legs
        # the module sits lower by the closed form's sag, and its least-pressed leg presses as the closed form's
        # (the rod's weight, 1 % of a module's, is on top: within 2 % of the sag)
        z = -d.qpos[qpos_address(m, ("rear_vertical", "front_vertical")[i])]
        assert z == pytest.approx(sag(p, i), rel=0.02)
        assert press[0, i].min() == pytest.approx(check["weight_press_n"][i], abs=0.02 * (F_n / 2 - press[0, i].min()))


def test_the_wheels_roll_against_F_r_and_stay_in_their_cone():
    """Stepped by hand through the default motor's first 0.3 s (both modules roll and stand in turn)."""
    p = CRUISE
    m, d, ctl = by_hand(p)
    worst_cone, rolled, stood = 0.0, [False, False], [False, False]
    force = np.zeros(6)
    for _ in range(int(0.3 / m.opt.timestep)):
        ctl.before_step()
        mujoco.mj_step(m, d)
        for c in range(d.ncon):
            mujoco.mj_contactForce(m, d, c, force)
            worst_cone = max(worst_cone, np.hypot(force[1], force[2]) - p.mu_wall * force[0])
        states, _ = ctl.states()
        for i in (0, 1):
            if states[i] == 1:  # rolling: every hub's friction row at its bound, together F_r at the wall
                rows = [d.efc_force[d.ne + k] for k, _ in ctl.friction_rows[i]]
                assert sum(rows) / p.wheel_radius == pytest.approx(-(p.F_r1, p.F_r2)[i], rel=1e-9)
                rolled[i] = True
            stood[i] |= states[i] == 0
    assert worst_cone <= 1e-9 * p.F_n1
    assert all(rolled) and all(stood)


def test_each_module_starts_at_its_own_sag_with_the_loop_closed():
    """A heavy module on a light press sags further than its partner: each starts at its own closed-form sag (at
    most to its lower legs' stops), the rod tilted out of the crank's plane on its cross pin by asin of the height
    difference over L, and the loop's pin closed (no gap): a common start height dropped the heavier module at
    the first step, and its upper wheels lifted as it bounced (design 5 of the agreement benchmark, 3.46 kg on
    9 N at -79 deg, before: a wheel off 0.030 s)."""
    from ipir_mujoco.engine.builders.model import pin_offset

    p = RobotParams(m1=3.0, F_n1=40.0, m2=0.5, F_n2=60.0, incline=30.0, phi0=2.0)
    m = build_wheels_model(p)
    d = mujoco.MjData(m)
    set_wheels_state(m, d, p)
    heights = [-d.qpos[qpos_address(m, name)] for name in ("rear_vertical", "front_vertical")]
    assert heights == pytest.approx([sag(p, 0), sag(p, 1)], rel=1e-12) and heights[0] > 3 * heights[1]
    site, front, offset = pin_offset(m, d)
    assert np.abs(d.site_xpos[site] - d.xpos[front] - offset).max() < 1e-12
    assert d.qpos[qpos_address(m, "rod_tilt")] == pytest.approx(math.asin((heights[1] - heights[0]) / p.L), rel=1e-12)


def test_every_wheel_starts_on_its_round_wall_however_far_its_module_sags():
    """A module sagged by delta moves its upper wheels delta u_y along the round wall as well as delta u_z towards
    it: each arm reaches the wall exactly (the sphere's contact at the initial state's seat, 1e-8 m, not the
    (delta u_y)^2 / (2 reach) = 0.3 mm the straight-line reach left at a 7 mm sag), so no contact kicks an arm off
    at the first steps and the first 20 ms (half a period of an arm on its spring here) slide no wheel across the
    wall by more than the contacts' softness (before: 1.25 mm of slide at the start of agreement design 107 of
    seed 3, which the scrub check had no load for)."""
    from ipir_mujoco.engine.builders.wheels_model import SEAT

    p = RobotParams(m1=0.5, m2=0.63, F_n1=30.0, F_n2=7.0, incline=-35.4, mu_wall=0.89, drive="motor",
                    M_stall=0.108, omega_noload=25.3)
    m, d, ctl = by_hand(p, 1e-4)
    assert sag(p, 1) > 6e-3
    wheels = {m.geom(n + "_wheel").id for names in leg_names(p) for n in names}
    dists = [d.contact.dist[c] for c in range(d.ncon) if {int(g) for g in d.contact.geom[c]} & wheels]
    assert len(dists) == len(wheels) and max(abs(x + SEAT) for x in dists) < 1e-12
    start, swing = leg_press(m, p, d.qpos[None, :])[0][0, 1], 0.0
    for _ in range(200):
        ctl.before_step()
        mujoco.mj_step(m, d)
        swing = max(swing, np.abs(leg_press(m, p, d.qpos[None, :])[0][0, 1] - start).max())
    # kicked, the upper arms swung by 0.47 of their preload P within 7 ms (0.31 N of 1.17 N rising to 0.99 N);
    # seated, the legs follow only the module's first response to its drive and its rod (0.02 P): 0.1 P parts them
    assert swing < 0.1 * leg_preload(p, 1)


def test_the_wheeled_run_reports_its_press_grip_and_the_lift_off_check():
    run = registry.run("mujoco-wheels", CRUISE, 0.2, dt_out=1e-3)
    s = run.summary
    # the springs' press, mean over the run: F_n to the legs' rocking (a few tenths of a percent)
    assert s["press1_n"] == pytest.approx(CRUISE.F_n1, rel=1e-2) and s["press2_n"] == pytest.approx(CRUISE.F_n2,
                                                                                                   rel=1e-2)
    # the grip as MuJoCo has it: mu_wall times that press (the equations' mu_wall F_n beside it); none unlimited
    assert s["grip1_n"] == pytest.approx(CRUISE.mu_wall * s["press1_n"], rel=1e-12)
    assert s["grip2_n"] == pytest.approx(CRUISE.mu_wall * s["press2_n"], rel=1e-12)
    assert s["wheel_off_s"] == 0.0 and s["lift_predicted"] is False and s["unpredicted"] is None
    assert registry.run("mujoco-wheels", RobotParams(), 0.02, dt_out=1e-3).summary["grip1_n"] is None
    # a press below the weight: the upper legs lift, and the closed form says so
    light = RobotParams(drive="motor", mu_wall=0.8, F_n1=8.0, F_n2=8.0)
    lifted = registry.run("mujoco-wheels", light, 0.2, dt_out=1e-3).summary
    assert lift_check(light)["lift_predicted"] and lifted["lift_predicted"]
    assert lifted["wheel_off_s"] > 0.1 and lifted["unpredicted"] is None
    # a module resting on its lower legs' stops presses harder than F_n: its grip is above mu_wall F_n
    assert lifted["grip1_n"] > light.mu_wall * light.F_n1


def test_the_wheeled_run_reports_the_sideways_grip_check_beside_its_rings_slide():
    """The summary's sideways checks (core.wheel_checks.check on the run's own loads: the loop's pin force, the
    motor's couple, each module's grip use) beside MuJoCo's outcome. In the cruise (no skid, no wheel off) every
    wheel grips: the largest ring load stays within its wheels' sideways friction and only the contacts' softness
    moves the rings (0.008 mm in 1 s measured), far below the 1 mm that counts as a slide; with mu_wall 0.2 under
    a constant 0.3 N m the couple alone, 3 N per ring, is beyond the sqrt(3) mu_wall P = 2.9 N module 1's wheels
    hold along a leg, and the rings slide millimetres (5.2 mm in 0.3 s measured)."""
    s = registry.run("mujoco-wheels", CRUISE, 0.2, dt_out=1e-3).summary
    assert s["side_use1"] < 1 and s["side_use2"] < 1 and s["scrub_predicted"] is False
    assert s["slip1_m"] < 1e-6 and s["wheel_off_s"] == 0.0
    assert max(s["across1_m"], s["across2_m"]) < 0.1 * SCRUB_FLOOR and s["scrubbed"] is False
    low = RobotParams(drive="torque", M=0.3, mu_wall=0.2)
    s = registry.run("mujoco-wheels", low, 0.3, dt_out=1e-3, timestep=1e-4).summary
    assert s["side_use1"] > 1 and s["scrub_predicted"] is True
    assert s["across1_m"] > SCRUB_FLOOR and s["scrubbed"] is True
    from ipir_mujoco.cli.simulate import wall_lines  # what simulate prints for it without --json

    printed = "\n".join(wall_lines(s, low))
    assert "(slid: the wheels scrubbed)" in printed and "a slide predicted" in printed
    assert f"{1e3 * s['across1_m']:.3g} mm" in printed and f"check {s['side_use1']:.3g} / " in printed
    assert f"grip {s['grip1_n']:.4g} N" in printed and f"mu_wall F_n {0.2 * low.F_n1:.4g} N" in printed
    # along a route the check runs on the run's own loads in each module's frame; the rings' path across the
    # pipe is not the outcome there (the pipe turns under them: the wheels' own slide, slid1/2, is)
    along = registry.run("mujoco-wheels", CRUISE, 0.05, dt_out=1e-3, route=route_from_tables(
        [{"kind": "straight", "length": 1.0}])).summary
    assert "side_use1" in along and all(key not in along for key in ("across1_m", "scrubbed"))


def test_a_lift_the_checks_did_not_predict_is_said_in_the_summary_and_on_stderr(capsys, monkeypatch):
    """``unpredicted``: a wheel off its wall with lift_predicted false, in words, and simulate's one line on stderr
    (forced here: the check made to predict nothing over a run whose press is below its weight); nothing said
    where the check predicted the lift."""
    from ipir_mujoco.core import wall_summary

    argv = ("simulate", "--engine", "mujoco", "--mujoco-model", "wheels", "--t-end", "0.1", "--timestep", "1e-4",
            "--set", "mu_wall=0.8", "--set", "F_n1=8", "--set", "F_n2=8")
    code, _, err = run_cli(capsys, *argv)
    assert code == 0 and "note:" not in err  # predicted: nothing said
    check = wall_summary.check
    monkeypatch.setattr(wall_summary, "check", lambda *a, **k: {**check(*a, **k), "lift_predicted": False})
    code, out, err = run_cli(capsys, *argv)
    lines = err.strip().splitlines()
    assert code == 0 and len([line for line in lines if "note:" in line]) == 1
    assert "a wheel was off its wall" in err and "with no lift predicted" in err
    assert "not predicted: a wheel was off its wall" in out


@pytest.mark.slow
def test_a_fast_crank_keeps_its_energy_at_a_fine_step():
    """Under a constant 1 N m the crank reaches 100 rad/s in 1 s and the automatic step is 1.25e-5 s. The loop's
    pin, held at the contacts' 2e-4 s, gained energy there (first order in the step: -3.3 % of the drive's work
    in 1.5 s, measured, -14.5 J); at two steps, the slide model's rule, the energy closes to the monitor's
    tolerance."""
    run = registry.run("mujoco-wheels", RobotParams(M=1.0), 1.0, dt_out=1e-3)
    assert run.settings["timestep"] < 0.5 * wheels_timestep()
    assert abs(run.accuracy["residual_ratio"]) <= RESIDUAL_TOL


@pytest.mark.slow
def test_straight_pipe_cruise_speed_matches_the_analytic_finite_grip_model():
    """Default motor, mu_wall 0.5, F_n 50 N, to the periodic steady state. With rigid wheels (each module held
    square to the pipe by its wheels' friction, the equations' rails) what the wheels add to the analytic model's
    mechanism is their rolling inertia: a rolling module carries its wheels' J / R^2 = m_w / 2 each on top of its
    mass. Its effect on the steady speed is measured with the analytic model itself (both modules heavier by that
    much), and MuJoCo's own accuracy target (the monitor's RESIDUAL_TOL) comes on top. The default, steer-compliant
    wheels also let module 1 yaw under the motor's reaction couple while it rolls (its wheels' cornering
    compliance, the legs' springs), a degree of freedom the rails lack that speeds the robot up (mjcf/README.md,
    "The wheels' side force": +0.20 %); it is held to the accuracy the wheeled model states for travel
    (wheel_skids.TOLERANCE, 0.2 %) on top."""
    analytic = registry.run("analytic-unilateral", CRUISE, 30.0, dt_out=1e-3, until_steady=True)
    extra = 2 * int(CRUISE.wheel_legs) * WHEEL_SHARE / 2
    heavier = registry.run("analytic-unilateral", CRUISE.replace(m1=CRUISE.m1 * (1 + extra),
                                                                 m2=CRUISE.m2 * (1 + extra)),
                           30.0, dt_out=1e-3, until_steady=True)
    v_a = analytic.summary["steady_speed_m_s"]
    inertia_effect = abs(heavier.summary["steady_speed_m_s"] / v_a - 1)
    tolerance = inertia_effect + RESIDUAL_TOL
    assert tolerance < 0.005
    for p, allowed in ((CRUISE.replace(cornering_coefficient=None), tolerance),
                       (CRUISE, tolerance + TOLERANCE["steady_speed_m_s"])):
        wheels = registry.run("mujoco-wheels", p, 10.0, dt_out=1e-3, until_steady=True)
        assert abs(wheels.summary["steady_speed_m_s"] / v_a - 1) <= allowed
        assert wheels.accuracy["skid_check"] == "no skid"  # ample grip: no skid


@pytest.mark.slow
def test_a_riser_with_grip_below_the_weight_skids_down_as_the_analytic_model_does():
    """Both modules skid down the riser. How far: within the acceptance's 5 % + 2 mm of the analytic model's
    Coulomb skid, and MuJoCo's own discretization error (the change on halving the step) well inside that: the
    skid check's last halving, from twice the kept step to it, moved each skid by less than 1 % of itself (at
    first order the kept run is nearer the converged length than that by as much again)."""
    t_end = 0.4
    analytic = registry.run("analytic-unilateral", RISER, t_end, dt_out=1e-3)
    run = registry.run("mujoco-wheels", RISER, t_end, dt_out=1e-3)
    last = run.settings["skid_check"][-1]
    assert run.accuracy["skid_check"] == "verified" and last["half"] == run.settings["timestep"]
    for k in (1, 2):
        s_a, s_w = (r.summary[f"slip{k}_m"] for r in (analytic, run))
        assert s_a > 0.1 and s_w > 0.1  # both skid back, a long way
        assert abs(s_w - s_a) <= 0.05 * s_a + 2e-3
        # the check records d = (coarse - kept) / (the larger skid + R), R the resolution over its accuracy
        # (wheel_skids.WheelSkids.differences): the coarse run's skid back from it
        d, res = last["differences"][f"slip{k}_m"], skid_resolution(run, k) / TOLERANCE[f"slip{k}_m"]
        coarse = (s_w + d * res) / (1 - d) if d >= 0 else s_w + d * (s_w + res)
        assert abs(coarse - s_w) <= 0.01 * s_w


def test_a_wheeled_run_that_skids_is_kept_at_the_step_its_skid_check_reached():
    """A wheeled run whose wheels skid is rerun at half its step until its figures are within the model's accuracy
    (engine/run/wheel_skids.py): registry.timestep is the step it starts from (the cruise's 1e-4 s), the run kept is
    that step halved as its check records (at least twice), the same run as one given that step, and the summary's
    text says the step."""
    t_end = 0.1
    start = registry.timestep("mujoco-wheels", RISER, t_end, 1e-3)
    assert start == registry.timestep("mujoco-wheels", CRUISE, t_end, 1e-3) == wheels_timestep()
    run = registry.run("mujoco-wheels", RISER, t_end, dt_out=1e-3)
    history = run.settings["skid_check"]
    assert len(history) >= 2 and run.settings["timestep"] == start / 2 ** len(history)
    assert run.accuracy["skid_check"] in ("verified", "failed")
    error = math.inf if history[-1]["difference"] is None else history[-1]["difference"]  # None: JSON's inf
    assert (run.accuracy["skid_check"] == "verified") == (error <= TOLERANCE[history[-1]["figure"]])
    given = registry.run("mujoco-wheels", RISER, t_end, dt_out=1e-3, timestep=run.settings["timestep"])
    for key in ("x1_final", "x2_final", "slip1_m", "slip2_m", "revolutions"):
        assert given.summary[key] == run.summary[key]  # deterministic: the step it kept is the step it took
    assert given.accuracy["skid_check"] == "not verified: timestep given"
    json.dumps(run.to_json_dict(), allow_nan=False)


def test_a_cruise_that_does_not_skid_keeps_the_default_step():
    """Rigid wheels give back only their hubs' ratchets' give (1/75 of the check's floor here); steer-compliant
    ones also their steer's: a held wheel steered by its ring's side load swings back on its trail by about
    e delta^2 / 2 (4.7 um of module 2's 20 um floor measured), below the floor: no skid either way."""
    for p, share in ((CRUISE.replace(cornering_coefficient=None), 0.1), (CRUISE, 1.0)):
        run = registry.run("mujoco-wheels", p, 0.2, dt_out=1e-3)
        assert run.accuracy["skid_check"] == "no skid" and run.settings["timestep"] == wheels_timestep()
        assert all(run.summary[f"slip{k}_m"] < share * skid_floor(run, k) for k in (1, 2))


@pytest.mark.parametrize("before, last, expected", [
    (2e-3, 1e-3, 1e-3),  # first order (q = 1/2): the finer run's error is the last difference
    (-9e-3, -3e-3, 1.5e-3),  # q = 1/3: the rest of the geometric series, 3e-3 (1/3) / (2/3)
    (2e-4, -1e-3, 2e-3),  # a sign change: no trend, both must lie within ACCEPT (1/2) of the accuracy
    (1e-4, 3e-4, 6e-4),  # growing: the same
    (0.0, 0.0, 0.0),
    (math.inf, 1e-3, math.inf),  # a figure that had no difference (one run steady, the other not): no estimate
])
def test_the_skid_checks_error_estimate(before, last, expected):
    assert estimate(before, last) == pytest.approx(expected, rel=1e-12, abs=1e-15)


def test_unlimited_grip_never_skids():
    """A heavy robot pressed lightly up a riser under a strong motor: with unlimited grip nothing skids (its
    modules stand on their locked wheels whatever the load)."""
    p = RobotParams(drive="motor", M_stall=2.0, m1=4.0, m2=4.0, F_n1=5.0, F_n2=5.0, incline=90.0)
    run = registry.run("mujoco-wheels", p, 0.3, dt_out=1e-3)
    assert run.summary["slip1_m"] < 1e-4 and run.summary["slip2_m"] < 1e-4
    assert run.summary["revolutions"] > 0.2


def test_simulate_runs_the_wheeled_model_and_refuses_what_it_does_not_have(capsys):
    code, out, err = run_cli(capsys, "simulate", "--engine", "mujoco", "--mujoco-model", "wheels", "--drive", "motor",
                             "--set", "mu_wall=0.8", "--t-end", "0.1", "--json")
    assert code == 0 and err == ""
    record = json.loads(out)
    assert record["settings"]["mujoco_model"] == "wheels"
    s = record["summary"]
    assert s["revolutions"] > 0.1 and s["slip1_m"] == 0.0
    assert {"press1_n", "press2_n", "wheel_off_s"} <= set(s)
    for argv, word in ((("--engine", "mujoco", "--mujoco-model", "wheels", "--mujoco-clutch", "lock"), "ratchet"),
                       (("--engine", "mujoco", "--mujoco-model", "wheels", "--set", "clutch_stiffness=1e5"), "rigid"),
                       (("--engine", "mujoco", "--mujoco-model", "wheels", "--set", "pipe_diameter=0.1"), "2 r")):
        code, out, err = run_cli(capsys, "simulate", *argv)
        assert code == 2 and word in err and len(err.strip().splitlines()) == 1


def test_the_closed_form_rod_side_force_and_leg_geometry():
    """The rod's side force T |sin beta| / (r |sin(phi - beta)|) over a turn, sampled, peaks at the closed form's
    T / (L - r) (the inner dead centre); the legs' outward directions are unit vectors summing to zero, leg 0
    down."""
    from ipir_mujoco.core.pipe import rod_side_force

    r, L, T = 0.05, 0.2, 1.0
    phi = np.linspace(1e-3, math.pi - 1e-6, 20001)
    beta = np.arcsin(-r * np.sin(phi) / L)
    side = T * np.abs(np.sin(beta)) / (r * np.abs(np.sin(phi - beta)))
    assert side.max() <= rod_side_force(T, r, L) * (1 + 1e-9)
    assert side.max() == pytest.approx(rod_side_force(T, r, L), rel=1e-4)  # approached at the dead centre
    for n in (3, 4, 5):
        u = np.array([leg_direction(k, n) for k in range(n)])
        assert np.allclose(np.linalg.norm(u, axis=1), 1.0) and np.allclose(u.sum(axis=0), 0.0, atol=1e-12)
        assert np.allclose(u.T @ u, np.diag([0.0, n / 2, n / 2]))  # the ring's stiffness n k / 2 either way
        assert u[0] == pytest.approx([0.0, 0.0, -1.0])
    assert leg_stiffness(RobotParams(), 0) == pytest.approx(50.0 / 6 / 0.005)


def test_the_closed_form_bend_fit():
    """l_max = 2 sqrt((R + D/2)^2 - (R - D/2 + w)^2), checked against its own geometry: the rectangle of that
    length with its inner side on the inner wall's tangent has its outer corners exactly on the outer wall."""
    from ipir_mujoco.core.pipe import bend_max_length

    D, R, w = 0.16, 0.24, 0.06
    length = bend_max_length(w, R, D)
    corner = np.hypot(R - D / 2 + w, length / 2)  # distance of an outer corner from the bend's centre
    assert corner == pytest.approx(R + D / 2, rel=1e-12)
    assert bend_max_length(D, R, D) == 0.0  # a module as wide as the pipe never turns rigidly
    assert bend_max_length(w, 100.0, D) > 10 * length  # a gentle bend passes long modules
    with pytest.raises(ParameterError, match="radius"):
        bend_max_length(w, 0.05, D)
