"""One-way clutches in MuJoCo: a joint-limit ratchet and velocity-triggered locks.

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
:func:`clutch_controller` picks the controller for a run (the compliant
clutches' is in :mod:`.compliant`).
"""

from __future__ import annotations

import math

import mujoco

from ipir_mujoco.core.errors import ParameterError, SimulationError
from ipir_mujoco.core.params import RobotParams

from .compliant import CompliantClutches
from .model import CRANK_HINGE, FRONT_LOCK, REAR_LOCK, ROD_HINGE, SLIDES, dof_address, qpos_address

# constraint rows per equality type (connect: 3 translations, weld: 6, joint/tendon/distance: 1)
EQUALITY_ROWS = {int(mujoco.mjtEq.mjEQ_CONNECT): 3, int(mujoco.mjtEq.mjEQ_WELD): 6}
# the constraint rows the stepping loop reads after a step, by the code _stepper.c returns when one is absent
MISSING_ROWS = {1: "a held lock's equality row", 2: "the resistances' frictionloss rows"}


def missing_rows(code: int, t: float) -> SimulationError:
    """The one-line error of a step after which constraint rows the loop reads are absent (``code``: a key
    of MISSING_ROWS; ``t`` [s] the simulated time after the step)."""
    return SimulationError(f"MuJoCo's step to t={t:.6g} s produced no {MISSING_ROWS[code]} (a constraint "
                           "disabled in the model's options?): the run cannot measure the clutch and the "
                           "resistances")


FRICTION_DOF, FRICTION_TENDON = (int(mujoco.mjtConstraint.mjCNSTR_FRICTION_DOF),
                                 int(mujoco.mjtConstraint.mjCNSTR_FRICTION_TENDON))


class FrictionRows:
    """Where the frictionloss rows of some of a model's dofs and tendons sit, and their bounds.

    ``elements``: (kind, index) pairs, kind FRICTION_DOF (index a dof) or FRICTION_TENDON (a tendon), in the
    order :meth:`forces` returns them. MuJoCo puts the friction rows after the equality rows, the dofs' in
    dof order, then the tendons' in tendon order, one per element with friction, so each element's offset
    among them is fixed by the model; read once per sample at those rows. ``resistance`` [N]: each element's
    frictionloss; ``offsets``: its offset among the friction rows (-1: it has none); ``count``: how many
    friction rows the model has.
    """

    def __init__(self, model: mujoco.MjModel, elements: list[tuple[int, int]]):
        order = [(FRICTION_DOF, i) for i in range(model.nv) if model.dof_frictionloss[i] > 0]
        order += [(FRICTION_TENDON, i) for i in range(model.ntendon) if model.tendon_frictionloss[i] > 0]
        self.resistance = [float((model.dof_frictionloss if kind == FRICTION_DOF else model.tendon_frictionloss)[i])
                           for kind, i in elements]
        self.offsets = [order.index(e) if e in order else -1 for e in elements]
        self.count = len(order)

    @classmethod
    def of_dofs(cls, model: mujoco.MjModel, dofs: list[int]) -> "FrictionRows":
        """The rows of the dofs ``dofs`` (the slides' resistances)."""
        return cls(model, [(FRICTION_DOF, dof) for dof in dofs])

    def forces(self, data: mujoco.MjData) -> list[float]:
        """The rows' forces [N] of the last step, per element (0.0 for one without a row)."""
        if data.nf != self.count:  # as the stepping loops: never a row that is not this element's
            raise missing_rows(2, data.time)
        ne, force = data.ne, data.efc_force
        return [force.item(ne + k) if k >= 0 else 0.0 for k in self.offsets]


def clutch_share(hold: float, resistance: float) -> float:
    """The clutch's part [N] of a held module's total hold ``hold`` [N] (clutch plus static resistance, > 0
    forward), with ``resistance`` [N] the module's F_r: the resistance takes a forward push (hold < 0) up to
    F_r, the clutch the rest (a lock may pull beyond it). The analytic models' convention: a one-way clutch
    reports max(hold, 0)."""
    return hold - min(max(hold, -resistance), 0.0)


def equality_row(model: mujoco.MjModel, data: mujoco.MjData, eq_id: int) -> int:
    """Index of the first constraint row of equality ``eq_id`` (active): MuJoCo puts the rows of the
    active equalities first, in id order."""
    row = 0
    for e in range(eq_id):
        if data.eq_active[e]:
            row += EQUALITY_ROWS.get(int(model.eq_type[e]), 1)
    return row


