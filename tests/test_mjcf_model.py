"""The MJCF model: every element named, parameters really in the compiled model, loop closed."""

from __future__ import annotations

import math

import mujoco
import numpy as np
import pytest

from ipir_mujoco.analytic import ParameterError, RobotParams
from ipir_mujoco.engine import captured_warnings
from ipir_mujoco.engine.builders.model import (CRANK_HINGE, FRONT_SLIDE, LOOP, MOTOR, REAR_SLIDE, ROD_END, ROD_HINGE,
                                      SolverSettings, build_model, closed_loop_pose, default_mjcf, drive_control,
                                      qpos_address, set_closed_loop_state)

NAMED_KINDS = {  # object type -> count field of MjModel
    mujoco.mjtObj.mjOBJ_BODY: "nbody", mujoco.mjtObj.mjOBJ_JOINT: "njnt", mujoco.mjtObj.mjOBJ_GEOM: "ngeom",
    mujoco.mjtObj.mjOBJ_SITE: "nsite", mujoco.mjtObj.mjOBJ_CAMERA: "ncam", mujoco.mjtObj.mjOBJ_LIGHT: "nlight",
    mujoco.mjtObj.mjOBJ_ACTUATOR: "nu", mujoco.mjtObj.mjOBJ_EQUALITY: "neq", mujoco.mjtObj.mjOBJ_TENDON: "ntendon",
    mujoco.mjtObj.mjOBJ_SENSOR: "nsensor", mujoco.mjtObj.mjOBJ_MESH: "nmesh", mujoco.mjtObj.mjOBJ_MATERIAL: "nmat",
}


def unnamed_elements(model: mujoco.MjModel) -> list[str]:
    missing = []
    for kind, count in NAMED_KINDS.items():
        for i in range(getattr(model, count)):
            if kind == mujoco.mjtObj.mjOBJ_BODY and i == 0:
                continue  # the world body
            if not mujoco.mj_id2name(model, kind, i):
                missing.append(f"{kind.name} #{i}")
    return missing


def test_every_element_of_the_shipped_model_is_named():
    assert unnamed_elements(mujoco.MjModel.from_xml_path(str(default_mjcf()))) == []


def test_the_naming_check_catches_an_unnamed_element():
    spec = mujoco.MjSpec.from_file(str(default_mjcf()))
    spec.body("front_module").add_geom(type=mujoco.mjtGeom.mjGEOM_SPHERE, size=[0.01, 0, 0])
    assert unnamed_elements(spec.compile()) == ["mjOBJ_GEOM #" + str(spec.compile().ngeom - 1)]


