"""The wheeled MuJoCo model (``--mujoco-model wheels``): MuJoCo's own arrays say the wheels press with F_n, roll
against F_r and never pull outside their friction cone; in a straight pipe it crawls as the analytic
finite-grip model does, and skids in a riser as it does.

Tolerances are derived where they are used: an arm's static balance (spring against contact), the friction
cone's own bound, the wheels' rolling inertia (the one mass term the analytic model lacks) plus the
MuJoCo monitor's 0.1 % target, and MuJoCo's discretization error bounded by the change on halving its step.
"""

from __future__ import annotations

import json

import mujoco
import numpy as np
import pytest

from ipir_mujoco import registry
from ipir_mujoco.analytic import ParameterError, RobotParams
from ipir_mujoco.engine.model import MOTOR, SolverSettings, dof_address, drive_control, qpos_address
from ipir_mujoco.engine.monitor import RESIDUAL_TOL
from ipir_mujoco.engine.wheels import WheelRatchet
from ipir_mujoco.engine.wheels_model import (HUBS, WALLS, WHEEL_NAMES, WHEEL_SHARE, WHEELS_PER_MODULE,
                                             build_wheels_model, set_wheels_state)

from cli_run import run_cli

CRUISE = RobotParams(drive="motor", mu_wall=0.8)  # the acceptance case: F_n = 50 N, grip 40 N per module
RISER = RobotParams(drive="motor", mu_wall=0.18, incline=90.0)  # grip 9 N per module against a weight of 9.81 N


def by_hand(p: RobotParams, dt: float = 1e-4):
    model = build_wheels_model(p, SolverSettings(timestep=dt))
    data = mujoco.MjData(model)
    set_wheels_state(model, data, p)
    data.ctrl[model.actuator(MOTOR).id] = drive_control(p)
    mujoco.mj_forward(model, data)
    return model, data, WheelRatchet(model, data, p)


def module_contacts(model, data) -> tuple[np.ndarray, np.ndarray]:
    """Per module, the normal forces and tangential force magnitudes [N] of its contacts (mj_contactForce)."""
    owner = {model.geom(n + "_wheel").id: i for i, names in enumerate(WHEEL_NAMES) for n in names}
    normal, tangential = np.zeros(2), np.zeros(2)
    force = np.zeros(6)
    for c in range(data.ncon):
        con = data.contact[c]
        i = owner.get(int(con.geom[0]), owner.get(int(con.geom[1])))
        mujoco.mj_contactForce(model, data, c, force)
        normal[i] += force[0]
        tangential[i] += np.hypot(force[1], force[2])
    return normal, tangential


def test_the_compiled_model_holds_the_parameters():
    p = RobotParams(F_n1=40.0, F_n2=60.0, F_r1=1.0, F_r2=2.0, mu_wall=0.6, wheel_radius=0.02, pipe_diameter=0.2)
    m = build_wheels_model(p)
    for i, names in enumerate(WHEEL_NAMES):
        arms = [m.joint(n + "_arm").id for n in names]
        # each arm's spring at the wall (slide at 0): stiffness * springref, together the module's F_n
        preload = sum(m.jnt_stiffness[j] * m.qpos_spring[m.jnt_qposadr[j]] for j in arms)
        assert preload == pytest.approx((p.F_n1, p.F_n2)[i], rel=1e-12)
        hubs = [dof_address(m, n + "_hub") for n in names]
        assert sum(m.dof_frictionloss[h] for h in hubs) / p.wheel_radius == pytest.approx((p.F_r1, p.F_r2)[i], rel=1e-12)
        assert len(names) == WHEELS_PER_MODULE
        for n in names:
            g = m.geom(n + "_wheel")
            assert g.size[0] == p.wheel_radius and g.friction[0] == p.mu_wall and g.condim[0] == 3
    for k, name in enumerate(WALLS):
        assert m.geom(name).pos[1] == pytest.approx((0.1, -0.1)[k])
    # the wheels and arms are part of their module's mass: module 1 + crank + rod, module 2
    assert m.body_subtreemass[m.body("rear_module").id] == pytest.approx(p.m1 + p.rod_mass, rel=1e-12)
    assert m.body_subtreemass[m.body("front_module").id] == pytest.approx(p.m2, rel=1e-12)
    assert m.opt.cone == mujoco.mjtCone.mjCONE_ELLIPTIC and m.opt.noslip_iterations >= 10
    # only the hubs have friction, only the walls and wheels collide; every element is named
    assert set(np.flatnonzero(m.dof_frictionloss)) == {dof_address(m, n) for n in HUBS}
    for kind, count in ((mujoco.mjtObj.mjOBJ_BODY, m.nbody), (mujoco.mjtObj.mjOBJ_JOINT, m.njnt),
                        (mujoco.mjtObj.mjOBJ_GEOM, m.ngeom)):
        assert all(mujoco.mj_id2name(m, kind, i) for i in range(1 if kind == mujoco.mjtObj.mjOBJ_BODY else 0, count))


