"""Many ratcheted MuJoCo designs at once, stepped by ``mujoco.batch`` on C threads.

Each design's model is checked, compiled and started by the slide model's kind as a single run
(:data:`ipir_mujoco.engine.kinds.SLIDES`: its checks, build and initial state), with the timestep it
chooses for that design unless settings are given; the batch runs one model with per-simulation copies of
every field in which the designs differ (timestep, gravity, drive included),
so the builder stays the only place that turns parameters into a model. All
designs share the output times (multiples of ``dt_out``); a design with a
smaller timestep takes more substeps between them. Between substeps the
ratchet raises each simulation's lower slide bounds (the rule of
:class:`ipir_mujoco.engine.kinds.slides.clutches.Ratchet`), in one vectorized write.

What a batch can measure is the state and MuJoCo's energies: positions and
speeds, the drive's work (from MuJoCo's actuator force, as the serial engine),
the work against the resistances (F_r |v| per step, which equals the
frictionloss rows' work while a module slides and differs only in the steps
where one starts or stops: tests/test_mujoco_batch.py bounds the difference),
kinetic and potential energy, the loop gap and the backward excursion, so the
same accuracy monitor as a serial run, the steady state and stalls. Constraint
forces (clutch reactions, rod force) are not exposed per simulation and are
left out. Compliant clutches (a finite ``clutch_stiffness``) are not batched:
such a design is reported with a one-line error (run it serially). A design
that fails the monitor (``accuracy='stop'``), becomes unstable (MuJoCo resets
it: its clock falls behind) or non-finite, or in which MuJoCo raises an error
(``mujoco.batch.SimulationError``, e.g. its memory arena is too small: the
serial engine's one-line "MuJoCo failed after t=... s: <reason>") is reported
with the reason and stops stepping, the others going on; so does a steady
(with ``until_steady``) or stalled one.
"""

from __future__ import annotations

import math
from dataclasses import replace
from typing import Sequence

import mujoco
import numpy as np
from mujoco import batch as mjbatch

from ipir_mujoco.core.cycles import STEADY_CYCLES, STEADY_TOL
from ipir_mujoco.core.steady_test import steady_target
from ipir_mujoco.core.steady_watch import SteadyWatch
from ipir_mujoco.core.errors import ParameterError
from ipir_mujoco.core.options import RunOptions
from ipir_mujoco.core.params import RobotParams

from . import KIND as SLIDE_KIND
from .. import kind_for
from ...builders.model import (CRANK_HINGE, MOTOR, SLIDES, SolverSettings, dof_address, drive_control, drive_torque_slope,
                    pin_offset, qpos_address)
from ...loop.controller import follow
from ...loop.monitor import AccuracyError, AccuracyMonitor, Tolerances, check_accuracy_mode, energy_audit, residual_ratio
from ..common import (BLOCK_TIME, REFINEMENTS, captured_warnings, climb_energy, mujoco_failure,
                     rest_since, stall_reason, steps_per_output)
from ..timestep import DT_MIN

OPTION_FIELDS = ("timestep", "gravity", "integrator")
MODELLED_DRIVES = ("torque", "motor")  # each design's own actuator gain and bias (checked against the serial engine)
_NONE = np.zeros(0, dtype=int)  # no simulation
COLUMNS = ("t", "phi", "omega", "x1", "x2", "v1", "v2", "a1", "a2", "motor_work", "friction_work", "kinetic",
           "potential", "loop_gap")


def _differing_fields(models: Sequence[mujoco.MjModel]) -> list[str]:
    """Model fields (of those a batch can expand) whose values differ between the designs."""
    base = models[0]
    names = []
    for name in mjbatch.MODEL_FIELDS:
        if name.startswith("opt."):
            continue
        value = getattr(base, name, None)
        if not isinstance(value, np.ndarray) or value.dtype.kind not in "fiub":
            continue
        if any(not np.array_equal(getattr(m, name), value) for m in models[1:]):
            names.append(name)
    for name in OPTION_FIELDS:
        value = np.asarray(getattr(base.opt, name))
        if any(not np.array_equal(np.asarray(getattr(m.opt, name)), value) for m in models[1:]):
            names.append("opt." + name)
    return names


