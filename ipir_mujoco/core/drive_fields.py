"""Which parameters act through which drive, or through another parameter; and the refusal of one given where
nothing acts through it.

A run refuses a parameter no chosen drive uses (the constant torque's ``M`` under the DC gearmotor, the speed
controller's gains under anything but the servo) in one line, never ignoring it silently: the drives' tables
here (:data:`DRIVE_FIELDS`) and the refusals every engine and study calls (:func:`refuse_idle_parameters`,
:func:`refuse_idle_under`, :func:`refuse_idle_names`). :mod:`.param_table` builds the parameter set's drive
fields from these tables; :mod:`.params` re-exports every name here.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Iterable

from .errors import ParameterError

if TYPE_CHECKING:
    from .param_table import RobotParams

DRIVES = ("torque", "motor", "servo")
FEEDFORWARDS = ("none", "paper", "exact")  # drive = servo: the feedforward table's model (core/control.py)
# the speed controller's parameters: they act only with drive=servo
SERVO_FIELDS = ("omega_target", "speed_dip", "feedforward", "control_rate", "speed_kp", "speed_ki")
MOTOR_FIELDS = ("M_stall", "omega_noload")  # the DC gearmotor's: drive=motor, and the servo's motor
# the parameters each drive acts through; one that no chosen drive uses is refused (refuse_idle_parameters)
DRIVE_FIELDS = {"torque": ("M",), "motor": MOTOR_FIELDS, "servo": (*MOTOR_FIELDS, *SERVO_FIELDS)}
_DRIVEN_BY = {"M": "the constant torque", **{n: "the DC gearmotor" for n in MOTOR_FIELDS},
              **{n: "the speed controller" for n in SERVO_FIELDS}}


# (parameter, the parameters that act only through it when it is not None, what they need, its value that
# leaves them idle, the unit the message gives them): refused together (refuse_idle_parameters)
_ACTS_THROUGH = (
    ("clutch_stiffness", ("clutch_damping", "clutch_backlash"),
     "a finite clutch_stiffness (a rigid clutch has no spring for it to act with)", "rigid", ""),
)


def refuse_idle_parameters(params: RobotParams) -> None:
    """Parameters that act only through another one, given without it, refused in one line (never silently
    ignored), for every engine: each drive's own (DRIVE_FIELDS: M for drive=torque, M_stall and omega_noload for
    drive=motor or servo, the speed controller's for drive=servo) with another drive, the message naming the
    drives that use it; clutch damping and backlash need a clutch with a spring (a finite ``clutch_stiffness``).
    (The wheels' normal forces F_n1, F_n2 are not refused with unlimited grip: they are the wheeled MuJoCo
    model's leg preload whatever mu_wall is.)"""
    defaults = type(params)()  # RobotParams(): its defaults (this module is below the table: it imports none)
    for name in _DRIVEN_BY:
        value, default = getattr(params, name), getattr(defaults, name)
        if name not in DRIVE_FIELDS[params.drive] and value != default:
            raise ParameterError(_idle_message(f"{name}={'model' if value is None else value!r}", name, params.drive))
    for through, names, needs, idle, unit in _ACTS_THROUGH:
        if getattr(params, through) is not None:
            continue
        for name in names:
            value, default = getattr(params, name), getattr(defaults, name)
            if value != default:
                raise ParameterError(f"{name}={value!r}{unit} needs {needs}; allowed: {default!r} with "
                                     f"{through}={idle}")


def refuse_idle_under(params: RobotParams, drives: Iterable[str]) -> None:
    """A drive's parameter given (not at its default) in ``params`` that none of ``drives`` acts through, refused
    in one line naming the first of ``drives`` and the drives that use it: the check of a study that runs one
    design under drives of its own choosing (each case's ``params.replace(drive=...)`` would otherwise return the
    parameter to its default without a word)."""
    drives = tuple(dict.fromkeys(drives))
    used = {name for drive in drives for name in DRIVE_FIELDS[drive]}
    defaults = type(params)()  # RobotParams(): its defaults (this module is below the table: it imports none)
    for name in _DRIVEN_BY:
        value = getattr(params, name)
        if name not in used and value != getattr(defaults, name):
            raise ParameterError(_idle_message(f"{name}={'model' if value is None else value!r}", name, drives[0]))


def refuse_idle_names(drive: str, names: Iterable[str], what: str = "varied") -> None:
    """A study that varies (``what``) parameters ``names`` of which one only another drive than ``drive`` uses
    (DRIVE_FIELDS: ``M_stall`` swept under the constant torque), refused in one line before any run, as every
    run would refuse it (:func:`refuse_idle_parameters`)."""
    for name in names:
        if name in _DRIVEN_BY and name not in DRIVE_FIELDS[drive]:
            raise ParameterError(_idle_message(f"{name} ({what})", name, drive))


def _idle_message(given: str, name: str, drive: str) -> str:
    users = [d for d in DRIVES if name in DRIVE_FIELDS[d]]
    return (f"{given} sets {_DRIVEN_BY[name]}, which only {' or '.join(f'drive={d}' for d in users)} uses, and the "
            f"drive here is {drive!r}; allowed: {' or '.join(f'--drive {d}' for d in users)} (drive = ... in a "
            f"file), or leave {name} out")

