"""Where MuJoCo puts the constraint rows the clutch controllers and the loop read: equality and friction rows.

MuJoCo lays out a step's constraint rows as: the active equalities' (in id order), then the frictionloss
rows (the dofs' in dof order, then the tendons'), then the limits', then the contacts'. The controllers
(:mod:`.slide_clutches`, :mod:`.grip`, :mod:`.wheels`) and the loops (:mod:`.stepper`, ``_stepper.c``) read
them at offsets fixed here. :func:`clutch_share` is the package's one split of a held module's hold between
its clutch and its resistance.
"""

from __future__ import annotations

import mujoco

from ipir_mujoco.core.errors import SimulationError

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
