"""The parameter set's table: :class:`RobotParams`, each field with its meaning, unit, default and allowed range.

One frozen dataclass, defined once: each field carries its meaning, unit,
default and allowed range in its metadata, and everything else reads them from
there: validation on construction (here), ``NAME=VALUE`` parsing and TOML files
(:mod:`.params`), the ``ipir-mujoco params`` listing (:func:`describe_parameters`),
``--help`` and the reports. Units are SI except ``incline``, which is in degrees
as users state pipe slopes. Import it from :mod:`.params`, which re-exports every
name here.

Defaults are the paper's simulation case (m1 = m2 = 1 kg, r = 0.05 m,
L = 0.2 m, J_A = 0.001 kg m^2, F_r = 1 N, M = 0.25 N m, start from rest at
phi = 0) with a horizontal pipe and ideal, rigid clutches. The rod's mass,
which the paper neglects, defaults to a small positive value so that the
exact-geometry model and the MuJoCo model (which needs a body with mass) can
agree on the same mechanism.
"""

from __future__ import annotations

import dataclasses
import functools
import math
from dataclasses import dataclass, field
from typing import Any, Mapping

from .checks import as_real
from .drive_fields import _DRIVEN_BY, DRIVE_FIELDS, DRIVES, FEEDFORWARDS
from .errors import ParameterError, ParameterTypeError


def _number(units: str, text: str, default: float, low: float, high: float, *, low_open: bool = False,
            high_open: bool = False, none_word: str | None = None, none_text: str = "") -> Any:
    """A real-valued field with its unit, meaning and allowed interval (bounds finite)."""
    meta = {"kind": "number", "units": units, "doc": text, "low": low, "high": high, "low_open": low_open,
            "high_open": high_open, "none_word": none_word, "none_text": none_text}
    return field(default=default, metadata=meta)


def _choice(text: str, default: str, choices: tuple[str, ...]) -> Any:
    return field(default=default, metadata={"kind": "choice", "units": "-", "doc": text, "choices": choices})