def test_a_robot_that_does_not_fit_its_pipe_is_refused():
    for bad, word in ((dict(pipe_diameter=0.09), "pipe_diameter"), (dict(wheel_radius=0.041), "wheel_radius")):
        with pytest.raises(ParameterError, match=word):
            build_wheels_model(RobotParams(**bad))
    with pytest.raises(ParameterError, match="wheels' hubs"):
        registry.from_flags("mujoco", None, "kinematic", None, "wheels")
    assert registry.from_flags("mujoco", None, None, None, "wheels").name == "mujoco-wheels"
    assert registry.from_flags("mujoco", None, None, None).name == "mujoco-lock"  # the slide model's default


def test_the_wheels_press_with_F_n_roll_against_F_r_and_stay_in_their_cone():
    """Stepped by hand through the default motor's first 0.4 s (both modules roll and stand in turn)."""
    p = CRUISE
    m, d, ctl = by_hand(p)
    k_arm = [[m.jnt_stiffness[m.joint(n + "_arm").id] for n in names] for names in WHEEL_NAMES]
    arm_q = [[qpos_address(m, n + "_arm") for n in names] for names in WHEEL_NAMES]
    arm_v = [[dof_address(m, n + "_arm") for n in names] for names in WHEEL_NAMES]
    across = [[dof_address(m, n) for n in (f"{module}_lateral", f"{module}_yaw")] for module in ("rear", "front")]
    carried = [WHEEL_SHARE * 2 * mass for mass in (p.m1, p.m2)]  # an arm with its wheel (ARM_SHARE = WHEEL_SHARE)
    reach = 0.1 + p.pipe_diameter / 2  # farthest wheel from its module's origin [m]
    worst_cone, rolled = 0.0, [False, False]
    for step in range(4000):
        ctl.before_step()
        mujoco.mj_step(m, d)
        normal, tangential = module_contacts(m, d)
        # each light arm's balance across the pipe: its contact presses with its spring's force k (springref - q)
        # less its mass times its acceleration across the pipe (there is no gravity across it), which is bounded
        # by the arm's own, its module's lateral and yaw accelerations (MuJoCo's qacc)
        for i in (0, 1):
            springs = sum(k * (m.qpos_spring[a] - d.qpos[a]) for k, a in zip(k_arm[i], arm_q[i]))
            lateral, yaw = (abs(d.qacc[v]) for v in across[i])
            spin = d.qvel[across[i][1]] ** 2  # the centripetal part of the yawing module's acceleration
            inertia = sum(carried[i] * (abs(d.qacc[v]) + lateral + (yaw + spin) * reach) for v in arm_v[i])
            # the arms slide along the module's y axis, the walls push along the pipe's: the springs' share
            # across the pipe is cos(yaw) of their force
            tilt = springs * (1 / np.cos(d.qpos[qpos_address(m, ("rear_yaw", "front_yaw")[i])]) - 1)
            # the step's forces are the state's before it, the springs read after it: they moved by k v dt
            moved = sum(k * abs(d.qvel[v]) * m.opt.timestep for k, v in zip(k_arm[i], arm_v[i]))
            assert abs(normal[i] - springs) <= inertia + abs(tilt) + moved + 1e-9 * p.F_n1
            assert abs(springs - (p.F_n1, p.F_n2)[i]) < 0.01 * p.F_n1  # the springs' give: 1 % of the preload
        # every contact inside its friction cone (the cone's own bound, to round-off)
        for c in range(d.ncon):
            f = np.zeros(6)
            mujoco.mj_contactForce(m, d, c, f)
            worst_cone = max(worst_cone, np.hypot(f[1], f[2]) - p.mu_wall * f[0])
        states, _ = ctl.states()
        for i in (0, 1):
            if states[i] == 1:  # rolling: every hub's friction row at its bound, together F_r at the wall
                rows = [d.efc_force[d.ne + k] for k in ctl.friction_rows[i]]
                assert sum(rows) / p.wheel_radius == pytest.approx(-(p.F_r1, p.F_r2)[i], rel=1e-9)
                rolled[i] = True
    assert worst_cone <= 1e-9 * p.F_n1
    assert all(rolled)


