"""The slide model's one-way clutches in MuJoCo: a joint-limit ratchet and velocity-triggered locks.

A controller is called before every ``mj_step`` (:meth:`before_step`) and, if
it needs the step's constraint forces, after it (:meth:`after_step`; None when
it does not). At the output samples :meth:`reactions` reports per module
whether it is held and the clutch's reaction force [N] (positive pushes
the module forward), read from MuJoCo's constraint rows of the step just taken.

A held module stands on two supports at once, its clutch row and its
resistance's frictionloss row, and a rigid model leaves the split between them
undetermined; only their sum, the module's total hold R_i, is. MuJoCo's soft
solution splits it its own way: while the soft ratchet limit relaxes, the held
module creeps forward (far below REST_SPEED) and its friction row pulls back
with the whole F_r, which the limit row then carries on top of the load, so the
limit row alone would overstate the clutch's mean force; where neither
saturates the two rows share the load about equally. So the reported reaction
follows the package's one convention (:func:`clutch_share`, the analytic
models' too): of the total hold, the resistance takes a forward push (R_i < 0,
up to F_ri), the clutch everything else. And a module is held while it stands,
i.e. while its clutch row pushes or its friction row sticks (below F_ri): not
only while the clutch row pushes, which flickers on and off in the last
moments before each release as the friction row takes over the last of the load.
These run every step, so they work on Python floats and touch only the few
entries they need; :mod:`.stepper` runs the same rules compiled (a change here
is a change there: its test compares the two bit for bit).

Nothing here uses the analytic model: the lock rules read MuJoCo's state.
:func:`slide_controller` picks the slide model's controller for a run (the compliant
clutches' is in :mod:`.compliant`; on finite grip :mod:`.grip`, :mod:`.compliant_grip`).
"""

from __future__ import annotations

import math

import mujoco

from ipir_mujoco.core.errors import ParameterError
from ipir_mujoco.core.params import RobotParams

from .compliant import CompliantClutches
from ...loop.controller import ControllerBase, RunningBound
from ...loop.native import LayoutError
from ...builders.model import CRANK_HINGE, FRONT_LOCK, REAR_LOCK, ROD_HINGE, SLIDES, dof_address, qpos_address
from ...loop.rows import FrictionRows, clutch_share, equality_row, missing_rows
from .loop_rows import require_friction_power