def run_ratchet_batch(designs: Sequence[RobotParams], t_end: float, dt_out: float = 1e-3,
                      settings: SolverSettings | None = None, nthread: int = 0, *, accuracy: str = "stop",
                      until_steady: bool = False, steady_tol: float = STEADY_TOL,
                      steady_cycles: int = STEADY_CYCLES) -> list[dict]:
    """Run every design with the joint-limit ratchet.

    One dict per design: ``{"series": {column: ndarray (n,)}, "motor_work_j": J,
    "friction_work_j": J, "energy": {...}, "accuracy": {...}, "stall": str | None,
    "steady": bool, "settings": {...}}``. ``motor_work_j`` and ``friction_work_j``
    are M (phi_end - phi_0) and F_r1 x1 + F_r2 x2 under a constant torque (exact
    there, the ratchet letting modules move only forward), the cumulative
    columns' last values under the motor; ``energy`` is the audit as a serial
    run's. The columns are those of :data:`COLUMNS`
    (t [s], phi [rad], omega [rad/s], x1, x2 [m], v1, v2 [m/s], a1, a2 [m/s^2],
    cumulative motor_work and friction_work, kinetic and potential [J], loop_gap
    [m]), or ``{"error": message}`` (with ``"accuracy"`` when the monitor
    stopped it). ``settings`` None: each design's own automatic timestep, halved
    (at most twice) for a design the monitor stops, as in a serial run; the
    halvings are in the outcome's ``settings["refinements"]``.
    """
    check_accuracy_mode(accuracy)
    RunOptions(t_end, dt_out, until_steady, steady_tol, steady_cycles)  # the one check of the run options
    results: list[dict | None] = [None] * len(designs)
    chosen: dict[int, SolverSettings] = {}
    for i, params in enumerate(designs):
        try:
            SLIDE_KIND.check(params, "ratchet", "unilateral")
            if params.clutch_stiffness is not None:
                raise ParameterError(f"clutch_stiffness={params.clutch_stiffness!r} N/m: batched runs have rigid "
                                     "ratchets only; allowed: clutch_stiffness=rigid (run compliant clutches "
                                     "serially, with simulate_mujoco)")
            if kind_for("slides", params) is not SLIDE_KIND:  # finite grip: another kind
                raise ParameterError(f"mu_wall={params.mu_wall!r}: batched runs have unlimited grip only (a batch "
                                     "cannot read the carriages' friction rows per simulation); allowed: "
                                     "mu_wall=unlimited (run finite grip serially, with simulate_mujoco)")
            chosen[i] = settings if settings is not None else SLIDE_KIND.settings(params, t_end, dt_out)[0]
        except ValueError as exc:
            results[i] = {"error": str(exc)}
    halvings = {i: [] for i in chosen}
    for attempt in range(REFINEMENTS + 1):
        models, index = [], []
        for i, own in chosen.items():
            try:
                steps_per_output(dt_out, own.timestep)
                models.append(SLIDE_KIND.build(designs[i], own, implementation="ratchet"))
                index.append(i)
            except ValueError as exc:
                results[i] = {"error": str(exc)}
        if not models:
            break
        batch = _Batch(models, [designs[i] for i in index], [chosen[i] for i in index], t_end, dt_out, nthread,
                       accuracy, until_steady, steady_tol, steady_cycles)
        retry = {}
        for i, outcome, failed in zip(index, batch.run(), batch.inaccurate):
            outcome.setdefault("settings", {})["refinements"] = halvings[i]
            results[i] = outcome
            # as a serial run: an automatic step the monitor stops is halved (at most twice)
            if failed and settings is None and attempt < REFINEMENTS and chosen[i].timestep / 2 >= DT_MIN:
                halvings[i].append({"timestep": chosen[i].timestep, "reason": outcome["error"]})
                retry[i] = replace(chosen[i], timestep=chosen[i].timestep / 2)
        if not retry:
            break
        chosen = retry
    return results


