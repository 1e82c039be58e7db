"""Output samples of a MuJoCo run: raw rows while it runs, the result's columns at the end.

While the run goes, a sample stores whole rows (qpos, qvel, the velocities
before the sample's step, a few scalars) into preallocated arrays, which costs
a few row copies; the columns are computed from them, vectorized, once at the
end (:meth:`Recorder.series`).

Timing of what a sample holds: the sample at t_{n+1} holds the state after step
n, the module accelerations of that step ((v_{n+1} - v_n) / dt), the
constraint forces MuJoCo computed for it, and the torque the drive applied over
it. The energies, the loop gap and the momentum at t_{n+1} are what MuJoCo
computes at the start of the *next* step, so they are filled in then
(:meth:`Recorder.fill_deferred`; the last sample after a final ``mj_forward``).
So are a compliant clutch's force and overlap: MuJoCo computes the clutch
force at the start of a step, from the anchor the controller has just set for
that state, so a sample's ``lambda1``/``lambda2`` and ``clutch_overlap1``/
``clutch_overlap2`` describe the sample's own state.

``mode`` comes from the clutch controller's held flags (a module stands), which
the controller may relabel (:meth:`.controller.ClutchController.modes`: with
rigid clutches a sample where both stand while the crank turns is a passage
through a dead centre and takes the mode it leads to). What differs by
controller is the controller's to say (its sampled reactions, deferred values,
columns and modes): the recorder holds no test on which controller runs.
"""

from __future__ import annotations

import math

import mujoco
import numpy as np

from ipir_mujoco.core.params import RobotParams
from ipir_mujoco.core.results import COLUMNS, Mode

from ipir_mujoco.core.results import REST_SPEED

from .controller import NO_WHEELS
from ..builders.model import CRANK_HINGE, FRONT_SLIDE, LOOP, REAR_SLIDE, ROD_HINGE, dof_address, pin_offset, qpos_address
from .rows import equality_row

# Columns beyond the shared ones: rod axial force [N, tension > 0] (pin force at C
# along the rod), motor power [W], total momentum along x [kg m/s], motor torque [N m],
# loop-closure gap [m]; and the cumulative energy columns every driving engine writes [J].
# With compliant clutches also: overlaps clutch_overlap1/2 d_i [m] (> 0: the spring is compressed), the springs'
# stored energy clutch_spring_energy and the dampers' cumulative dissipation clutch_damper_work [J]. With finite
# grip also: slip1/2, grip_use1/2, skid_work, wheels1/2 (ipir_mujoco.core.results). The wheeled model also: its
# modules' planar pose y1/2 [m], yaw1/2 [rad] (Recorder._planar_pose).
EXTRA_COLUMNS = ("rod_force", "motor_power", "momentum", "motor_torque", "loop_gap")
# the per-sample scalars, in their order in Recorder.scalars (the compiled loop writes them too: native.py checks
# the order against _stepper.c's)
SCALARS = ("motor_torque", "loop_fx", "loop_fy", "loop_fz", "held1", "held2", "lambda1", "lambda2", "motor_work",
           "friction_work", "clutch_damper_work", "skid_work", "wheels1", "wheels2")
# MuJoCo's values at the start of the next step, per sample (clutch_spring: the stepped spring energy [J])
DEFERRED = ("kinetic", "potential", "loop_gap", "momentum", "clutch_force1", "clutch_force2", "clutch_overlap1",
            "clutch_overlap2", "clutch_spring")


