"""What the stepping loop reads of a built model's friction rows, checked once before a run.

The loop (:mod:`ipir_mujoco.engine.loop.stepper`) counts the work against the resistances from MuJoCo's
frictionloss rows after every step, at the offsets fixed here (its work rates ``power``): without grip the two
slides' rows (:class:`FrictionPower`); with finite grip (the carriages of
:mod:`ipir_mujoco.engine.builders.grip_model`) the rolling resistances' rows and the grips' (:class:`GripPower`).
A model whose rows are laid out otherwise (friction the engine does not count) is refused with a ParameterError.
"""

from __future__ import annotations

import mujoco
import numpy as np

from ipir_mujoco.core.errors import ParameterError

from ...builders.grip_model import ROLLS, SKIDS
from ...builders.model import CRANK_HINGE, MOTOR, SLIDES, dof_address, drive_torque_slope, qpos_address
from ...loop.rows import FRICTION_DOF, FRICTION_TENDON, FrictionRows, missing_rows

FRICTION_ROW = FRICTION_DOF



def loop_options(model: mujoco.MjModel, data: mujoco.MjData) -> dict:
    """:func:`make_steps`' keyword arguments for a built model after ``mj_forward`` on its initial state: the
    crank actuator and joint, the drive's implicit torque slope (:func:`.model.drive_torque_slope`), the
    dofs with friction and the initial torque [N m]. The loop counts the work against the resistances from
    the two slides' frictionloss rows only (``power``: :class:`FrictionPower`):
    friction on another dof, or other rows, is a ParameterError. A model with finite grip (its carriages,
    :mod:`ipir_mujoco.engine.builders.grip_model`) counts the rolling resistances' rows and the grips'
    (:class:`GripPower` on :func:`grip_layout`) instead."""
    motor = model.actuator(MOTOR).id
    common = dict(motor=motor, crank_q=qpos_address(model, CRANK_HINGE), crank_v=dof_address(model, CRANK_HINGE),
                  slope=drive_torque_slope(model), torque=data.actuator_force.item(motor))
    if has_grip(model):
        return dict(common, friction_dofs=[], power=GripPower(data, grip_layout(model, data)))
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
    return dict(common, friction_dofs=friction_dofs, power=FrictionPower(data, friction_dofs))


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


class GripPower:
    """``power(v)``: the work rates [W] after a step of a model with finite grip, ``v`` the velocities as a list:
    (the rolling resistances' rows' force times the speed they act at, the grips' rows' force times the carriages'
    speed), summed module by module as ``_clutch_parts.h``'s grip_work sums them. The rolling resistance acts at
    the roll's speed v_x - v_c (rigid clutches: on the roll tendon) or the slide's v_x (compliant ones), the grip at
    the carriage's v_c. ``layout``: :func:`grip_layout`'s (the grip controllers' compiled forms read it). A missing
    row is an error, not a zero."""

    def __init__(self, data: mujoco.MjData, layout: dict):
        self.data, self.layout = data, layout
        self.count, self.tendon = layout["count"], layout["rolling_tendon"]
        self.per_module = tuple(zip(layout["roll"], layout["grip"], layout["x_dof"], layout["c_dof"]))

    def __call__(self, v) -> tuple[float, float]:
        d, tendon = self.data, self.tendon
        if d.nf != self.count:
            raise missing_rows(2, d.time)
        ne, force, rolling, skidding = d.ne, d.efc_force, 0.0, 0.0  # the rows move in MuJoCo's arena
        for roll, grip, x, c in self.per_module:
            if roll >= 0:
                rolling += force.item(ne + roll) * ((v[x] - v[c]) if tendon else v[x])
            if grip >= 0:
                skidding += force.item(ne + grip) * v[c]
        return rolling, skidding


class FrictionPower:
    """``power(v)``: the work rates [W] after a step of a model whose only rows doing work are the frictionloss
    rows of the dofs ``friction_dofs`` (at most two: the slide model's, :func:`loop_options`), ``v`` the
    velocities v_{n+1} as a list: (their rows' force times their dofs' speed, summed in dof order; 0.0 against
    skidding). The rows follow the equality rows, one per dof with friction; a
    missing row is an error, not a zero. The slide controllers' compiled forms count the same
    (``_clutch_slides.c``'s friction_work, on the loop's ``friction_dofs``)."""

    def __init__(self, data: mujoco.MjData, friction_dofs: list[int]):
        self.data, self.friction_dofs = data, list(friction_dofs)
        self.count = len(self.friction_dofs)
        self.fric_a, self.fric_b = (self.friction_dofs + [0, 0])[:2]

    def __call__(self, v) -> tuple[float, float]:
        d, nfric = self.data, self.count
        if nfric and d.nf != nfric:
            raise missing_rows(2, d.time)
        if nfric == 2:
            ne = d.ne
            f0, f1 = d.efc_force[ne:ne + 2].tolist()
            return f0 * v[self.fric_a] + f1 * v[self.fric_b], 0.0
        if nfric == 1:
            return d.efc_force.item(d.ne) * v[self.fric_a], 0.0
        return 0.0, 0.0


def require_friction_power(loop) -> None:
    """:class:`ipir_mujoco.engine.loop.native.LayoutError` unless the compiled loop ``loop`` counts :class:`FrictionPower`'s work rates on
    its ``friction_dofs``: what the slide controllers' compiled forms count (their ``load_compiled`` asks)."""
    from ...loop.native import LayoutError

    if not isinstance(loop.power, FrictionPower) or loop.power.friction_dofs != loop.friction_dofs:
        raise LayoutError("the slide controllers' compiled forms count the slides' friction rows, not this loop's "
                          "work rates")


class GripRows:
    """Where each module's friction rows sit among MuJoCo's friction rows (:class:`ipir_mujoco.engine.loop.rows.FrictionRows`): the
    carriage's (the grip) and the rolling resistance's (the roll tendon with rigid clutches, the module slide
    with compliant ones). ``grip``, ``roll``: offsets among them per module (-1: no row, a zero grip or
    resistance); ``count``: how many; ``grips``, ``resistances`` [N].
    """

    def __init__(self, model: mujoco.MjModel, roll_on_tendon: bool):
        skids = [(FRICTION_DOF, dof_address(model, n)) for n in SKIDS]
        rolls = ([(FRICTION_TENDON, model.tendon(n).id) for n in ROLLS] if roll_on_tendon
                 else [(FRICTION_DOF, dof_address(model, n)) for n in SLIDES])
        self.rows = FrictionRows(model, skids + rolls)
        self.count = self.rows.count
        self.grip, self.roll = self.rows.offsets[:2], self.rows.offsets[2:]
        self.grips, self.resistances = self.rows.resistance[:2], self.rows.resistance[2:]

    def forces(self, data: mujoco.MjData) -> tuple[list[float], list[float]]:
        """(grip rows, roll rows) [N] of the last step, per module (0.0 where a module has no row)."""
        forces = self.rows.forces(data)
        return forces[:2], forces[2:]
