"""The clutch controller protocol: what the run loop asks of a model kind's clutches, and the one meaning of held.

A model kind (:mod:`.kinds`) makes one controller per run, after the initial state is set. The loop
(:mod:`.stepper`) calls :meth:`ClutchController.before_step` before every ``mj_step`` and
``after_step`` (when not None) after it; at each output sample the recorder reads
:meth:`ClutchController.reactions`, :meth:`ClutchController.wheels`, ``excursion`` and ``damper_work``.

Held, one definition for every controller (and the analytic model's): a module is *held* while its clutch
carries it and it stands. A module whose wheels skid back on the wall is not held, even though its clutch
pushes (it carries the grip, G_i, while the module slides); a module that rolls or slides forward is not held.
:func:`held` says it for one module, :func:`held_where` for a column of samples.

The ratchets' running bound (:class:`RunningBound`): a one-way limit that follows the running maximum (or
minimum) of a coordinate, one margin from it, and the largest give below (above) it so far. The slide model's
ratchet, the finite grip's two ratchets per module and the wheels' hub ratchets are each a RunningBound over
their coordinates.
"""

from __future__ import annotations

import math
from typing import Callable, Protocol

import numpy as np

# a module's wheels, as the controllers report them (wheels1/2 columns): rolling forward, standing, skidding back
ROLLING, STANDING, SKIDDING = 1, 0, -1
NO_WHEELS = (0.0, 0.0)  # the wheels' states a controller without wheels reports (none are written)


def held(carries: bool, state: int = STANDING) -> bool:
    """Whether a module is held: its clutch ``carries`` it (pushes, or its static resistance sticks) and its
    wheels' ``state`` (ROLLING, STANDING, SKIDDING) is standing, not skidding back."""
    return carries and state == STANDING


def held_where(carries: np.ndarray, wheels: np.ndarray) -> np.ndarray:
    """:func:`held` per sample: ``carries`` (bool, shape (n,)) and ``wheels`` (float states, shape (n,))."""
    return carries & (wheels != SKIDDING)


class ClutchController(Protocol):
    """What a model kind's clutch controller gives the run loop (every controller in :mod:`.kinds`' kinds).

    Attributes
    ----------
    name : str
        The controller in words (recorded nowhere: for messages).
    excursion : float
        The largest give [m] of a one-way limit so far (a rigid clutch's or the wall's; the compliant clutch's
        backward travel is its physics and not counted), checked before every step.
    damper_work : float
        Cumulative work [J] the clutches' dampers dissipated (0.0 without dampers).
    after_step : Callable[[], None] or None
        Called after every step where the controller needs the step's forces; None where it does not.
    deferred : bool
        True where the clutch forces of a sample are MuJoCo's at the sample's own state, a step later (the
        compliant clutches: ``forces()``, ``overlap``, ``k``, ``stepped_spring_energy()``); the recorder then
        fills reactions and held from them.
    """

    name: str
    excursion: float
    damper_work: float
    after_step: Callable[[], None] | None
    deferred: bool

    def before_step(self) -> None:
        """Move the clutches' limits, anchors or locks for the step about to be taken."""

    def reactions(self) -> tuple[bool, bool, float, float]:
        """(rear held, front held, rear reaction [N], front reaction [N]) of the last step (held: :func:`held`)."""

    def wheels(self) -> tuple[float, float]:
        """Each module's wheels of the last step: ROLLING, STANDING or SKIDDING as floats (NO_WHEELS without)."""

    # optional: load_compiled(loop) -> sync(state values): the controller chooses its compiled form (loop.use(kind),
    # a name in the extension's table of controllers, _clutch_table.c), writes its own block of indices and state
    # into the compiled loop's arrays (loop.set_config, loop.set_state, by its fields' names; loop.getter) and
    # returns how to read its state back after each call; a controller without it steps in the Python loop


class ControllerBase:
    """What most controllers share of :class:`ClutchController`: no after-step work, no damper, no excursion yet,
    forces read at the step (not deferred), no wheels."""

    after_step = None
    damper_work = 0.0
    excursion = 0.0
    deferred = False

    def wheels(self) -> tuple[float, float]:
        """No wheels: NO_WHEELS."""
        return NO_WHEELS


class RunningBound:
    """One-way limits following the running maximum (``upper=False``: a lower limit one margin below it) or the
    running minimum (``upper=True``: an upper limit one margin above it) of some coordinates.

    Parameters
    ----------
    limits : ndarray, shape (n, 2)
        The model's range array the limits are written into (``jnt_range`` or ``tendon_range``), by reference.
    ids : list of int
        The limited elements' rows in ``limits``, one per coordinate.
    start : list of float
        The coordinates' values at the start [m or rad]: the first running extremes.
    margins : list of float
        Each limit's margin [m or rad] (MuJoCo adds a limit row while the distance is below it).
    upper : bool
        Follow the running minimum with an upper limit (the carriages' wall ratchet) instead.
    exact : bool
        Place the bound exactly one margin away (the slide ratchet's ``x - margin``) rather than moved by the
        last ulps until MuJoCo's distance to it is below the margin (:func:`lower_bound`, :func:`upper_bound`).

    Attributes
    ----------
    extremes : list of float
        The running extremes so far.
    """

    def __init__(self, limits, ids, start, margins, *, upper: bool = False, exact: bool = False):
        self.limits, self.ids, self.margins, self.upper = limits, list(ids), list(margins), upper
        self.extremes = [float(v) for v in start]
        self.column = 1 if upper else 0
        self.place = (_exact_lower if exact else lower_bound) if not upper else upper_bound
        for k in range(len(self.ids)):
            self.limits[self.ids[k], self.column] = self.place(self.extremes[k], self.margins[k])

    def follow(self, k: int, value: float) -> float:
        """Move limit ``k`` to ``value`` if it passed the running extreme (returns 0.0); else return how far
        ``value`` has given back from it (>= 0)."""
        extremes = self.extremes
        if (value < extremes[k]) if self.upper else (value > extremes[k]):
            extremes[k] = value
            self.limits[self.ids[k], self.column] = self.place(value, self.margins[k])
            return 0.0
        return value - extremes[k] if self.upper else extremes[k] - value


def _exact_lower(value: float, margin: float) -> float:
    return value - margin


def lower_bound(value: float, margin: float) -> float:
    """The lower bound [m] one margin [m] below ``value``, raised by the last ulps until MuJoCo's distance to it,
    value - bound, is below the margin: so the limit row exists at the running extreme itself (MuJoCo adds a
    row while the distance is below the margin, and its soft limit pulls the distance to the margin, the
    row's own edge)."""
    bound = value - margin
    while value - bound >= margin:
        bound = math.nextafter(bound, math.inf)
    return bound


def upper_bound(value: float, margin: float) -> float:
    """As :func:`lower_bound`, the upper bound one margin above ``value`` (MuJoCo's distance: bound - value)."""
    bound = value + margin
    while bound - value >= margin:
        bound = math.nextafter(bound, -math.inf)
    return bound