class Ratchet:
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
    after_step = None
    damper_work = 0.0  # no damper: the compliant clutches' cumulative dissipation [J]

    def __init__(self, model: mujoco.MjModel, data: mujoco.MjData):
        self.model, self.data = model, data
        self.joint_ids = [model.joint(n).id for n in SLIDES]
        self.qpos_adr = [qpos_address(model, n) for n in SLIDES]
        limited = [j for j in range(model.njnt) if model.jnt_limited[j]]
        if sorted(limited) != sorted(self.joint_ids):
            raise ValueError("the ratchet needs the two slides, and only them, limited: build the model with "
                             "ratchet=True")
        self.bounds = [float(data.qpos[a]) for a in self.qpos_adr]  # running maximum of each module's position
        self.margins = [float(model.jnt_margin[j]) for j in self.joint_ids]
        self.range = model.jnt_range
        for j, b, margin in zip(self.joint_ids, self.bounds, self.margins):
            self.range[j, 0] = b - margin
        self.excursion = 0.0
        self._qpos = data.qpos
        self._slides = tuple(zip(self.qpos_adr, self.joint_ids))  # (qpos address, joint id) per module
        self.dof_adr = [dof_address(model, n) for n in SLIDES]
        self.friction = FrictionRows.of_dofs(model, self.dof_adr)  # and F_r1, F_r2 [N]

    def before_step(self) -> None:
        """Raise each module's bound to its running maximum, or note how far it is below it."""
        q, bounds, margins = self._qpos, self.bounds, self.margins
        for k, (a, j) in enumerate(self._slides):
            x = float(q[a])
            if x > bounds[k]:
                bounds[k] = x
                self.range[j, 0] = x - margins[k]
            elif bounds[k] - x > self.excursion:
                self.excursion = bounds[k] - x

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


class Locks:
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
    damper_work = 0.0

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
            self.after_step = None  # the paper's rule needs no forces between samples
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


class NoClutch:
    """Both modules free (for checks such as momentum conservation)."""

    name = "none"
    after_step = None
    excursion = 0.0
    damper_work = 0.0

    def __init__(self, model: mujoco.MjModel, data: mujoco.MjData):
        pass

    def before_step(self) -> None:
        pass

    def reactions(self) -> tuple[bool, bool, float, float]:
        return False, False, 0.0, 0.0


def refuse_compliant(params: RobotParams, implementation: str) -> None:
    """ParameterError (one line) for a finite ``clutch_stiffness`` with a clutch that is rigid only."""
    if params.clutch_stiffness is not None and implementation != "ratchet":
        raise ParameterError(f"clutch_stiffness={params.clutch_stiffness!r} N/m with the MuJoCo {implementation!r} "
                             "clutch: only the ratchet has a compliant form; allowed: --clutch unilateral "
                             "--mujoco-clutch ratchet")


def refuse_grip(params: RobotParams, implementation: str) -> None:
    """ParameterError (one line) for a finite ``mu_wall`` with a clutch that has no grip: the locks (an equality
    holds whatever the load) and no clutch. (Wheel normal forces given with unlimited grip are refused for
    every engine by :func:`ipir_mujoco.core.params.refuse_idle_parameters`.)"""
    if params.mu_wall is not None and implementation != "ratchet":
        raise ParameterError(f"mu_wall={params.mu_wall!r} with the MuJoCo {implementation!r} clutch: only the ratchet "
                             "is modelled on wheels of finite grip (a lock holds whatever the load); allowed: "
                             "--mujoco-clutch ratchet, or mu_wall=unlimited")


def clutch_controller(model: mujoco.MjModel, data: mujoco.MjData, params: RobotParams, implementation: str,
                      rule: str = "unilateral"):
    """The clutch controller of a run, for a model built with ``ratchet=implementation == 'ratchet'``.

    'ratchet': the joint-limit ratchet, or with a finite ``params.clutch_stiffness`` the compliant clutches
    (:class:`.compliant.CompliantClutches`), with a finite ``params.mu_wall`` on wheels of finite grip
    (:mod:`.grip`); 'lock': the locks with ``rule``; 'none': no clutches. Call it after the initial state is
    set (the ratchet and the anchors start at the modules' positions). A finite ``clutch_stiffness`` or
    ``mu_wall`` with the locks or no clutch is a ParameterError: they are rigid only, and hold any force.
    """
    refuse_compliant(params, implementation)
    refuse_grip(params, implementation)
    if implementation == "ratchet":
        if params.grip is not None:  # the wheels' finite grip: the carriages' model (.grip_model)
            from .grip import GripRatchet  # here: grip builds on this module
            from .grip_compliant import CompliantGrip

            if params.clutch_stiffness is None:
                return GripRatchet(model, data, params)
            return CompliantGrip(model, data, params)
        if params.clutch_stiffness is not None:
            return CompliantClutches(model, data, params)
        return Ratchet(model, data)
    if implementation == "lock":
        return Locks(model, data, rule, params.r, params.L)
    if implementation == "none":
        return NoClutch(model, data)
    raise ValueError(f"mujoco clutch {implementation!r} is unknown; allowed: ratchet, lock, none")
