"""Compliant one-way clutches on wheels of finite grip in MuJoCo: the clutch's anchor rides on the carriage.

The compliant clutch (:mod:`.compliant`) is a spring k and damper c from a
ratcheting anchor to its module. With finite grip (:mod:`.grip_model`) the
anchor is on the carriage, the locked wheels on the wall: each clutch actuator
acts on its roll tendon L_i = x_i - c_i, so its force k (a_i - L_i) - c L_i_dot
(clamped to >= 0) pushes the module forward and the carriage back, and the
carriage's friction holds it up to G_i. Beyond, the carriage slides back at
G_i, carrying the anchor with it: the clutch's force is capped by the grip by
construction, and the anchor slides. The module keeps its own Coulomb
resistance F_ri either way (the analytic compliant model's), on its slide.

The controller does what :class:`.compliant.CompliantClutches` does, in the
roll's coordinate (the anchor a_i = running maximum of L_i less the backlash,
the damper on while the overlap a_i - L_i > 0, the dampers' work at the roll's
speed), and ratchets each carriage's forward limit as :class:`.grip.GripRatchet`
does; ``excursion`` is that limit's give (the wall's), the clutch's own backward
travel being its physics. Each module's wheels (:meth:`CompliantGrip.wheels`):
skidding while its carriage's friction row is at G_i (with G_i = 0: while the
carriage moves back faster than REST_SPEED), rolling while the module was at
its running maximum at the last step's start and rolls on faster than
REST_SPEED, standing otherwise; the analytic model's sliding, tracking and
other clutch states. The same rules run compiled in ``_stepper.c``.
"""

from __future__ import annotations

import mujoco

from ipir_mujoco.core.params import RobotParams

from ipir_mujoco.core.results import REST_SPEED

from .compliant import CLUTCHES, CompliantClutches, check_transmissions, clutch_actuators
from .controller import ROLLING, SKIDDING, STANDING, RunningBound
from .grip import GripRows
from .grip_model import ROLLS, SKIDS
from .model import SLIDES, dof_address, implicit_damping, qpos_address


class CompliantGrip(CompliantClutches):
    """The compliant clutches on finite grip (module docstring): ``anchor``, ``overlap``, ``v_before`` in the
    roll's coordinate [m, m/s]; ``lowest`` [m]: each carriage's running minimum; ``tracking``: whether each
    module was at its running maximum at the last step's start."""

    name = "compliant grip"

    def __init__(self, model: mujoco.MjModel, data: mujoco.MjData, params: RobotParams):
        if params.grip is None or params.clutch_stiffness is None:
            raise ValueError("CompliantGrip needs a model built with a finite mu_wall and clutch_stiffness")
        self.model, self.data = model, data
        self.act = [model.actuator(n).id for n in CLUTCHES]
        self.qpos_adr = [qpos_address(model, n) for n in SLIDES]
        self.dof_adr = [dof_address(model, n) for n in SLIDES]
        self.c_adr = [qpos_address(model, n) for n in SKIDS]
        self.c_dof = [dof_address(model, n) for n in SKIDS]
        self.skid_ids = [model.joint(n).id for n in SKIDS]
        check_transmissions(model, self.act, mujoco.mjtTrn.mjTRN_TENDON, [model.tendon(n).id for n in ROLLS], ROLLS)
        k, c = clutch_actuators(model, self.act, params)
        self.k, self.c, self.backlash, self.dt = float(k), float(c), params.clutch_backlash, float(model.opt.timestep)
        self.implicit = implicit_damping(model)
        self._ctrl, self._biasprm = data.ctrl, model.actuator_biasprm
        self._qpos, self._qvel, self._force = data.qpos, data.qvel, data.actuator_force
        q = data.qpos
        self.anchor = [float(q[x]) - float(q[c]) - self.backlash for x, c in zip(self.qpos_adr, self.c_adr)]
        for u, a in zip(self.act, self.anchor):
            data.ctrl[u] = a
        self.skid_margins = [float(model.jnt_margin[j]) for j in self.skid_ids]
        self.wall_limit = RunningBound(model.jnt_range, self.skid_ids, [float(q[c]) for c in self.c_adr],
                                       self.skid_margins, upper=True)
        self.lowest = self.wall_limit.extremes  # each carriage's running minimum
        self._per_module = tuple(zip((0, 1), self.qpos_adr, self.dof_adr, self.act))
        self._carriages = tuple(zip(self.c_adr, self.c_dof, self.skid_ids))
        self.damped = [True, True]
        self.overlap = [0.0, 0.0]
        self.v_before = [0.0, 0.0]
        self.tracking = [False, False]
        self.damper_work = 0.0
        self.excursion = 0.0
        self.rows = GripRows(model, roll_on_tendon=False)
        self.grip = self.rows.grips  # G_i [N]
        self.before_step()

    def before_step(self) -> None:
        """Raise each anchor to (L - backlash) if the roll went further; damper on while d > 0; lower each
        carriage's forward bound to its running minimum, or note how far it has given."""
        q, v, backlash, anchor, overlap = self._qpos, self._qvel, self.backlash, self.anchor, self.overlap
        for (i, adr, dof, act), (ca, cv, j) in zip(self._per_module, self._carriages):
            c = q.item(ca)
            roll = q.item(adr) - c
            self.tracking[i] = roll - backlash > anchor[i]
            if self.tracking[i]:
                anchor[i] = roll - backlash
                self._ctrl[act] = anchor[i]
            d = anchor[i] - roll
            overlap[i] = d
            self.v_before[i] = v.item(dof) - v.item(cv)
            if (d > 0.0) != self.damped[i]:
                self.damped[i] = d > 0.0
                self._biasprm[act, 2] = -self.c if d > 0.0 else 0.0
            give = self.wall_limit.follow(i, c)
            if give > self.excursion:
                self.excursion = give

    def after_step(self) -> None:
        """Add the step's damper dissipation at the roll's speed (:meth:`.CompliantClutches.after_step`)."""
        work = 0.0
        for (i, _, dof, act), (_, cv, _) in zip(self._per_module, self._carriages):
            d, applied = self.overlap[i], self._force.item(act)
            if d <= 0.0 and applied == 0.0:
                continue
            speed = self._qvel.item(dof) - self._qvel.item(cv)
            if applied > 0.0 and self.damped[i] and self.implicit:
                applied -= self.c * (speed - self.v_before[i])
            work += ((self.k * d if d > 0.0 else 0.0) - applied) * speed
        self.damper_work += work * self.dt

    def wheels(self) -> tuple[float, float]:
        """Each module's wheels' state of the last step: +1.0 rolling, 0.0 standing, -1.0 skidding."""
        grip_force, _ = self.rows.forces(self.data)
        v = self._qvel
        out = []
        for (i, _, dof, _), (_, cv, _) in zip(self._per_module, self._carriages):
            G = self.grip[i]
            skids = grip_force[i] >= G if G > 0.0 else v.item(cv) < -REST_SPEED
            if skids:
                out.append(float(SKIDDING))
            elif self.tracking[i] and v.item(dof) - v.item(cv) > REST_SPEED:
                out.append(float(ROLLING))
            else:
                out.append(float(STANDING))
        return out[0], out[1]
