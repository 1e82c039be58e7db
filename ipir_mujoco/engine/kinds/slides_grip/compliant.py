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

from .compiled import load_compliant_grip
from ..slides.compliant import CompliantClutches, check_transmissions
from ...loop.controller import ROLLING, SKIDDING, STANDING, RunningBound
from ..slides.loop_rows import GripRows
from ...builders.grip_model import ROLLS, SKIDS
from ...builders.model import dof_address, qpos_address


class CompliantGrip(CompliantClutches):
    """The compliant clutches on finite grip (module docstring): the compliant mechanism of
    :class:`.compliant.CompliantClutches` on the roll's coordinate, a :class:`.controller.RunningBound` on each
    carriage (the wall) and the carriages' rows (:class:`.grip.GripRows`). ``anchor``, ``overlap``, ``v_before``
    in the roll's coordinate [m, m/s]; ``lowest`` [m]: each carriage's running minimum; ``tracking``: whether
    each module was at its running maximum at the last step's start."""

    name = "compliant grip"

    def attach(self, model: mujoco.MjModel, data: mujoco.MjData, params: RobotParams) -> None:
        """The carriages: their addresses, the wall's running bound, their friction rows (G_i)."""
        if params.grip is None or params.clutch_stiffness is None:
            raise ValueError("CompliantGrip needs a model built with a finite mu_wall and clutch_stiffness")
        self.c_adr = [qpos_address(model, n) for n in SKIDS]
        self.c_dof = [dof_address(model, n) for n in SKIDS]
        self.skid_ids = [model.joint(n).id for n in SKIDS]
        check_transmissions(model, self.act, mujoco.mjtTrn.mjTRN_TENDON, [model.tendon(n).id for n in ROLLS], ROLLS)
        self.skid_margins = [float(model.jnt_margin[j]) for j in self.skid_ids]
        self.wall_limit = RunningBound(model.jnt_range, self.skid_ids, [data.qpos.item(c) for c in self.c_adr],
                                       self.skid_margins, upper=True)
        self.lowest = self.wall_limit.extremes  # each carriage's running minimum
        self._carriage = [0.0, 0.0]  # each carriage's position at the step's start [m]
        self.excursion = 0.0
        self.rows = GripRows(model, roll_on_tendon=False)
        self.grip = self.rows.grips  # G_i [N]

    def coordinate(self, i: int) -> float:
        """The roll L_i = x_i - c_i [m]."""
        c = self._qpos.item(self.c_adr[i])
        self._carriage[i] = c
        return self._qpos.item(self.qpos_adr[i]) - c

    def speed(self, i: int) -> float:
        """The roll's rate [m/s]."""
        return self._qvel.item(self.dof_adr[i]) - self._qvel.item(self.c_dof[i])

    def after_module(self, i: int) -> None:
        """Lower the carriage's forward bound to its running minimum, or note how far it has given."""
        give = self.wall_limit.follow(i, self._carriage[i])
        if give > self.excursion:
            self.excursion = give

    def load_compiled(self, loop):
        """Its block in the compiled loop (:func:`.compiled_grip.load_compliant_grip`)."""
        return load_compliant_grip(self, loop)

    def sync_also(self, lowest0: float, lowest1: float, excursion: float) -> None:
        """The carriages' running minima and the excursion, read back from the compiled loop."""
        self.lowest[0], self.lowest[1] = lowest0, lowest1  # in place: the wall's running bound holds this list
        self.excursion = excursion

    def wheels(self) -> tuple[float, float]:
        """Each module's wheels' state of the last step: +1.0 rolling, 0.0 standing, -1.0 skidding."""
        grip_force, _ = self.rows.forces(self.data)
        v = self._qvel
        out = []
        for i, dof, cv in zip((0, 1), self.dof_adr, self.c_dof):
            G = self.grip[i]
            skids = grip_force[i] >= G if G > 0.0 else v.item(cv) < -REST_SPEED
            if skids:
                out.append(float(SKIDDING))
            elif self.tracking[i] and v.item(dof) - v.item(cv) > REST_SPEED:
                out.append(float(ROLLING))
            else:
                out.append(float(STANDING))
        return out[0], out[1]
