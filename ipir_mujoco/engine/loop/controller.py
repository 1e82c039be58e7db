"""The clutch controller protocol: what the run loop asks of a model kind's clutches, and the one meaning of held.

A model kind (:mod:`ipir_mujoco.engine.kinds`) makes one controller per run, after the initial state is set. The
loop (:mod:`.stepper`) calls :meth:`ClutchController.before_step` before every ``mj_step`` and
:meth:`ClutchController.after_step` after it; at each output sample the recorder stores
:meth:`ClutchController.sampled_reactions`, :meth:`ClutchController.wheels`, ``excursion`` and ``damper_work``, and
at the start of the next step :meth:`ClutchController.deferred_values`; at the end of the run it asks the controller
for its columns and its modes (:meth:`ClutchController.clutch_columns`, :meth:`ClutchController.modes`). The compiled
loop asks it to lay out its compiled form (:meth:`ClutchController.load_compiled`). Everything the loop and the
recorder do differently for one controller is a member here, so they hold no test on which controller runs.

Held, one definition for every controller (and the analytic model's; docs/cli.md says what a user reads): a
module is *held* while its clutch carries it and it stands, its wheels neither rolling forward nor skidding back.
A module whose wheels skid back on the wall is not held, even though its clutch pushes (it carries the grip, G_i,
while the module slides): its grip at its limit, or its module moving back faster than SKID_SPEED; a module that
rolls or slides forward is not held. (A compliant clutch's module moving back on its spring while the clutch
pushes is held: the clutch's own travel, not a skid.) :func:`held` says it for one module, :func:`held_where` for
a column of samples.

The ratchets' running bound (:func:`follow`, :class:`RunningBound`): a one-way limit that follows the running
maximum (or minimum) of a coordinate, one margin from it, and the largest give below (above) it so far. The slide
model's ratchet, the finite grip's two ratchets per module and the wheels' hub ratchets are each a RunningBound over
their coordinates, the compliant clutch's anchor follows one, and the batched ratchet follows its slides' for every
design at once; all through :func:`follow` (``_stepper.h``'s ``follow`` in the compiled controllers).
"""

from __future__ import annotations

import math
from typing import Protocol

import numpy as np

# a module's wheels, as the controllers report them (wheels1/2 columns): rolling forward, standing, skidding back
ROLLING, STANDING, SKIDDING = 1, 0, -1
# m/s: a module whose clutch carries it and that moves back faster than this skids, whatever its wheels' forces say
# (docs/cli.md, "held"): far above the creep of a held module on its soft rows and contacts (at most 1e-6 m/s,
# REST_SPEED), far below a stroke's speeds (0.1-0.5 m/s). The wheeled model's hubs hold while its body tips and
# slides on its legs, its contacts inside their cone: 171 of 1000 samples read held so before (issue 51)
SKID_SPEED = 1e-3
NO_WHEELS = (0.0, 0.0)  # the wheels' states a controller without wheels reports (none are written)


def held(carries: bool, state: int = STANDING) -> bool:
    """Whether a module is held: its clutch ``carries`` it (pushes, or its static resistance sticks) and its
    wheels' ``state`` (ROLLING, STANDING, SKIDDING) is standing, not skidding back."""
    return carries and state == STANDING


def held_where(carries: np.ndarray, wheels: np.ndarray) -> np.ndarray:
    """:func:`held` per sample: ``carries`` (bool, shape (n,)) and ``wheels`` (float states, shape (n,))."""
    return carries & (wheels != SKIDDING)


class LayoutError(RuntimeError):
    """What the compiled loop relies on does not hold here (the pure-Python loop is used instead): raised by a
    controller's :meth:`ClutchController.load_compiled` and by :mod:`.native` (its older place)."""


NO_REACTIONS = (False, False, 0.0, 0.0)  # no module held, no reaction
NO_DEFERRED = (0.0, 0.0, 0.0, 0.0, 0.0)  # a controller's deferred values where it has none