def test_the_shipped_file_runs_one_second_without_a_warning(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    model = mujoco.MjModel.from_xml_path(str(default_mjcf()))
    data = mujoco.MjData(model)
    data.ctrl[model.actuator("crank_motor").id] = 0.25
    with captured_warnings() as messages:
        while data.time < 1.0:
            mujoco.mj_step(model, data)
    assert messages == [] and sum(w.number for w in data.warning) == 0
    assert np.all(np.isfinite(data.qpos)) and data.qpos[qpos_address(model, CRANK_HINGE)] > 2 * math.pi
    assert list(tmp_path.iterdir()) == []  # no MUJOCO_LOG.TXT


@pytest.mark.parametrize("params", [RobotParams(), RobotParams(m1=2.5, m2=0.4, r=0.03, L=0.05, J_A=3e-3,
                                                               F_r1=0.7, F_r2=2.2, rod_mass=0.2, rod_inertia=1e-4)])
def test_the_compiled_model_carries_the_parameters_and_nothing_hidden(params):
    settings = SolverSettings(timestep=5e-5)
    m = build_model(params, settings)
    rear, crank, rod, front = (m.body(n).id for n in ("rear_module", "crank", "rod", "front_module"))
    # module 1 translates with the crank (and the rod rides on it): m1 = its subtree minus the rod
    assert m.body_subtreemass[rear] - m.body_mass[rod] == pytest.approx(params.m1, rel=1e-12)
    assert m.body_mass[front] == pytest.approx(params.m2, rel=1e-12)
    assert m.body_mass[rod] == pytest.approx(params.rod_mass, rel=1e-12)
    # inertia about z (the hinge axis); MuJoCo may reorder principal axes, so compare the z-axis value
    assert m.body_inertia[crank][2] == pytest.approx(params.J_A, rel=1e-9)
    assert max(m.body_inertia[rod]) == pytest.approx(params.rod_inertia_value, rel=1e-9)
    assert np.allclose(m.body_ipos[crank], 0) and m.body_ipos[rod][0] == pytest.approx(params.L / 2)
    for name, force in ((REAR_SLIDE, params.F_r1), (FRONT_SLIDE, params.F_r2)):
        assert m.dof_frictionloss[m.joint(name).dofadr[0]] == pytest.approx(force)
    assert np.all(m.dof_armature == 0) and np.all(m.dof_damping == 0) and np.all(m.jnt_stiffness == 0)
    assert np.all(m.actuator_damping == 0) and np.all(m.actuator_armature == 0)
    # a horizontal pipe: gravity is all across the pipe (-z), normal to the mechanism's plane
    assert np.array_equal(m.opt.gravity, [0.0, 0.0, -params.g]) and m.opt.timestep == 5e-5
    assert m.eq_solref[m.equality(LOOP).id][0] == pytest.approx(2 * settings.timestep)
    assert m.eq_data[m.equality(LOOP).id][:3] == pytest.approx([params.L, 0, 0])


@pytest.mark.parametrize("phi", np.linspace(-3, 9, 13))
def test_the_start_pose_closes_the_loop(phi):
    params = RobotParams(r=0.05, L=0.08)
    model = build_model(params)
    data = mujoco.MjData(model)
    for name, value in closed_loop_pose(params, phi).items():
        data.qpos[qpos_address(model, name)] = value
    mujoco.mj_kinematics(model, data)
    rod_end = data.site(ROD_END).xpos
    front = data.body("front_module").xpos
    np.testing.assert_allclose(rod_end, front, atol=1e-15)
    assert data.qpos[qpos_address(model, ROD_HINGE)] == pytest.approx(math.asin(-0.05 * math.sin(phi) / 0.08) - phi)


def test_missing_or_broken_mjcf_is_bad_input(tmp_path):
    with pytest.raises(ParameterError, match="does not exist"):
        build_model(RobotParams(), mjcf=tmp_path / "nope.xml")
    broken = tmp_path / "broken.xml"
    broken.write_text("<mujoco><worldbody><body name='a'></worldbody></mujoco>")
    with pytest.raises(ParameterError, match="broken.xml.*not a valid model"):
        build_model(RobotParams(), mjcf=broken)
    lacking = tmp_path / "lacking.xml"
    lacking.write_text(default_mjcf().read_text().replace('name="rod_bar"', 'name="bar"'))
    with pytest.raises(ParameterError, match="'rod_bar'"):
        build_model(RobotParams(), mjcf=lacking)


@pytest.mark.parametrize("change,fragment", [({"rod_mass": 0.0}, "rod_mass=0.0"),
                                             ({"rod_inertia": 0.0}, "rod_inertia=0.0")])
def test_the_physics_engine_needs_a_rod_with_mass(change, fragment):
    with pytest.raises(ParameterError, match=fragment):
        build_model(RobotParams(**change))


def test_solver_settings_are_validated():
    with pytest.raises(ParameterError, match="timestep=0"):
        SolverSettings(timestep=0)
    with pytest.raises(ParameterError, match="constraint_time_constant"):
        SolverSettings(timestep=1e-4, constraint_time_constant=1e-4)
    with pytest.raises(ParameterError, match="integrator"):
        SolverSettings(integrator="leapfrog")


@pytest.mark.parametrize("incline,g", [(0.0, 9.81), (30.0, 9.81), (90.0, 9.81), (-20.0, 9.81), (45.0, 1.62)])
def test_gravity_follows_the_pipe_incline(incline, g):
    """Along the pipe axis x: -g sin(incline); the rest across the pipe, where it moves nothing."""
    params = RobotParams(incline=incline, g=g)
    m = build_model(params)
    angle = math.radians(incline)
    # the compiler stores the vector as given: equal to a few ulps of g
    np.testing.assert_allclose(m.opt.gravity, [-g * math.sin(angle), 0.0, -g * math.cos(angle)], rtol=0,
                               atol=4 * np.finfo(float).eps * g)
    # the across-pipe part only loads bearings: with the component along x removed, gravity's
    # generalized force (qfrc_bias at rest) is zero on every joint, at any pose
    m.opt.gravity[0] = 0.0
    d = mujoco.MjData(m)
    for phi in (0.3, 1.9, 4.0):
        for name, value in closed_loop_pose(params, phi).items():
            d.qpos[qpos_address(m, name)] = value
        mujoco.mj_forward(m, d)
        assert np.all(np.abs(d.qfrc_bias) <= 1e-15 * g), phi


def test_the_motor_is_mujocos_own_actuator_with_the_dc_motor_line():
    """drive = motor: a general actuator whose gain and bias give M_stall (1 - omega / omega_noload).

    The force MuJoCo computes, gainprm[0] ctrl + biasprm[2] omega (XML reference,
    actuator/general), read from data.actuator_force at crank speeds below zero,
    at rest, below, at and above the no-load speed; a handful of roundings: 1e-14 M_stall.
    """
    params = RobotParams(drive="motor", M_stall=0.8, omega_noload=25.0)
    m = build_model(params)
    motor = m.actuator(MOTOR).id
    assert m.actuator_gaintype[motor] == mujoco.mjtGain.mjGAIN_FIXED
    assert m.actuator_biastype[motor] == mujoco.mjtBias.mjBIAS_AFFINE
    d = mujoco.MjData(m)
    set_closed_loop_state(m, d, params)
    d.ctrl[motor] = drive_control(params)
    crank = m.joint(CRANK_HINGE).dofadr[0]
    for omega in (-40.0, -3.0, 0.0, 12.5, 25.0, 37.0, 200.0):
        d.qvel[:] = 0.0
        d.qvel[crank] = omega
        mujoco.mj_forward(m, d)
        expected = params.M_stall * (1 - omega / params.omega_noload)
        assert d.actuator_force[motor] == pytest.approx(expected, rel=0, abs=1e-14 * params.M_stall), omega
    # the constant torque stays a constant torque, whatever the speed
    params = RobotParams(M=0.3)
    m = build_model(params)
    d = mujoco.MjData(m)
    d.ctrl[motor] = drive_control(params)
    for omega in (-10.0, 0.0, 50.0):
        d.qvel[m.joint(CRANK_HINGE).dofadr[0]] = omega
        mujoco.mj_forward(m, d)
        assert d.actuator_force[motor] == 0.3


def test_the_clutch_actuators_carry_the_clutch_spring_and_damper_and_nothing_else():
    """Compliant clutches: per slide a general actuator with force k ctrl - k x - c v, clamped to [0, ...]
    (it never pulls), no mass, armature or damping of its own (the anchor it pulls from is its ctrl, so the
    clutch adds no inertia to the robot); rigid clutches: all zero, no force at any state."""
    from ipir_mujoco.engine.builders.model import FRONT_CLUTCH, REAR_CLUTCH

    params = RobotParams(clutch_stiffness=3e6, clutch_damping=40.0, clutch_backlash=1e-3)
    for p, k, c in ((params, 3e6, 40.0), (RobotParams(), 0.0, 0.0)):
        m = build_model(p)
        assert m.nu == 3 and np.all(m.actuator_armature == 0) and np.all(m.actuator_damping == 0)
        assert m.body_subtreemass[0] == build_model(RobotParams()).body_subtreemass[0]
        for name, slide in ((REAR_CLUTCH, REAR_SLIDE), (FRONT_CLUTCH, FRONT_SLIDE)):
            a = m.actuator(name).id
            assert m.actuator_trnid[a, 0] == m.joint(slide).id and m.actuator_gear[a, 0] == 1.0
            assert list(m.actuator_gainprm[a, :3]) == [k, 0, 0] and list(m.actuator_biasprm[a, :3]) == [0, -k, -c]
            assert m.actuator_forcelimited[a] and m.actuator_forcerange[a, 0] == 0.0
        # with compliant clutches the slides are not limited: the springs hold the modules, no limit row
        assert not any(build_model(p, ratchet=True).jnt_limited) == (k > 0)
