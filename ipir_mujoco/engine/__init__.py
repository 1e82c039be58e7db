"""The MuJoCo engine: the real linkage built from a parameter set, its clutches, serial and batched runs.

Nothing here computes the analytic model's dynamics: it shares only the
parameter set, the result container and the errors with
:mod:`ipir_mujoco.analytic`.
"""

from .model import SolverSettings, build_model
from .simulate import CrankServo, captured_warnings, simulate_mujoco

__all__ = ["CrankServo", "SolverSettings", "build_model", "captured_warnings", "simulate_mujoco"]
