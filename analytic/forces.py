"""The external loads of the analytic model: the drive's torque and gravity along the pipe.

Defined once for every analytic model (the paper's rule, one-way clutches,
compliant clutches, kinetostatics). The MuJoCo engine states the same physics
in its own terms (an actuator's gain and bias, the model's gravity vector) and
never calls this.
"""

from __future__ import annotations

import math

import numpy as np

from ipir_mujoco.core.params import RobotParams



def drive_torque(params: RobotParams, omega, u=1.0):
    """Torque the drive applies to the crank [N m] at crank speed ``omega`` [rad/s] (float or ndarray).

    ``drive='torque'``: the constant M (the paper's case). ``drive='motor'``: a DC
    gearmotor at constant voltage, M_stall (1 - omega / omega_noload), linear on
    both sides (it brakes above omega_noload and gives more than M_stall when
    driven backward). ``drive='servo'``: that motor at the voltage fraction ``u``
    (float or ndarray like omega, in [-1, 1]) the speed controller set,
    M_stall (u - omega / omega_noload).
    """
    if params.drive in ("motor", "servo"):  # one expression for floats and arrays: both paths the same law
        return params.M_stall * (u - omega / params.omega_noload)
    return params.M + 0.0 * omega if isinstance(omega, np.ndarray) else params.M


def drive_damping(params: RobotParams) -> float:
    """-d(torque)/d(omega) [N m s/rad]: 0 for a constant torque, M_stall / omega_noload for the motor (and servo)."""
    return params.M_stall / params.omega_noload if params.drive in ("motor", "servo") else 0.0


def gravity_along_pipe(params: RobotParams) -> float:
    """Acceleration gravity gives every body along the pipe axis x [m/s^2]: -g sin(incline).

    Negative uphill (it pulls the robot back), positive downhill. The component
    across the pipe only loads the wheels and bearings; the resistances F_r1, F_r2
    are wall-press rolling resistance and do not depend on it.
    """
    return -params.g * math.sin(math.radians(params.incline))
