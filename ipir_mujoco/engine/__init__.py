"""The MuJoCo engine: the real linkage built from a parameter set, its clutches, serial and batched runs.

Its folders, from the bottom up (a module imports only from its own folder and the folders below it;
``tests/test_import_graph.py`` holds it, ``docs/architecture.md`` draws it):

``builders``
    A parameter set to an ``MjModel``: the slide model, its finite grip's carriages, the wheeled model,
    the pipe's walls (and their compiled contacts, ``_pipewall.c``).
``loop``
    The stepping loop every run steps through (``stepper``, compiled in ``_stepper.c``), the constraint rows
    it reads, the recorder, the accuracy monitor, the clutch controller protocol it calls, the servo's ticks.
``controllers``
    The clutch controllers: the slides' ratchet and locks, the compliant clutches, finite grip's, the wheels'.
``modelkinds``
    The model kinds (slides, slides on finite grip, wheels), each one object owning its checks, settings,
    build, initial state, controller and loop options; the automatic timestep; a route's watch.
``run``
    A run on top: ``simulate_mujoco``, the run setup (runs, the viewer, ``--save-mjcf``), batched runs.

Nothing here computes the analytic model's dynamics: of the rest of the package it
imports only the shared vocabulary, :mod:`ipir_mujoco.core` (the parameter set, the
result container, the errors, the per-revolution figures), never
:mod:`ipir_mujoco.analytic`.

The modules' older paths (``ipir_mujoco.engine.simulate``, ``ipir_mujoco.engine.stepper``, ...: the engine was
one folder) keep working: :class:`_OlderPaths` imports each as the very module at its new place.
"""

import importlib
import importlib.abc
import importlib.util
import sys

from .builders.model import SolverSettings, build_model
from .run.export import compiled_mjcf, save_mjcf
from .run.simulate import CrankServo, captured_warnings, simulate_mujoco

__all__ = ["CrankServo", "SolverSettings", "build_model", "captured_warnings", "compiled_mjcf", "save_mjcf",
           "simulate_mujoco"]

# each folder's modules, by the name they had when the engine was one folder (old name = module name)
FOLDERS = {
    "builders": ("model", "grip_model", "wheels_model", "pipe_walls", "pipe_drawing", "pipe_rig", "route_walls",
                 "_pipewall"),
    "loop": ("stepper", "native", "rows", "recorder", "monitor", "controller", "servo_drive", "_stepper"),
    "controllers": ("slide_clutches", "compliant", "grip", "grip_compliant", "compiled_grip", "wheels"),
    "modelkinds": ("kinds", "loop_rows", "timestep", "route_watch", "common"),
    "run": ("simulate", "run_setup", "batch", "export", "block_checks", "skid_check"),
}
OLDER_PATHS = {f"{__name__}.{module}": f"{__name__}.{folder}.{module}"
               for folder, modules in FOLDERS.items() for module in modules}


class _OlderPaths(importlib.abc.MetaPathFinder, importlib.abc.Loader):
    """Imports ``ipir_mujoco.engine.<module>`` (an older path) as ``ipir_mujoco.engine.<folder>.<module>``: the same
    module object under both names, so that a patched or read attribute is the one the engine uses."""

    def find_spec(self, fullname, path=None, target=None):
        if fullname not in OLDER_PATHS:
            return None
        return importlib.util.spec_from_loader(fullname, self)

    def create_module(self, spec):
        module = importlib.import_module(OLDER_PATHS[spec.name])
        spec.loader_state = module.__spec__  # the import system sets the older spec on the module: kept to undo it
        return module

    def exec_module(self, module):
        module.__spec__ = module.__spec__.loader_state  # the module's own spec again (reload, python -m)


if not any(isinstance(finder, _OlderPaths) for finder in sys.meta_path):
    sys.meta_path.append(_OlderPaths())
