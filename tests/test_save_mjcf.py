"""``simulate --save-mjcf`` and ``ipir_mujoco.engine.compiled_mjcf``: the model a run compiles, loadable in plain
MuJoCo, with its initial state and a header saying what the package does between steps."""

from __future__ import annotations

import mujoco
import numpy as np
import pytest

from ipir_mujoco.core.errors import ParameterError
from ipir_mujoco.core.params import RobotParams
from ipir_mujoco.engine import compiled_mjcf, simulate_mujoco
from ipir_mujoco.engine.run.export import KEYFRAME
from ipir_mujoco.engine.kinds import kind_for
from ipir_mujoco.engine.run.run_setup import RunSetup

from cli_run import run_cli


def _run_model(params, implementation, rule, model="slides", t_end=0.2, dt_out=1e-3):
    """The model and initial state a run of these options builds through the one run setup."""
    kind = kind_for(model, params)
    params = kind.check(params, implementation, rule)
    settings, _ = kind.settings(params, t_end, dt_out, None, implementation)
    setup = RunSetup(kind, params, settings, implementation=implementation, rule=rule)
    setup.start()
    return setup


@pytest.mark.parametrize("params,implementation,rule,model", [
    (RobotParams(), "ratchet", "unilateral", "slides"),
    (RobotParams(L=0.13, m2=2.2, drive="motor", phi0=1.0), "lock", "kinematic", "slides"),
    (RobotParams(drive="motor", clutch_stiffness=1e6, clutch_backlash=1e-3), "ratchet", "unilateral", "slides"),
    (RobotParams(drive="motor", mu_wall=0.8), "ratchet", "unilateral", "wheels"),
])
def test_the_saved_model_is_the_runs_model_in_its_initial_state(params, implementation, rule, model):
    """Loaded by plain MuJoCo, the file has the run's sizes, timestep, masses, geometry and actuators (to the
    6 significant digits MuJoCo's XML writer prints: relative 5e-6, the half unit of the 6th digit, with an
    absolute floor of 5e-6 of the largest entry for numbers near 0) and, reset to its keyframe, the run's
    initial state and ctrl exactly (written at full precision)."""
    params = params.replace(L=params.L * (1 + 1 / 3e3), m2=params.m2 * (1 + 1 / 7e3))  # digits beyond the 4th
    xml = compiled_mjcf(params, rule, implementation, model=model, t_end=0.2, dt_out=1e-3)
    saved = mujoco.MjModel.from_xml_string(xml)
    setup = _run_model(params, implementation, rule, model)
    run_model, run_data = setup.model, setup.data
    assert (saved.nq, saved.nv, saved.nu, saved.nbody, saved.njnt) == (run_model.nq, run_model.nv, run_model.nu,
                                                                        run_model.nbody, run_model.njnt)
    assert saved.opt.timestep == run_model.opt.timestep
    for name in ("body_mass", "body_inertia", "body_pos", "geom_size", "actuator_gainprm", "actuator_biasprm",
                 "dof_frictionloss", "dof_damping", "jnt_stiffness"):
        got, want = getattr(saved, name), getattr(run_model, name)
        floor = 5e-6 * max(float(np.abs(want).max(initial=0.0)), 1e-300)
        np.testing.assert_allclose(got, want, rtol=5e-6, atol=floor, err_msg=name)
    data = mujoco.MjData(saved)
    mujoco.mj_resetDataKeyframe(saved, data, saved.key(KEYFRAME).id)
    assert np.array_equal(data.qpos, run_data.qpos) and np.array_equal(data.qvel, run_data.qvel)
    assert np.array_equal(data.ctrl, run_data.ctrl)


def test_the_header_says_what_runs_between_steps():
    ratchet = compiled_mjcf(RobotParams(drive="motor"), "unilateral", "ratchet", t_end=0.2, dt_out=1e-3)
    header = ratchet.split("-->")[0]
    assert header.startswith("<!--") and "does not crawl" in header and "running" in header
    assert "ratchet raises each module's slide lower limit" in header and "ctrl = 1" in header
    assert "--" not in header[4:]  # an XML comment may not hold '--'
    wheels = compiled_mjcf(RobotParams(drive="motor", mu_wall=0.8), "unilateral", "ratchet", model="wheels",
                           t_end=0.2, dt_out=1e-3).split("-->")[0]
    assert "every wheel hub" in wheels
    lock = compiled_mjcf(RobotParams(), "kinematic", "lock", t_end=0.2, dt_out=1e-3).split("-->")[0]
    assert "locks" in lock and "'kinematic'" in lock and "M = 0.25 N m" in lock


def test_simulate_writes_the_file_it_runs_and_refuses_what_has_none(capsys, tmp_path):
    path = tmp_path / "run.xml"
    code, out, err = run_cli(capsys, "simulate", "--engine", "mujoco", "--clutch", "unilateral", "--t-end", "0.05",
                             "--save-mjcf", path)
    assert code == 0, err
    assert f"wrote {path}" in out and path.read_text().startswith("<!--")
    run = simulate_mujoco(RobotParams(), "unilateral", "ratchet", 0.05)
    assert mujoco.MjModel.from_xml_path(str(path)).opt.timestep == run.settings["timestep"]
    code, out, err = run_cli(capsys, "simulate", "--save-mjcf", tmp_path / "a.xml")
    assert code == 2 and err.count("\n") == 1 and "analytic engines have no MJCF" in err
    code, out, err = run_cli(capsys, "simulate", "--engine", "mujoco", "--clutch", "unilateral", "--save-mjcf",
                             tmp_path / "a.txt")
    assert code == 2 and "not an .xml file name" in err and not (tmp_path / "a.txt").exists()
    with pytest.raises(ParameterError, match="kinematic"):  # refused as the run would refuse it
        compiled_mjcf(RobotParams(), "kinematic", "ratchet")