class _Batch:
    def __init__(self, models, designs, settings, t_end, dt_out, nthread, accuracy, until_steady, steady_tol,
                 steady_cycles):
        self.models, self.designs, self.settings = models, designs, settings
        self.t_end, self.dt_out, self.accuracy = t_end, dt_out, accuracy
        self.until_steady, self.steady_tol, self.steady_cycles = until_steady, steady_tol, steady_cycles
        self.n = len(models)
        self.nthread = nthread
        self.dt = np.array([s.timestep for s in settings])
        self.k = np.array([steps_per_output(dt_out, dt) for dt in self.dt])  # substeps per output interval
        self.n_steps = np.floor(t_end / self.dt * (1 + 1e-12)).astype(int)  # never past t_end
        self.n_samples = int(np.max(np.ceil(self.n_steps / self.k)))

    def run(self) -> list[dict]:
        with captured_warnings():
            self._start()
            self._loop()
        return [self._outcome(k) for k in range(self.n)]

    def _start(self) -> None:
        base, n = self.models[0], self.n
        batch = self.batch = mjbatch.Batch(base, nsim=n, nthread=self.nthread)
        fields = _differing_fields(self.models)
        # the ratchet's bounds are per simulation: expanded whether or not the designs' ranges differ
        for name in fields + (["jnt_range"] if "jnt_range" not in fields else []):
            per_sim = batch.expand(name)  # the same live array on every call
            for k, model in enumerate(self.models):
                per_sim[k] = getattr(model.opt, name[4:]) if name.startswith("opt.") else getattr(model, name)
        self.qpos, self.qvel, ctrl, self.clock = (batch.bind(f) for f in ("qpos", "qvel", "ctrl", "time"))
        self.energy, self.force = batch.bind("energy"), batch.bind("actuator_force")
        qacc = batch.bind("qacc")
        self.site_xpos, self.xpos = batch.bind("site_xpos"), batch.bind("xpos")
        motor = base.actuator(MOTOR).id
        self.motor = motor
        for k, (model, params) in enumerate(zip(self.models, self.designs)):
            data = mujoco.MjData(model)
            SLIDE_KIND.initial_state(model, data, params)
            self.qpos[k], self.qvel[k] = data.qpos, data.qvel
            ctrl[k, motor] = drive_control(params)
        self.record = {c: np.full((self.n_samples + 1, n), np.nan) for c in COLUMNS}
        self.last_row = np.zeros(n, dtype=int)
        self.failed: list[str | None] = [None] * n
        self.inaccurate = [False] * n  # stopped by the accuracy monitor (a halved timestep may pass)
        self.stall: list[str | None] = [None] * n
        self.running = np.ones(n, dtype=bool)
        self._call(batch.forward)
        self.slides_q = np.array([qpos_address(base, s) for s in SLIDES])
        self.slides_v = np.array([dof_address(base, s) for s in SLIDES])
        self.slide_joints = np.array([base.joint(s).id for s in SLIDES])
        self.crank_q, self.crank_v = qpos_address(base, CRANK_HINGE), dof_address(base, CRANK_HINGE)
        self.margins = np.array([m.jnt_margin[self.slide_joints] for m in self.models])
        self.friction = np.array([m.dof_frictionloss[self.slides_v] for m in self.models])
        self.slope = np.array([drive_torque_slope(m) for m in self.models])  # as the serial engine, per integrator
        self.jnt_range = batch.expand("jnt_range")
        self.bounds = self.qpos[:, self.slides_q].copy()
        self.jnt_range[:, self.slide_joints, 0] = self.bounds - self.margins
        self.x_start = self.qpos[:, self.slides_q].copy()
        self.site, self.front, self.pin_offset = pin_offset(base)

        self.wm, self.wf = np.zeros(n), np.zeros(n)
        self.excursion = np.zeros(n)
        self.monitors = [AccuracyMonitor(Tolerances.for_params(p), self.accuracy, s.timestep)
                         for p, s in zip(self.designs, self.settings)]
        torque = self.force[:, motor]
        self.energy0 = self.energy.copy()  # (potential, kinetic) [J] at t = 0
        climb = [climb_energy(m, p) for m, p in zip(self.models, self.designs)]
        self.floor = np.maximum.reduce([self.energy0[:, 1], 2 * math.pi * np.abs(torque), climb])
        self.watches = [SteadyWatch(float(self.qpos[k, self.crank_q]), self.steady_tol, self.steady_cycles,
                                   steady_target("mujoco", self.steady_tol))
                        for k in range(n)] if self.until_steady else None
        self.fed = 0
        self._sample(0, self.qvel - self.dt[:, None] * qacc, np.zeros(n))  # first accelerations: MuJoCo's qacc

    def _loop(self) -> None:
        batch, n = self.batch, self.n
        block = max(1, round(BLOCK_TIME / self.dt_out))
        done = np.zeros(n, dtype=int)
        vel_stage = int(mujoco.mjtStage.mjSTAGE_VEL)
        slides_q, slides_v, joints, crank_v = self.slides_q, self.slides_v, self.slide_joints, self.crank_v
        for s in range(1, self.n_samples + 1):
            steps = np.where(self.running, np.minimum(self.k, self.n_steps - done), 0)
            stepping = steps > 0
            if not stepping.any():
                break
            substeps = int(steps.max())
            # the common case: every simulation still running takes every substep
            uniform = bool(np.all(steps[stepping] == substeps))
            ids = None if stepping.all() else np.flatnonzero(stepping)
            v_before = self.qvel.copy()
            dt = np.where(stepping, self.dt, 0.0)
            torque = None  # stays None if MuJoCo fails every simulation in the first substep
            for j in range(substeps):
                # each slide's running maximum, the serial ratchet's rule (follow) for every design at once
                self.bounds, give = follow(self.bounds, self.qpos[:, slides_q])
                np.maximum(self.excursion, np.max(give, axis=1), out=self.excursion)
                self.jnt_range[:, joints, 0] = self.bounds - self.margins
                omega_prev = self.qvel[:, crank_v].copy()
                if uniform:
                    if j == substeps - 1:
                        v_before[:] = self.qvel
                        failed = self._call(batch.step, ids, stage=vel_stage)
                    else:
                        failed = self._call(batch.step, ids)
                else:
                    active = steps > j
                    dt = np.where(active, self.dt, 0.0)
                    ending = np.flatnonzero(active & (steps == j + 1))
                    going = np.flatnonzero(steps > j + 1)
                    v_before[ending] = self.qvel[ending]
                    failed = self._call(batch.step, going) if going.size else _NONE
                    if ending.size:
                        failed = np.concatenate([failed, self._call(batch.step, ending, stage=vel_stage)])
                if failed.size:  # those kept their state before the step and take no more
                    steps[failed] = 0
                    stepping = steps > 0
                    ids = np.flatnonzero(stepping)
                    if not ids.size:
                        break
                omega = self.qvel[:, crank_v]
                torque = self.force[:, self.motor] + self.slope * (omega - omega_prev)
                self.wm += torque * omega * dt
                self.wf += (self.friction * np.abs(self.qvel[:, slides_v])).sum(axis=1) * dt
            done += steps
            self._sample(s, v_before, stepping.astype(float), torque)
            self._check_health(s, stepping, done)
            if s % block == 0 or s == self.n_samples:
                self._block(s)

    def _call(self, method, ids: np.ndarray | None = None, **options) -> np.ndarray:
        """``method(ids, **options)`` (the batch's step or forward); the simulations in which MuJoCo raised
        (they keep their state from before the call, the others complete it) fail with the serial
        engine's one-line message. Returns their ids."""
        try:
            method(ids, **options)
        except mjbatch.SimulationError as exc:
            for k in exc.ids:
                k = int(k)
                row = int(self.last_row[k])
                t_good = float(self.record["t"][row, k]) if np.isfinite(self.record["t"][row, k]) else 0.0
                self._finish(k, error=mujoco_failure(t_good, self.batch.error(k)))
            return np.asarray(exc.ids, dtype=int)
        return _NONE

    def _sample(self, s: int, v_before: np.ndarray, stepped: np.ndarray, torque: np.ndarray | None = None) -> None:
        """Record row ``s`` for the simulations that stepped into it, and feed their monitors."""
        rows = np.flatnonzero(stepped > 0) if s else np.arange(self.n)
        r, q, v = self.record, self.qpos, self.qvel
        dt = self.dt[rows]
        r["t"][s, rows] = self.clock[rows]
        r["phi"][s, rows], r["omega"][s, rows] = q[rows, self.crank_q], v[rows, self.crank_v]
        x = q[rows][:, self.slides_q] - self.x_start[rows]
        r["x1"][s, rows], r["x2"][s, rows] = x.T
        vv = v[rows][:, self.slides_v]
        r["v1"][s, rows], r["v2"][s, rows] = vv.T
        a = (vv - v_before[rows][:, self.slides_v]) / dt[:, None]
        r["a1"][s, rows], r["a2"][s, rows] = a.T
        r["motor_work"][s, rows], r["friction_work"][s, rows] = self.wm[rows], self.wf[rows]
        kinetic = self.energy[rows, 1]
        potential = self.energy[rows, 0] - self.energy0[rows, 0]
        r["kinetic"][s, rows], r["potential"][s, rows] = kinetic, potential
        gap = np.linalg.norm(self.site_xpos[rows, self.site] - self.xpos[rows, self.front] - self.pin_offset, axis=1)
        r["loop_gap"][s, rows] = gap
        self.last_row[rows] = s
        if torque is not None:
            self.floor[rows] = np.maximum(self.floor[rows], 2 * math.pi * np.abs(torque[rows]))
        residual, scale = energy_audit(self.wm[rows], self.wf[rows], kinetic - self.energy0[rows, 1], potential,
                                       self.floor[rows])
        for k, t, res, sc, g, e in zip(rows, self.clock[rows], residual, scale, gap, self.excursion[rows]):
            monitor = self.monitors[k]
            try:
                if sc > 0 and abs(res) > abs(monitor.worst["residual_ratio"]) * sc:
                    monitor.residual(float(t), float(res), float(sc))
                if g > monitor.worst["loop_gap_m"]:
                    monitor.loop_gap(float(t), float(g))
                if e > monitor.worst["excursion_m"]:
                    monitor.excursion(float(t), float(e))
            except AccuracyError as exc:
                self.inaccurate[k] = self.failed[k] is None
                self._finish(k, error=str(exc))

    def _check_health(self, s: int, stepped: np.ndarray, done: np.ndarray) -> None:
        """MuJoCo resets a simulation it finds unstable (its clock falls behind): fail it."""
        expected = done * self.dt
        bad = stepped & self.running & ((np.abs(self.clock - expected) > 0.5 * self.dt)
                                        | ~np.all(np.isfinite(self.qpos), axis=1)
                                        | ~np.all(np.isfinite(self.qvel), axis=1))
        for k in np.flatnonzero(bad):
            t_good = float(self.record["t"][s - 1, k])
            self._finish(k, error=f"MuJoCo became unstable after t={t_good:.6g} s (a smaller timestep may carry "
                                  "the run further)")
        self.running &= done < self.n_steps

    def _block(self, s: int) -> None:
        """Steady state and stalls of the running designs, from the rows since the last block."""
        r = self.record
        for k in np.flatnonzero(self.running):
            last = int(self.last_row[k])
            if self.watches is not None:
                t = r["t"][self.fed:last + 1, k]
                travel = 0.5 * (r["x1"][self.fed:last + 1, k] + r["x2"][self.fed:last + 1, k])
                if self.watches[k].update(t, r["phi"][self.fed:last + 1, k], travel):
                    end = int(np.searchsorted(r["t"][:last + 1, k], self.watches[k].steady_at - 1e-12))
                    self._finish(k, last=end)
                    continue
            since = rest_since(r["t"][:last + 1, k], r["omega"][:last + 1, k], r["v1"][:last + 1, k],
                               r["v2"][:last + 1, k], self.designs[k].r)
            if since is not None:
                self.stall[k] = stall_reason(self.designs[k], since, float(r["phi"][last, k]))
                self._finish(k)
        self.fed = s + 1

    def _finish(self, k: int, error: str | None = None, last: int | None = None) -> None:
        if not self.running[k] and self.failed[k] is None and error is None:
            return
        self.running[k] = False
        if error is not None and self.failed[k] is None:
            self.failed[k] = error
        if last is not None:
            self.last_row[k] = last

    def _outcome(self, k: int) -> dict:
        monitor = self.monitors[k]
        if self.failed[k] is not None:
            return {"error": self.failed[k], "accuracy": monitor.record()}
        n = int(self.last_row[k]) + 1
        series = {c: values[:n, k].copy() for c, values in self.record.items()}
        wm, wf = float(series["motor_work"][-1]), float(series["friction_work"][-1])
        kinetic = float(series["kinetic"][-1] - series["kinetic"][0])
        potential = float(series["potential"][-1])
        residual, scale = energy_audit(wm, wf, kinetic, potential, float(self.floor[k]))
        steady = self.watches is not None and self.watches[k].steady_at is not None
        p = self.designs[k]
        if p.drive == "torque":  # the sweep's figures: exact for a constant torque and forward-only modules
            motor = p.M * float(series["phi"][-1] - series["phi"][0])
            against = p.F_r1 * float(series["x1"][-1]) + p.F_r2 * float(series["x2"][-1])
        else:
            motor, against = wm, wf
        return {"series": series, "motor_work_j": motor, "friction_work_j": against,
                "energy": {"motor_work_j": wm, "kinetic_j": kinetic, "friction_j": wf, "potential_j": potential,
                           "residual_j": float(residual)},
                "accuracy": monitor.record(residual_ratio(residual, scale)),
                "stall": self.stall[k], "steady": steady,
                "settings": {"timestep": float(self.dt[k]), "dt_out": self.dt_out,
                             "solimp": list(self.settings[k].solimp),
                             "steady_tol": self.steady_tol, "steady_cycles": self.steady_cycles}}
