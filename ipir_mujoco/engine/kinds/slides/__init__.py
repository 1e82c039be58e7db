"""The slide model's kind: the modules on two slides along the pipe, unlimited grip.

Its clutches (:mod:`.clutches`): a joint-limit ratchet on each slide (rigid, or with a finite ``clutch_stiffness``
the compliant clutches of :mod:`ipir_mujoco.engine.kinds.slides.compliant`), velocity-triggered locks or none; their
compiled forms in ``_clutch_slides.c``. Its builder is the mechanism's, :mod:`ipir_mujoco.engine.builders.model`
(from ``mjcf/inchworm.xml``); the loop counts the work against the resistances from its slides' friction rows
(:mod:`.loop_rows`); its batched runs: :mod:`.batch`; its drawing and replay: :mod:`.drawing`. The slides on finite
grip are a kind of their own built on this one (:mod:`ipir_mujoco.engine.kinds.slides_grip`).
"""

from __future__ import annotations

from ..base import ModelKind

CONTROLLERS = "ipir_mujoco.engine.kinds.slides.clutches"  # where the header of a saved MJCF file sends a reader


class SlidesKind(ModelKind):
    """The slide model (module docstring); the slides on finite grip subclass it."""

    name = "slides"
    model = "slides"
    mjcf = "inchworm.xml"
    free = "slides"
    variants = (
        dict(name="mujoco-lock", rule="kinematic", clutch="lock", label="MuJoCo, paper's rule"),
        dict(name="mujoco-lock-unilateral", rule="unilateral", clutch="lock", label="MuJoCo one-way locks"),
        dict(name="mujoco-ratchet", rule="unilateral", clutch="ratchet", label="MuJoCo ratchet"),
    )

    def check(self, params, implementation, rule, route=None, until_steady=False):
        from ipir_mujoco.core.errors import ParameterError

        from ..common import check_clutch_options

        if route is not None:
            raise ParameterError("--route applies only to the wheeled model; allowed: --mujoco-model wheels")
        check_clutch_options(params, rule, implementation)
        return params

    def takes(self, params):
        """The slides with unlimited grip."""
        return params.grip is None

    def settings(self, params, t_end, dt_out, servo=None, implementation="ratchet", route=None):
        """:func:`ipir_mujoco.engine.kinds.timestep.choose_settings`."""
        from ..timestep import choose_settings

        return choose_settings(params, t_end, dt_out, servo, implementation)

    def build(self, params, settings, *, mjcf=None, implementation="ratchet", route=None, decorate=None):
        from ...builders.model import build_model

        return build_model(params, settings, self.template() if mjcf is None else mjcf,
                           ratchet=implementation == "ratchet", decorate=decorate)

    def initial_state(self, model, data, params):
        """The loop closed at ``phi0``, at rest or at ``omega0``."""
        from ...builders.model import set_closed_loop_state

        set_closed_loop_state(model, data, params)

    def controller(self, model, data, params, implementation, rule="unilateral"):
        from .clutches import slide_controller

        return slide_controller(model, data, params, implementation, rule)

    def loop_options(self, model, data):
        from .loop_rows import loop_options

        return loop_options(model, data)

    def between_steps(self, params, implementation, rule):
        compliant = "ipir_mujoco.engine.kinds.slides.compliant"
        if implementation == "ratchet" and params.clutch_stiffness is not None:
            return ["Before every mj_step each module's clutch anchor is ratcheted: its slide's lower limit is raised "
                    f"to the anchor's running maximum ({compliant}); the spring, damper and play between "
                    "anchor and module are MuJoCo's own, in this file."]
        if implementation == "ratchet":
            return ["Before every mj_step a ratchet raises each module's slide lower limit to the module's running "
                    f"maximum ({CONTROLLERS}): a module moves forward and never back. MuJoCo alone "
                    "keeps the limits this file holds."]
        if implementation == "lock":
            return ["Before every mj_step velocity-triggered locks fix a module's slide (both limits at its "
                    f"position) when it would move back, and release it by the clutch rule '{rule}' "
                    f"({CONTROLLERS})."]
        return ["No clutch: nothing changes the model between steps but the drive below."]

    def drawing(self, params, route=None, facing=None):
        """The slide model (:func:`ipir_mujoco.engine.builders.model.build_spec`) in its pipe (:meth:`dress`)."""
        from ...builders.model import build_spec

        spec = build_spec(params, mjcf=self.template())
        self.dress(spec, params, facing)
        return spec

    def dress(self, spec, params, facing=None):
        """The round pipe around the slide model (:func:`.drawing.in_pipe`), which its build has not."""
        from .drawing import in_pipe

        in_pipe(spec, params, facing)

    def replay(self, model, run):
        from .drawing import SlideReplay

        return SlideReplay(model, run)


KIND = SlidesKind()