@dataclass(frozen=True)
class RobotParams:
    """Parameters of the two-module inchworm robot (SI units; ``incline`` in degrees).

    Run ``ipir-mujoco params`` (or see :func:`describe_parameters`) for every
    field's meaning, unit, default and allowed range. ``rod_inertia`` left as
    ``None`` means a uniform slender rod, ``rod_mass * L**2 / 12`` (read the
    value in use from :attr:`rod_inertia_value`); ``clutch_stiffness`` left as
    ``None`` means rigid, ideal clutches; ``mu_wall`` left as ``None`` means unlimited grip (read the
    grips in use from :attr:`grip`).
    """

    m1: float = _number("kg", "mass of module 1 (rear, carries the crank and motor)", 1.0, 0.0, 1e4, low_open=True)
    m2: float = _number("kg", "mass of module 2 (front)", 1.0, 0.0, 1e4, low_open=True)
    r: float = _number("m", "crank length AB (the stroke is 2 r)", 0.05, 0.0, 10.0, low_open=True)
    L: float = _number("m", "connecting-rod length BC (must exceed r)", 0.2, 0.0, 100.0, low_open=True)
    J_A: float = _number("kg m^2", "inertia of crank and motor rotor about the crank axis A", 0.001, 0.0, 1e4,
                         low_open=True)
    F_r1: float = _number("N", "resistance on module 1 while it slides (wall-press rolling resistance)", 1.0,
                          0.0, 1e6)
    F_r2: float = _number("N", "resistance on module 2 while it slides (wall-press rolling resistance)", 1.0,
                          0.0, 1e6)
    M: float = _number("N m", "constant motor torque on the crank (drive = torque, the paper's case)", 0.25,
                       -1e6, 1e6)
    rod_mass: float = _number("kg", "connecting-rod mass (the paper neglects it)", 0.01, 0.0, 1e4)
    rod_inertia: float | None = _number("kg m^2", "rod inertia about its centre of mass", None, 0.0, 1e4,
                                        none_word="uniform", none_text="uniform slender rod, rod_mass L^2 / 12")
    phi0: float = _number("rad", "initial crank angle (0 = crank pointing at module 2, full extension)", 0.0,
                          -1e4, 1e4)
    omega0: float = _number("rad/s", "initial crank speed", 0.0, -1e4, 1e4)
    drive: str = _choice("what turns the crank: 'torque' = the constant M; 'motor' = a DC gearmotor, "
                         "torque M_stall (1 - omega / omega_noload); 'servo' = that motor at a voltage fraction u "
                         "in [-1, 1] set by a speed controller, torque M_stall (u - omega / omega_noload)",
                         "torque", DRIVES)
    M_stall: float = _number("N m", "motor stall torque at the crank (drive = motor or servo)", 0.5, 0.0, 1e6,
                             low_open=True)
    omega_noload: float = _number("rad/s", "motor no-load crank speed (drive = motor or servo)", 30.0, 0.0, 1e5,
                                  low_open=True)
    clutch_stiffness: float | None = _number("N/m", "stiffness of each one-way clutch once engaged", None, 0.0,
                                             1e12, low_open=True, none_word="rigid",
                                             none_text="rigid, ideal clutches")
    clutch_damping: float = _number("N s/m", "damping of each one-way clutch while engaged", 0.0, 0.0, 1e9)
    clutch_backlash: float = _number("m", "free play of each one-way clutch before it engages", 0.0, 0.0, 10.0)
    incline: float = _number("deg", "pipe axis above the horizontal (90 = vertical climb, negative = downhill)",
                             0.0, -90.0, 90.0)
    g: float = _number("m/s^2", "gravitational acceleration", 9.81, 0.0, 100.0)
    mu_wall: float | None = _number("-", "wheel-wall friction coefficient, static = kinetic: a held module's locked "
                                    "wheels grip the wall with at most G_i = mu_wall F_ni, beyond that it skids "
                                    "back (rubber on steel 0.5-1; the bound 10 is far above any wheel)",
                                    None, 0.0, 10.0, none_word="unlimited",
                                    none_text="a held module's clutch holds any force")
    F_n1: float = _number("N", "wall-press normal force on module 1's wheels, all together (the grip with a finite "
                          "mu_wall; the wheeled MuJoCo model's leg preload whatever mu_wall is); "
                          "the default with F_r1 = 1 N is a rolling-resistance coefficient of 0.02, as for hard "
                          "polyurethane wheels on steel", 50.0, 0.0, 1e6)
    F_n2: float = _number("N", "wall-press normal force on module 2's wheels, all together (as F_n1); "
                          "default as F_n1", 50.0, 0.0, 1e6)
    pipe_diameter: float = _number("m", "inside diameter of the pipe (the wheeled MuJoCo model's walls; must exceed "
                                   "2 r and 4 wheel_radius); the default fits the paper's design", 0.16, 0.0, 10.0,
                                   low_open=True)
    wheel_radius: float = _number("m", "radius of the wheeled MuJoCo model's wheels (below pipe_diameter / 4)", 0.015,
                                  0.0, 1.0, low_open=True)
    wheel_legs: float = _number("-", "wheel legs per ring of the wheeled MuJoCo model, evenly spaced about the pipe's "
                                "axis (two rings per module; a whole number)", 3.0, 3.0, 8.0)
    suspension_travel: float = _number("m", "each wheel leg's spring deflection at its preload (the wheeled MuJoCo "
                                       "model: stiffness = preload / suspension_travel; the arm stops at the "
                                       "spring's free length and at 4 x suspension_travel compression)", 0.005,
                                       0.0, 0.05, low_open=True)
    ring_spacing: float = _number("m", "distance along the pipe between a module's two rings of wheel legs (the "
                                  "wheeled MuJoCo model; it carries the module's pitch and yaw moments)", 0.1,
                                  0.0, 1.0, low_open=True)
    cornering_coefficient: float | None = _number(
        "1/rad", "each wheel's cornering stiffness over its leg's preload (the wheeled MuJoCo model): a rolling "
        "wheel's side force grows from zero with its slip angle, cornering_coefficient x preload x slip angle, up "
        "to mu_wall times its press, where it slides; 8 /rad: Kalker's rolling-contact theory for a 15 mm "
        "polyurethane wheel at its 8.3 N preload, within car tyres' 6-11 /rad (mjcf/README.md)", 8.0, 0.0, 100.0,
        low_open=True, none_word="rigid",
        none_text="wheels fixed on their axles: sideways, Coulomb friction at any slip angle")

    omega_target: float = _number("rad/s", "crank speed the speed controller holds (drive = servo; below "
                                  "omega_noload)", 10.0, 0.0, 1e5, low_open=True)
    speed_dip: float = _number("-", "drive = servo: how far the speed target dips through the dead centres, where "
                               "the modules hand over: omega_ref = omega_0 (1 - speed_dip cos 2 phi), omega_0 = "
                               "omega_target / sqrt(1 - speed_dip^2), so the mean crank speed stays omega_target "
                               "(0: constant speed)", 0.0, 0.0, 0.9)
    feedforward: str = _choice("drive = servo: the torque table added to the PI controller, from inverse "
                               "kinetostatics at omega_target: 'none' (PI alone), 'paper' (the paper's first-order "
                               "geometry, L >> r), 'exact' (the exact slider-crank)", "none", FEEDFORWARDS)
    control_rate: float = _number("Hz", "rate of the speed controller's ticks; u is held between them (drive = "
                                  "servo)", 1000.0, 0.0, 1e5, low_open=True)
    speed_kp: float | None = _number("s/rad", "speed controller's proportional gain, u per rad/s of speed error "
                                     "(drive = servo)", None, 0.0, 1e4, none_word="model",
                                     none_text="derived from the model, docs/control.md")
    speed_ki: float | None = _number("1/rad", "speed controller's integral gain, u per rad of integrated speed "
                                     "error (drive = servo)", None, 0.0, 1e8, none_word="model",
                                     none_text="derived from the model, docs/control.md")

    def __post_init__(self) -> None:
        for f in dataclasses.fields(self):
            meta = f.metadata
            value = getattr(self, f.name)
            if meta["kind"] == "choice":
                if not isinstance(value, str):
                    raise ParameterTypeError(f"{f.name}={value!r} is not a string; allowed: "
                                             f"{', '.join(meta['choices'])}")
                if value not in meta["choices"]:
                    raise ParameterError(f"{f.name}={value!r} is unknown; allowed: {', '.join(meta['choices'])}")
                continue
            if value is None and meta["none_word"] is not None:
                continue
            number = as_real(value)
            if number is None:  # a wrong type: a ParameterTypeError (a TypeError too)
                raise ParameterTypeError(f"{f.name}={value!r} is not a number; allowed: {allowed_text(f.name)}")
            if not math.isfinite(number):
                raise ParameterError(f"{f.name}={number} is not finite; allowed: {allowed_text(f.name)}")
            if not _inside(number, meta):
                raise ParameterError(f"{f.name}={value!r} is out of range; allowed: {allowed_text(f.name)}")
            object.__setattr__(self, f.name, number)  # one type inside: a plain float
        if self.wheel_legs != int(self.wheel_legs):
            raise ParameterError(f"wheel_legs={self.wheel_legs!r} is not a whole number; allowed: "
                                 f"{allowed_text('wheel_legs')}")
        if not self.L > self.r:
            raise ParameterError(
                f"L={self.L} m with r={self.r} m: the connecting rod must be longer than the crank "
                f"(allowed: L > r), or the linkage locks or cannot close")
        if self.mu_wall is not None:
            for name in ("F_n1", "F_n2"):
                if not getattr(self, name) > 0:
                    raise ParameterError(
                        f"{name}={getattr(self, name)!r} N with mu_wall={self.mu_wall!r}: a finite grip needs the "
                        f"wheels pressed on; allowed: 0 < {name} <= 1e+06 N, or mu_wall=unlimited")
        if self.drive == "servo" and not self.omega_target < self.omega_noload:
            raise ParameterError(
                f"omega_target={self.omega_target:g} rad/s is out of range; allowed: 0 < omega_target < "
                f"omega_noload = {self.omega_noload:g} rad/s (at full voltage the motor turns the crank no faster)")
        if self.drive == "servo" and self.speed_dip > 0:
            fastest = self.omega_target * math.sqrt((1 + self.speed_dip) / (1 - self.speed_dip))
            if not fastest < self.omega_noload:
                raise ParameterError(
                    f"speed_dip={self.speed_dip:g} with omega_target={self.omega_target:g} rad/s is out of range: "
                    f"the target's fastest, mid-stroke, is {fastest:.4g} rad/s; allowed: below omega_noload = "
                    f"{self.omega_noload:g} rad/s (a smaller speed_dip or omega_target)")
        if not self.clutch_backlash <= 0.5 * self.r:
            raise ParameterError(
                f"clutch_backlash={self.clutch_backlash} m is out of range; allowed: 0 <= clutch_backlash <= "
                f"r / 2 = {0.5 * self.r:g} m (a quarter of the stroke 2r; more play would lose most of every stroke)")

    @property
    def rod_inertia_value(self) -> float:
        """Rod inertia about its centre of mass in use [kg m^2]."""
        if self.rod_inertia is None:
            return self.rod_mass * self.L**2 / 12.0
        return self.rod_inertia

    @property
    def rigid_clutches(self) -> bool:
        """True for ideal clutches (no ``clutch_stiffness`` given)."""
        return self.clutch_stiffness is None

    @property
    def grip(self) -> tuple[float, float] | None:
        """(G1, G2) [N], the most each module's locked wheels hold against the wall (mu_wall F_ni); None
        with unlimited grip (``mu_wall`` left as None)."""
        if self.mu_wall is None:
            return None
        return self.mu_wall * self.F_n1, self.mu_wall * self.F_n2

    def as_dict(self) -> dict[str, Any]:
        """Every parameter with the value in use (rod inertia resolved; rigid clutch stiffness None)."""
        values = {f.name: getattr(self, f.name) for f in dataclasses.fields(self)}
        values["rod_inertia"] = self.rod_inertia_value
        return values

    def replace(self, **changes: Any) -> "RobotParams":
        """A copy with some values changed (validated like a new set). ``drive`` given (the same or another)
        also returns every drive's parameter that drive does not act through (DRIVE_FIELDS: M for the constant
        torque, M_stall and omega_noload for the motor and the servo, the speed controller's SERVO_FIELDS), if not
        given in ``changes``, to its default: a run would refuse it
        (:func:`.drive_fields.refuse_idle_parameters`). So a study that runs one design under several drives
        names the drive of each case, and each case keeps what its drive uses."""
        drive = changes.get("drive")
        if drive in DRIVE_FIELDS:
            for name in _DRIVEN_BY:
                if name not in DRIVE_FIELDS[drive]:
                    changes.setdefault(name, _FIELDS[name].default)
        return dataclasses.replace(self, **changes)


