"""Checks of single values shared by the parameter set (:mod:`.params`), the run options (:mod:`.options`),
the study files and the Python API: is it a real number, inside an interval, a whole number. Each refuses
bad input with a :class:`ParameterError` naming the value and the allowed range in one line."""

from __future__ import annotations

import decimal
import math
import numbers
from typing import Any

from .errors import ParameterError, ParameterTypeError


def as_real(value: Any) -> float | None:
    """``value`` as a float if it is a real number of any numeric type (int, float, numpy scalar or
    0-d array, Fraction, Decimal); None otherwise (bool, complex, strings, containers)."""
    if isinstance(value, bool):
        return None
    if isinstance(value, (numbers.Real, decimal.Decimal)):
        try:
            return float(value)
        except (OverflowError, ValueError):
            return math.inf
    shape, kind = getattr(value, "shape", None), getattr(getattr(value, "dtype", None), "kind", None)
    if shape == () and kind in ("i", "u", "f"):  # a 0-d numpy array
        return float(value)
    return None


def check_real(name: str, value: Any, *, low: float = 0.0, high: float = math.inf, low_open: bool = True,
               unit: str = "") -> float:
    """``value`` as a float if it is a finite real number (any numeric type) inside the interval; else a
    ParameterError naming ``name``, the value and the allowed range."""
    unit_text = f" {unit}" if unit else ""
    low_text = f"{low:g} {'<' if low_open else '<='} {name}"
    allowed = low_text + (f" <= {high:g}{unit_text}" if math.isfinite(high) else unit_text)
    number = as_real(value)
    if number is None:  # a wrong type (None, a string, a list): a ParameterTypeError, a TypeError too
        raise ParameterTypeError(f"{name}={value!r} is not a number; allowed: {allowed}")
    if not math.isfinite(number) or not (number > low if low_open else number >= low) or number > high:
        raise ParameterError(f"{name}={_shown(value)} is out of range; allowed: {allowed}")
    return number


def _shown(value: Any) -> str:
    """A number as the message shows it: 1e+09 rather than 1000000000.0; -1.0 and 0.25 as written."""
    if isinstance(value, float) and math.isfinite(value) and value != 0 and not 1e-4 <= abs(value) < 1e6:
        return f"{value:g}"
    return repr(value)


def check_whole(name: str, value: Any, *, low: int = 0, high: int | None = None, why: str = "") -> int:
    """``value`` as an int if it is a whole number (int, numpy integer, or an integral float) in
    [low, high]; else a ParameterError naming it. ``why`` explains the upper limit."""
    allowed = f"a whole number >= {low}" + (f" and <= {high}{why}" if high is not None else "")
    number = as_real(value)
    if number is None:
        raise ParameterTypeError(f"{name}={value!r} is not a whole number; allowed: {allowed}")
    if not math.isfinite(number) or number != int(number):
        raise ParameterError(f"{name}={value!r} is not a whole number; allowed: {allowed}")
    whole = int(number)
    if whole < low or (high is not None and whole > high):
        raise ParameterError(f"{name}={_shown(value)} is out of range; allowed: {allowed}")
    return whole


def check_text(name: str, value: Any, allowed: str) -> str:
    """``value`` if it is a string (a name, a choice, a specification to parse), else a ParameterTypeError naming
    the argument and what is allowed (``allowed``): a wrong type from the Python API, not an AttributeError or a
    TypeError from inside a parser."""
    if not isinstance(value, str):
        raise ParameterTypeError(f"{name}={value!r} ({type(value).__name__}) is not a string; allowed: {allowed}")
    return value


def check_path(name: str, value: Any, allowed: str = "a str or pathlib.Path") -> Any:
    """``value`` if it is a path (a str or an os.PathLike giving a str), else a ParameterTypeError (bytes, None,
    a number: a wrong type, not a TypeError from inside pathlib)."""
    import os

    if not isinstance(value, (str, os.PathLike)) or isinstance(os.fspath(value), bytes):
        raise ParameterTypeError(f"{name}={value!r} ({type(value).__name__}) is not a path; allowed: {allowed}")
    return value


def check_sequence(name: str, value: Any, allowed: str = "a list or tuple") -> Any:
    """``value`` if it is a list, tuple or 1-d array (not a string, bytes, a dict or a single value), else a
    ParameterTypeError naming it."""
    shape = getattr(value, "shape", None)
    if isinstance(value, (str, bytes, dict)) or not (isinstance(value, (list, tuple, range)) or
                                                      (shape is not None and len(shape) == 1)):
        raise ParameterTypeError(f"{name}={value!r} ({type(value).__name__}) is not a list; allowed: {allowed}")
    return value


def check_numbers(name: str, value: Any, allowed: str = "a list of numbers") -> tuple[float, ...]:
    """``value`` as a tuple of floats if it is a list, tuple, range or 1-d array of real numbers (not a string,
    bytes or a single number), else a ParameterTypeError naming it."""
    check_sequence(name, value, allowed)
    numbers = [as_real(v) for v in value]
    if any(n is None for n in numbers):
        bad = next(v for v, n in zip(value, numbers) if n is None)
        raise ParameterTypeError(f"{name} holds {bad!r}, not a number; allowed: {allowed}")
    return tuple(numbers)
