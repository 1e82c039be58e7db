"""The robot's parameter set, shared by every engine.

One frozen dataclass, SI units throughout, validated on construction. Defaults
are the paper's simulation case (see ``shared/paper/MODEL.md``); the rod's mass,
which the paper neglects, defaults to a small positive value so that the
exact-geometry model and the MuJoCo model (which needs a body with mass) can
agree on the same mechanism.

Build one from defaults, a TOML file and ``NAME=VALUE`` overrides with
:func:`load_params`.
"""

from __future__ import annotations

import dataclasses
import math
import tomllib
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Iterable, Mapping

from .errors import ParameterError


def _doc(units: str, text: str) -> dict[str, str]:
    return {"units": units, "doc": text}


@dataclass(frozen=True)
class RobotParams:
    """Parameters of the two-module inchworm robot (SI units).

    ``rod_inertia`` left as ``None`` means a uniform slender rod,
    ``rod_mass * L**2 / 12``; read the value in use from
    :attr:`rod_inertia_value`.
    """

    m1: float = field(default=1.0, metadata=_doc("kg", "mass of module 1 (rear, carries the crank)"))
    m2: float = field(default=1.0, metadata=_doc("kg", "mass of module 2 (front)"))
    r: float = field(default=0.05, metadata=_doc("m", "crank length AB"))
    L: float = field(default=0.2, metadata=_doc("m", "connecting-rod length BC"))
    J_A: float = field(default=0.001, metadata=_doc("kg m^2", "crank + rotor inertia about A"))
    F_r1: float = field(default=1.0, metadata=_doc("N", "resistance on module 1 while it moves forward"))
    F_r2: float = field(default=1.0, metadata=_doc("N", "resistance on module 2 while it moves forward"))
    M: float = field(default=0.25, metadata=_doc("N m", "constant motor torque on the crank"))
    rod_mass: float = field(default=0.01, metadata=_doc("kg", "connecting-rod mass (paper: neglected)"))
    rod_inertia: float | None = field(
        default=None, metadata=_doc("kg m^2", "rod inertia about its centre of mass; default uniform rod")
    )
    phi0: float = field(default=0.0, metadata=_doc("rad", "initial crank angle (0 = full extension)"))
    omega0: float = field(default=0.0, metadata=_doc("rad/s", "initial crank speed"))

    def __post_init__(self) -> None:
        for f in dataclasses.fields(self):
            value = getattr(self, f.name)
            if value is None and f.name == "rod_inertia":
                continue
            if isinstance(value, bool) or not isinstance(value, (int, float)):
                raise ParameterError(f"{f.name}={value!r} is not a number; {f.name} takes a real number in {f.metadata['units']}")
            if not math.isfinite(value):
                raise ParameterError(f"{f.name}={value} is not finite; allowed: a finite number in {f.metadata['units']}")
        for name in ("m1", "m2", "r", "L", "J_A"):
            _require(name, getattr(self, name), "> 0", getattr(self, name) > 0)
        for name in ("F_r1", "F_r2", "rod_mass"):
            _require(name, getattr(self, name), ">= 0", getattr(self, name) >= 0)
        if self.rod_inertia is not None:
            _require("rod_inertia", self.rod_inertia, ">= 0", self.rod_inertia >= 0)
        if not self.L > self.r:
            raise ParameterError(
                f"L={self.L} m with r={self.r} m: the connecting rod must be longer than the crank "
                f"(allowed: L > r), or the linkage locks or cannot close"
            )

    @property
    def rod_inertia_value(self) -> float:
        """Rod inertia about its centre of mass in use [kg m^2]."""
        if self.rod_inertia is None:
            return self.rod_mass * self.L**2 / 12.0
        return self.rod_inertia

    def as_dict(self) -> dict[str, float]:
        """Every parameter with the value in use (rod inertia resolved)."""
        values = {f.name: getattr(self, f.name) for f in dataclasses.fields(self)}
        values["rod_inertia"] = self.rod_inertia_value
        return values

    def replace(self, **changes: Any) -> "RobotParams":
        """A copy with some values changed (validated like a new set)."""
        unknown = sorted(set(changes) - set(PARAMETER_NAMES))
        if unknown:
            raise ParameterError(_unknown_message(unknown[0]))
        return dataclasses.replace(self, **changes)


def _require(name: str, value: float, allowed: str, ok: bool) -> None:
    if not ok:
        units = RobotParams.__dataclass_fields__[name].metadata["units"]
        raise ParameterError(f"{name}={value} is out of range; allowed: {name} {allowed} ({units})")


PARAMETER_NAMES: tuple[str, ...] = tuple(f.name for f in dataclasses.fields(RobotParams))


def _unknown_message(name: str) -> str:
    return f"unknown parameter {name!r}; known parameters: {' '.join(PARAMETER_NAMES)}"


def parse_overrides(items: Iterable[str]) -> dict[str, float]:
    """Parse ``NAME=VALUE`` strings into a dict of floats.

    Raises :class:`ParameterError` for a malformed item, an unknown name or a
    value that is not a number. Range checks happen when the set is built.
    """
    values: dict[str, float] = {}
    for item in items:
        name, sep, text = item.partition("=")
        name = name.strip()
        if not sep or not name:
            raise ParameterError(f"--set {item!r} is malformed; expected NAME=VALUE, e.g. L=0.3")
        if name not in PARAMETER_NAMES:
            raise ParameterError(_unknown_message(name))
        try:
            values[name] = float(text)
        except ValueError:
            raise ParameterError(f"{name}={text!r} is not a number; {name} takes a real number") from None
    return values


def read_toml(path: str | Path) -> dict[str, float]:
    """Read parameter values from a TOML file.

    Parameters may stand at the top level or in a ``[params]`` table. Any other
    key is an error, so a typo never passes silently.
    """
    path = Path(path)
    try:
        with path.open("rb") as fh:
            data = tomllib.load(fh)
    except FileNotFoundError:
        raise ParameterError(f"config file {str(path)!r} does not exist") from None
    except OSError as exc:
        raise ParameterError(f"config file {str(path)!r} cannot be read: {exc.strerror}") from None
    except tomllib.TOMLDecodeError as exc:
        raise ParameterError(f"config file {str(path)!r} is not valid TOML: {exc}") from None
    table = dict(data)
    nested = table.pop("params", {})
    if not isinstance(nested, dict):
        raise ParameterError(f"config file {str(path)!r}: 'params' must be a table, got {nested!r}")
    values: dict[str, float] = {}
    for name, value in list(table.items()) + list(nested.items()):
        if name not in PARAMETER_NAMES:
            raise ParameterError(f"config file {str(path)!r}: {_unknown_message(name)}")
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise ParameterError(f"config file {str(path)!r}: {name}={value!r} is not a number")
        values[name] = float(value)
    return values


def load_params(
    config: str | Path | None = None,
    overrides: Iterable[str] | Mapping[str, float] = (),
) -> RobotParams:
    """Defaults, then the TOML file ``config``, then ``overrides`` (last wins)."""
    values: dict[str, float] = {}
    if config is not None:
        values.update(read_toml(config))
    if isinstance(overrides, Mapping):
        unknown = [n for n in overrides if n not in PARAMETER_NAMES]
        if unknown:
            raise ParameterError(_unknown_message(unknown[0]))
        values.update(overrides)
    else:
        values.update(parse_overrides(overrides))
    return RobotParams(**values)
