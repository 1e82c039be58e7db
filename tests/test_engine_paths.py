"""The engine's modules under their older paths (the engine was one folder; users' scripts import
``ipir_mujoco.engine.simulate``, ``ipir_mujoco.engine.stepper``, ...): each is the very module at its new place,
and a run started through the older names steps with the compiled loop and with the Python loop."""

from __future__ import annotations

import importlib
import os
import subprocess
import sys

import pytest

import ipir_mujoco.engine as engine
from ipir_mujoco.engine.loop import stepper

OLDER = sorted(engine.OLDER_PATHS.items())


@pytest.mark.parametrize(("older", "newer"), OLDER, ids=[older.rsplit(".", 1)[1] for older, _ in OLDER])
def test_an_older_path_imports_the_same_module(older, newer):
    if newer.rsplit(".", 1)[1].startswith("_"):  # a compiled part: it may be absent where it was not built
        try:
            importlib.import_module(newer)
        except ImportError:
            pytest.skip(f"{newer} is not built here")
    module = importlib.import_module(older)
    assert module is importlib.import_module(newer) is sys.modules[older] is sys.modules[newer]
    assert module.__name__ == newer and module.__spec__.name == newer  # its own spec, not the older path's
    name = older.rsplit(".", 1)[1]
    assert getattr(engine, name) is module  # `from ipir_mujoco.engine import stepper` and attribute access


def test_every_module_of_the_engines_folders_has_its_older_path():
    """The table names every module the folders hold (a module added to a folder later has no older path: it
    is left out here by name, below, when there is one)."""
    root = os.path.dirname(engine.__file__)
    held = {f"{engine.__name__}.{folder}.{file.split('.')[0]}" for folder in os.listdir(root)
            if os.path.isfile(os.path.join(root, folder, "__init__.py"))
            for file in os.listdir(os.path.join(root, folder))
            if file.endswith((".py", ".c")) and file != "__init__.py"}
    assert held == set(engine.OLDER_PATHS.values())


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


def test_a_run_through_the_older_paths_steps_in_both_loops():
    """The same short run in a fresh process, once with the compiled loop (where it is built) and once with
    IPIR_MUJOCO_STEPPER=python: the same final position, bit for bit (the two loops round alike)."""
    env = {k: v for k, v in os.environ.items() if k != stepper.ENV}
    compiled = subprocess.run([sys.executable, "-c", RUN], capture_output=True, text=True, env=env)
    python = subprocess.run([sys.executable, "-c", RUN], capture_output=True, text=True,
                            env={**env, stepper.ENV: "python"})
    assert compiled.returncode == python.returncode == 0 and compiled.stderr == python.stderr == ""
    loop, x1 = compiled.stdout.split()
    assert python.stdout.split() == ["PythonSteps", x1]
    assert loop == ("CompiledSteps" if stepper.compiled_status()[0] else "PythonSteps")
