"""What a run's time series holds, for every engine: its columns and their units, the clutch modes of its
``mode`` column, and the speed below which the robot is at rest.

The columns' meanings are in :mod:`.results` (the container's documentation), which re-exports every name
here; :mod:`.summary` reads them into the summary figures.
"""

from __future__ import annotations

from enum import IntEnum

# [m/s] a module, the crank pin or the gap slower than this is at rest: far below any motion a run resolves,
# orders of magnitude above the creep of a module MuJoCo's soft constraints hold, so every engine's series
# reads rest alike (the analytic engines' rest is an exact 0). The summary's first minimum of S and MuJoCo's
# stall test use it.
REST_SPEED = 1e-6
# [s] how long every engine runs on once the robot is at rest for good (a stall) before it ends the run: MuJoCo
# needs that long below REST_SPEED to call a rest final, and its soft constraints to settle to the statics
REST_TIME = 0.1

COLUMNS: tuple[str, ...] = (
    "t", "phi", "omega", "alpha", "x1", "x2", "v1", "v2", "a1", "a2",
    "S", "S_dot", "lambda1", "lambda2", "mode",
)


# every series column any engine writes, and its unit (a column an engine adds is listed here too)
SERIES_UNITS: dict[str, str] = {
    "t": "s", "phi": "rad", "omega": "rad/s", "alpha": "rad/s^2", "x1": "m", "x2": "m", "v1": "m/s", "v2": "m/s",
    "a1": "m/s^2", "a2": "m/s^2", "S": "m", "S_dot": "m/s", "lambda1": "N", "lambda2": "N", "mode": "-",
    "motor_work": "J", "friction_work": "J", "kinetic": "J", "potential": "J", "clutch_spring_energy": "J",
    "clutch_damper_work": "J", "skid_work": "J", "motor_torque": "N m", "motor_power": "W", "rod_force": "N",
    "crank_pin_force": "N", "resistance1": "N", "resistance2": "N", "clutch_overlap1": "m", "clutch_overlap2": "m",
    "slip1": "m", "slip2": "m", "grip_use1": "-", "grip_use2": "-", "wheels1": "-", "wheels2": "-",
    "loop_gap": "m", "momentum": "kg m/s", "drive_u": "-", "y1": "m", "y2": "m", "yaw1": "rad", "yaw2": "rad",
    "link_y1": "N", "link_y2": "N", "link_z1": "N", "link_z2": "N",
}


class Mode(IntEnum):
    """Which clutches hold their module."""

    BOTH_LOCKED = 0  # nothing moves (stall)
    CONTRACTION = 1  # front locked, rear moves forward (S_dot < 0)
    EXPANSION = 2  # rear locked, front moves forward (S_dot > 0)
    BOTH_MOVING = 3  # neither clutch engaged (one-way clutches only)

    @property
    def rear_locked(self) -> bool:
        return self in (Mode.BOTH_LOCKED, Mode.EXPANSION)

    @property
    def front_locked(self) -> bool:
        return self in (Mode.BOTH_LOCKED, Mode.CONTRACTION)


MODE_NAMES: dict[int, str] = {int(m): m.name.lower() for m in Mode}
