"""Simulate the robot in MuJoCo and fill the shared result container.

The stepping loop: before each ``mj_step`` the clutch controller updates its
limits or locks; after it, the loop accumulates the energy terms and, every
output interval, records a sample. MuJoCo warnings are intercepted (nothing is
written to ``MUJOCO_LOG.TXT``) and turn into a :class:`SimulationError` with the
time and MuJoCo's message, as does a non-finite state.

Sampling: a sample at time t_{n+1} holds the state after step n, the module
accelerations of that step ((v_{n+1} - v_n) / dt) and the constraint forces
MuJoCo computed for it.

Energy audit, per step with the velocities v_{n+1} that move the positions:
motor work ctrl * (phi_{n+1} - phi_n) (exact for MuJoCo's update), friction work from
the frictionloss rows, the work absorbed by the clutch rows (``clutch_j``),
and the kinetic energy from ``mj_energyVel``. ``residual_j`` = motor - kinetic
- friction is what the soft constraints (clutches and loop) and the time
discretization took together. The loop's own share is not reported: its
constraint power measured this way carries an O(dt) bookkeeping term (J(q_n)
v_{n+1} != 0 on a curved constraint) that the discretization term cancels, so
the split would be noise, not physics.
"""

from __future__ import annotations

import contextlib
import math
import time
from dataclasses import dataclass
from typing import Callable, Iterator

import mujoco
import numpy as np

from ipir_mujoco.analytic.errors import ParameterError, SimulationError
from ipir_mujoco.analytic.params import RobotParams, check_run_options
from ipir_mujoco.analytic.results import COLUMNS, Mode, RunResult

from .clutches import EQUALITY_ROW, LIMIT_ROW, Locks, NoClutch, Ratchet, StepForces
from .model import (CRANK_HINGE, FRONT_SLIDE, LOOP, MOTOR, REAR_SLIDE, ROD_HINGE, SolverSettings, build_model,
                    dof_address, qpos_address, set_closed_loop_state)

FRICTION_ROW = int(mujoco.mjtConstraint.mjCNSTR_FRICTION_DOF)


@dataclass(frozen=True)
class CrankServo:
    """A stiff PD servo that makes the crank follow phi_ref(t), omega_ref(t).

    Motor torque = kp (phi_ref - phi) + kv (omega_ref - omega), recomputed every
    step; no feedforward, so the torque MuJoCo reports is what its own physics
    needs to follow the reference (inverse kinetostatics by simulation).
    Defaults: natural frequency 1000 rad/s, critical damping, for J = 1e-3 kg m^2.
    """

    phi_ref: Callable[[float], float]
    omega_ref: Callable[[float], float]
    kp: float = 1000.0  # N m / rad
    kv: float = 2.0  # N m s / rad

    def torque(self, t: float, phi: float, omega: float) -> float:
        return self.kp * (float(self.phi_ref(t)) - phi) + self.kv * (float(self.omega_ref(t)) - omega)
# Columns beyond the shared ones: rod axial force [N, tension > 0] (pin force at C
# along the rod), motor power [W], total momentum along x [kg m/s], motor torque [N m].
EXTRA_COLUMNS = ("rod_force", "motor_power", "momentum", "motor_torque")
IMPLEMENTATIONS = ("ratchet", "lock", "none")


@contextlib.contextmanager
def captured_warnings() -> Iterator[list[str]]:
    """Route MuJoCo's warning text into a list instead of MUJOCO_LOG.TXT and stderr."""
    messages: list[str] = []
    previous = mujoco.get_mju_user_warning()
    mujoco.set_mju_user_warning(messages.append)
    try:
        yield messages
    finally:
        mujoco.set_mju_user_warning(previous)


def _warning_count(data: mujoco.MjData) -> int:
    return sum(int(w.number) for w in data.warning)


def _mode(rear_held: bool, front_held: bool) -> int:
    if rear_held and front_held:
        return int(Mode.BOTH_LOCKED)
    if front_held:
        return int(Mode.CONTRACTION)
    if rear_held:
        return int(Mode.EXPANSION)
    return int(Mode.BOTH_MOVING)


