"""The robot's parameter set, shared by every engine and every interface.

One frozen dataclass, defined once: each field carries its meaning, unit,
default and allowed range in its metadata, and everything else reads them from
there: validation on construction, ``NAME=VALUE`` parsing, TOML files, the
``ipir-mujoco params`` listing, ``--help`` and the reports. Units are SI except
``incline``, which is in degrees as users state pipe slopes.

Defaults are the paper's simulation case, with a horizontal pipe and ideal,
rigid clutches (:mod:`.param_table` says which and why).

Build one from defaults, a TOML file and ``NAME=VALUE`` overrides with
:func:`load_params`; list them with :func:`describe_parameters`.

This module is the place to import every name of the parameter set from. It holds the readers of a set's
text forms (``NAME=VALUE`` overrides, TOML files, :func:`load_params`) and re-exports the rest, which lives
below it: the table itself, :class:`RobotParams` with its checks and the words of its ranges, in
:mod:`.param_table`; which parameters act through which drive, and the refusal of one that nothing acts
through, in :mod:`.drive_fields`; the checks of single values in :mod:`.checks`; the reading of users' files
in :mod:`.files`.
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any, Iterable, Mapping

from .checks import as_real, check_real, check_whole  # noqa: F401  (re-exported: their home was here)
from .drive_fields import (DRIVE_FIELDS, DRIVES, FEEDFORWARDS, MOTOR_FIELDS, SERVO_FIELDS,  # noqa: F401
                           refuse_idle_names, refuse_idle_parameters, refuse_idle_under)  # (re-exported)
from .errors import ParameterError, ParameterTypeError
from .files import MAX_TEXT_BYTES, read_text_file, read_toml_file  # noqa: F401  (re-exported)
from .param_table import (_FIELDS, PARAMETER_NAMES, RobotParams, _unknown_message, allowed_text,  # noqa: F401
                          check_own_range, describe_parameters, parameter_meaning, parameter_units,
                          require_params)  # (re-exported: their home was here)


def parse_value(name: str, text: str) -> Any:
    """The value of parameter ``name`` from its text form (as on the command line)."""
    if name not in _FIELDS:
        raise ParameterError(_unknown_message(name))
    meta = _FIELDS[name].metadata
    text = text.strip()
    if meta["kind"] == "choice":
        return text
    if meta["none_word"] is not None and text.lower() == meta["none_word"]:
        return None
    try:
        return float(text)
    except ValueError:
        raise ParameterError(f"{name}={text!r} is not a number; allowed: {allowed_text(name)}") from None


def parse_overrides(items: Iterable[str]) -> dict[str, Any]:
    """Parse ``NAME=VALUE`` strings into a dict of values.

    Raises :class:`ParameterError` for a malformed item, an unknown name or a
    value that is not a number. Range checks happen when the set is built.
    """
    if isinstance(items, (str, bytes)) or not isinstance(items, Iterable):
        raise ParameterTypeError(f"overrides={items!r} is not a list of NAME=VALUE strings; allowed: e.g. "
                                 "['L=0.3', 'm2=2']")
    values: dict[str, Any] = {}
    for item in items:
        if not isinstance(item, str):
            raise ParameterTypeError(f"overrides holds {item!r}, not a NAME=VALUE string; allowed: e.g. ['L=0.3']")
        name, sep, text = item.partition("=")
        name = name.strip()
        if not sep or not name:
            raise ParameterError(f"--set {item!r} is malformed; expected NAME=VALUE, e.g. L=0.3")
        values[name] = parse_value(name, text)
    return values


def read_toml(path: str | Path) -> dict[str, Any]:
    """Read parameter values from a TOML file.

    Parameters may stand at the top level or in a ``[params]`` table. Any other
    key is an error, so a typo never passes silently.
    """
    table = dict(read_toml_file(path, "config file"))
    nested = table.pop("params", {})
    if not isinstance(nested, dict):
        raise ParameterError(f"config file {str(path)!r}: 'params' must be a table, got {nested!r}")
    values: dict[str, Any] = {}
    for name, value in list(table.items()) + list(nested.items()):
        if name not in PARAMETER_NAMES:
            raise ParameterError(f"config file {str(path)!r}: {_unknown_message(name)}")
        meta = _FIELDS[name].metadata
        if meta["kind"] == "number" and isinstance(value, str) and value.strip().lower() == meta["none_word"]:
            value = None
        elif meta["kind"] == "number" and as_real(value) is None:
            raise ParameterError(f"config file {str(path)!r}: {name}={value!r} is not a number; "
                                 f"allowed: {allowed_text(name)}")
        values[name] = value
    return values


def load_params(
    config: str | Path | None = None,
    overrides: Iterable[str] | Mapping[str, Any] = (),
) -> RobotParams:
    """Defaults, then the TOML file ``config``, then ``overrides`` (last wins)."""
    values: dict[str, Any] = {}
    if config is not None:
        if not isinstance(config, (str, os.PathLike)):
            raise ParameterTypeError(f"config={config!r} is not a path; allowed: the path of a TOML file, or None")
        values.update(read_toml(config))
    if isinstance(overrides, Mapping):
        unknown = [n for n in overrides if n not in PARAMETER_NAMES]
        if unknown:
            raise ParameterError(_unknown_message(unknown[0]))
        values.update(overrides)
    else:
        values.update(parse_overrides(overrides))
    return RobotParams(**values)