class Recorder:
    """Preallocated sample rows for ``capacity`` samples (see the module docstring); ``data`` after
    ``mj_forward`` on the run's initial state."""

    def __init__(self, model: mujoco.MjModel, data: mujoco.MjData, params: RobotParams, capacity: int,
                 controller, kind):
        self.model, self.data, self.params = model, data, params
        self.controller = controller  # its deferred values, columns and modes
        self.kind = kind  # the model kind (ipir_mujoco.engine.kinds): its own columns
        self.qa = {n: qpos_address(model, n) for n in (CRANK_HINGE, REAR_SLIDE, FRONT_SLIDE, ROD_HINGE)}
        self.va = {n: dof_address(model, n) for n in (CRANK_HINGE, REAR_SLIDE, FRONT_SLIDE, ROD_HINGE)}
        self.loop_id = model.equality(LOOP).id
        # module 2's pin in the world, relative to its body frame: fixed, as the body only slides
        self.site, self.front, offset = pin_offset(model, data)  # data: after mj_forward
        self.pin_offset = offset.tolist()
        self.t = np.empty(capacity)
        self.qpos = np.empty((capacity, model.nq))
        self.qvel = np.empty((capacity, model.nv))
        self.qvel_before = np.empty((capacity, model.nv))
        self.scalars = np.zeros((capacity, len(SCALARS)))  # one row of SCALARS per sample
        self.deferred = np.full((capacity, len(DEFERRED)), np.nan)  # one row of DEFERRED per sample
        self.excursion = np.zeros(capacity)  # the clutch controller's backward excursion so far [m]
        self.count = 0
        self.total_mass = float(model.body_subtreemass[0])
        # views of the fields read at every sample (their memory is fixed for the life of the MjData)
        self._rod_end, self._front_pos = data.site_xpos[self.site], data.xpos[self.front]
        self._energy, self._subtree_linvel = data.energy, data.subtree_linvel

    def sample(self, torque: float, motor_work: float, friction_work: float, reactions,
               damper_work: float = 0.0, excursion: float = 0.0, skid_work: float = 0.0, wheels=NO_WHEELS) -> int:
        """Store the current state as a sample; returns its row (its deferred values come later).

        ``torque`` [N m]: the drive's torque over the last step; ``motor_work``,
        ``friction_work``, ``damper_work`` (the compliant clutches' dampers) [J]:
        cumulative; ``reactions``: the clutch controller's sampled reactions
        (rear held, front held, rear reaction [N], front reaction [N]: none
        where they are read from its deferred forces, a step later,
        :meth:`.controller.ClutchController.sampled_reactions`); ``excursion`` [m]: its backward excursion so
        far; with finite grip ``skid_work`` [J]: the grips' cumulative work against skidding, and ``wheels``:
        each module's wheels (+1.0 rolling, 0.0 standing, -1.0 skidding).
        """
        d, i = self.data, self.count
        self.t[i] = d.time
        self.qpos[i] = d.qpos
        self.qvel[i] = d.qvel
        row = equality_row(self.model, d, self.loop_id)
        fx, fy, fz = d.efc_force[row:row + 3].tolist() if d.ne >= row + 3 else (0.0, 0.0, 0.0)
        self.scalars[i] = (torque, fx, fy, fz, *reactions, motor_work, friction_work, damper_work, skid_work, *wheels)
        self.excursion[i] = excursion
        self.count += 1
        return i

    def fill_deferred(self, i: int) -> None:
        """Energies, loop gap, momentum and the clutch controller's deferred values (its forces, overlaps and
        springs' energy as the step conserves it: :meth:`.controller.ClutchController.deferred_values`) of sample
        ``i`` from MuJoCo's current (start of step) values."""
        sx, sy, sz = self._rod_end.tolist()
        bx, by, bz = self._front_pos.tolist()
        ox, oy, oz = self.pin_offset
        dx, dy, dz = sx - bx - ox, sy - by - oy, sz - bz - oz
        gap = math.sqrt(dx * dx + dy * dy + dz * dz)
        mujoco.mj_subtreeVel(self.model, self.data)
        momentum = self._subtree_linvel.item(0) * self.total_mass
        potential, kinetic = self._energy.tolist()
        self.deferred[i] = (kinetic, potential, gap, momentum, *self.controller.deferred_values())

    def series(self, last: int | None = None) -> dict[str, np.ndarray]:
        """Every column, for the samples 0..``last`` (default: all)."""
        n = self.count if last is None else last + 1
        p, dt = self.params, self.model.opt.timestep
        q, v, vb = self.qpos[:n], self.qvel[:n], self.qvel_before[:n]
        sc = dict(zip(SCALARS, self.scalars[:n].T))
        de = dict(zip(DEFERRED, self.deferred[:n].T))
        c, r1, f2, rod = (self.qa[k] for k in (CRANK_HINGE, REAR_SLIDE, FRONT_SLIDE, ROD_HINGE))
        cv, r1v, f2v = (self.va[k] for k in (CRANK_HINGE, REAR_SLIDE, FRONT_SLIDE))
        accel = (v - vb) / dt
        phi, omega = q[:, c], v[:, cv]
        beta = phi + q[:, rod]
        clutch = self.controller.clutch_columns(sc, de)  # (deferred forces: its reactions and held flags into sc)
        held1, held2 = sc["held1"] > 0.5, sc["held2"] > 0.5
        mode = np.where(held1 & held2, int(Mode.BOTH_LOCKED),
                        np.where(held2, int(Mode.CONTRACTION),
                                 np.where(held1, int(Mode.EXPANSION), int(Mode.BOTH_MOVING))))
        # the wheels' states pass through a dead centre with the mode
        mode, sc["wheels1"], sc["wheels2"] = self.controller.modes(
            mode, held1 & held2, p.r * np.abs(omega) > REST_SPEED, sc["wheels1"], sc["wheels2"])
        out = {
            "t": self.t[:n].copy(), "phi": phi.copy(), "omega": omega.copy(), "alpha": accel[:, cv],
            "x1": q[:, r1] - q[0, r1], "x2": q[:, f2] - q[0, f2], "v1": v[:, r1v].copy(), "v2": v[:, f2v].copy(),
            "a1": accel[:, r1v], "a2": accel[:, f2v], "S": q[:, f2] + p.r + p.L - q[:, r1],
            "S_dot": v[:, f2v] - v[:, r1v], "lambda1": sc["lambda1"].copy(), "lambda2": sc["lambda2"].copy(),
            "mode": mode.astype(int),
            # the pin force on the rod at C along the rod's axis: tension > 0
            "rod_force": sc["loop_fx"] * np.cos(beta) + sc["loop_fy"] * np.sin(beta),
            "motor_power": sc["motor_torque"] * omega, "momentum": de["momentum"].copy(),
            "motor_torque": sc["motor_torque"].copy(), "loop_gap": de["loop_gap"].copy(),
            "motor_work": sc["motor_work"].copy(), "friction_work": sc["friction_work"].copy(),
            "kinetic": de["kinetic"].copy(), "potential": de["potential"] - de["potential"][0],
        }
        out.update(clutch)
        out.update(self.kind.columns(self.model, p, q, sc, out))
        assert set(COLUMNS) <= set(out)
        return out