def simulate_mujoco(
    params: RobotParams,
    clutch: str = "unilateral",
    implementation: str = "ratchet",
    t_end: float = 1.0,
    *,
    dt_out: float = 1e-4,
    settings: SolverSettings = SolverSettings(),
    mjcf=None,
    progress: Callable[[float], None] | None = None,
    servo: CrankServo | None = None,
) -> RunResult:
    """Run MuJoCo on the real linkage.

    ``implementation``: 'ratchet' (joint-limit ratchet; one-way by
    construction, so ``clutch`` must be 'unilateral'), 'lock' (velocity-
    triggered locks released by ``clutch`` = 'kinematic', the paper's rule, or
    'unilateral', a lock that would pull lets go), or 'none' (no clutches).
    ``dt_out`` [s] must be a whole number of timesteps. ``progress`` is called
    with the simulated time about every 0.1 s of it. ``servo`` replaces the
    constant torque M by a crank servo (:class:`CrankServo`).
    """
    defaults = RobotParams()
    for name in ("drive", "clutch_stiffness", "clutch_damping", "clutch_backlash", "incline"):
        if getattr(params, name) != getattr(defaults, name):  # refused, never silently ignored
            raise ParameterError(f"{name}={getattr(params, name)!r} is not modelled by the MuJoCo engine yet; "
                                 f"allowed: {getattr(defaults, name)!r}")
    if implementation not in IMPLEMENTATIONS:
        raise ParameterError(f"mujoco clutch {implementation!r} is unknown; allowed: {', '.join(IMPLEMENTATIONS)}")
    if clutch not in ("kinematic", "unilateral"):
        raise ParameterError(f"clutch={clutch!r} is unknown; allowed: kinematic, unilateral")
    if implementation == "ratchet" and clutch == "kinematic":
        raise ParameterError("--clutch kinematic with the ratchet: a ratchet is a one-way clutch; use "
                             "--mujoco-clutch lock for the paper's rule, or --clutch unilateral")
    t_end, dt_out = check_run_options(t_end, dt_out)  # the one check every engine and interface shares
    steps_per_sample = round(dt_out / settings.timestep)
    if steps_per_sample < 1 or abs(steps_per_sample * settings.timestep - dt_out) > 1e-9 * dt_out:
        raise ParameterError(f"dt_out={dt_out} s is out of range; allowed: a whole multiple of the timestep "
                             f"({settings.timestep} s)")
    n_samples = max(1, math.ceil(t_end / dt_out - 1e-9))

    started = time.perf_counter()
    model = build_model(params, settings, mjcf, ratchet=implementation == "ratchet")
    data = mujoco.MjData(model)
    with captured_warnings() as messages:
        set_closed_loop_state(model, data, params)
        if implementation == "ratchet":
            controller = Ratchet(model, data)
        elif implementation == "lock":
            controller = Locks(model, data, clutch, params.r, params.L)
        else:
            controller = NoClutch(model, data)
        recorder = _Recorder(model, data, params, n_samples + 1)
        loop_id = model.equality(LOOP).id
        motor = model.actuator(MOTOR).id
        crank_q, crank_v = qpos_address(model, CRANK_HINGE), dof_address(model, CRANK_HINGE)
        data.ctrl[motor] = params.M if servo is None else servo.torque(0.0, data.qpos[crank_q], data.qvel[crank_v])
        mujoco.mj_forward(model, data)
        _check(data, messages, 0.0)
        recorder.start(controller)
        next_report = 0.1
        for _sample in range(n_samples):
            for _step in range(steps_per_sample):
                if servo is not None:
                    data.ctrl[motor] = servo.torque(data.time, data.qpos[crank_q], data.qvel[crank_v])
                controller.before_step()
                recorder.before_step()
                mujoco.mj_step(model, data)
                forces = StepForces(data, loop_id)
                controller.after_step(forces)
                recorder.after_step(forces)
            _check(data, messages, recorder.last_time)
            recorder.sample(controller)
            if progress is not None and data.time >= next_report:
                progress(float(data.time))
                next_report += 0.1
        mujoco.mj_forward(model, data)  # energy terms at the final state
        _check(data, messages, recorder.last_time, recorder.warnings_seen)
        energy = recorder.energy()

    label = {"ratchet": "unilateral", "lock": clutch, "none": "none"}[implementation]
    return RunResult(
        engine="mujoco",
        geometry="exact",
        clutch=label,
        params=params,
        t_end=float(data.time),
        series=recorder.series(),
        energy=energy,
        wall_time_s=time.perf_counter() - started,
        settings={"mujoco_clutch": implementation, "clutch_rule": clutch, "dt_out": dt_out,
                  "mujoco_version": mujoco.__version__, **settings.as_dict()},
    )


def _check(data: mujoco.MjData, messages: list[str], t_good: float, seen: int | None = None) -> None:
    """Raise on a MuJoCo warning or a non-finite state.

    MuJoCo passes the first occurrence of each warning to the user handler, so
    ``messages`` catches every warning of a fresh MjData; the counters
    (``seen``: the count at the start) are read only when asked, as reading
    them costs more than a step. ``t_good`` [s] is the last sample known good:
    MuJoCo resets the state, clock included, when it detects a bad one.
    """
    if messages or (seen is not None and _warning_count(data) > seen):
        reason = messages[0] if messages else "MuJoCo raised a warning"
        raise SimulationError(f"MuJoCo became unstable after t={t_good:.6g} s: {reason} "
                              "(a smaller --timestep may carry the run further)")
    if not (np.all(np.isfinite(data.qpos)) and np.all(np.isfinite(data.qvel))):
        raise SimulationError(f"non-finite state after t={t_good:.6g} s")


