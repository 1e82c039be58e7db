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
one folder) keep working: :func:`ipir_mujoco.core.older_paths.keep_older_paths` imports each as the very module at its new place.
"""

from ipir_mujoco.core.older_paths import keep_older_paths

from .builders.model import SolverSettings, build_model
from .run.export import compiled_mjcf, save_mjcf
from .run.simulate import CrankServo, captured_warnings, simulate_mujoco

__all__ = ["CrankServo", "SolverSettings", "build_model", "captured_warnings", "compiled_mjcf", "save_mjcf",
           "simulate_mujoco"]

# each folder's modules (bottom up)
FOLDERS = {
    "builders": ("model", "grip_model", "wheels_model", "pipe_walls", "pipe_drawing", "pipe_rig", "route_walls",
                 "_pipewall"),
    "loop": ("stepper", "native", "rows", "recorder", "monitor", "controller", "servo_drive", "_stepper"),
    "controllers": ("slide_clutches", "compliant", "grip", "compliant_grip", "compiled_grip", "wheels"),
    "modelkinds": ("kinds", "loop_rows", "timestep", "route_watch", "common"),
    "run": ("simulate", "run_setup", "batch", "export", "block_checks", "skid_check",
            "wheel_skids"),
}
RENAMED = {"compliant_grip": "grip_compliant"}  # a module's name now: its older name (as the analytic model's)
# older path (the engine was one folder; a renamed module also under its older name in its folder): path now
OLDER_PATHS = {f"{__name__}.{RENAMED.get(module, module)}": f"{__name__}.{folder}.{module}"
               for folder, modules in FOLDERS.items() for module in modules}
OLDER_PATHS |= {f"{__name__}.{folder}.{RENAMED[module]}": f"{__name__}.{folder}.{module}"
                for folder, modules in FOLDERS.items() for module in modules if module in RENAMED}
keep_older_paths(OLDER_PATHS)
