"""Modules under their older paths (the engine was one folder: users' scripts import
``ipir_mujoco.engine.simulate``, ``ipir_mujoco.engine.stepper``, ...; the analytic run loops were
``unilateral_clutch``, ...): each is the very module at its new place, and a run started through the engine's
older names steps with the compiled loop and with the Python loop."""

from __future__ import annotations

import importlib
import os
import subprocess
import sys

import pytest

import ipir_mujoco.analytic  # noqa: F401  (registers the analytic model's older paths)
import ipir_mujoco.engine as engine
from ipir_mujoco.core.older_paths import OLDER_PATHS
from ipir_mujoco.engine.loop import stepper

OLDER = sorted(OLDER_PATHS.items())


@pytest.mark.parametrize(("older", "newer"), OLDER, ids=[older.removeprefix("ipir_mujoco.") for older, _ in OLDER])
def test_an_older_path_imports_the_same_module(older, newer):
    if newer.rsplit(".", 1)[1].startswith("_"):  # a compiled part: it may be absent where it was not built
        try:
            importlib.import_module(newer)
        except ImportError:
            pytest.skip(f"{newer} is not built here")
    module = importlib.import_module(older)
    assert module is importlib.import_module(newer) is sys.modules[older] is sys.modules[newer]
    assert module.__name__ == newer and module.__spec__.name == newer  # its own spec, not the older path's
    parent, _, name = older.rpartition(".")
    assert getattr(sys.modules[parent], name) is module  # `from ipir_mujoco.engine import stepper`, attributes


# the engine's modules when it was one folder (before its regroup, issue 31)
ONE_FOLDER = ("batch", "block_checks", "common", "compiled_grip", "compliant", "controller", "export", "grip",
              "grip_compliant", "grip_model", "kinds", "loop_rows", "model", "monitor", "native", "pipe_drawing",
              "pipe_rig", "pipe_walls", "recorder", "route_walls", "route_watch", "rows", "run_setup",
              "servo_drive", "simulate", "skid_check", "slide_clutches", "stepper", "timestep", "wheels",
              "wheels_model", "_stepper", "_pipewall")


def test_every_module_of_the_one_folder_engine_has_its_older_path():
    # kinds: a module then, the kinds' package now (which keeps its names)
    missing = [name for name in ONE_FOLDER if f"{engine.__name__}.{name}" not in engine.OLDER_PATHS and name != "kinds"]
    assert missing == []
    assert all(older in OLDER_PATHS for older in engine.OLDER_PATHS)


def test_names_that_are_no_older_path_are_not_found():
    with pytest.raises(ModuleNotFoundError):
        importlib.import_module("ipir_mujoco.engine.no_such_module")


RUN = ("from ipir_mujoco.analytic import RobotParams\n"
       "from ipir_mujoco.engine.simulate import simulate_mujoco\n"
       "import ipir_mujoco.engine.stepper as stepper\n"
       "used, init = set(), stepper.PythonSteps.__init__\n"
       "def spy(self, *a, **k):\n"
       "    used.add(type(self).__name__)\n"
       "    init(self, *a, **k)\n"
       "stepper.PythonSteps.__init__ = spy\n"
       "run = simulate_mujoco(RobotParams(), 'unilateral', 'ratchet', 0.02, dt_out=1e-3)\n"
       "print(','.join(sorted(used)), run.series['x1'][-1].hex())\n")


def test_a_run_through_the_older_paths_steps_in_both_loops(tmp_path):
    """The same short run in a fresh process, once with the compiled loop (where it is built) and once with
    IPIR_MUJOCO_STEPPER=python: the same final position, bit for bit (the two loops round alike). The processes
    run in an empty folder: ``python -c`` puts its working folder first on sys.path, and from the repository's
    root it would import the source tree, which a non-editable install (CI's) leaves without its compiled loop."""
    env = {k: v for k, v in os.environ.items() if k != stepper.ENV}
    compiled = subprocess.run([sys.executable, "-c", RUN], capture_output=True, text=True, env=env, cwd=tmp_path)
    python = subprocess.run([sys.executable, "-c", RUN], capture_output=True, text=True,
                            env={**env, stepper.ENV: "python"}, cwd=tmp_path)
    assert compiled.returncode == python.returncode == 0 and compiled.stderr == python.stderr == ""
    loop, x1 = compiled.stdout.split()
    assert python.stdout.split() == ["PythonSteps", x1]
    assert loop == ("CompiledSteps" if stepper.compiled_status()[0] else "PythonSteps")


def test_older_names_of_the_variant_lists_keep_their_values():
    """``ENGINES`` names the two engines (registry) only; the studies' variant lists have their own names, the
    older ones still read."""
    from ipir_mujoco import registry
    from ipir_mujoco.studies import climb_limits, climbing, sweep_space
    from ipir_mujoco.studies.climbing import ENGINES as climbing_engines

    assert registry.ENGINES == ("analytic", "mujoco")
    assert climbing_engines is climbing.ENGINES is climb_limits.ENGINES is climbing.CLIMB_VARIANTS
    assert sweep_space.ENGINES is registry.NAMES and sweep_space.DEFAULT_ENGINES is sweep_space.DEFAULT_VARIANTS
    with pytest.raises(AttributeError):
        climbing.NO_SUCH_NAME