class Ratchet(ControllerBase):
    """Each slide's lower limit follows the running maximum of its position, one margin below it.

    A limit row exists while the distance from the bound is below the joint's
    margin (1e-9 m), and MuJoCo's soft limit pulls that distance toward the
    margin itself. So the bound is kept at (running maximum - margin): a module
    that has not moved back feels no clutch force, and one that has is pushed
    back toward its running maximum, never beyond it. (A bound at the running
    maximum itself would push every held module forward by up to a margin per
    step: a creep of ~1e-5 m/s at 1e-4 s.) The limit force is the clutch
    reaction, >= 0 by construction. ``excursion`` [m] is the largest backward
    excursion of a module below its running maximum seen so far (checked
    before every step).
    """

    name = "ratchet"

    def __init__(self, model: mujoco.MjModel, data: mujoco.MjData):
        self.model, self.data = model, data
        self.joint_ids = [model.joint(n).id for n in SLIDES]
        self.qpos_adr = [qpos_address(model, n) for n in SLIDES]
        limited = [j for j in range(model.njnt) if model.jnt_limited[j]]
        if sorted(limited) != sorted(self.joint_ids):
            raise ValueError("the ratchet needs the two slides, and only them, limited: build the model with "
                             "ratchet=True")
        self.margins = [float(model.jnt_margin[j]) for j in self.joint_ids]
        self.range = model.jnt_range
        self.limit = RunningBound(self.range, self.joint_ids, [float(data.qpos[a]) for a in self.qpos_adr],
                                  self.margins, exact=True)
        self.bounds = self.limit.extremes  # running maximum of each module's position
        self.excursion = 0.0
        self._qpos = data.qpos
        self._slides = tuple(enumerate(self.qpos_adr))  # (module, qpos address)
        self.dof_adr = [dof_address(model, n) for n in SLIDES]
        self.friction = FrictionRows.of_dofs(model, self.dof_adr)  # and F_r1, F_r2 [N]

    def before_step(self) -> None:
        """Raise each module's bound to its running maximum, or note how far it is below it."""
        q, follow = self._qpos, self.limit.follow
        for k, a in self._slides:
            give = follow(k, float(q[a]))
            if give > self.excursion:
                self.excursion = give

    def load_compiled(self, loop):
        """Its block in the compiled loop (:mod:`.controller`, ``_clutch_slides.c``): the slides, their bounds and
        their resistance rows."""
        require_friction_power(loop)
        loop.use("ratchet")
        (off0, off1), (r0, r1) = self.friction.offsets, self.friction.resistance
        loop.set_config(x_q0=self.qpos_adr[0], x_q1=self.qpos_adr[1], joint0=self.joint_ids[0],
                        joint1=self.joint_ids[1], fric_off0=off0, fric_off1=off1)
        loop.set_state(bound0=self.bounds[0], bound1=self.bounds[1], margin0=self.margins[0],
                       margin1=self.margins[1], resist0=r0, resist1=r1, excursion=self.excursion)
        get = loop.getter("bound0", "bound1", "excursion")

        def sync(state) -> None:
            self.bounds[0], self.bounds[1], self.excursion = get(state)
        return sync

    def reactions(self) -> tuple[bool, bool, float, float]:
        """(rear held, front held, rear reaction [N], front reaction [N]) of the last step.

        A module is held while its limit row pushes or its friction row sticks (a force above -F_r: a
        sliding module's row sits at exactly -F_r, MuJoCo's bound); its reaction is the clutch's share
        (:func:`clutch_share`) of limit plus friction row, 0 while it slides (see the module docstring).
        The limit rows follow the equality and friction rows, in joint order, and only the two slides
        are limited (checked at construction).
        """
        d = self.data
        start, nl = d.ne + d.nf, d.nl
        if nl == 2:
            rear, front = d.efc_force[start:start + 2].tolist()
            if self.joint_ids[0] > self.joint_ids[1]:
                rear, front = front, rear
        elif nl == 1:
            force = float(d.efc_force[start])
            rear, front = (force, 0.0) if d.efc_id[start] == self.joint_ids[0] else (0.0, force)
        else:
            rear = front = 0.0
        f1, f2 = self.friction.forces(d)
        r1, r2 = self.friction.resistance
        held1, held2 = rear > 0.0 or f1 > -r1, front > 0.0 or f2 > -r2
        return (held1, held2, clutch_share(rear + f1, r1) if held1 else 0.0,
                clutch_share(front + f2, r2) if held2 else 0.0)


