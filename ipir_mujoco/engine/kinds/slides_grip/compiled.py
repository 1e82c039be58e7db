"""The finite-grip clutch controllers in the compiled loop: their blocks (``_clutch_grip.c``) in its arrays.

:class:`.stepper.CompiledSteps` asks a controller to lay out its own block in the C loop's CONFIG (indices) and
STATE (doubles) arrays before it runs and to read its state back after each call (``load_compiled``); the two
controllers on finite grip, :class:`.grip.GripRatchet` and :class:`.compliant_grip.CompliantGrip`, do it here.
Both blocks start with the carriages' part (``_clutch_parts.h``: the loop's grip rows, the wall's running bound,
G_i); the compliant grip's goes on with the compliant clutch's part (:func:`.compliant.load_spring`).
"""

from __future__ import annotations

from ipir_mujoco.core.results import REST_SPEED

from ..slides.compliant import load_spring
from ...loop.native import LayoutError


def _carriages(ctl, loop, kind: str, x_adr: list[int], x_dof: list[int]) -> None:
    """Choose the compiled ``kind`` and write the carriages' part: the loop's grip rows (its work rates
    ``loop.power``, a :class:`ipir_mujoco.engine.kinds.slides.loop_rows.GripPower`, on
    :func:`~ipir_mujoco.engine.kinds.slides.loop_rows.grip_layout`), after checking that the controller's dofs are
    the loop's, the slides' and carriages' addresses, the wall's running bound and the grips."""
    from ..slides.loop_rows import GripPower

    if not isinstance(loop.power, GripPower):
        raise LayoutError("the grip controllers' compiled forms count the grips' rows, not this loop's work rates")
    grip = loop.power.layout
    if [x_dof, ctl.c_dof] != [grip["x_dof"], grip["c_dof"]]:
        raise LayoutError("the grip controller's dofs are not the loop's")
    loop.use(kind)
    loop.set_config(count=grip["count"], roll_off0=grip["roll"][0], roll_off1=grip["roll"][1],
                    grip_off0=grip["grip"][0], grip_off1=grip["grip"][1], rolling_tendon=grip["rolling_tendon"],
                    x_q0=x_adr[0], x_q1=x_adr[1], x_v0=x_dof[0], x_v1=x_dof[1], c_q0=ctl.c_adr[0],
                    c_q1=ctl.c_adr[1], c_v0=ctl.c_dof[0], c_v1=ctl.c_dof[1], skid_j0=ctl.skid_ids[0],
                    skid_j1=ctl.skid_ids[1])
    loop.set_state(cmin0=ctl.lowest[0], cmin1=ctl.lowest[1], cmargin0=ctl.skid_margins[0],
                   cmargin1=ctl.skid_margins[1], grip0=ctl.grip[0], grip1=ctl.grip[1], rest_speed=REST_SPEED,
                   excursion=ctl.excursion)


def load_grip_ratchet(ctl, loop):
    """:class:`.grip.GripRatchet`'s block in ``loop`` (a :class:`.stepper.CompiledSteps`): returns its
    sync(state values)."""
    _carriages(ctl, loop, "grip_ratchet", ctl.x_adr, ctl.x_dof)
    loop.set_config(roll_t0=ctl.roll_ids[0], roll_t1=ctl.roll_ids[1])
    loop.set_state(lmax0=ctl.bounds[0], lmax1=ctl.bounds[1], tmargin0=ctl.roll_margins[0],
                   tmargin1=ctl.roll_margins[1], resist0=ctl.resistance[0], resist1=ctl.resistance[1])
    get = loop.getter("lmax0", "lmax1", "cmin0", "cmin1", "excursion")

    def sync(state) -> None:
        l0, l1, c0, c1, ctl.excursion = get(state)
        ctl.bounds[0], ctl.bounds[1], ctl.lowest[0], ctl.lowest[1] = l0, l1, c0, c1
    return sync


def load_compliant_grip(ctl, loop):
    """:class:`.compliant_grip.CompliantGrip`'s block in ``loop``: returns its sync(state values)."""
    _carriages(ctl, loop, "compliant_grip", ctl.qpos_adr, ctl.dof_adr)
    return load_spring(ctl, loop, "cmin0", "cmin1", "excursion")
