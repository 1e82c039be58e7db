"""The MuJoCo engine: the real linkage built from a parameter set, its clutches, serial and batched runs.

Each MuJoCo model of the robot is a model kind (:mod:`.kinds`: the slides, the slides on finite grip, the
wheels), chosen once per run; one run setup (:mod:`.run_setup`) builds and starts it, and one run loop
(:mod:`.simulate`, :mod:`.stepper`, :mod:`.recorder`, :mod:`.monitor`) steps it with the kind's clutch
controller (:mod:`.controller`'s protocol). ``docs/architecture.md`` draws the folder.

Nothing here computes the analytic model's dynamics: of the rest of the package it
imports only the shared vocabulary, :mod:`ipir_mujoco.core` (the parameter set, the
result container, the errors, the per-revolution figures), never
:mod:`ipir_mujoco.analytic`.
"""

from .export import compiled_mjcf, save_mjcf
from .model import SolverSettings, build_model
from .simulate import CrankServo, captured_warnings, simulate_mujoco

__all__ = ["CrankServo", "SolverSettings", "build_model", "captured_warnings", "compiled_mjcf", "save_mjcf",
           "simulate_mujoco"]