class Locks(ControllerBase):
    """A joint-equality lock per module, switched on and off between steps.

    ``rule='kinematic'`` is the paper's: the gap rate S_dot decides, front
    locked while it is negative, rear locked while it is positive. S_dot is
    the linkage's own rate, -r sin(phi) omega - L sin(beta) beta_dot from the
    crank and rod joints, which equals x2_dot - x1_dot while the loop is closed
    and still tells which way the linkage drives when both modules are held.
    At S_dot = 0 the locks stay as they are (both held at a start from rest).

    ``rule='unilateral'``: a lock whose reaction in the last step pulled
    backward (< 0) is released; a free module moving backward is locked where
    it stands. Both start locked when the modules start at rest.

    A lock is anchored at the module's position when it engages
    (``eq_data[e, 0] = q``: a joint equality without joint2 holds q = q0 + a0,
    and q0 = 0 for the slides). ``excursion`` [m]: the largest distance a held
    module was found behind its anchor at the start of a step.
    """

    name = "lock"

    def __init__(self, model: mujoco.MjModel, data: mujoco.MjData, rule: str, r: float, L: float):
        if rule not in ("kinematic", "unilateral"):
            raise ValueError(f"lock rule {rule!r} is unknown; allowed: kinematic, unilateral")
        self.model, self.data, self.rule, self.r, self.L = model, data, rule, r, L
        self.eq_ids = [model.equality(n).id for n in (REAR_LOCK, FRONT_LOCK)]
        self.qpos_adr = [qpos_address(model, n) for n in SLIDES]
        self.dof_adr = [dof_address(model, n) for n in SLIDES]
        self.crank_q, self.rod_q = qpos_address(model, CRANK_HINGE), qpos_address(model, ROD_HINGE)
        self.crank_v, self.rod_v = dof_address(model, CRANK_HINGE), dof_address(model, ROD_HINGE)
        self.friction = FrictionRows.of_dofs(model, self.dof_adr)  # and F_r1, F_r2 [N]
        self.held = [False, False]
        self.forces = [0.0, 0.0]
        self.excursion = 0.0
        if rule == "kinematic":
            s_dot = self.gap_rate()
            self._apply([s_dot >= 0, s_dot <= 0])
            self.after_step = super().after_step  # the paper's rule needs no forces between samples: nothing
        else:
            self._apply([data.qvel[a] <= 0 for a in self.dof_adr])

    def gap_rate(self) -> float:
        """The linkage's S_dot [m/s] from the crank and rod joint states."""
        q, v = self.data.qpos, self.data.qvel
        phi, omega = q[self.crank_q], v[self.crank_v]
        beta, beta_rate = phi + q[self.rod_q], omega + v[self.rod_v]
        return -self.r * math.sin(phi) * omega - self.L * math.sin(beta) * beta_rate

    def _apply(self, wanted: list[bool]) -> None:
        for i, (now, want) in enumerate(zip(self.held, wanted)):
            if want and not now:
                self.model.eq_data[self.eq_ids[i], 0] = self.data.qpos[self.qpos_adr[i]]
            if want != now:
                self.data.eq_active[self.eq_ids[i]] = want
        self.held = list(wanted)

    def before_step(self) -> None:
        q = self.data.qpos
        for i in (0, 1):
            if self.held[i]:
                back = self.model.eq_data[self.eq_ids[i], 0] - q[self.qpos_adr[i]]
                if back > self.excursion:
                    self.excursion = float(back)
        if self.rule == "kinematic":
            s_dot = self.gap_rate()
            if s_dot < 0:
                self._apply([False, True])
            elif s_dot > 0:
                self._apply([True, False])
        else:
            v = self.data.qvel
            self._apply([self.forces[i] >= 0.0 if self.held[i] else v[self.dof_adr[i]] < 0.0 for i in (0, 1)])

    def after_step(self) -> None:
        self.forces = self._lock_forces()

    def _lock_forces(self) -> list[float]:
        forces = [0.0, 0.0]
        for i in (0, 1):
            if self.held[i]:
                row = equality_row(self.model, self.data, self.eq_ids[i])
                if row >= self.data.ne:  # as _stepper.c: never a row that is not this lock's
                    raise missing_rows(1, self.data.time)
                forces[i] = float(self.data.efc_force[row])
        return forces

    def load_compiled(self, loop):
        """Its block in the compiled loop (:mod:`.controller`, ``_clutch_slides.c``): the slides, the locks, the
        linkage's joints, the slides' resistance rows."""
        if (self.crank_q, self.crank_v) != (loop.crank_q, loop.crank_v):
            raise LayoutError("the locks' crank joint is not the run's")
        require_friction_power(loop)
        loop.use("lock_" + self.rule)
        (off0, off1), (r0, r1) = self.friction.offsets, self.friction.resistance
        loop.set_config(x_q0=self.qpos_adr[0], x_q1=self.qpos_adr[1], x_v0=self.dof_adr[0], x_v1=self.dof_adr[1],
                        eq0=self.eq_ids[0], eq1=self.eq_ids[1], rod_q=self.rod_q, rod_v=self.rod_v,
                        fric_off0=off0, fric_off1=off1)
        loop.set_state(held0=self.held[0], held1=self.held[1], force0=self.forces[0], force1=self.forces[1],
                       r=self.r, L=self.L, resist0=r0, resist1=r1, excursion=self.excursion)
        get = loop.getter("held0", "held1", "force0", "force1", "excursion")

        def sync(state) -> None:
            held0, held1, force0, force1, self.excursion = get(state)
            self.held, self.forces = [held0 != 0.0, held1 != 0.0], [force0, force1]
        return sync

    def reactions(self) -> tuple[bool, bool, float, float]:
        """(rear held, front held, rear reaction [N], front reaction [N]) of the last step.

        A locked module's total hold is its lock row plus its friction row (see the module docstring).
        Under the paper's rule a module is held while it is locked, and the lock carries the whole hold
        while the other module moves, as the paper's model has it (a held module there has no resistance,
        and a lock that pulls is what the rule reveals). Under the one-way rule a module is held while it
        stands, locked or on its static friction (its row above -F_r: a lock lets go as soon as its row
        would pull, which can be well before the push on the module exceeds F_r), as the ratchet's; there, and
        with both locked under the paper's rule, the resistance takes a forward push up to F_r
        (:func:`clutch_share`), as the analytic models do.
        """
        forces = self._lock_forces()
        friction, resistance = self.friction.forces(self.data), self.friction.resistance
        kinematic = self.rule == "kinematic"
        whole = kinematic and not all(self.held)
        held, out = [], []
        for i in (0, 1):
            held.append(self.held[i] or (not kinematic and friction[i] > -resistance[i]))
            hold = forces[i] + friction[i]
            out.append(0.0 if not held[i] else hold if whole else clutch_share(hold, resistance[i]))
        return held[0], held[1], out[0], out[1]