class ClutchController(Protocol):
    """What a model kind's clutch controller gives the run loop and the recorder (every kind's controller;
    :class:`ControllerBase` gives the defaults most share).

    Attributes
    ----------
    name : str
        The controller in words (recorded nowhere: for messages).
    clutch_model : str
        The clutch model a run records (``settings["clutch_model"]``): 'rigid' | 'compliant'.
    excursion : float
        The largest give [m] of a one-way limit so far (a rigid clutch's or the wall's; the compliant clutch's
        backward travel is its physics and not counted), checked before every step.
    damper_work : float
        Cumulative work [J] the clutches' dampers dissipated (0.0 without dampers).
    deferred : bool
        True where the clutch forces of a sample are MuJoCo's at the sample's own state, a step later (the
        compliant clutches): :meth:`deferred_values` then holds them and :meth:`clutch_columns` reads them.
    """

    name: str
    clutch_model: str
    excursion: float
    damper_work: float
    deferred: bool

    def before_step(self) -> None:
        """Move the clutches' limits, anchors or locks for the step about to be taken."""

    def after_step(self) -> None:
        """The clutches' bookkeeping after a step (where they need its forces)."""

    def reactions(self) -> tuple[bool, bool, float, float]:
        """(rear held, front held, rear reaction [N], front reaction [N]) of the last step (held: :func:`held`)."""

    def sampled_reactions(self) -> tuple[bool, bool, float, float]:
        """What a sample records of the step just taken: :meth:`reactions`, or NO_REACTIONS where the forces are
        deferred (:meth:`clutch_columns` fills them from :meth:`deferred_values`)."""

    def wheels(self) -> tuple[float, float]:
        """Each module's wheels of the last step: ROLLING, STANDING or SKIDDING as floats (NO_WHEELS without)."""

    def deferred_values(self) -> tuple[float, float, float, float, float]:
        """At the start of a step (MuJoCo's values for the state the last sample holds): the clutch forces [N], the
        overlaps [m] and the springs' energy as the step conserves it [J] (NO_DEFERRED without)."""

    def clutch_columns(self, scalars: dict, deferred: dict) -> dict:
        """The clutch's own series columns from the recorder's per-sample ``scalars`` and ``deferred`` values (name:
        (n,) arrays), and, where its forces are deferred, its reactions and held flags written into ``scalars``."""

    def modes(self, mode, both, turning, wheels1, wheels2) -> tuple:
        """(mode, wheels1, wheels2) of the samples from the held flags' ``mode`` (n,), where ``both`` modules are
        held (bool (n,)) and the crank ``turning`` (bool (n,)): rigid clutches pass a dead centre
        (:func:`dead_centre_passages`)."""

    def finish(self) -> None:
        """Before the run's final ``mj_forward``, which fills the last sample's deferred values."""

    def load_compiled(self, loop):
        """Choose the controller's compiled form (``loop.use(name)``: a name in the extension's table of
        controllers, ``_clutch_table.c``), write its own block of indices and state into the compiled loop's
        arrays (``loop.set_config``, ``loop.set_state``, by its fields' names; ``loop.getter``) and return
        ``sync(state values)``, which reads its state back after each call; :class:`.native.LayoutError` where it
        has no compiled form or the loop's options do not fit it (the run then steps in Python)."""


class ControllerBase:
    """What most controllers share of :class:`ClutchController`: rigid clutches whose forces are read at the step
    (not deferred), no after-step work, no damper, no excursion yet, no wheels, no compiled form."""

    clutch_model = "rigid"
    damper_work = 0.0
    excursion = 0.0
    deferred = False

    def after_step(self) -> None:
        """Nothing after a step."""

    def sampled_reactions(self) -> tuple[bool, bool, float, float]:
        return self.reactions()

    def wheels(self) -> tuple[float, float]:
        """No wheels: NO_WHEELS."""
        return NO_WHEELS

    def deferred_values(self) -> tuple[float, float, float, float, float]:
        return NO_DEFERRED

    def clutch_columns(self, scalars: dict, deferred: dict) -> dict:
        """None: the reactions and held flags are the samples' own."""
        return {}

    def modes(self, mode, both, turning, wheels1, wheels2) -> tuple:
        """Rigid clutches: the samples where both modules are held while the crank turns take the mode they lead
        to, the wheels' states with them (:func:`dead_centre_passages`)."""
        return dead_centre_passages(mode, both, turning, wheels1, wheels2)

    def finish(self) -> None:
        """Nothing before the final ``mj_forward``."""

    def load_compiled(self, loop):
        raise LayoutError(f"no compiled form of the clutch controller {type(self).__name__}")


def dead_centre_passages(mode: np.ndarray, both: np.ndarray, turning: np.ndarray, *also: np.ndarray):
    """``mode`` with each sample where both modules are held while the crank turns (at it or at the next
    sample) given the mode of the next sample that is not such (arrays of shape (n,); both, turning: bool).
    Arrays in ``also`` (of shape (n,): the wheels' states with finite grip) are relabeled alike, and then
    returned after the mode, as a tuple.

    With rigid clutches both modules stand still only where the crank is at rest, or for an instant as it
    passes a dead centre (dS/dphi = 0): where one module stops just as the other starts, the equations
    switch at once, and MuJoCo's step may order the two events a step apart, with both modules held for
    that step. Such a passage belongs to the mode it leads to; so does the last sample at rest before the
    crank turns (a start from rest, where the equations' module slides at once). A run that ends so keeps
    its samples.
    """
    turning = turning | np.concatenate([turning[1:], turning[-1:]])
    passing = both & turning
    if not passing.any():
        return (mode, *also) if also else mode
    n = mode.size
    # index of the first sample at or after each that is not a passage (n where none is)
    following = np.minimum.accumulate(np.where(passing, n, np.arange(n))[::-1])[::-1]
    relabel = passing & (following < n)
    outs = []
    for values in (mode, *also):
        out = values.copy()
        out[relabel] = values[following[relabel]]
        outs.append(out)
    return tuple(outs) if also else outs[0]


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
        self.extremes[k], give = follow(self.extremes[k], value, self.upper)
        if give < 0.0:
            self.limits[self.ids[k], self.column] = self.place(value, self.margins[k])
            return 0.0
        return give


def follow(extreme, value, upper: bool = False):
    """A coordinate's running maximum (``upper``: minimum) ``extreme`` after its new ``value``: (the running
    extreme now, ``value``'s give), the give being how far ``value`` lies behind the extreme it had, > 0 where it
    went back, < 0 where it passed it (and is the extreme now). Floats, or numpy arrays element by element (the
    batched ratchet's designs). The one rule of every ratchet (:class:`RunningBound`, the compliant clutch's
    anchor, the batch; compiled: ``_stepper.h``'s ``follow``): the same double arithmetic in each."""
    give = value - extreme if upper else extreme - value
    if isinstance(give, np.ndarray):
        return np.where(give < 0.0, value, extreme), give
    return (value if give < 0.0 else extreme), give


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
