"""What a MuJoCo run checks every BLOCK_TIME of simulated time (:mod:`.simulate`'s loop): progress, the
wall-time budget, the periodic steady state, a route's end or jam, and a stall."""

from __future__ import annotations

import math
import time

import numpy as np

from ipir_mujoco.core.steady_test import steady_target
from ipir_mujoco.core.steady_watch import SteadyWatch
from ipir_mujoco.core.errors import SimulationError

from ..kinds.common import rest_since, stall_reason
from ..builders.model import CRANK_HINGE, FRONT_SLIDE, REAR_SLIDE


# s of wall time: a run whose 0.1 s of simulated time takes longer (a wheeled run at a finer step: 3-4 s at
# 1.25e-5 s beside another job) reports once this much wall time has passed too, so that a terminal's status line
# moves at least every second (ipir_mujoco.terminal) and a log gets its line every 5 s
PROGRESS_WALL_S = 0.5
# s of wall time: the most one call of the stepper takes, about (a block of BLOCK_TIME that takes longer is
# stepped in parts, the progress reported between them; the checks stay at the blocks' ends: the same results)
CHUNK_WALL_S = 0.25


def chunk_after(chunk: int, block: int, recorded: int, wall: float) -> int:
    """The samples the stepper's next call records: as many as the last call's rate (``recorded`` samples in
    ``wall`` seconds) steps in CHUNK_WALL_S, at least 1 and at most a ``block``."""
    if wall <= 0:
        return block
    return max(1, min(block, int(CHUNK_WALL_S * recorded / wall)))


class BlockChecks:
    """What the run checks every BLOCK_TIME of simulated time: progress (every 0.1 s of simulated time, or of
    PROGRESS_WALL_S of wall time, whichever comes first), budget, steady state, stall."""

    def __init__(self, run):
        self.run = run
        self.next_report = 0.1
        self.reported_at = time.perf_counter()  # wall time of the last progress call
        self.fed = 0  # samples given to the steady-state watch so far
        rec = run.recorder
        self.r1, self.f2 = rec.qa[REAR_SLIDE], rec.qa[FRONT_SLIDE]
        self.v_adr = [rec.va[n] for n in (CRANK_HINGE, REAR_SLIDE, FRONT_SLIDE)]
        self.watch = SteadyWatch(float(rec.qpos[0, rec.qa[CRANK_HINGE]]), run.steady_tol, run.steady_cycles,
                                 steady_target("mujoco", run.steady_tol)) \
            if run.until_steady else None
        # a stall is final only under constant loads: not with a crank servo's time-varying torque; the speed
        # controller's only while it asks for full voltage (:meth:`_stall`)
        self.stall_watch = run.servo is None

    def progress_only(self, newest: int) -> None:
        """Between a slow block's parts: the progress, if PROGRESS_WALL_S of wall time has passed (nothing else:
        the checks keep their simulated times)."""
        run = self.run
        now = time.perf_counter()
        if run.progress is not None and now - self.reported_at >= PROGRESS_WALL_S:
            run.progress(float(run.recorder.t[newest]))
            self.reported_at = now

    def check(self, newest: int, messages: list[str]) -> int | None:
        """Returns the row to end the run at (steady state or stall), or None to go on."""
        run, rec = self.run, self.run.recorder
        t = float(rec.t[newest])
        run._check(messages, float(rec.t[max(newest - 1, 0)]))
        now = time.perf_counter()
        if run.progress is not None and (t >= self.next_report - 1e-12 or now - self.reported_at >= PROGRESS_WALL_S):
            run.progress(t)
            self.reported_at = now
            self.next_report = 0.1 * (math.floor(t / 0.1 + 1e-9) + 1)
        if run.wall_budget_s is not None and now - run.started > run.wall_budget_s:
            raise SimulationError(f"the run exceeded its wall-time budget of {run.wall_budget_s:g} s at "
                                  f"t={t:.6g} s (simulated)")
        if self.watch is not None:
            q = rec.qpos[self.fed:newest + 1]
            travel = 0.5 * (q[:, self.r1] - rec.qpos[0, self.r1] + q[:, self.f2] - rec.qpos[0, self.f2])
            steady = self.watch.update(rec.t[self.fed:newest + 1], q[:, rec.qa[CRANK_HINGE]], travel)
            self.fed = newest + 1
            if steady:
                return int(np.searchsorted(rec.t[:newest + 1], self.watch.steady_at - 1e-12, side="left"))
        if (stop := run.route_watch.check(newest)) is not None:  # a route's end or jam
            return stop
        if self.stall_watch:
            return self._stall(newest, t)
        return None

    def _stall(self, newest: int, t: float) -> int | None:
        rec = self.run.recorder
        v = rec.qvel[:newest + 1]
        since = rest_since(rec.t[:newest + 1], v[:, self.v_adr[0]], v[:, self.v_adr[1]], v[:, self.v_adr[2]],
                           self.run.params.r)
        if since is None or (self.run.ticked is not None and not self.run.ticked.saturated_since(since)):
            return None
        self.run.stall = stall_reason(self.run.params, since, float(rec.qpos[newest, rec.qa[CRANK_HINGE]]))
        return newest
