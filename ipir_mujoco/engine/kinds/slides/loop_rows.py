"""What the stepping loop reads of a built model's friction rows, checked once before a run.

The loop (:mod:`.stepper`) counts the work against the resistances from MuJoCo's frictionloss rows after
every step, at the offsets fixed here: without grip the two slides' rows; with finite grip (the carriages of
:mod:`.grip_model`) the rolling resistances' rows and the grips'. A model whose rows are laid out otherwise
(friction the engine does not count) is refused with a ParameterError.
"""

from __future__ import annotations

import mujoco
import numpy as np

from ipir_mujoco.core.errors import ParameterError

from ..slides_grip.ratchet import GripRows
from ...builders.grip_model import ROLLS, SKIDS
from ...builders.model import CRANK_HINGE, MOTOR, SLIDES, dof_address, drive_torque_slope, qpos_address
from ...loop.rows import FRICTION_DOF as FRICTION_ROW, FRICTION_TENDON



def loop_options(model: mujoco.MjModel, data: mujoco.MjData) -> dict:
    """:func:`make_steps`' keyword arguments for a built model after ``mj_forward`` on its initial state: the
    crank actuator and joint, the drive's implicit torque slope (:func:`.model.drive_torque_slope`), the
    dofs with friction and the initial torque [N m]. The loop counts the work against the resistances from
    the two slides' frictionloss rows only: friction on another dof, or other rows, is a ParameterError.
    A model with finite grip (its carriages, :mod:`.grip_model`) counts the rolling resistances' rows and
    the grips' (``grip``: :func:`grip_layout`) instead."""
    motor = model.actuator(MOTOR).id
    common = dict(motor=motor, crank_q=qpos_address(model, CRANK_HINGE), crank_v=dof_address(model, CRANK_HINGE),
                  slope=drive_torque_slope(model), torque=data.actuator_force.item(motor))
    if has_grip(model):
        return dict(common, friction_dofs=[], grip=grip_layout(model, data))
    slides = {dof_address(model, n) for n in SLIDES}
    friction_dofs = [int(i) for i in np.flatnonzero(model.dof_frictionloss > 0)]
    if not set(friction_dofs) <= slides:
        names = ", ".join(repr(model.joint(model.dof_jntid[i]).name) for i in friction_dofs if i not in slides)
        raise ParameterError(f"frictionloss on {names} in the MJCF model: the engine counts resistances on the "
                             "two slides only; allowed: frictionloss on rear_slide and front_slide (F_r1, F_r2)")
    # the frictionloss rows follow the equality rows, one per dof with friction, in dof order
    rows = range(data.ne, data.ne + data.nf)
    if data.nf != len(friction_dofs) or any(data.efc_type[r] != FRICTION_ROW or data.efc_id[r] != dof
                                            for r, dof in zip(rows, friction_dofs)):
        raise ParameterError("the MJCF model has friction rows the engine does not expect (only the slides' "
                             "frictionloss)")
    return dict(common, friction_dofs=friction_dofs)


def has_grip(model: mujoco.MjModel) -> bool:
    """Whether ``model`` was built with finite grip (it has the carriages' slides)."""
    return mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, SKIDS[0]) >= 0


def grip_layout(model: mujoco.MjModel, data: mujoco.MjData) -> dict:
    """What the loop reads of a finite-grip model's friction rows each step (:class:`.grip.GripRows`):
    ``count`` rows; per module the offsets of its rolling resistance's row (``roll``) and its grip's
    (``grip``) among them (-1: none), its slide's and its carriage's dofs (``x_dof``, ``c_dof``), and
    whether the rolling resistance is on the roll tendon (rigid clutches: its speed is v_x - v_c) or on
    the module's slide (compliant clutches: v_x). Rows MuJoCo does not lay out so are a ParameterError."""
    rolling_tendon = bool(model.tendon_limited[model.tendon(ROLLS[0]).id])
    rows = GripRows(model, roll_on_tendon=rolling_tendon)
    expected = {FRICTION_ROW: set(), FRICTION_TENDON: set()}
    for dof in [dof_address(model, n) for n in SKIDS] + ([] if rolling_tendon else
                                                          [dof_address(model, n) for n in SLIDES]):
        if model.dof_frictionloss[dof] > 0:
            expected[FRICTION_ROW].add(dof)
    if rolling_tendon:
        expected[FRICTION_TENDON] = {model.tendon(n).id for n in ROLLS if model.tendon_frictionloss[model.tendon(n).id] > 0}
    found = {FRICTION_ROW: {int(i) for i in np.flatnonzero(model.dof_frictionloss > 0)},
             FRICTION_TENDON: {int(i) for i in np.flatnonzero(model.tendon_frictionloss > 0)}}
    laid = [(int(data.efc_type[r]), int(data.efc_id[r])) for r in range(data.ne, data.ne + data.nf)]
    order = sorted((FRICTION_ROW, i) for i in found[FRICTION_ROW]) + sorted(
        (FRICTION_TENDON, i) for i in found[FRICTION_TENDON])
    if found != expected or laid != order or data.nf != rows.count:
        raise ParameterError("the MJCF model has friction rows the engine does not expect (only the carriages' grip "
                             "and the rolling resistances)")
    return dict(count=rows.count, roll=rows.roll, grip=rows.grip, x_dof=[dof_address(model, n) for n in SLIDES],
                c_dof=[dof_address(model, n) for n in SKIDS], rolling_tendon=rolling_tendon)
