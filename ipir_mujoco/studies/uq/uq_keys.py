"""What an uncertainty study measures: its metric keys, their units and words, and its events.

A metric (``--metric KEY``) is one of :data:`KEYS`: a run's summary number (:data:`SUMMARY_KEYS`), a sweep
metric or one of :data:`DERIVED`; an event (``--event``) is ``KEY>V`` (also ``<``, ``>=``, ``<=``) or a name of
:data:`NAMED_EVENTS`, read by :func:`parse_event` into an :class:`Event`. :func:`key_words` and
:func:`event_words` put them in words for the figure. :mod:`.uncertainty` runs the study.
"""

from __future__ import annotations

import math
import operator
from dataclasses import dataclass

import numpy as np

from ipir_mujoco.core.checks import check_text
from ipir_mujoco.core.errors import ParameterError

from ...labels import SUMMARY
from ..sweeps.sweep_metrics import METRICS, UNITS


# a run's number beside its summary's and the sweep metrics: [unit] meaning
DERIVED = {"travel_m": "m: mean travel of the two modules over the run, (x1_final + x2_final) / 2 (< 0: slid back)",
           "skid_m": "m: the larger module's backward skid on the wall, max(slip1_m, slip2_m)"}
SUMMARY_KEYS = ("revolutions", "x1_final", "x2_final", "v1_max", "v2_max", "first_contraction_end_s", "mode_switches",
                "min_clutch_reaction_n", "slip1_m", "slip2_m", "peak_grip_use", "cycles", "cycle_energy_residual_j",
                "motor_work_j", "kinetic_j", "friction_j", "residual_j", "wheel_off_s", "press1_n", "press2_n",
                "route_done", "route_time_s")
KEYS = tuple(dict.fromkeys((*METRICS, *SUMMARY_KEYS, *DERIVED)))
KEY_UNITS = {**{k: u for k, (_, u) in SUMMARY.items()}, **UNITS, "x1_final": "m", "x2_final": "m", "v1_max": "m/s",
             "v2_max": "m/s", "slip1_m": "m", "slip2_m": "m", "peak_grip_use": "-", "motor_work_j": "J",
             "kinetic_j": "J", "friction_j": "J", "residual_j": "J", "wheel_off_s": "s", "press1_n": "N",
             "press2_n": "N", "route_time_s": "s", "travel_m": "m", "skid_m": "m"}
# every key in words, for the figure: the summary's and the sweep's names, and those of the keys only a run has
_WORDS = {"slip1_m": "backward skid, module 1", "slip2_m": "backward skid, module 2", "peak_grip_use": "peak grip use",
          "motor_work_j": "motor work", "kinetic_j": "kinetic energy", "friction_j": "work of the resistances",
          "residual_j": "energy residual", "wheel_off_s": "time a wheel is off the wall",
          "press1_n": "wall press, module 1", "press2_n": "wall press, module 2", "route_time_s": "time along the route",
          "route_done": "route completed", "travel_m": "travel (mean of the modules)",
          "skid_m": "larger backward skid", "cycles": "crank cycles", "cycle_energy_residual_j":
          "energy residual over the cycles", "mean_speed_mps": "mean forward speed",
          "accel_jump_mps2": "acceleration jump at a clutch switch"}
NAMED_WORDS = {"stall": "stalls", "no-steady-state": "no steady state", "slides-back": "slides back (travel < 0 m)"}


def key_words(key: str) -> tuple[str, str]:
    """(words, unit) of a metric key: ('energy per metre', 'J/m') for 'energy_per_metre_j_m'."""
    from ..sweeps.sweep_metrics import DESCRIBED

    words = DESCRIBED.get(key, SUMMARY.get(key, (_WORDS.get(key, key.replace("_", " ")), "")))[0]
    return _WORDS.get(key, words), KEY_UNITS.get(key, "-")


def event_words(text: str) -> str:
    """An event in words: 'slides back (travel < 0 m)', 'larger backward skid > 0.05 m' for 'skid_m>0.05'."""
    event = parse_event(text)
    if event.text in NAMED_WORDS:
        return NAMED_WORDS[event.text]
    words, unit = key_words(event.key)
    return f"{words} {event.op} {event.value:g}" + ("" if unit in ("-", "0/1") else f" {unit}")


NAMED_EVENTS = {"stall": ("stalled", ">", 0.5), "no-steady-state": ("steady", "<", 0.5),
                "slides-back": ("travel_m", "<", 0.0)}
OPERATORS = {">=": operator.ge, "<=": operator.le, ">": operator.gt, "<": operator.lt}


@dataclass(frozen=True)
class Event:
    """``key op value``, with the text the user gave (its name in the output)."""

    text: str
    key: str
    op: str
    value: float

    def hits(self, values: np.ndarray) -> np.ndarray:
        """Booleans of shape (n,): the samples with the event (a missing value, NaN, is not the event)."""
        with np.errstate(invalid="ignore"):
            return np.isfinite(values) & OPERATORS[self.op](values, self.value)


def check_metric(key: str) -> str:
    key = key.strip()
    if key not in KEYS:
        raise ParameterError(f"--metric {key!r} is unknown; allowed: {', '.join(KEYS)}")
    return key


def parse_event(text: str) -> Event:
    """``KEY>V``, ``KEY>=V``, ``KEY<V``, ``KEY<=V`` or a name of :data:`NAMED_EVENTS`."""
    spec = check_text("event", text, "'KEY>V', 'KEY>=V', 'KEY<V', 'KEY<=V' or " + ", ".join(NAMED_EVENTS)).strip()
    if spec in NAMED_EVENTS:
        return Event(spec, *NAMED_EVENTS[spec])
    for op in (">=", "<=", ">", "<"):
        key, sep, value = spec.partition(op)
        if sep:
            key = key.strip()
            if key not in KEYS:
                raise ParameterError(f"--event {text!r}: unknown key {key!r}; allowed: {', '.join(KEYS)}")
            try:
                number = float(value)
            except ValueError:
                raise ParameterError(f"--event {text!r}: {value.strip()!r} is not a number") from None
            if not math.isfinite(number):
                raise ParameterError(f"--event {text!r}: the threshold must be finite")
            return Event(spec, key, op, number)
    raise ParameterError(f"--event {text!r} is malformed; allowed: KEY>V, KEY>=V, KEY<V, KEY<=V or one of "
                         f"{', '.join(NAMED_EVENTS)}")
