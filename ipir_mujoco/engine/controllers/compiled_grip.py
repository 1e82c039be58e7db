"""The finite-grip clutch controllers in the compiled loop: their indices and state in ``_stepper.c``'s arrays.

:class:`.stepper.CompiledSteps` asks a controller to copy its state into the C loop's CONFIG (indices) and STATE
(doubles) arrays before it runs and back after each call (``load_compiled``); the two controllers on finite
grip, :class:`.grip.GripRatchet` and :class:`.compliant_grip.CompliantGrip`, do it here.
"""

from __future__ import annotations

from ipir_mujoco.core.results import REST_SPEED

from ..loop.native import LayoutError


def _common(ctl, loop, modules: list[int]) -> None:
    """The carriages' indices and state, after checking that the controller's dofs are the loop's."""
    grip = loop.grip
    if grip is None or [modules, ctl.c_dof] != [grip["x_dof"], grip["c_dof"]]:
        raise LayoutError("the grip controller's dofs are not the loop's")
    loop.set_config(skid_q0=ctl.c_adr[0], skid_q1=ctl.c_adr[1], skid_j0=ctl.skid_ids[0], skid_j1=ctl.skid_ids[1])
    loop.set_state(cmin0=ctl.lowest[0], cmin1=ctl.lowest[1], cmargin0=ctl.skid_margins[0],
                   cmargin1=ctl.skid_margins[1], grip0=ctl.grip[0], grip1=ctl.grip[1], rest_speed=REST_SPEED,
                   excursion=ctl.excursion)


def load_grip_ratchet(ctl, loop):
    """:class:`.grip.GripRatchet`'s layout in ``loop`` (a :class:`.stepper.CompiledSteps`): returns (its C kind,
    sync(state values))."""
    _common(ctl, loop, ctl.x_dof)
    loop.set_config(slide_q0=ctl.x_adr[0], slide_q1=ctl.x_adr[1], roll_t0=ctl.roll_ids[0], roll_t1=ctl.roll_ids[1])
    loop.set_state(lmax0=ctl.bounds[0], lmax1=ctl.bounds[1], tmargin0=ctl.roll_margins[0],
                   tmargin1=ctl.roll_margins[1])
    get = loop.getter("lmax0", "lmax1", "cmin0", "cmin1", "excursion")

    def sync(state) -> None:
        l0, l1, c0, c1, ctl.excursion = get(state)
        ctl.bounds[0], ctl.bounds[1], ctl.lowest[0], ctl.lowest[1] = l0, l1, c0, c1
    return "grip_ratchet", sync


def load_compliant_grip(ctl, loop):
    """:class:`.compliant_grip.CompliantGrip`'s layout in ``loop``: returns (its C kind, sync(state values))."""
    _common(ctl, loop, ctl.dof_adr)
    if ctl.dt != loop.model.opt.timestep:
        raise LayoutError("the compliant clutches' timestep is not the model's")
    loop.set_config(slide_q0=ctl.qpos_adr[0], slide_q1=ctl.qpos_adr[1], act0=ctl.act[0], act1=ctl.act[1],
                    implicit=ctl.implicit)
    loop.set_state(anchor0=ctl.anchor[0], anchor1=ctl.anchor[1], overlap0=ctl.overlap[0], overlap1=ctl.overlap[1],
                   v_before0=ctl.v_before[0], v_before1=ctl.v_before[1], damped0=ctl.damped[0],
                   damped1=ctl.damped[1], damper_work=ctl.damper_work, k=ctl.k, c=ctl.c, backlash=ctl.backlash,
                   tracking0=ctl.tracking[0], tracking1=ctl.tracking[1])
    get = loop.getter("anchor0", "anchor1", "overlap0", "overlap1", "v_before0", "v_before1", "damped0", "damped1",
                      "damper_work", "tracking0", "tracking1", "cmin0", "cmin1", "excursion")

    def sync(state) -> None:
        a0, a1, d0, d1, v0, v1, damped0, damped1, ctl.damper_work, t0, t1, c0, c1, ctl.excursion = get(state)
        ctl.anchor, ctl.overlap, ctl.v_before = [a0, a1], [d0, d1], [v0, v1]
        ctl.damped, ctl.tracking = [damped0 != 0.0, damped1 != 0.0], [t0 != 0.0, t1 != 0.0]
        ctl.lowest[0], ctl.lowest[1] = c0, c1  # in place: the wall's running bound holds this list
    return "compliant_grip", sync