_generated_init = RobotParams.__init__


@functools.wraps(_generated_init)
def _init(self, *args, **kwargs):
    # an unknown keyword is bad input like any other: a ParameterError naming it, not a TypeError
    unknown = [name for name in kwargs if name not in PARAMETER_NAMES]
    if unknown:
        raise ParameterError(_unknown_message(unknown[0]))
    if len(args) > len(PARAMETER_NAMES):
        raise ParameterError(f"RobotParams takes at most {len(PARAMETER_NAMES)} values; give them by name")
    _generated_init(self, *args, **kwargs)


RobotParams.__init__ = _init

PARAMETER_NAMES: tuple[str, ...] = tuple(f.name for f in dataclasses.fields(RobotParams))
_FIELDS = {f.name: f for f in dataclasses.fields(RobotParams)}


def _inside(x: float, meta: Mapping[str, Any]) -> bool:
    low_ok = x > meta["low"] if meta["low_open"] else x >= meta["low"]
    high_ok = x < meta["high"] if meta["high_open"] else x <= meta["high"]
    return low_ok and high_ok


def allowed_text(name: str) -> str:
    """The allowed values of parameter ``name`` in words, e.g. '0 < m1 <= 10000 kg'."""
    meta = _FIELDS[name].metadata
    if meta["kind"] == "choice":
        return " or ".join(meta["choices"])
    low = f"{meta['low']:g} {'<' if meta['low_open'] else '<='} "
    high = f" {'<' if meta['high_open'] else '<='} {meta['high']:g}"
    text = f"{low}{name}{high}" + (f" {meta['units']}" if meta["units"] != "-" else "")  # no unit: a ratio
    if name == "L":
        text += ", and L > r"
    if name == "omega_target":
        text = f"0 < omega_target < omega_noload {meta['units']}"
    if name == "clutch_backlash":
        text = f"0 <= clutch_backlash <= r / 2 {meta['units']}"
    if name in ("F_n1", "F_n2"):
        text += f", and {name} > 0 with a finite mu_wall"
    if name == "wheel_legs":
        text += ", a whole number"
    if meta["none_word"]:
        text += f", or '{meta['none_word']}' ({meta['none_text']})"
    return text


