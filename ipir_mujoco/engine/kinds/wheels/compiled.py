"""The wheels' hub ratchet in the compiled loop: :class:`.wheels.WheelRatchet`'s block in ``_stepper.c``'s arrays.

The block (``_clutch_wheels.c``) holds scalars and the addresses of a few arrays kept here, on the controller's
layout (how many hubs depends on ``wheel_legs``): per hub its qpos address, joint, friction row and stick bound
and its running maximum (the one array the loop writes, read back into ``WheelRatchet.bounds`` after each call);
per joint and per geom the module it belongs to (-1: none); the dofs of the loop's work rates
(:class:`.wheels.WheelPower`).
"""

from __future__ import annotations

import numpy as np

from ipir_mujoco.core.results import REST_SPEED

from ...loop.controller import SKID_SPEED
from ...loop.native import LayoutError
from ...loop.native import address as array_address


def load_wheel_ratchet(ctl, loop, power, sticks: float):
    """:class:`.wheels.WheelRatchet` ``ctl``'s block in ``loop`` (a :class:`.stepper.CompiledSteps`) with the loop's
    work rates ``power`` (a :class:`.wheels.WheelPower`) and the friction rows' stick share ``sticks``: returns its
    sync(state values)."""
    model = ctl.model
    nhub, per_module = len(ctl.joint_ids), ctl.wheels_per_module
    if nhub != 2 * per_module or sorted(power.hub_dofs) != power.hub_dofs or len(power.hub_dofs) != ctl.friction_count:
        raise LayoutError("the wheel ratchet's hubs are not the loop's")
    hub_row, stick = np.full(nhub, -1, dtype=np.int64), np.zeros(nhub)
    for k, dof in enumerate(ctl.dof_adr):  # each hub's friction row among the friction rows (-1: none)
        if dof in power.hub_dofs:
            hub_row[k] = power.hub_dofs.index(dof)
            stick[k] = -ctl.torques[k] * sticks
    rows = [(int(hub_row[k]), ctl.torques[k]) for k in range(nhub) if hub_row[k] >= 0]
    if rows != [row for module in ctl.friction_rows for row in module]:  # per module, in hub order
        raise LayoutError("the wheel ratchet's friction rows are not the loop's")
    joint_module = np.full(model.njnt, -1, dtype=np.int64)
    for j, i in ctl.module_of.items():
        joint_module[j] = i
    geom_module = np.full(model.ngeom, -1, dtype=np.int64)
    for g, i in ctl.geom_module.items():
        geom_module[g] = i
    arrays = dict(hub_q=np.array(ctl.qpos_adr, dtype=np.int64), hub_joint=np.array(ctl.joint_ids, dtype=np.int64),
                  hub_row=hub_row, joint_module=joint_module, geom_module=geom_module,
                  work_dofs=np.array(power.hub_dofs, dtype=np.int64), stick=stick,
                  margin=np.array(ctl.margins, dtype=np.float64), bound=np.array(ctl.bounds, dtype=np.float64))
    loop.use("wheel_ratchet")
    loop.set_config(nhub=nhub, per_module=per_module, friction_count=ctl.friction_count, x_v0=ctl.x_dof[0],
                    x_v1=ctl.x_dof[1], elliptic=power.elliptic, ngeom=model.ngeom,
                    **{name: array_address(values) for name, values in arrays.items()})
    loop.set_state(radius=ctl.radius, cone=ctl.cone, rest_speed=REST_SPEED, skid_speed=SKID_SPEED,
                   resist0=ctl.resistance[0], resist1=ctl.resistance[1], excursion=ctl.excursion)
    loop.keep(arrays)  # alive as long as the loop
    bound, get = arrays["bound"], loop.getter("excursion")

    def sync(state) -> None:
        ctl.bounds[:] = bound.tolist()  # in place: the running bound holds this list
        ctl.excursion = get(state)
    return sync
