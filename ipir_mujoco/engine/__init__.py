"""The MuJoCo engine: the real linkage built from a parameter set, its clutches, serial and batched runs.

Its folders, from the bottom up (a module imports only from its own folder and the folders below it;
``tests/test_import_graph.py`` holds it, ``docs/architecture.md`` draws it):

``builders``
    A parameter set to an ``MjModel``: the mechanism every kind builds on (the slide model, with its finite
    grip's carriages), the round pipe's walls (and their compiled contacts, ``_pipewall.c``).
``loop``
    The stepping loop every run steps through (``stepper``, compiled in ``_stepper.c``), the constraint rows
    it reads, the recorder, the accuracy monitor, the clutch controller protocol it calls, the servo's ticks.
``controllers``
    What several kinds' clutch controllers share: the compliant clutch, the compiled parts and the table of
    compiled controllers.
``kinds``
    The model kinds, each a folder (``slides``, ``slides_grip``, ``wheels``) holding all that kind is: its
    declaration (checks, settings, build, initial state, controller, loop options, columns, skid rule, variants,
    drawing), its builder, controllers and their compiled forms; beside them what kinds share (the automatic
    timestep, the skid check).
``run``
    A run on top: ``simulate_mujoco``, the run setup (runs, the viewer, ``--save-mjcf``), the checks between
    blocks.

Nothing here computes the analytic model's dynamics: of the rest of the package it
imports only the shared vocabulary, :mod:`ipir_mujoco.core` (the parameter set, the
result container, the errors, the per-revolution figures), never
:mod:`ipir_mujoco.analytic`.

The modules' older paths (``ipir_mujoco.engine.simulate``, ``ipir_mujoco.engine.stepper``, ...: the engine was
one folder; ``ipir_mujoco.engine.controllers.wheels``, ``ipir_mujoco.engine.modelkinds``, ...: five) keep working: :func:`ipir_mujoco.core.older_paths.keep_older_paths` imports each as the very module at its new place.
"""

import importlib

from ipir_mujoco.core.older_paths import keep_older_paths

# the engine's public names, each imported from its module when first asked for (importing the package, as the
# registry does to read the model kinds' variants, loads no MuJoCo)
PUBLIC = {"CrankServo": "run.simulate", "SolverSettings": "builders.solver_settings", "build_model": "builders.model",
          "captured_warnings": "run.simulate", "compiled_mjcf": "run.export", "save_mjcf": "run.export",
          "simulate_mujoco": "run.simulate"}
__all__ = sorted(PUBLIC)


def __getattr__(name: str):
    if name not in PUBLIC:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    value = getattr(importlib.import_module(f"{__name__}.{PUBLIC[name]}"), name)
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted({*globals(), *PUBLIC})


# each module's place now (below the engine), by its folder and name in the layout of issue 31 (builders, loop,
# controllers, modelkinds, run), where its older paths point
PLACES = {
    "builders": {"model": "builders.model", "grip_model": "builders.grip_model", "wheels_model": "kinds.wheels.model",
                 "pipe_walls": "builders.pipe_walls", "pipe_drawing": "builders.pipe_drawing",
                 "pipe_rig": "builders.pipe_rig", "route_walls": "kinds.wheels.route_walls",
                 "_pipewall": "builders._pipewall"},
    "loop": {name: f"loop.{name}" for name in ("stepper", "native", "rows", "recorder", "monitor", "controller",
                                               "servo_drive", "_stepper")},
    "controllers": {"slide_clutches": "kinds.slides.clutches", "compliant": "kinds.slides.compliant",
                    "grip": "kinds.slides_grip.ratchet", "compliant_grip": "kinds.slides_grip.compliant",
                    "compiled_grip": "kinds.slides_grip.compiled", "wheels": "kinds.wheels.ratchet",
                    "compiled_wheels": "kinds.wheels.compiled"},
    "modelkinds": {"kinds": "kinds", "loop_rows": "kinds.slides.loop_rows", "timestep": "kinds.timestep",
                   "route_watch": "kinds.wheels.route_watch", "common": "kinds.common"},
    "run": {"simulate": "run.simulate", "run_setup": "run.run_setup", "batch": "kinds.slides.batch", "export": "run.export",
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
