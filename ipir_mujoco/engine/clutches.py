"""One-way clutches in MuJoCo: a joint-limit ratchet and velocity-triggered locks.

A controller is called before every ``mj_step`` (:meth:`before_step`) and
after it (:meth:`after_step`, with the step's :class:`StepForces`); it reports
per module whether its clutch holds and the clutch's reaction force [N]
(positive pushes the module forward), read from MuJoCo's constraint forces of
the step just taken.

Nothing here uses the analytic model: the lock rules read MuJoCo's state.
"""

from __future__ import annotations

import math

import mujoco
import numpy as np

from .model import (CRANK_HINGE, FRONT_LOCK, FRONT_SLIDE, REAR_LOCK, REAR_SLIDE, ROD_HINGE, dof_address,
                    qpos_address)

LIMIT_ROW = int(mujoco.mjtConstraint.mjCNSTR_LIMIT_JOINT)
EQUALITY_ROW = int(mujoco.mjtConstraint.mjCNSTR_EQUALITY)
SLIDES = (REAR_SLIDE, FRONT_SLIDE)


class StepForces:
    """The constraint forces of the step just taken, read from MuJoCo once per step.

    ``by_row[(type, id)]``: the summed force of the rows of one constraint
    element (mjtConstraint type, element id); ``loop``: the three rows of the
    loop-closing ``connect`` (world-frame force on the rod at C). A plain
    Python pass over the few rows (about seven) costs less than numpy masks.
    """

    __slots__ = ("by_row", "loop")

    def __init__(self, data: mujoco.MjData, loop_id: int):
        n = data.nefc
        self.by_row: dict[tuple[int, int], float] = {}
        self.loop: list[float] = []
        for row_type, element, force in zip(data.efc_type[:n].tolist(), data.efc_id[:n].tolist(),
                                            data.efc_force[:n].tolist()):
            if row_type == EQUALITY_ROW and element == loop_id:
                self.loop.append(force)
            else:
                key = (row_type, element)
                self.by_row[key] = self.by_row.get(key, 0.0) + force

    def force(self, row_type: int, element: int) -> float | None:
        """Summed force of one element's rows, None if it has no active row."""
        return self.by_row.get((row_type, element))


class Ratchet:
    """Each slide's lower limit follows the running maximum of its position.

    A limit row exists only while the distance to the bound is below the
    joint's margin (1e-9 m), so the bound is raised to max(bound, q) rather
    than to q, which would leave the distance at exactly 0 and the clutch never
    engaged (see shared/DESIGN.md). The limit force is the clutch reaction,
    >= 0 by construction.
    """

    name = "ratchet"

    def __init__(self, model: mujoco.MjModel, data: mujoco.MjData):
        self.model, self.data = model, data
        self.joint_ids = np.array([model.joint(n).id for n in SLIDES])
        self.qpos_adr = np.array([qpos_address(model, n) for n in SLIDES])
        if not np.all(model.jnt_limited[self.joint_ids]):
            raise ValueError("the ratchet needs limited slides: build the model with ratchet=True")
        self.bounds = data.qpos[self.qpos_adr].copy()  # running maximum of each module's position
        model.jnt_range[self.joint_ids, 0] = self.bounds
        self.forces = [0.0, 0.0]

    def before_step(self) -> None:
        np.maximum(self.bounds, self.data.qpos[self.qpos_adr], out=self.bounds)
        self.model.jnt_range[self.joint_ids, 0] = self.bounds

    def after_step(self, forces: StepForces) -> None:
        self.forces = [forces.force(LIMIT_ROW, int(j)) or 0.0 for j in self.joint_ids]

    def reactions(self) -> tuple[list[bool], list[float]]:
        return [f > 0.0 for f in self.forces], list(self.forces)


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
    and q0 = 0 for the slides).
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
        self.held = [False, False]
        self.forces = [0.0, 0.0]
        velocities = [data.qvel[a] for a in self.dof_adr]
        if rule == "kinematic":
            s_dot = self.gap_rate()
            self._apply([s_dot >= 0, s_dot <= 0])
        else:
            self._apply([v <= 0 for v in velocities])

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
            self.data.eq_active[self.eq_ids[i]] = want
        self.held = list(wanted)

    def before_step(self) -> None:
        if self.rule == "kinematic":
            s_dot = self.gap_rate()
            if s_dot < 0:
                self._apply([False, True])
            elif s_dot > 0:
                self._apply([True, False])
        else:
            wanted = []
            for i in range(2):
                if self.held[i]:
                    wanted.append(self.forces[i] >= 0.0)
                else:
                    wanted.append(self.data.qvel[self.dof_adr[i]] < 0.0)
            self._apply(wanted)

    def after_step(self, forces: StepForces) -> None:
        self.forces = [(forces.force(EQUALITY_ROW, eq_id) or 0.0) if held else 0.0
                       for eq_id, held in zip(self.eq_ids, self.held)]

    def reactions(self) -> tuple[list[bool], list[float]]:
        return list(self.held), list(self.forces)


class NoClutch:
    """Both modules free (for checks such as momentum conservation)."""

    name = "none"

    def __init__(self, model: mujoco.MjModel, data: mujoco.MjData):
        pass

    def before_step(self) -> None:
        pass

    def after_step(self, forces: StepForces) -> None:
        pass

    def reactions(self) -> tuple[list[bool], list[float]]:
        return [False, False], [0.0, 0.0]
