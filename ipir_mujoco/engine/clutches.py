"""Shim: the slide model's clutches moved to :mod:`.kinds.slides.clutches`, the constraint rows to :mod:`.loop.rows` and the
choice of a controller to the model kinds (:mod:`.kinds`); kept so that older imports keep working."""

from .kinds import clutch_controller, refuse_grip
from .loop.rows import (EQUALITY_ROWS, FRICTION_DOF, FRICTION_TENDON, MISSING_ROWS, FrictionRows, clutch_share,
                   equality_row, missing_rows)
from .kinds.slides.clutches import Locks, NoClutch, Ratchet, refuse_compliant

__all__ = ["EQUALITY_ROWS", "FRICTION_DOF", "FRICTION_TENDON", "MISSING_ROWS", "FrictionRows", "Locks", "NoClutch",
           "Ratchet", "clutch_controller", "clutch_share", "equality_row", "missing_rows", "refuse_compliant",
           "refuse_grip"]