class NoClutch(ControllerBase):
    """Both modules free (for checks such as momentum conservation)."""

    name = "none"

    def __init__(self, model: mujoco.MjModel, data: mujoco.MjData):
        pass

    def before_step(self) -> None:
        pass

    def reactions(self) -> tuple[bool, bool, float, float]:
        return False, False, 0.0, 0.0

    def load_compiled(self, loop):
        """Nothing to load or read back in the compiled loop."""
        require_friction_power(loop)
        loop.use("none")
        return lambda state: None


def refuse_compliant(params: RobotParams, implementation: str) -> None:
    """ParameterError (one line) for a finite ``clutch_stiffness`` with a clutch that is rigid only."""
    if params.clutch_stiffness is not None and implementation != "ratchet":
        raise ParameterError(f"clutch_stiffness={params.clutch_stiffness!r} N/m with the MuJoCo {implementation!r} "
                             "clutch: only the ratchet has a compliant form; allowed: --clutch unilateral "
                             "--mujoco-clutch ratchet")


def slide_controller(model: mujoco.MjModel, data: mujoco.MjData, params: RobotParams, implementation: str,
                     rule: str = "unilateral"):
    """The slide model's clutch controller of a run (unlimited grip), for a model built with
    ``ratchet=implementation == 'ratchet'``: 'ratchet', the joint-limit ratchet, or with a finite
    ``params.clutch_stiffness`` the compliant clutches (:class:`.compliant.CompliantClutches`); 'lock': the
    locks with ``rule``; 'none': no clutches. Call it after the initial state is set (the ratchet and the
    anchors start at the modules' positions). A finite ``clutch_stiffness`` with the locks or no clutch is a
    ParameterError: they are rigid only."""
    refuse_compliant(params, implementation)
    if implementation == "ratchet":
        if params.clutch_stiffness is not None:
            return CompliantClutches(model, data, params)
        return Ratchet(model, data)
    if implementation == "lock":
        return Locks(model, data, rule, params.r, params.L)
    if implementation == "none":
        return NoClutch(model, data)
    raise ValueError(f"mujoco clutch {implementation!r} is unknown; allowed: ratchet, lock, none")
