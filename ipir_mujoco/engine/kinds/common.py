"""What serial and batched MuJoCo runs (and the viewer) share: the clutch check, warnings, the crank servo, stalls.

Stall: under a constant torque or the motor (loads that do not change with
time; the speed controller's motor once it asks for full voltage, u = 1, which
at rest it keeps), a robot whose crank pin and modules have all been slower than
REST_SPEED for REST_TIME is in a static equilibrium it will not leave; the run
ends there (REST_TIME after the rest began, as every engine's run does), with a
one-line reason (:func:`stall_reason`), not an error.
"""

from __future__ import annotations

import contextlib
import math
from dataclasses import dataclass
from typing import Callable, Iterator

import mujoco
import numpy as np

from ipir_mujoco.core.checks import check_text
from ipir_mujoco.core.errors import ParameterError
from ipir_mujoco.core.limits import CLUTCH_RULES as RULES  # the clutch rules
from ipir_mujoco.core.options import RepeatProgress
from ipir_mujoco.core.params import RobotParams, refuse_idle_parameters
from ipir_mujoco.core.results import REST_SPEED, REST_TIME  # at rest: slower [m/s], this long [s] is a stall
from ipir_mujoco.core.results import stall_reason as core_stall_reason

from ..builders.model import check_params
from .base import MUJOCO_CLUTCHES
from .slides.clutches import refuse_compliant

BLOCK_TIME = 0.05  # s of simulated time between progress, budget, steady-state and stall checks
REFINEMENTS = 2  # an automatically chosen timestep that fails the accuracy monitor is halved at most this often
IMPLEMENTATIONS = (*MUJOCO_CLUTCHES, "none")  # the MuJoCo clutches: a variant's, or none (checks such as momentum)


@dataclass(frozen=True)
class CrankServo:
    """A stiff PD servo that makes the crank follow phi_ref(t), omega_ref(t).

    Motor torque = kp (phi_ref - phi) + kv (omega_ref - omega), recomputed every
    step; no feedforward, so the torque MuJoCo reports is what its own physics
    needs to follow the reference (inverse kinetostatics by simulation).
    Defaults: natural frequency 1000 rad/s, critical damping, for J = 1e-3 kg m^2.
    """

    phi_ref: Callable[[float], float]
    omega_ref: Callable[[float], float]
    kp: float = 1000.0  # N m / rad
    kv: float = 2.0  # N m s / rad

    def torque(self, t: float, phi: float, omega: float) -> float:
        return self.kp * (float(self.phi_ref(t)) - phi) + self.kv * (float(self.omega_ref(t)) - omega)


@contextlib.contextmanager
def captured_warnings() -> Iterator[list[str]]:
    """Route MuJoCo's warning text into a list instead of MUJOCO_LOG.TXT and stderr."""
    messages: list[str] = []
    previous = mujoco.get_mju_user_warning()
    mujoco.set_mju_user_warning(messages.append)
    try:
        yield messages
    finally:
        mujoco.set_mju_user_warning(previous)


def check_clutch_options(params: RobotParams, clutch: str = "unilateral", implementation: str = "ratchet") -> None:
    """What every MuJoCo entry point (serial and batched runs, the viewer) refuses in the parameters and the
    clutch choice (ParameterError, one line): ``clutch`` a rule of RULES, ``implementation`` one of
    IMPLEMENTATIONS."""
    check_text("implementation", implementation, ", ".join(IMPLEMENTATIONS))
    check_text("clutch", clutch, ", ".join(RULES))
    if implementation not in IMPLEMENTATIONS:
        raise ParameterError(f"mujoco clutch {implementation!r} is unknown; allowed: {', '.join(IMPLEMENTATIONS)}")
    if clutch not in RULES:
        raise ParameterError(f"clutch={clutch!r} is unknown; allowed: {', '.join(RULES)}")
    if implementation == "ratchet" and clutch == "kinematic":
        raise ParameterError("--clutch kinematic with the ratchet: a ratchet is a one-way clutch; use "
                             "--mujoco-clutch lock for the paper's rule, or --clutch unilateral")
    refuse_compliant(params, implementation)
    refuse_idle_parameters(params)
    check_params(params)


