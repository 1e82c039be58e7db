"""The discrete state of the compliant one-way clutch model and what a state implies: the clutch states, the
regime between two events, the motion a state gives, and the tolerances of the model's sign tests and switches.

Shared by the model (:mod:`.compliant_model`), its driver (:mod:`.compliant_run`) and its finite-grip
additions (:mod:`.compliant_grip`), which each import it; the model's equations are in :mod:`.compliant_model`.
"""

from __future__ import annotations

import math
from enum import IntEnum
from typing import NamedTuple

import numpy as np

from ipir_mujoco.core.results import Mode

from .dynamics import MassTerms

NO_SLIDE = (math.nan, math.nan)  # (t_s, d0) of a clutch whose anchor holds (.compliant_grip)


class Clutch(IntEnum):
    """State of one compliant one-way clutch."""

    TRACKING = 0  # the module is at its running maximum: the anchor follows it
    FREE = 1  # behind its maximum, inside the backlash (d <= 0): no force
    ENGAGED = 2  # d > 0 and k d - c v > 0: pushes with k d - c v
    CLIPPED = 3  # d > 0 but k d - c v <= 0: the damper would pull, so no force
    SLIDING = 4  # finite grip: k d - c v would exceed G, so the anchor slides and the force is G (.compliant_grip)


class Regime(NamedTuple):
    """The discrete state between two events."""

    slip: tuple[int, int]  # per module: +1 sliding forward, -1 backward, 0 stuck
    clutch: tuple[Clutch, Clutch]
    peak: tuple[float, float]  # running maximum of x1, x2 [m] (of a TRACKING module: at the segment's start)
    slide: tuple = (NO_SLIDE,) * 2  # per module, while its anchor slides: (start [s], overlap then [m])

    @property
    def static(self) -> bool:
        """Both modules stuck: the crank is at rest too (v2 - v1 = K omega = 0)."""
        return self.slip == (0, 0)

    @property
    def mode(self) -> Mode:
        """The mode column's label: a module is held while its clutch pushes (ENGAGED, or SLIDING at the grip),
        as in MuJoCo's compliant clutch; one standing in its play on its resistance, or sliding back into it,
        is not (with rigid clutches a module that stands counts as held: there is no play to stand in)."""
        held = [c in (Clutch.ENGAGED, Clutch.SLIDING) for c in self.clutch]
        return {(False, True): Mode.CONTRACTION, (True, False): Mode.EXPANSION,
                (False, False): Mode.BOTH_MOVING, (True, True): Mode.BOTH_LOCKED}[tuple(held)]


class Motion(NamedTuple):
    """Everything a state implies in a regime (floats or arrays of one shape); SI units."""

    alpha: np.ndarray  # crank angular acceleration [rad/s^2]
    a1: np.ndarray  # module accelerations [m/s^2]
    a2: np.ndarray
    x2: np.ndarray  # front module position [m]
    v2: np.ndarray  # front module velocity [m/s]
    force: tuple  # clutch forces on modules 1, 2 [N], >= 0
    overlap: tuple  # d1, d2 [m] (> 0: clutch compressed)
    friction: tuple  # friction forces on modules 1, 2 [N] (stuck: the force needed to stay at rest)
    torque: np.ndarray  # drive torque [N m]
    mass: MassTerms


# relative tolerances of the sign tests (speeds; forces and accelerations), far above the
# event-location error (~rtol), far below any physical margin (as in the rigid one-way model)
_TOL_V, _TOL_F = 1e-8, 1e-7
# [m/s] the absolute floor of the regime logic's rest test (|v| <= _TOL_V * v_scale + floor): as the one-way
# model's _MODE_REST_FLOOR (1e-12), but a hundred times its switches' hysteresis speed (_HYSTERESIS_SPEED, 1e-12),
# so that a module let go at the hysteresis speed reads as rest, not as moving; far below the series' rest
# (core.columns.REST_SPEED, 1e-6)
_REGIME_REST_FLOOR = 1e-10
# [rad] how far on from a dead centre at rest the friction states are decided: the module loads then are
# O(K' step) = 5e-7 of the stroke's (far above roundoff), the gap has moved O(K' step^2) = 1e-12 of it
_DEAD_CENTRE_STEP = 1e-5
# hysteresis of the switches (see CompliantModel.events): a clutch engages at an overlap of 1 pm (its
# force then k * 1 pm: 1e-5 N at 1e7 N/m) and a module turns at 1 pm/s; a stuck module lets go
# 1e-10 of its friction late
_HYSTERESIS_OVERLAP, _HYSTERESIS_SPEED, _HYSTERESIS_FORCE = 1e-12, 1e-12, 1e-10


