"""Simulate the robot in MuJoCo and fill the shared result container.

The stepping loop: before each ``mj_step`` the clutch controller updates its
limits or locks (and tracks how far a module slid back); after it, the loop
accumulates the drive's work and the work against the resistances. Those
steps run in :mod:`.stepper`, compiled where it can be (same numbers bit for
bit as its pure-Python form). Every output interval the run records a sample
(:mod:`.recorder`) and feeds the accuracy monitor (:mod:`.monitor`). Every
0.05 s of simulated time it checks the wall-time budget, the periodic steady
state and a stall, and reports progress about every 0.1 s of it or every
second of wall time, whichever comes first (never going
back: a run repeated at a halved timestep, which may take minutes, reports
:class:`ipir_mujoco.core.options.RepeatProgress` values, its own time with
the time already reported: :class:`ipir_mujoco.engine.kinds.common.PassProgress`).
MuJoCo warnings are intercepted (nothing is written to ``MUJOCO_LOG.TXT``) and
turn into a :class:`SimulationError` with the time and MuJoCo's message, as
do a non-finite state and a MuJoCo error (``mujoco.FatalError``).

Clutches: rigid one-way clutches are the joint-limit ratchet or the locks
(:mod:`.clutches`); with a finite ``clutch_stiffness`` the ratchet becomes the
compliant clutch (:mod:`.compliant`): a ratcheting anchor per module and a
spring and damper from it to the module, MuJoCo actuator forces. With a finite
``mu_wall`` the wheels grip the wall with at most G_i: a light carriage per
module on the wall, held by friction G_i, carries the clutch (:mod:`.grip_model`,
:mod:`.grip`, :mod:`.compliant_grip`).

Energy audit, per step with the velocities v_{n+1} that move the positions
(q_{n+1} = q_n + dt v_{n+1}): drive work tau * (phi_{n+1} - phi_n) with the
torque MuJoCo applied over the step (for the motor, whose velocity term the
implicit integrator treats implicitly, tau(omega_{n+1})), work against the
resistances from the frictionloss rows, kinetic and potential energy from
MuJoCo's own ``energy``; with compliant clutches also the springs' stored
energy and the dampers' dissipation (:mod:`.compliant`); with finite grip
also the grips' work against skidding, from the carriages' friction rows
(``skid_j``). ``residual_j`` = motor - friction - kinetic - potential
(- clutch spring and damper - skid) is what
the soft constraints (rigid clutches, loop, friction rows) and the time
discretization (the clutch springs' stepping included) took together; the
monitor holds it to a tolerance.
"""

from __future__ import annotations

import math
import os
import time
from dataclasses import replace
from typing import Callable

import mujoco
import numpy as np

from ipir_mujoco.core.cycles import STEADY_CYCLES, STEADY_TOL
from ipir_mujoco.core import energy
from ipir_mujoco.core.energy import DISSIPATED, ENERGY_COLUMNS, INPUT, KINETIC, RESIDUAL_KEY, STORED, audit_keys, by_role
from ipir_mujoco.core.energy import changes as energy_changes
from ipir_mujoco.core.errors import ParameterError, SimulationError
from ipir_mujoco.core.options import RunOptions, check_step_count, check_type
from ipir_mujoco.core.params import RobotParams, require_params
from ipir_mujoco.core.results import RunResult

from .block_checks import BlockChecks, chunk_after
from ..kinds.common import (BLOCK_TIME, IMPLEMENTATIONS, REFINEMENTS, CrankServo, PassProgress, captured_warnings,
                                 climb_energy, mujoco_failure, steps_per_output)
from ..kinds import ModelKind, kind_for
from ..builders.model import SolverSettings
from ..loop.monitor import (AccuracyError, AccuracyMonitor, Tolerances, check_accuracy_mode, energy_audit, residual_ratio,
                      rising as _rising)
