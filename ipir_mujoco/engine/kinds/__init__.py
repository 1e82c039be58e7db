"""MuJoCo's models of the robot, each one *model kind* (:class:`.base.ModelKind`) in a folder of its own.

Every folder here with an ``__init__.py`` naming its instance ``KIND`` is a kind (:data:`KINDS`, in the folders'
order): ``slides/`` (the modules on slides, unlimited grip), ``slides_grip/`` (the slides on finite grip),
``wheels/`` (a 3-D robot on sprung wheel legs in a round pipe). A kind declares there, in one place, all that
differs: its checks, settings, build and MJCF template, initial state, controller, loop options, columns, skid
rule, its variants (:data:`ipir_mujoco.registry.VARIANTS` reads them), its drawing and replay (``render``, the
viewer). Beside the folders, what kinds share: :mod:`.base` (the abstract kind), :mod:`.timestep` (the automatic
timestep), :mod:`.common` (the clutch-option check, stalls, the crank servo), :mod:`.skid_check` (the skid check's
loop and the slide model's rule). Adding a kind: ``docs/architecture.md``, "Adding a model kind".

Light to import (the registry reads the variants when ``ipir_mujoco`` is imported, before MuJoCo is): the kinds'
``__init__`` modules import their own modules when their methods are called.

``ipir_mujoco.engine.kinds`` was a module once (the engine in one folder), and ``ipir_mujoco.engine.modelkinds.kinds``
after: their names (``kind_for``, ``KINDS``, ``ModelKind``, ``SLIDES``, ...) are this package's.
"""

from __future__ import annotations

import importlib
import pkgutil

from .base import ModelKind

# every kind, by name, in its folder's order (kind_for asks them so)
KINDS: dict[str, ModelKind] = {}
for _folder in sorted(found.name for found in pkgutil.iter_modules(__path__) if found.ispkg):
    _kind = importlib.import_module(f"{__name__}.{_folder}").KIND
    KINDS[_kind.name] = _kind
MODELS = tuple(dict.fromkeys(kind.model for kind in KINDS.values()))  # the words a user names them by

# the kinds by their older names (the kinds' module's)
SLIDES, GRIP_SLIDES, WHEELS = KINDS["slides"], KINDS["slides-grip"], KINDS["wheels"]
from .slides import SlidesKind  # noqa: E402
from .slides_grip import GripSlidesKind, refuse_grip  # noqa: E402
from .wheels import WheelsKind  # noqa: E402


def kind_for(model: str, params) -> ModelKind:
    """The model kind of a run of MuJoCo's model ``model`` (a word of :data:`MODELS`) on ``params``: the first of
    that word's kinds that takes them (on the slides a finite ``mu_wall`` chooses the carriages' model).

    Parameters
    ----------
    model : str
    params : RobotParams

    Returns
    -------
    ModelKind

    Raises
    ------
    ParameterError
        For an unknown ``model``.
    """
    from ipir_mujoco.core.errors import ParameterError

    for kind in KINDS.values():
        if kind.model == model and kind.takes(params):
            return kind
    raise ParameterError(f"mujoco model {model!r} is unknown; allowed: {', '.join(MODELS)}")


def drawn(model: str) -> ModelKind:
    """The kind that draws and replays a run of MuJoCo's model ``model`` (a run's ``settings["mujoco_model"]``,
    'slides' where none is recorded): the first kind of that word (its drawing is the same whatever the grip).
    ParameterError for an unknown word."""
    from ipir_mujoco.core.errors import ParameterError

    for kind in KINDS.values():
        if kind.model == model:
            return kind
    raise ParameterError(f"mujoco model {model!r} is unknown; allowed: {', '.join(MODELS)}")


def clutch_controller(model, data, params, implementation: str, rule: str = "unilateral"):
    """The slide model's clutch controller of a run (the slide kinds' :meth:`ModelKind.controller`): kept for
    scripts that built the slide model themselves."""
    return kind_for("slides", params).controller(model, data, params, implementation, rule)


