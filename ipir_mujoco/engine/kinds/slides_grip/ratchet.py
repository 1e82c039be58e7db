"""The one-way clutches on wheels of finite grip in MuJoCo: two ratchets per module, MuJoCo's rows do the rest.

The model (:mod:`.grip_model`) gives each module a carriage c_i on the wall,
held by Coulomb friction G_i, and a tendon L_i = x_i - c_i, the wheels' roll,
with the rolling resistance F_ri. Before every step the controller moves two
one-sided bounds per module, each as the rigid ratchet does
(:class:`.clutches.Ratchet`, one margin from the running extreme):

- the clutch: the roll's lower limit follows the running maximum of L_i (the
  wheels do not roll back);
- the wall: the carriage's upper limit follows the running minimum of c_i
  (the locked wheels skid back, never forward).

Everything else is MuJoCo's: a held module's ground force g = clutch row +
roll friction row is held by the carriage's friction row up to G_i; beyond,
that row sits at exactly G_i and the carriage slides back with the module; the
roll's friction row lets the module roll forward at exactly F_ri.

Reported per module (:meth:`GripRatchet.reactions`, :meth:`GripRatchet.wheels`):
rolling while the roll's friction row slides (at -F_ri) and the clutch row does
not push (the ratchet's test on x_i without grip); skidding while it does not
roll and the carriage's friction row is at its bound G_i (with G_i = 0, where
there is no row, while its hold pushes back at all); standing otherwise. The
clutch's reaction is the clutch's share of the hold (:func:`.clutches.clutch_share`),
0 while rolling; a skidding module's is what its clutch carries, G_i and the
carriage's inertia times its acceleration. ``excursion`` [m]: the largest give
of either one-way limit so far (L_i below its running maximum, c_i above its
running minimum), checked before every step: the clutch's and the wall's give,
never a skid (a skid moves c_i down, which is the running minimum itself).

The same rules run compiled in ``_stepper.c`` (held equal bit for bit by
``tests/test_mujoco_stepper.py``).
"""

from __future__ import annotations

import math

import mujoco

from ipir_mujoco.core.params import RobotParams
from ipir_mujoco.core.results import REST_SPEED

from .compiled import load_grip_ratchet
from ...loop.controller import ROLLING, SKIDDING, STANDING, ControllerBase, RunningBound, held, lower_bound, upper_bound
from ...builders.grip_model import ROLLS, SKIDS
from ...builders.model import SLIDES, dof_address, qpos_address
from ...loop.rows import clutch_share
from ..slides.loop_rows import GripRows

__all__ = ["LIMIT_TENDON", "GripRatchet", "GripRows", "lower_bound", "upper_bound"]  # GripRows: an older place

LIMIT_TENDON = int(mujoco.mjtConstraint.mjCNSTR_LIMIT_TENDON)