def test_straight_pipe_cruise_speed_matches_the_analytic_finite_grip_model():
    """The acceptance case: default motor, mu_wall 0.8, F_n 50 N, to the periodic steady state.

    What the wheels add to the analytic model's mechanism is their rolling inertia: a rolling module carries
    its wheels' J / R^2 = m_w / 2 each on top of its mass. Its effect on the steady speed is measured here with
    the analytic model itself (both modules heavier by that much), and MuJoCo's own accuracy target (the
    monitor's RESIDUAL_TOL, 0.1 % of the motion) comes on top; the 1 % of the acceptance is the outer bound."""
    analytic = registry.run("analytic-unilateral", CRUISE, 30.0, dt_out=1e-3, until_steady=True)
    extra = WHEELS_PER_MODULE * WHEEL_SHARE / 2
    heavier = registry.run("analytic-unilateral", CRUISE.replace(m1=CRUISE.m1 * (1 + extra),
                                                                 m2=CRUISE.m2 * (1 + extra)),
                           30.0, dt_out=1e-3, until_steady=True)
    v_a = analytic.summary["steady_speed_m_s"]
    inertia_effect = abs(heavier.summary["steady_speed_m_s"] / v_a - 1)
    # 1e-4 s: the automatic step for the motor; the convergence study (mjcf/README.md) shows the cruise converged
    # there (no skid), so the test takes it rather than the finite-grip cap meant for skids
    wheels = registry.run("mujoco-wheels", CRUISE, 10.0, dt_out=1e-3, until_steady=True, timestep=1e-4)
    v_w = wheels.summary["steady_speed_m_s"]
    tolerance = inertia_effect + RESIDUAL_TOL
    assert tolerance < 0.01
    assert abs(v_w / v_a - 1) <= tolerance
    assert wheels.summary["slip1_m"] < 1e-6 and wheels.summary["slip2_m"] < 1e-6  # ample grip: no skid
    assert wheels.accuracy["ok"]


def test_a_riser_with_grip_below_the_weight_skids_down_as_the_analytic_model_does():
    """Both modules skid down the riser; how far, to within MuJoCo's discretization error, bounded by the
    change of the skid when the step is doubled (its error falls faster than linearly with the step: the
    convergence study in mjcf/README.md)."""
    t_end = 0.5
    analytic = registry.run("analytic-unilateral", RISER, t_end, dt_out=1e-3)
    fine = registry.run("mujoco-wheels", RISER, t_end, dt_out=1e-3)  # the automatic step: the skid cap
    assert fine.settings["timestep"] <= 2.5e-5
    coarse = registry.run("mujoco-wheels", RISER, t_end, dt_out=1e-3, timestep=2 * fine.settings["timestep"],
                          accuracy="warn")  # at twice the step its energy residual grazes the monitor's tolerance
    for k in (1, 2):
        s_a, s_w, s_c = (run.summary[f"slip{k}_m"] for run in (analytic, fine, coarse))
        assert s_a > 0.1 and s_w > 0.1  # both skid back, a long way
        assert fine.summary[f"x{k}_final"] < 0 and analytic.summary[f"x{k}_final"] < 0
        assert abs(s_w - s_a) <= abs(s_c - s_w)
    assert fine.accuracy["ok"]