def check_own_range(name: str, value: Any) -> float:
    """``value`` as a float if it lies in parameter ``name``'s own allowed range (its row of the table alone, not
    the rules that tie it to other parameters, as L > r), else a one-line ParameterError naming it: the check of
    a range of designs (a study's ``--vary``) before any design is made. A parameter that is not a number
    (``drive``, ``feedforward``) is refused here too."""
    meta = _FIELDS[name].metadata
    if meta["kind"] != "number":
        raise ParameterError(f"{name} is not a number (allowed: {allowed_text(name)}); a study varies numeric "
                             "parameters only (give it with --set or --drive)")
    number = as_real(value)
    if number is None or not math.isfinite(number) or not _inside(number, meta):
        raise ParameterError(f"{name}={value!r} is out of range; allowed: {allowed_text(name)}")
    return number


def describe_parameters() -> list[dict[str, Any]]:
    """Every parameter: name, meaning, unit, default and allowed range (for listings and reports)."""
    rows = []
    for name, f in _FIELDS.items():
        meta = f.metadata
        default = f.default
        if default is None:
            default_text = meta["none_word"]
        else:
            default_text = default if isinstance(default, str) else f"{default:g}"
        rows.append({"name": name, "meaning": meta["doc"], "units": meta["units"], "default": default,
                     "default_text": str(default_text), "allowed": allowed_text(name)})
    return rows


