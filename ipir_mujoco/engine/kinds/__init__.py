"""The model kinds (:mod:`.kinds`: slides, slides on finite grip, wheels), each one object, and what a kind
chooses for its runs: the automatic timestep, the clutch-option check, the skid check. Each kind's own modules sit
in its folder (``slides/``, ``slides_grip/``, ``wheels/``). They import the controllers, the loop and the builders.

``ipir_mujoco.engine.kinds`` was a module once (the engine in one folder): its names are this package's too.
"""

from .kinds import GRIP_SLIDES, KINDS, MODELS, SLIDES, WHEELS, GripSlidesKind, ModelKind, WheelsKind, clutch_controller, kind_for, refuse_grip  # noqa: F401
