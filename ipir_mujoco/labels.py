"""Readable names and units of the summary figures and time-series quantities, and how a figure is written.

Tables, reports and text output show these instead of the code names
(``x1_final``, ``first_contraction_end_s``); the code names stay the keys of
summary.json and metrics.json.
"""

from __future__ import annotations

import functools
import numbers

# summary key -> (name, unit)
SUMMARY: dict[str, tuple[str, str]] = {
    "revolutions": ("crank revolutions", "rev"),
    "x1_final": ("module 1 (rear) travel", "m"),
    "x2_final": ("module 2 (front) travel", "m"),
    "v1_max": ("peak speed, module 1", "m/s"),
    "v2_max": ("peak speed, module 2", "m/s"),
    "first_contraction_end_s": ("end of first contraction", "s"),
    "min_clutch_reaction_n": ("smallest clutch reaction", "N"),
    "mode_switches": ("mode switches", "-"),
    "steady_speed_m_s": ("steady forward speed", "m/s"),
    "distance_per_rev_m": ("distance per revolution", "m"),
    "energy_per_metre_j_m": ("energy per metre", "J/m"),
    "efficiency": ("efficiency", "-"),
    "peak_clutch_force_n": ("peak clutch force", "N"),
    "t_steady_s": ("time to steady state", "s"),
    "mean_omega_rad_s": ("mean crank speed", "rad/s"),
    "speed_ripple": ("crank speed ripple, peak-to-peak / mean", "-"),
}

# time-series column -> name; its unit is the result container's (core.columns.SERIES_UNITS). ``SERIES``
# (column -> (name, unit)) is built at its first use: core.results loads numpy, which a command's --help does not
SERIES_NAMES = {"t": "time", "phi": "crank angle", "omega": "crank speed", "x1": "module 1 position",
                "x2": "module 2 position", "v1": "module 1 velocity", "v2": "module 2 velocity", "S": "gap S",
                "S_dot": "gap rate S_dot"}


@functools.cache
def _series() -> dict[str, tuple[str, str]]:
    from ipir_mujoco.core.results import SERIES_UNITS

    return {column: (name, SERIES_UNITS[column]) for column, name in SERIES_NAMES.items()}


def __getattr__(name: str):
    if name == "SERIES":
        return _series()
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def summary_label(key: str) -> str:
    """'module 1 (rear) travel [m]' for 'x1_final'; the key itself if it has no entry."""
    name, unit = SUMMARY.get(key, (key, ""))
    return f"{name} [{unit}]" if unit and unit != "-" else name


def series_label(key: str) -> str:
    """'gap S [m]' for 'S'; the key itself if it has no entry."""
    name, unit = _series().get(key, (key, ""))
    return f"{name} [{unit}]" if unit else name


def significant(value: float, digits: int) -> str:
    """``value`` to ``digits`` significant digits, trailing zeros kept so that a figure shows its precision
    beside its neighbours ('0.1000', not '0.1', next to '0.1108'); an integer (a count) as it is, and no
    '-0' for a round-off below zero."""
    if isinstance(value, numbers.Integral):
        return str(int(value))
    text = f"{float(value) + 0.0:#.{digits}g}"
    mantissa, e, exponent = text.partition("e")
    return mantissa.rstrip(".") + e + exponent


def signed(value: float, digits: int) -> str:
    """:func:`significant` with a sign ('+26.02', '-16.00', '0.000'): for ranges that cross zero."""
    text = significant(value, digits)
    return text if text.startswith("-") or float(text) == 0 else "+" + text


def fixed(value: float, decimals: int) -> str:
    """``value`` to ``decimals`` places; a value that rounds to zero shows as '0.00', not '-0.00' (a held
    module's round-off speed would otherwise read as moving back)."""
    text = f"{float(value):.{decimals}f}"
    return text.lstrip("-") if float(text) == 0 else text


def signed_percent(fraction: float, decimals: int) -> str:
    """A fraction as a signed percentage to ``decimals`` places ('+0.013 %'); a difference that rounds to
    zero shows as '0.000 %', not '-0.000 %' (its sign would be round-off's)."""
    text = f"{100 * float(fraction):+.{decimals}f}"
    if float(text) == 0:
        text = text.lstrip("+-")
    return text + " %"