from ..loop.recorder import DEFERRED, EXTRA_COLUMNS, SCALARS, Recorder
from .run_setup import RunSetup
from ..loop.servo_drive import TickedDrive, controller_for
from ..loop.stepper import WARNED
from ..kinds.timestep import DT_MIN, halved

# columns of the recorder's arrays the monitor reads
_TORQUE, _GAP = SCALARS.index("motor_torque"), DEFERRED.index("loop_gap")
# where the recorder keeps each energy term of core.energy's table while a run goes: (deferred?, index); the
# per-sample audit reads every term here (a new term's column must be recorded: tests/test_energy_table.py)
_RECORDED_AS = {"clutch_spring_energy": "clutch_spring"}  # the deferred name of a series column, where it differs
ENERGY_SLOTS = {column: (False, SCALARS.index(column)) if column in SCALARS
                else (True, DEFERRED.index(_RECORDED_AS.get(column, column)))
                for column in ENERGY_COLUMNS if column in SCALARS or _RECORDED_AS.get(column, column) in DEFERRED}


__all__ = ["EXTRA_COLUMNS", "IMPLEMENTATIONS", "CrankServo", "captured_warnings", "simulate_mujoco"]


def simulate_mujoco(
    params: RobotParams,
    clutch: str = "unilateral",
    implementation: str = "ratchet",
    t_end: float = 1.0,
    *,
    dt_out: float = 1e-4,
    settings: SolverSettings | None = None,
    mjcf=None,
    progress: Callable[[float], None] | None = None,
    servo: CrankServo | None = None,
    accuracy: str | None = None,
    until_steady: bool = False,
    steady_tol: float = STEADY_TOL,
    steady_cycles: int = STEADY_CYCLES,
    wall_budget_s: float | None = None,
    model: str = "slides",
    feedforward=None,
    route=None,
) -> RunResult:
    """Run MuJoCo on the real linkage.

    ``implementation``: 'ratchet' (joint-limit ratchet; one-way by
    construction, so ``clutch`` must be 'unilateral'; with a finite
    ``params.clutch_stiffness`` the compliant clutch: a ratcheting anchor with
    a spring and damper to the module, see :mod:`.compliant`), 'lock'
    (velocity-triggered locks released by ``clutch`` = 'kinematic', the
    paper's rule, or 'unilateral', a lock that would pull lets go; rigid
    only), or 'none' (no clutches; rigid parameters only).
    ``dt_out`` [s] (<= t_end) must be a whole number of timesteps. ``settings``:
    None chooses the timestep from the motion (:func:`.timestep.choose_settings`)
    and halves it (at most twice) if the accuracy monitor fails; given settings
    are used as they are. ``accuracy``: 'stop' (a failed accuracy check is a
    SimulationError) or 'warn' (recorded in ``RunResult.accuracy``); None: the model kind's own
    (:attr:`.kinds.ModelKind.accuracy`: 'stop' on the slides, 'warn' on wheels).
    ``until_steady`` stops at the end of the revolution where the periodic
    steady state is reached (``t_end`` caps it). ``progress`` is called with the
    simulated time about every 0.1 s of it or second of wall time (in a repeat, a RepeatProgress);
    ``wall_budget_s`` [s] caps the wall time. ``servo`` replaces the drive by a crank servo
    (:class:`CrankServo`). ``feedforward``: with
    ``params.drive = 'servo'``, the speed controller's table (:class:`ipir_mujoco.core.control.FeedforwardTable`,
    required unless ``params.feedforward`` is 'none'; :mod:`.servo_drive`). ``model``: 'slides' or 'wheels'
    (on wheels in a pipe, a ratchet in every hub: :mod:`.wheels_model`, :mod:`.wheels`).
    ``route``: a :class:`ipir_mujoco.core.route.Route` (the wheeled model only): the walls along it, the run
    ended at its end or where the robot jams (:mod:`.route_watch`).
    """
    params = require_params(params)
    check_type("settings", settings, (SolverSettings, type(None)), "a SolverSettings, or None (chosen from the motion)")
    check_type("mjcf", mjcf, (str, os.PathLike, type(None)), "a path to an MJCF file, or None (the shipped one)")
    check_type("servo", servo, (CrankServo, type(None)), "a CrankServo, or None (the drive)")
    kind = kind_for(model, params)
    params = kind.check(params, implementation, clutch, route, until_steady)
    controller_for(params, feedforward)  # refused here, before any work, if the table does not fit
    if servo is not None and params.drive == "servo":
        raise ParameterError("a crank servo with drive='servo': one thing sets the crank's actuator; allowed: one")
    run = RunOptions(t_end, dt_out, until_steady, steady_tol, steady_cycles, progress, wall_budget_s)
    accuracy = check_accuracy_mode(kind.accuracy if accuracy is None else accuracy)
    t_end, dt_out = run.t_end, run.dt_out
    if settings is not None:  # bounded up front: a tiny given timestep is refused, not run for days
        check_step_count(t_end, settings.timestep)
        if params.drive == "servo" and settings.timestep * params.control_rate > 1 + 1e-9:
            raise ParameterError(f"timestep={settings.timestep:g} s is longer than the speed controller's period "
                                 f"1 / control_rate = {1 / params.control_rate:g} s; allowed: a timestep of at most "
                                 "that (or none: the engine then chooses one)")

    passes = None if run.progress is None else PassProgress(run.progress)  # one across the attempts
    options = dict(clutch=clutch, implementation=implementation, t_end=t_end, dt_out=dt_out, mjcf=mjcf,
                   progress=passes, servo=servo, accuracy=accuracy, until_steady=run.until_steady,
                   steady_tol=run.steady_tol, steady_cycles=run.steady_cycles, wall_budget_s=run.wall_budget_s,
                   kind=kind, feedforward=feedforward, route=route)
    rule = kind.skid_rule(params)  # the kind's skid check (kinds/skid_check.py)
    if settings is not None:
        settings, given = rule.given_settings(
            params, settings, lambda: kind.settings(params, t_end, dt_out, servo, implementation, route=route)[0])
        return rule.given(_Run(params, settings, **options).result({"timestep_source": "given", **given}))
    started = time.perf_counter()
    chosen, why = kind.settings(params, t_end, dt_out, servo, implementation, route=route)
    failures = []
    extra = {"timestep_source": "auto", "timestep_rule": why, "refinements": failures}
    for attempt in range(REFINEMENTS + 1):
        try:
            result = _Run(params, chosen, started=started, **options).result(extra)
            break
        except AccuracyError as exc:
            if attempt == REFINEMENTS or chosen.timestep / 2 < DT_MIN:
                raise
            failures.append({"timestep": chosen.timestep, "reason": str(exc)})
            chosen = halved(chosen)  # still a whole fraction of dt_out
    return rule.verify(result, _Reruns(params, chosen, options, extra, started), accuracy, DT_MIN,
                       run.wall_budget_s)