class _Recorder:
    """Samples, energy accumulators and constraint-force bookkeeping."""

    def __init__(self, model: mujoco.MjModel, data: mujoco.MjData, params: RobotParams, capacity: int):
        self.model, self.data, self.params = model, data, params
        self.q = [qpos_address(model, n) for n in (CRANK_HINGE, REAR_SLIDE, FRONT_SLIDE, ROD_HINGE)]
        self.v = [dof_address(model, n) for n in (CRANK_HINGE, REAR_SLIDE, FRONT_SLIDE)]
        self.loop_id = model.equality(LOOP).id
        # the slide each clutch row acts on: limit rows by joint id, lock rows by equality id
        self.limit_dof = {int(j): int(model.jnt_dofadr[j]) for j in range(model.njnt)}
        self.lock_dof = {e: int(model.jnt_dofadr[model.eq_obj1id[e]]) for e in range(model.neq)
                         if model.eq_type[e] == mujoco.mjtEq.mjEQ_JOINT}
        self.loop_force: list[float] = []  # the last step's connect rows
        self.dt = model.opt.timestep
        self.table = {c: np.empty(capacity) for c in COLUMNS + EXTRA_COLUMNS}
        self.count = 0
        self.v_before = np.zeros(model.nv)
        self.work = {"friction": 0.0, "clutch": 0.0, "motor": 0.0}
        self.motor_id = model.actuator(MOTOR).id
        self.warnings_seen = 0

    def start(self, controller) -> None:
        self.phi0 = float(self.data.qpos[self.q[0]])
        self.x0 = self.data.qpos[[self.q[1], self.q[2]]].copy()
        self.kinetic0 = float(self.data.energy[1])
        self.v_before[:] = self.data.qvel
        self.warnings_seen = _warning_count(self.data)
        self.sample(controller, initial=True)

    def before_step(self) -> None:
        self.v_before[:] = self.data.qvel

    def after_step(self, forces: StepForces) -> None:
        d = self.data
        v = d.qvel
        # constraint power with the velocities that moved the positions (rows act on one slide each)
        friction = clutch = 0.0
        for (row_type, element), force in forces.by_row.items():
            if row_type == FRICTION_ROW:
                friction += force * v[element]  # a dof-friction row's id is its dof
            elif row_type == LIMIT_ROW:
                clutch += force * v[self.limit_dof[element]]
            elif row_type == EQUALITY_ROW:
                clutch += force * v[self.lock_dof[element]]
        self.work["friction"] -= friction * self.dt
        self.work["clutch"] -= clutch * self.dt
        self.work["motor"] += float(d.ctrl[self.motor_id]) * v[self.v[0]] * self.dt  # = ctrl * (phi change)
        self.loop_force = forces.loop

    def sample(self, controller, initial: bool = False) -> None:
        d, p, i = self.data, self.params, self.count
        q, v = d.qpos, d.qvel
        phi, omega = q[self.q[0]], v[self.v[0]]
        x1, x2 = q[self.q[1]] - self.x0[0], q[self.q[2]] - self.x0[1]
        accel = np.zeros(3) if initial else (v[self.v] - self.v_before[self.v]) / self.dt
        held, reactions = controller.reactions()
        beta = phi + q[self.q[3]]
        loop = [] if initial else self.loop_force
        # the pin force on the rod at C along the rod's axis: tension > 0
        rod_force = loop[0] * math.cos(beta) + loop[1] * math.sin(beta) if len(loop) == 3 else 0.0
        row = {
            "t": d.time, "phi": phi, "omega": omega, "alpha": accel[0], "x1": x1, "x2": x2,
            "v1": v[self.v[1]], "v2": v[self.v[2]], "a1": accel[1], "a2": accel[2],
            "S": q[self.q[2]] + p.r + p.L - q[self.q[1]], "S_dot": v[self.v[2]] - v[self.v[1]],
            "lambda1": reactions[0], "lambda2": reactions[1], "mode": _mode(*held),
            "rod_force": rod_force, "motor_power": d.ctrl[self.motor_id] * omega, "momentum": self._momentum_x(),
            "motor_torque": d.ctrl[self.motor_id],
        }
        for name, value in row.items():
            self.table[name][i] = value
        self.count += 1
        self.last_time = float(d.time)

    def _momentum_x(self) -> float:
        """Total linear momentum of the robot along the pipe [kg m/s]."""
        mujoco.mj_subtreeVel(self.model, self.data)
        return float(self.data.subtree_linvel[0, 0] * self.model.body_subtreemass[0])

    def series(self) -> dict[str, np.ndarray]:
        out = {name: values[: self.count].copy() for name, values in self.table.items()}
        out["mode"] = out["mode"].astype(int)
        return out

    def energy(self) -> dict[str, float]:
        motor = float(self.work["motor"])
        kinetic = float(self.data.energy[1]) - self.kinetic0
        friction = float(self.work["friction"])
        residual = motor - kinetic - friction
        return {
            "motor_work_j": motor, "kinetic_j": kinetic, "friction_j": friction, "residual_j": residual,
            "clutch_j": float(self.work["clutch"]),
        }