def test_render_and_the_viewer_draw_the_pipe_walls_and_the_wheels():
    """What render and the viewer draw is the wheeled model itself: its walls and wheels are visible geoms, and
    the viewer steps it with the engine's loop (no screen needed for either check)."""
    from ipir_mujoco.cli.view import ViewedRobot
    from ipir_mujoco.video import VideoSettings, _render_model

    drawn = _render_model(CRUISE, VideoSettings(), wheeled=True)
    for name in WALLS + tuple(n + "_wheel" for names in WHEEL_NAMES for n in names):
        assert drawn.geom_rgba[drawn.geom(name).id][3] > 0  # drawn, not transparent
    robot = ViewedRobot(CRUISE, model="wheels", settings=SolverSettings(timestep=1e-4))
    assert isinstance(robot.controller, WheelRatchet)
    robot.step(500)
    assert robot.data.qpos[qpos_address(robot.model, "crank_hinge")] > 0.1  # the crank turns
    with pytest.raises(ParameterError, match="wheels' hubs"):
        ViewedRobot(CRUISE, "kinematic", model="wheels")


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


def test_simulate_runs_the_wheeled_model_and_refuses_what_it_does_not_have(capsys):
    import json

    code, out, err = run_cli(capsys, "simulate", "--engine", "mujoco", "--mujoco-model", "wheels", "--drive", "motor",
                             "--set", "mu_wall=0.8", "--t-end", "0.2", "--timestep", "1e-4", "--json")
    assert code == 0 and err == ""
    record = json.loads(out)
    assert record["settings"]["mujoco_model"] == "wheels" and record["settings"]["cone"] == "elliptic"
    assert record["summary"]["revolutions"] > 0.3 and record["summary"]["slip1_m"] == 0.0
    for argv, word in ((("--mujoco-model", "wheels"), "--engine mujoco"),
                       (("--engine", "mujoco", "--mujoco-model", "wheels", "--mujoco-clutch", "lock"), "ratchet"),
                       (("--engine", "mujoco", "--mujoco-model", "wheels", "--set", "clutch_stiffness=1e5"), "rigid"),
                       (("--engine", "mujoco", "--mujoco-model", "wheels", "--set", "pipe_diameter=0.1"), "2 r")):
        code, out, err = run_cli(capsys, "simulate", *argv)
        assert code == 2 and word in err and len(err.strip().splitlines()) == 1


def test_the_wheeled_model_warns_by_default_and_the_slides_stop(capsys):
    """On wheels the soft contacts take work the audit cannot book (~0.3 % of the motor's under the paper's
    torque, whatever the step), so the monitor's default there is 'warn'; on the slides it stays 'stop'; a
    mode given explicitly wins. The default 1 s wheeled run is such a case: its residual passes the 1e-3
    tolerance at ~0.8 s, which stopped it with exit status 1 while 'stop' was every model's default."""
    assert registry.run("mujoco-wheels", RobotParams(), 0.01).summary["accuracy"]["mode"] == "warn"
    assert registry.run("mujoco-ratchet", RobotParams(), 0.01).summary["accuracy"]["mode"] == "stop"
    given = registry.run("mujoco-wheels", RobotParams(), 0.01, accuracy="stop")
    assert given.summary["accuracy"]["mode"] == "stop"
    code, out, err = run_cli(capsys, "simulate", "--engine", "mujoco", "--mujoco-model", "wheels", "--json")
    assert code == 0, err
    accuracy = json.loads(out)["summary"]["accuracy"]
    assert accuracy["mode"] == "warn" and not accuracy["ok"] and accuracy["residual_ratio"] > 1e-3
