"""The slide model on wheels of finite grip (a finite ``mu_wall``): a carriage per module on the wall, held by
friction G_i, carries the clutch.

Its builder is the slide model's, which adds the carriages where the parameters give a finite grip
(:mod:`ipir_mujoco.engine.builders.grip_model`); its clutches: the rigid ratchets of :mod:`.ratchet` or the
compliant clutches of :mod:`.compliant`, their compiled forms in :mod:`.compiled` and ``_clutch_grip.c``; its skid
rule: a skidding run's figures extrapolated to the rigid limit (:mod:`.rigid_limit`).
"""

from __future__ import annotations

from ..slides import SlidesKind

RATCHETS = "ipir_mujoco.engine.kinds.slides_grip.ratchet"  # where the header of a saved MJCF file sends a reader


def refuse_grip(params, implementation: str) -> None:
    """ParameterError (one line) for a finite ``mu_wall`` with a clutch that has no grip: the locks (an equality
    holds whatever the load) and no clutch. (Wheel normal forces given with unlimited grip are refused for
    every engine by :func:`ipir_mujoco.core.drive_fields.refuse_idle_parameters`.)"""
    from ipir_mujoco.core.errors import ParameterError

    if params.mu_wall is not None and implementation != "ratchet":
        raise ParameterError(f"mu_wall={params.mu_wall!r} with the MuJoCo {implementation!r} clutch: only the ratchet "
                             "is modelled on wheels of finite grip (a lock holds whatever the load); allowed: "
                             "--mujoco-clutch ratchet, or mu_wall=unlimited")


class GripSlidesKind(SlidesKind):
    """The slide model on wheels of finite grip (module docstring)."""

    name = "slides-grip"
    variants = ()  # the slides' variants: a finite mu_wall chooses this kind
    skid = True

    def takes(self, params):
        """The slides with a finite grip."""
        return params.grip is not None

    def check(self, params, implementation, rule, route=None, until_steady=False):
        params = super().check(params, implementation, rule, route, until_steady)
        refuse_grip(params, implementation)
        return params

    def settings(self, params, t_end, dt_out, servo=None, implementation="ratchet", route=None):
        """The automatic step (:func:`ipir_mujoco.engine.kinds.timestep.choose_settings`); with rigid clutches
        the grip rows' time constant STEPS_PER_TIME_CONSTANT steps and the carriage's share set: the first run of
        the rigid limit's family (:func:`ipir_mujoco.engine.kinds.timestep.first_settings`)."""
        from ..timestep import first_settings

        chosen, why = super().settings(params, t_end, dt_out, servo, implementation, route)
        if params.clutch_stiffness is None:
            chosen = first_settings(chosen, params)
        return chosen, why

    def between_steps(self, params, implementation, rule):
        return [*super().between_steps(params, implementation, rule),
                f"Finite grip (mu_wall {params.mu_wall:g}): each module's carriage is ratcheted the same way "
                f"({RATCHETS})."]

    def controller(self, model, data, params, implementation, rule="unilateral"):
        """:class:`.ratchet.GripRatchet` with rigid clutches, :class:`.compliant.CompliantGrip` with compliant
        ones."""
        from .compliant import CompliantGrip
        from .ratchet import GripRatchet

        refuse_grip(params, implementation)
        if params.clutch_stiffness is None:
            return GripRatchet(model, data, params)
        return CompliantGrip(model, data, params)

    def columns(self, model, params, q, scalars, out):
        """slip1/2 [m], each carriage's backward travel below its start (its running minimum over the samples:
        the carriage only skids back, its limit holds it from going forward), grip_use1/2
        (:func:`~ipir_mujoco.core.summary.grip_use`), the grips' cumulative work skid_work [J] and the wheels'
        states wheels1/2."""
        import numpy as np

        from ipir_mujoco.core.results import grip_use

        from ...builders.grip_model import SKIDS
        from ...builders.model import qpos_address

        cols = {}
        for k, (name, G) in enumerate(zip(SKIDS, params.grip), start=1):
            adr = qpos_address(model, name)
            wheels = scalars[f"wheels{k}"]
            cols[f"slip{k}"] = q[0, adr] - np.minimum.accumulate(q[:, adr])
            cols[f"grip_use{k}"] = grip_use(out[f"lambda{k}"], wheels, G)
            cols[f"wheels{k}"] = wheels.copy()
        cols["skid_work"] = scalars["skid_work"].copy()
        return cols

    def skid_rule(self, params):
        """The rigid limit (:data:`.rigid_limit.RIGID_LIMIT`); with compliant clutches the figures are not
        extrapolated (their skid is the anchor's slide on the spring, whose rate already sets a step of a few
        microseconds: :mod:`ipir_mujoco.engine.kinds.skid_check`)."""
        from ..skid_check import Unverified
        from .rigid_limit import RIGID_LIMIT

        if params.clutch_stiffness is not None:
            return Unverified(RIGID_LIMIT, "compliant clutches")
        return RIGID_LIMIT


KIND = GripSlidesKind()