def steps_per_output(dt_out: float, timestep: float) -> int:
    """How many timesteps make one output interval ``dt_out`` [s]; ParameterError unless a whole number."""
    steps = round(dt_out / timestep)
    if steps < 1 or abs(steps * timestep - dt_out) > 1e-9 * dt_out:
        raise ParameterError(f"dt_out={dt_out} s is out of range; allowed: a whole multiple of the timestep "
                             f"({timestep} s)")
    return steps


class PassProgress:
    """A run's ``progress`` across its attempts: the first attempt's simulated times [s] passed on as they come;
    each repeat at a finer step (:meth:`begin`; a failed accuracy check, the wheels' skid check) passes on
    :class:`ipir_mujoco.core.options.RepeatProgress` values, never below the time already reported: the times a
    user's callable sees never go back, and a repeat that takes minutes is not silent."""

    def __init__(self, progress: Callable[[float], None]):
        self.progress, self.reached, self.attempt, self.timestep = progress, -math.inf, 0, math.nan

    def begin(self, timestep: float) -> None:
        """An attempt at ``timestep`` [s] starts (the first is the run itself)."""
        self.attempt, self.timestep = self.attempt + 1, float(timestep)

    def __call__(self, t: float) -> None:
        if self.attempt <= 1:
            if t > self.reached:
                self.reached = t
                self.progress(t)
            return
        self.reached = max(self.reached, t)
        self.progress(RepeatProgress(self.reached, t, self.attempt, self.timestep))


def climb_energy(model: mujoco.MjModel, params: RobotParams) -> float:
    """Potential energy of raising the whole robot by one stroke 2 r along the pipe [J]: with the drive's
    2 pi |torque|, one revolution's energy scale, the floor of the monitor's energy scale."""
    return float(model.body_subtreemass[0] * abs(model.opt.gravity[0]) * 2 * params.r)


def rest_since(t: np.ndarray, omega: np.ndarray, v1: np.ndarray, v2: np.ndarray, r: float) -> float | None:
    """When the robot came to rest, if it has been at rest for the last REST_TIME; else None.

    Arrays of shape (n,), the samples so far: t [s], crank speed [rad/s], module
    speeds [m/s]; ``r`` [m] the crank length. At rest: the crank pin (r |omega|)
    and both modules slower than REST_SPEED.
    """
    if t[-1] - t[0] < REST_TIME:
        return None
    first = int(np.searchsorted(t, t[-1] - REST_TIME - 1e-12))
    if max(r * np.abs(omega[first:]).max(), np.abs(v1[first:]).max(), np.abs(v2[first:]).max()) > REST_SPEED:
        return None
    moving = np.flatnonzero((r * np.abs(omega) > REST_SPEED) | (np.abs(v1) > REST_SPEED) | (np.abs(v2) > REST_SPEED))
    return float(t[moving[-1] + 1]) if moving.size else float(t[0])


def stall_reason(params: RobotParams, since: float, phi: float) -> str:
    """The one-line RunResult.stall (core.summary.stall_reason: the same words as every engine's) of a robot
    at rest from ``since`` [s] with the crank at ``phi`` [rad]; the drive's torque at rest is its actuator's
    at zero speed (M, or the motor's M_stall)."""
    torque = params.M_stall if params.drive in ("motor", "servo") else params.M  # the servo stalls at u = 1
    return core_stall_reason(since, phi, torque, params.incline != 0 and params.g != 0)


def mujoco_failure(t_good: float, reason: str) -> str:
    """The one-line error of a run in which MuJoCo raised (``t_good`` [s]: the last sample known good)."""
    return f"MuJoCo failed after t={t_good:.6g} s: {' '.join(reason.split())}"