class _Reruns:
    """What a skid rule may run again of one automatically stepped run (``chosen`` its settings, ``options`` and
    ``extra`` its _Run's, ``started`` its start on the wall clock): the design at a finer step (called with the
    step [s]: :func:`ipir_mujoco.engine.kinds.skid_check.verify_skids`), or with other settings for ``t_end`` [s],
    recording and never stopping on its accuracy monitor nor at its steady state (:meth:`member`: the rigid
    limit's family, :mod:`ipir_mujoco.engine.kinds.slides_grip.rigid_limit`). A run sampled at each step is
    sampled at each of the finer ones' steps."""

    def __init__(self, params, chosen: SolverSettings, options: dict, extra: dict, started: float):
        self.params, self.chosen, self.options, self.extra, self.started = params, chosen, options, extra, started
        self.t_cap = options["t_end"]  # s: the run's t_end (with until_steady the cap)
        self.every_step = math.isclose(options["dt_out"], chosen.timestep, rel_tol=1e-12)

    def __call__(self, dt: float) -> RunResult:
        finer = {**self.options, "dt_out": dt} if self.every_step else self.options
        return _Run(self.params, replace(self.chosen, timestep=dt), started=self.started, **finer).result(self.extra)

    def member(self, settings: SolverSettings, member_end: float) -> RunResult:
        dt_out = self.options["dt_out"]
        out = settings.timestep * (1 if self.every_step else max(1, round(dt_out / settings.timestep)))
        member_options = {**self.options, "accuracy": "warn", "t_end": member_end, "until_steady": False,
                          "dt_out": out}
        return _Run(self.params, settings, started=self.started, **member_options).result(self.extra)