def _parameters_section() -> str:
    """RobotParams' numpydoc ``Parameters`` section, written from the fields' own metadata (one definition)."""
    import textwrap

    lines = ["", "", "    Parameters", "    ----------"]
    for row in describe_parameters():
        lines.append(f"    {row['name']} : {row['units']}")
        text = f"{row['meaning']}. Default {row['default_text']}; allowed {row['allowed']}."
        lines += textwrap.wrap(text, 110, initial_indent=" " * 8, subsequent_indent=" " * 8)
    lines += ["", "    Raises", "    ------", "    ParameterError",
              "        A value out of its range, an unknown choice, or fields that do not fit together (one line).", ""]
    return "\n".join(lines)


RobotParams.__doc__ = RobotParams.__doc__.rstrip() + _parameters_section()


def parameter_units(name: str) -> str:
    """The unit of parameter ``name`` ('-' for a choice)."""
    return _FIELDS[name].metadata["units"]


def parameter_meaning(name: str) -> str:
    return _FIELDS[name].metadata["doc"]


def _unknown_message(name: str) -> str:
    return f"unknown parameter {name!r}; known parameters: {' '.join(PARAMETER_NAMES)} (see 'ipir-mujoco params')"


def require_params(params: Any) -> RobotParams:
    """``params`` if it is a :class:`RobotParams`, else a ParameterError (for the Python API's entry points)."""
    if not isinstance(params, RobotParams):
        raise ParameterTypeError(f"params={params!r} is not a RobotParams; build one with RobotParams(...) "
                             "or load_params(...)")
    return params