class GripRatchet(ControllerBase):
    """The rigid one-way clutches on finite grip (module docstring): moves the clutch's and the wall's bounds.

    ``model`` built with a finite ``params.grip`` and rigid clutches; call it after the initial state is set.
    ``bounds`` [m]: running maximum of each roll L_i; ``lowest`` [m]: running minimum of each carriage c_i.
    """

    name = "grip ratchet"

    def __init__(self, model: mujoco.MjModel, data: mujoco.MjData, params: RobotParams):
        if params.grip is None or params.clutch_stiffness is not None:
            raise ValueError("GripRatchet needs a model built with a finite mu_wall and rigid clutches")
        self.model, self.data = model, data
        self._states = (math.nan, None)  # (data.time, states()) of the last step read
        self.x_adr = [qpos_address(model, n) for n in SLIDES]
        self.c_adr = [qpos_address(model, n) for n in SKIDS]
        self.c_dof = [dof_address(model, n) for n in SKIDS]
        self.x_dof = [dof_address(model, n) for n in SLIDES]
        self.skid_ids = [model.joint(n).id for n in SKIDS]
        self.roll_ids = [model.tendon(n).id for n in ROLLS]
        limited = [j for j in range(model.njnt) if model.jnt_limited[j]]
        if sorted(limited) != sorted(self.skid_ids) or not all(model.tendon_limited[t] for t in self.roll_ids):
            raise ValueError("the grip ratchet needs the carriages' slides and the rolls limited, and no other "
                             "joint: build the model from these parameters")
        self.roll_margins = [float(model.tendon_margin[t]) for t in self.roll_ids]
        self.skid_margins = [float(model.jnt_margin[j]) for j in self.skid_ids]
        q = data.qpos
        self.roll_limit = RunningBound(model.tendon_range, self.roll_ids,
                                   [float(q[x]) - float(q[c]) for x, c in zip(self.x_adr, self.c_adr)],
                                   self.roll_margins)
        self.wall_limit = RunningBound(model.jnt_range, self.skid_ids, [float(q[c]) for c in self.c_adr],
                                 self.skid_margins, upper=True)
        self.bounds, self.lowest = self.roll_limit.extremes, self.wall_limit.extremes
        self.excursion = 0.0
        self._qpos, self._qvel = q, data.qvel
        self._per_module = tuple(zip((0, 1), self.x_adr, self.c_adr))
        self.rows = GripRows(model, roll_on_tendon=True)
        self.grip, self.resistance = self.rows.grips, self.rows.resistances  # G_i, F_ri [N]

    def before_step(self) -> None:
        """Raise each roll's bound to its running maximum and lower each carriage's to its running minimum,
        or note how far either has given."""
        q, clutch, wall = self._qpos, self.roll_limit.follow, self.wall_limit.follow
        for k, xa, ca in self._per_module:
            c = q.item(ca)
            give = clutch(k, q.item(xa) - c)
            if give > self.excursion:
                self.excursion = give
            give = wall(k, c)
            if give > self.excursion:
                self.excursion = give

    def load_compiled(self, loop):
        """Its block in the compiled loop (:func:`.compiled_grip.load_grip_ratchet`)."""
        return load_grip_ratchet(self, loop)

    def _clutch_rows(self) -> list[float]:
        """The rolls' limit rows [N] of the last step (0.0 for a roll without one): the limit rows follow the
        equality and friction rows, the joints' first, then the tendons' in tendon order."""
        d = self.data
        out = [0.0, 0.0]
        start = d.ne + d.nf
        for row in range(start, start + d.nl):
            if d.efc_type[row] == LIMIT_TENDON:
                t = d.efc_id[row]
                out[0 if t == self.roll_ids[0] else 1] = d.efc_force.item(row)
        return out

    def states(self) -> tuple[list[int], list[float]]:
        """Per module, its wheels' state (+1 rolling, 0 standing, -1 skidding) and its clutch's share of
        the hold [N], of the last step (module docstring). Computed once per step: a sample reads it twice
        (:meth:`reactions`, :meth:`wheels`)."""
        if self._states[0] == self.data.time:
            return self._states[1]
        clutch = self._clutch_rows()
        grip_force, roll_force = self.rows.forces(self.data)
        states, shares = [], []
        for k in (0, 1):
            hold = clutch[k] + roll_force[k]
            F, G = self.resistance[k], self.grip[k]
            if not (clutch[k] > 0.0 or roll_force[k] > -F):
                states.append(ROLLING)
                shares.append(0.0)
                continue
            skids = grip_force[k] >= G if G > 0.0 else self._qvel.item(self.c_dof[k]) < -REST_SPEED
            states.append(SKIDDING if skids else STANDING)
            shares.append(clutch_share(hold, F))
        self._states = (self.data.time, (states, shares))
        return states, shares

    def reactions(self) -> tuple[bool, bool, float, float]:
        """(rear held, front held, rear reaction [N], front reaction [N]) of the last step: held while it
        stands."""
        states, shares = self.states()
        return held(True, states[0]), held(True, states[1]), shares[0], shares[1]

    def wheels(self) -> tuple[float, float]:
        """Each module's wheels' state of the last step: +1.0 rolling, 0.0 standing, -1.0 skidding."""
        states, _ = self.states()
        return float(states[0]), float(states[1])