class _Run:
    """One MuJoCo run with fixed settings (the loop is in :meth:`_integrate`)."""

    def __init__(self, params, settings, *, clutch, implementation, t_end, dt_out, mjcf, progress, servo, accuracy,
                 until_steady, steady_tol, steady_cycles, wall_budget_s, kind: ModelKind, feedforward=None,
                 route=None, started=None):
        self.params, self.settings, self.clutch, self.implementation = params, settings, clutch, implementation
        self.t_end, self.dt_out, self.progress, self.servo = t_end, dt_out, progress, servo
        if progress is not None:
            progress.begin(settings.timestep)  # a repeat's progress says so (PassProgress)
        self.until_steady, self.steady_tol, self.steady_cycles = until_steady, steady_tol, steady_cycles
        self.wall_budget_s = wall_budget_s
        self.started = time.perf_counter() if started is None else started
        dt = settings.timestep
        self.steps_per_sample = steps_per_output(dt_out, dt)
        self.n_steps = math.floor(t_end / dt * (1 + 1e-12))  # never past t_end
        self.kind = kind
        self.route = route
        self.setup = RunSetup(kind, params, settings, implementation=implementation, rule=clutch, mjcf=mjcf,
                              route=route, servo=servo)
        self.model, self.data = self.setup.model, self.setup.data
        built = time.perf_counter() - self.started
        if wall_budget_s is not None and built > wall_budget_s:  # the budget covers building, not only stepping
            raise SimulationError(f"the run exceeded its wall-time budget of {wall_budget_s:g} s while building its "
                                  f"model ({built:.3g} s), before the first step")
        self.monitor = AccuracyMonitor(Tolerances.for_params(params), accuracy, dt)
        self.stall: str | None = None
        self.recorder: Recorder | None = None  # made by _setup
        self.speed = controller_for(params, feedforward)  # drive = servo: this attempt's own controller
        self.ticked: TickedDrive | None = None

    def result(self, extra_settings: dict) -> RunResult:
        with captured_warnings() as messages:
            try:
                last = self._integrate(messages)
            except mujoco.FatalError as exc:  # MuJoCo's error inside mj_step or mj_forward: one line, no traceback
                rec = self.recorder  # None or empty if MuJoCo failed before the first sample
                t = float(rec.t[rec.count - 1]) if rec is not None and rec.count else 0.0
                raise SimulationError(mujoco_failure(t, str(exc))) from None
        rec = self.recorder
        series = rec.series(last)
        series = self.route_watch.along_series(series)  # along a route: x and v along its centreline
        if self.ticked is not None:
            series["drive_u"] = self.ticked.u_column(series["t"])
        change = energy_changes(series)  # every energy term the series has (core.energy's table)
        total = by_role(change)
        residual, scale = energy_audit(total[INPUT], total[DISSIPATED], total[KINETIC], total[STORED],
                                       self.energy_floor)
        energy = {**audit_keys(change), RESIDUAL_KEY: float(residual)}
        label = {"ratchet": "unilateral", "lock": self.clutch, "none": "none"}[self.implementation]
        return RunResult(
            engine="mujoco", geometry="exact", clutch=label, params=self.params, t_end=float(series["t"][-1]),
            series=series, energy=energy, wall_time_s=time.perf_counter() - self.started,
            settings={"mujoco_clutch": self.implementation, "clutch_rule": self.clutch,
                      "clutch_model": self.controller.clutch_model, "dt_out": self.dt_out,
                      "mujoco_version": mujoco.__version__, **self.settings.as_dict(), **extra_settings,
                      "steady_tol": self.steady_tol, "steady_cycles": self.steady_cycles, **self.kind.recorded_settings()},
            stall=self.stall,
            accuracy=self.monitor.record(residual_ratio(residual, scale)),
            route=self.route_watch.record(self.t_end, self.stall),
        )

    def _setup(self):
        setup, p = self.setup, self.params
        setup.start(self.speed)
        m, d = self.model, self.data
        self.controller, self.loop = setup.controller, setup.loop
        self.recorder = Recorder(m, d, p, self.n_steps // self.steps_per_sample + 2, self.controller, self.kind)
        self.route_watch = self.kind.route_watch(self.route, m, self.recorder, p, self.dt_out)

    def _integrate(self, messages: list[str]) -> int:
        """Step to t_end (or the steady state, or a stall); returns the last sample's row.

        The steps run and the samples are recorded in :mod:`.stepper` (compiled where it can be), a block of
        BLOCK_TIME at a time; a sample's deferred values are MuJoCo's at the start of the next step, so each
        sample is judged by the monitor in the next interval (:meth:`_replay`).
        """
        self._setup()
        m, d, rec, ctl = self.model, self.data, self.recorder, self.controller

        torque = self.loop["torque"]
        # so that the first sample's acceleration is MuJoCo's qacc
        rec.qvel_before[0] = d.qvel - m.opt.timestep * d.qacc
        row = rec.sample(torque, 0.0, 0.0, ctl.sampled_reactions(), excursion=ctl.excursion, wheels=ctl.wheels())
        rec.fill_deferred(row)  # the initial state's energies are MuJoCo's from mj_forward
        at_start = by_role(self._energy_rows(row, row + 1))
        self.energy0 = (at_start[KINETIC].item(0), at_start[STORED].item(0))  # the state terms' energy at the start
        self.energy_floor = max(self.energy0[0], 2 * math.pi * abs(torque), climb_energy(m, self.params))
        self._replay((0, 1), (0, 1))
        self._check(messages, 0.0)

        steps, self.ticked = self.setup.steps(rec.qvel_before, self.speed)
        self.steps = steps
        sps, n_steps, done, samples = self.steps_per_sample, self.n_steps, 0, 0
        block = max(1, round(BLOCK_TIME / self.dt_out))
        checks = BlockChecks(self)
        pending, last = -1, None  # the first interval has no sample before it to fill in
        chunk = block  # samples per call of the stepper: a block, fewer where a block takes long (CHUNK_WALL_S)
        while done < n_steps:
            first, called = rec.count, time.perf_counter()
            status, taken = steps.record(rec, min(chunk, block - samples % block), sps, n_steps - done, pending,
                                         messages)
            done += taken
            samples += rec.count - first
            pending = rec.count - 1 if rec.count > first else pending
            # each interval judged the sample before it, from its first step on (none before the first interval);
            # an interval in which MuJoCo warned is not recorded, but it judged the last sample first
            warned = status == WARNED
            self._replay((max(first - 1, 1), rec.count - (0 if warned else 1)), (first, rec.count), warned, messages)
            if samples % block == 0 or done >= n_steps:
                last = checks.check(pending, messages)
                if last is not None:
                    break
            elif pending >= 0:  # inside a slow block: its progress only (the checks stay at the blocks' ends)
                checks.progress_only(pending)
            if rec.count > first:
                chunk = chunk_after(chunk, block, rec.count - first, time.perf_counter() - called)
        ctl.finish()  # (the compliant clutches: the anchors and dampers for the final state)
        mujoco.mj_forward(m, d)  # energies, gap and momentum at the final state
        if pending >= 1:
            rec.fill_deferred(pending)
            self._replay((pending, pending + 1), (rec.count, rec.count))
        self._check(messages, float(rec.t[rec.count - 1]))
        return rec.count - 1 if last is None else last

    def _replay(self, judged: tuple[int, int], new: tuple[int, int], warned: bool = False, messages=()) -> None:
        """Feed the monitor what rows ``judged`` (a, b: rows a..b-1, whose deferred values are filled) and the
        new samples ``new`` (first, end) show, in the order the samples were taken: sample i's interval first
        judged row i - 1 (residual ratio, then loop gap), then raised the energy floor to sample i's torque and
        reported its excursion; if MuJoCo warned in the interval after the last new sample (``warned``: it was
        not recorded, but it judged that sample), the run fails with the last good time. Of each figure only the
        values that leave the monitor as feeding every one would are fed (:func:`.monitor.rising`: its first crossing
        of the tolerance and the block's worst), so a block costs a few array operations."""
        rec, mon = self.recorder, self.monitor
        tol = mon.tolerances
        (a, b), (first, end) = judged, new
        events = []  # (position in the sampling order, kind, row)
        if b > a:
            # the floor each judged row saw: raised by every sample's torque up to it (2 pi |torque|)
            revolution = 2 * math.pi * np.abs(rec.scalars[a:b, _TORQUE])
            floors = np.fmax.accumulate(np.append(self.energy_floor, revolution))[1:]
            residual, scale = self._audit(a, b, floors)
            ratio = np.divide(residual, scale, out=np.zeros_like(residual), where=scale > 0)
            events += [(2 * j + 2, 0, j) for j in _rising(ratio, mon.worst["residual_ratio"], tol.residual_ratio, a)]
            events += [(2 * j + 2, 1, j) for j in _rising(rec.deferred[a:b, _GAP], mon.worst["loop_gap_m"],
                                                          tol.loop_gap_m, a)]
        if warned and messages:  # in the interval after the last new sample, once it had judged the one before
            events.append((2 * end, 2, end - 1))
        if end > first:
            events += [(2 * i + 1, 3, i) for i in _rising(rec.excursion[first:end], mon.worst["excursion_m"],
                                                          tol.excursion_m, first)]
        for _, kind, j in sorted(events):
            t = rec.t.item(j)
            if kind == 0:
                mon.residual(t, residual.item(j - a), scale.item(j - a))
            elif kind == 1:
                mon.loop_gap(t, rec.deferred.item(j, _GAP))
            elif kind == 2:
                self._check(messages, t)
            else:
                mon.excursion(t, rec.excursion.item(j))
        if end > first:
            largest = float(np.max(np.abs(rec.scalars[first:end, _TORQUE])))
            self.energy_floor = max(self.energy_floor, 2 * math.pi * largest)

    def _energy_rows(self, a: int, b: int) -> dict:
        """{energy term: its recorded values in samples a..b-1} for every term of core.energy's table."""
        rec = self.recorder
        return {term: (rec.deferred if deferred else rec.scalars)[a:b, index]
                for term in energy.ENERGY_TERMS for deferred, index in (ENERGY_SLOTS[term.column],)}

    def _audit(self, a: int, b: int, floors: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The energy audit's (residual [J], scale [J]) of samples a..b-1 with energy floors ``floors`` [J]: every
        term of core.energy's table by its role (the state terms, kinetic and stored, as gained since t = 0)."""
        total = by_role(self._energy_rows(a, b))
        return energy_audit(total[INPUT], total[DISSIPATED], total[KINETIC] - self.energy0[0],
                            total[STORED] - self.energy0[1], floors)

    def _check(self, messages: list[str], t_good: float) -> None:
        """Raise on a MuJoCo warning or a non-finite state; ``t_good`` [s] is the last sample known good
        (MuJoCo resets the state, clock included, when it detects a bad one)."""
        if messages:
            raise SimulationError(f"MuJoCo became unstable after t={t_good:.6g} s: {messages[0]} "
                                  "(a smaller --timestep may carry the run further)")
        if not (np.all(np.isfinite(self.data.qpos)) and np.all(np.isfinite(self.data.qvel))):
            raise SimulationError(f"non-finite state after t={t_good:.6g} s")
