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

# each module's place now (below the engine), by its folder and name in the layout of issue 31 (builders, loop,
# controllers, modelkinds, run), where its older paths point
PLACES = {
    "builders": {"model": "builders.model", "grip_model": "builders.grip_model", "wheels_model": "kinds.wheels.model",
                 "pipe_walls": "builders.pipe_walls", "pipe_drawing": "builders.pipe_drawing",
                 "pipe_rig": "builders.pipe_rig", "route_walls": "kinds.wheels.route_walls",
                 "_pipewall": "builders._pipewall"},
    "loop": {name: f"loop.{name}" for name in ("stepper", "native", "rows", "recorder", "monitor", "controller",
                                               "servo_drive", "_stepper")},
    "controllers": {"slide_clutches": "kinds.slides.clutches", "compliant": "controllers.compliant",
                    "grip": "kinds.slides_grip.ratchet", "compliant_grip": "kinds.slides_grip.compliant",
                    "compiled_grip": "kinds.slides_grip.compiled", "wheels": "kinds.wheels.ratchet",
                    "compiled_wheels": "kinds.wheels.compiled"},
    "modelkinds": {"kinds": "kinds.kinds", "loop_rows": "kinds.slides.loop_rows", "timestep": "kinds.timestep",
                   "route_watch": "kinds.wheels.route_watch", "common": "kinds.common"},
    "run": {"simulate": "run.simulate", "run_setup": "run.run_setup", "batch": "run.batch", "export": "run.export",
            "block_checks": "run.block_checks", "skid_check": "kinds.skid_check", "wheel_skids": "kinds.wheels.skids"},
}
RENAMED = {"compliant_grip": "grip_compliant"}  # a module's name in issue 31's layout: its older name (as the analytic model's)
NOW = {module: f"{__name__}.{place}" for places in PLACES.values() for module, place in places.items()}
# older path: path now. The engine was one folder (``engine.simulate``; a renamed module also under its older name);
# then five (``engine.builders.wheels_model``, ``engine.modelkinds``: now ``engine.kinds``). ``engine.kinds``, once a
# module, is the kinds' package now, which keeps that module's names.
OLDER_PATHS = {f"{__name__}.{RENAMED.get(module, module)}": now for module, now in NOW.items()
               if module not in ("kinds", "compiled_wheels")}
OLDER_PATHS |= {f"{__name__}.{folder}.{older}": NOW[module] for folder, places in PLACES.items()
                for module in places for older in {module, RENAMED.get(module, module)}
                if f"{__name__}.{folder}.{older}" != NOW[module]}
OLDER_PATHS[f"{__name__}.modelkinds"] = f"{__name__}.kinds"
# `from engine.modelkinds import loop_rows` looks for the module under the package's name now
OLDER_PATHS |= {f"{__name__}.kinds.{module}": NOW[module] for module in PLACES["modelkinds"]
                if NOW[module] != f"{__name__}.kinds.{module}"}
keep_older_paths(OLDER_PATHS)
