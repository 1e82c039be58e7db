"""Helpers shared by the analytic solvers: the tolerance check, output sampling, finiteness, and the
run monitor (work budgets, progress, revolution ends, steady stop and truncation), written once for every
analytic driver (the paper's rule, the one-way clutches, the compliant clutches)."""

from __future__ import annotations

import math
import time

import numpy as np

from ipir_mujoco.core.steady_test import steady_target
from ipir_mujoco.core.steady_watch import SteadyWatch
from ipir_mujoco.core.errors import ParameterError, SimulationError
from ipir_mujoco.core.options import RunOptions
from ipir_mujoco.core.params import check_real

from . import accel
from .dense import CLEAR, GRAZE_POINTS
from .roots import brentq


def check_tolerances(rtol: float, atol: float) -> tuple[float, float]:
    """(rtol, atol) of the DOP853 solver as floats: both > 0, rtol >= 1e-13 (DOP853's floor)."""
    atol = check_real("atol", atol)
    if check_real("rtol", rtol) < 1e-13:
        raise ParameterError(f"rtol={rtol} is out of range; allowed: rtol >= 1e-13 (DOP853's floor)")
    return float(rtol), atol


def sample_times(t0: float, t1: float, grid: np.ndarray) -> np.ndarray:
    """Segment [t0, t1]: its end points and the output grid strictly inside (``grid`` ascending).

    Located by bisection, not by a mask over the whole grid: a run's cost must not grow with
    (segments x grid points)."""
    inside = grid[np.searchsorted(grid, t0, side="right"):max(np.searchsorted(grid, t1, side="left"), 0)]
    if not t1 > t0:
        return np.array([t0])
    times = np.empty(inside.size + 2)
    times[0], times[1:-1], times[-1] = t0, inside, t1
    return times


def steps_until(ends: np.ndarray, t_stop: float) -> np.ndarray:
    """A segment's step ends ``ends`` (ascending) before t_stop [s], then t_stop: its steps up to where it stopped."""
    if ends.size >= 2 and ends[-2] < t_stop == ends[-1]:  # stopped where it was integrated to: the usual end
        return ends
    return np.append(ends[ends < t_stop], t_stop)


def check_finite(series: dict[str, np.ndarray]) -> None:
    for name, values in series.items():
        bad = np.flatnonzero(~np.isfinite(values))
        if bad.size:
            t_bad = series["t"][bad[0]]
            raise SimulationError(f"non-finite {name} at t={t_bad:.6g} s")


def restart_step(sol, previous: float | None, t_end: float) -> float | None:
    """First step [s] for the segment after ``sol``: the last full step it took (its very last
    one is cut at the event), else ``previous``; capped by what is left to t_end [s].

    scipy's own first-step guess, from a crude second-derivative estimate, can propose a step far
    longer than the motion allows, and DOP853's error estimate has been seen to accept it (a
    2.4 ms step where 0.65 ms steps were needed: 3e-6 of the run's energy lost in one step).
    Starting each segment from the step size the previous one settled on avoids that guess.
    """
    ends = sol.t
    h = float(ends[-2] - ends[-3]) if ends.size >= 3 else previous
    left = t_end - float(ends[-1])
    return None if h is None or not h > 0 or not left > 0 else min(h, left)


def missed_crossing(sol, guards, events, scan=None):
    """A guard crossing that solve_ivp missed: (t, event index, state) of the first, or None.

    ``sol``: a solve_ivp result with dense output; ``guards(t (n,), Y (d, n))``: every
    event function at once, array (n_events, n); ``events``: the event functions,
    each falling through zero where its mode ends; ``scan()``: (times, negative,
    positive) as :func:`graze_signs` finds them, computed elsewhere (the compiled
    :meth:`.dense.DenseSolution.graze_scan`), or None: from ``guards`` here.

    solve_ivp reports a crossing only where an event function is >= 0 at one step
    end and <= 0 at the next. Two kinds slip through: a guard that dips below zero
    and recovers within one step (a graze, seen when a coasting crank takes long
    steps), and a guard that starts its segment a roundoff below zero (the state is
    projected onto the new mode, e.g. v1 = -K omega = -1e-17 at a dead centre),
    rises, and is below zero again at the next step end: no step then starts at
    >= 0, so solve_ivp sees no crossing at all. So every guard is sampled at the
    step ends and at interior points through the dense output, all in time order;
    where it is first clearly negative, its root after the last clearly positive
    sample is located with brentq (at the segment's start if it never was clearly
    positive). "Clearly": beyond 1e-9 of the guard's largest value in the segment.
    """
    if sol.t.size < 2:
        return None
    times, negative, positive = graze_signs(sol, guards) if scan is None else scan()
    first = None
    for k, (j, before) in enumerate(zip(negative.tolist(), positive.tolist())):
        if j < 0 or first is not None and times[j] >= first[0]:
            continue
        if before < 0:  # never clearly above zero since the segment's start: it left zero downward at once
            first = (float(times[0]), k)
            continue
        event = events[k]
        first = (brentq(lambda time: event(time, sol.sol(time)), times[before], times[j], xtol=1e-15,
                        rtol=4 * np.finfo(float).eps), k)
    return None if first is None else (first[0], first[1], sol.sol(first[0]))


def graze_signs(sol, guards) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The samples of :func:`missed_crossing`: (times (N,), negative (n_events,), positive (n_events,)).

    ``times``: each step's start and GRAZE_POINTS interior points, then the last end; per guard,
    ``negative`` the first sample where it is clearly negative and ``positive`` the last before that
    where it is clearly positive (-1: none). The reference of :func:`.dense.graze_scan`."""
    ends = sol.t
    fractions = np.arange(GRAZE_POINTS + 1) / (GRAZE_POINTS + 1)  # each step's start and interior points
    times = np.append((ends[:-1, None] + np.diff(ends)[:, None] * fractions).ravel(), ends[-1])
    values = guards(times, sol.sol(times))
    scale = np.maximum(np.abs(values).max(axis=1), 1e-300)
    negative, positive = np.full(len(values), -1), np.full(len(values), -1)
    for k, row in enumerate(values):
        below = np.flatnonzero(row < -CLEAR * scale[k])
        if below.size:
            negative[k] = below[0]
            above = np.flatnonzero(row[:below[0]] > CLEAR * scale[k])  # out of the roundoff at the start
            positive[k] = above[-1] if above.size else -1
    return times, negative, positive


PROGRESS_EVERY_S = 0.1  # simulated seconds between two progress calls, at least
# mode switches a run of the rigid-clutch models may make unless told otherwise (a work budget for designs that
# chatter)
MAX_SWITCHES = 100_000
# regime changes a run of the compliant model may make unless told otherwise: its clutches engage, clamp and release
# within every stroke, and stick/slip states change at each, so ten times the rigid models' budget
MAX_REGIME_CHANGES = 10 * MAX_SWITCHES
# a run whose mode switches stop advancing time is stuck (Zeno chatter, or a design at a degenerate limit such as
# r = 5e-324 m, where each switch leaves the state where it was): STUCK_SWITCHES switches in a row within
# STUCK_TIME (relative to 1 + t) of the first of them end it with that reason, rather than after spending
# MAX_SWITCHES (15 s of wall time). 1e-12 s is about 4500 roundings of t at t ~ 1 s; no stroke of a robot that
# moves switches its clutches a thousand times in it
STUCK_SWITCHES = 1000
STUCK_TIME = 1e-12
# a run stopped at its steady state ends on the first sample at or after the steady revolution's end less this
# (relative to 1 + t): the steady test interpolates that end between samples and may place it a rounding error
# past the revolution event's own sample, which must then be the last one kept
STEADY_SLACK = 1e-9


class RunMonitor:
    """What every analytic solver's loop shares: the work budgets, progress, revolutions, the steady stop.

    The solver calls :meth:`samples` for each segment's output times (the output grid plus a sample exactly
    where each crank revolution ends), :meth:`observe` with each finished piece (with ``until_steady`` it
    returns the time of the last sample to keep once the periodic steady state is reached, and the piece is
    then cut there with :func:`truncate`), :meth:`after_switch` at each mode switch (the switch budget, the
    wall-time budget and progress), :meth:`check_budget` wherever else a long stretch without switches may
    run (a stiff clutch's oscillations), and :meth:`report` at the end.

    ``options``: the run's :class:`~ipir_mujoco.core.options.RunOptions` (checked); ``phi0`` [rad]: the
    crank angle at t = 0; ``max_switches``: the engine's switch budget where the options give none.
    """

    def __init__(self, options: RunOptions, phi0: float, max_switches: int):
        self.options = options
        self.t_end, self.phi0 = options.t_end, float(phi0)
        self.watch = SteadyWatch(phi0, options.steady_tol, options.steady_cycles,
                                 steady_target("analytic", options.steady_tol))
        self.max_switches = options.max_switches if options.max_switches is not None else int(max_switches)
        self.wall_budget_s, self.progress, self.until_steady = (options.wall_budget_s, options.progress,
                                                                options.until_steady)
        self.switches = 0
        self._stuck_at, self._stuck_count = -math.inf, 0  # the first switch of the latest run of stuck switches
        accel.run_started()
        self.started = self._clock = time.perf_counter()
        self.next_report = PROGRESS_EVERY_S
        self.next_end = float(phi0) + 2 * math.pi  # crank angle at which the current revolution ends

    @property
    def settings(self) -> dict:
        """What a run records so that its summary applies the same steady-state test."""
        return self.options.steady_settings

    def revolution_ends(self, t0: float, step_ends: np.ndarray, dense) -> list[float]:
        """Times in (t0, step_ends[-1]] where the running maximum of phi first reaches phi0 + 2 pi k.

        ``step_ends``: the solver's accepted step ends (from t0); ``dense(t)``: its dense
        output, phi first. Each end is located with brentq on the dense output and moved
        to the first float at which phi >= the target, so the sample there counts it.
        """
        ends = []
        phis = np.asarray(dense(step_ends))[0]
        if not phis[1:].max(initial=-math.inf) >= self.next_end:  # no revolution ends here: the common case
            return ends
        phi_at = getattr(dense, "phi_at", None) or (lambda s: dense(s)[0])  # phi at one time (compiled if it can)
        for i in range(1, len(step_ends)):
            while phis[i] >= self.next_end:
                target = self.next_end
                lo, hi = step_ends[i - 1], step_ends[i]
                if phis[i - 1] >= target:  # reached at the start of the step (or a segment's start)
                    when = lo
                else:
                    when = brentq(lambda s: phi_at(s) - target, lo, hi, xtol=1e-15, rtol=4 * np.finfo(float).eps)
                    while phi_at(when) < target and when < hi:
                        when = min(np.nextafter(when, hi), hi)
                ends.append(float(when))
                self.next_end += 2 * math.pi
        return ends

    def samples(self, t0: float, t1: float, grid: np.ndarray, step_ends: np.ndarray | None = None,
                dense=None) -> np.ndarray:
        """Output times of the segment [t0, t1]: its end points, the grid inside and each revolution's end."""
        times = sample_times(t0, t1, grid)
        if dense is None or step_ends is None or t1 <= t0:
            return times
        ends = [s for s in self.revolution_ends(t0, np.asarray(step_ends, dtype=float), dense) if t0 < s < t1]
        if not ends:
            return times
        # np.union1d's sorted, distinct values, without its np.unique (which loads numpy.ma: 20-25 ms of a short
        # run's start-up, python -X importtime)
        merged = np.sort(np.concatenate((times, ends)))
        return merged[np.concatenate(([True], merged[1:] != merged[:-1]))]

    def observe(self, piece: dict[str, np.ndarray]) -> float | None:
        """Feed a finished piece; with ``until_steady``, the time [s] of its last sample to keep once steady
        (cut the piece there with :func:`truncate`), else None."""
        position = 0.5 * (np.asarray(piece["x1"]) + np.asarray(piece["x2"]))
        if not (self.watch.update(piece["t"], piece["phi"], position) and self.until_steady):
            return None
        # the watch interpolates the end of the revolution between samples; the sample there (the exact
        # revolution end) is the last kept, also where the interpolation lands a rounding error past it
        t, end = piece["t"], self.watch.steady_at
        return float(t[min(np.searchsorted(t, end - STEADY_SLACK * (1.0 + end)), t.size - 1)])

    def _tick(self) -> float:
        """The wall time now [s]; the time since the last tick goes to :func:`.accel.spent`, which compiles the
        kernels once Python-mode integration has cost what loading them would. That compilation is the
        process's one-time cost, not this run's work: it is kept out of the run's wall budget."""
        now = time.perf_counter()
        accel.spent(now - self._clock)
        after = time.perf_counter()
        self.started += after - now
        self._clock = after
        return after

    def after_switch(self, t: float, switches: int, phi: float) -> None:
        """Budget checks and progress at a mode switch at time t [s] (the ``switches``-th) at crank angle phi."""
        self.switches = switches
        if t - self._stuck_at <= STUCK_TIME * (1.0 + abs(t)):
            self._stuck_count += 1
            if self._stuck_count >= STUCK_SWITCHES:
                raise SimulationError(
                    f"the run is stuck: {self._stuck_count} mode switches in a row within {STUCK_TIME:g} s of "
                    f"t={self._stuck_at:.6g} s of {self.t_end:g} s (crank at "
                    f"{(phi - self.phi0) / (2 * math.pi):.4g} revolutions): the clutches chatter without the "
                    "motion advancing; check the design's parameters near their limits")
        else:
            self._stuck_at, self._stuck_count = t, 0
        if switches > self.max_switches:
            raise SimulationError(
                f"the work budget max_switches={self.max_switches} is spent at t={t:.6g} s of {self.t_end:g} s "
                f"(crank at {(phi - self.phi0) / (2 * math.pi):.4g} revolutions): raise max_switches or shorten "
                "t_end")
        self.check_budget(t, phi)
        self.report(t)

    def check_budget(self, t: float, phi: float | None = None) -> None:
        """Raise once the run has spent its wall-time budget (at simulated time t [s], crank angle phi [rad]
        where known)."""
        now = self._tick()
        if self.wall_budget_s is None or now - self.started <= self.wall_budget_s:
            return
        crank = "" if phi is None else f", crank at {(phi - self.phi0) / (2 * math.pi):.4g} revolutions"
        raise SimulationError(
            f"the work budget wall_budget_s={self.wall_budget_s:g} s is spent at t={t:.6g} s of "
            f"{self.t_end:g} s ({self.switches} mode switches{crank}): raise wall_budget_s or shorten t_end")

    def report(self, t: float, final: bool = False) -> None:
        """Call ``progress(t)`` if PROGRESS_EVERY_S of simulated time has passed since the last call (or at the end)."""
        if final:
            self._tick()
        if self.progress is not None and (t >= self.next_report or final):
            self.progress(t)
            self.next_report = t + PROGRESS_EVERY_S


def integrate_segment(model, mode, integrate, t: float, stop: float, y: np.ndarray, first_step: float | None,
                      t_end: float, monitor: RunMonitor, grid: np.ndarray, names: tuple[str, ...], early: int = 0):
    """One segment of a rigid-clutch model's run loop (the one-way clutches' and the route's): ``mode`` integrated
    from (t [s], y) to ``stop`` [s] or its first event by ``integrate(model, mode, events, t0, t1, y0, first_step,
    quiet=None)``, again with a guard quiet where it crossed only spuriously at the start (:func:`spurious_start`),
    the crossing the integrator missed (:func:`missed_crossing`) and the segment's samples (:func:`raw_piece`,
    columns ``names``); ``early``: :func:`spurious_start`'s. ``model``: its ``events``, ``guards`` and ``graze_scan``. Returns (events, sol, t_stop [s],
    the next segment's first step [s], the missed crossing (t, event index, state) or None, the piece)."""
    events = model.events(mode)
    sol = integrate(model, mode, events, t, stop, y, first_step)
    spurious = spurious_start(sol, lambda ts, ys: model.guards(ts, ys, mode), early=early)
    if spurious is not None:  # integrate again, that guard quiet until it has clearly risen
        events = model.events(mode, quiet=dict([spurious]))
        sol = integrate(model, mode, events, t, stop, y, first_step, dict([spurious]))
    t_stop, first_step = float(sol.t[-1]), restart_step(sol, first_step, t_end)
    grazed = missed_crossing(sol, lambda ts, ys: model.guards(ts, ys, mode), [e for e, _ in events],
                             model.graze_scan(sol, mode))
    if grazed is not None:
        t_stop = grazed[0]
    piece = raw_piece(mode, monitor.samples(t, t_stop, grid, steps_until(sol.t, t_stop), sol.sol), sol.sol, names)
    return events, sol, t_stop, first_step, grazed, piece


def first_event(sol, events, grazed) -> tuple[float, int, np.ndarray]:
    """(time [s], index, state) of the event that ended a segment (:func:`integrate_segment`): the missed crossing
    ``grazed`` where there is one, else the earliest of ``events`` the integrator found."""
    if grazed is not None:
        return grazed
    hit = min((k for k in range(len(events)) if sol.t_events[k].size), key=lambda k: sol.t_events[k][0])
    return float(sol.t_events[hit][0]), hit, sol.y_events[hit][0]


def switch_mode(model, mode, t: float, y_event: np.ndarray, fired, monitor: RunMonitor, switches: int):
    """The mode switch at an event (``fired``, its meaning) at time t [s] and state ``y_event`` of a rigid-clutch
    model's run: the next mode (``model.choose``), the state projected onto it, the switch counted and the
    budgets checked (:meth:`RunMonitor.after_switch`). Returns (mode, state, switches)."""
    velocities = model.velocities(y_event, mode)
    new = model.choose(t, y_event, velocities, fired, previous=mode)
    y = model.project(y_event, new, velocities)
    monitor.after_switch(t, switches + 1, float(y[0]))
    return new, y, switches + 1


def raw_piece(mode: int, times: np.ndarray, dense, names: tuple[str, ...]) -> dict[str, np.ndarray]:
    """A segment's integrated states at ``times`` (n,) from its dense output, as columns ``names``, and its mode."""
    return {"t": times, **dict(zip(names, dense(times))), "mode": np.full(times.shape, int(mode))}


def spurious_start(sol, guards, points: int = 32, early: int = 0):
    """(event index, time [s]) if the integrator put a crossing at the segment's start that is not one, else None.

    ``guards(t (n,), Y (d, n))``: every event function at once, array (n_events, n). A mode
    starts where its guards are zero and rising (that is why it was chosen), but the value there
    is a projected zero, +-1e-17 by roundoff. A guard that rises only briefly (e.g. a module
    starting from rest with a small acceleration and a large negative jerk, back at zero
    microseconds later) gives a first step that starts at 0 and ends below it; the root search
    then sticks in the roundoff next to the start, and the run would restart there, forever. If
    the guard is clearly positive in that first step before it is clearly negative, the crossing
    at the start is spurious: returned is where it has risen. ``early``: as many more points, at
    2^-early .. 2^-1 of the step, for a rise that ends before the first of the evenly spaced ones (a
    module that skids back from rest for 5e-5 s of a 3 ms step and turns: the route model's).
    """
    if sol.status != 1:
        return None
    t0 = sol.t[0]
    k = min((k for k in range(len(sol.t_events)) if sol.t_events[k].size), key=lambda k: sol.t_events[k][0])
    if sol.t_events[k][0] - t0 > 1e-12 * (1.0 + abs(t0)):
        return None
    step = sol.sol.interpolants[0]  # the whole first step's dense output, also past the event
    fractions = np.concatenate([2.0 ** -np.arange(early, 0, -1), np.arange(1, points + 1) / points])
    times = step.t_old + (step.t - step.t_old) * fractions
    values = guards(times, step(times))[k]
    threshold = 1e-9 * max(np.abs(values).max(), 1e-300)
    rising, falling = np.flatnonzero(values > threshold), np.flatnonzero(values < -threshold)
    if rising.size == 0 or falling.size and falling[0] < rising[0]:
        return None
    return k, float(times[rising[0]])


def assemble(pieces: list[dict[str, np.ndarray]], columns) -> dict[str, np.ndarray]:
    """The run's series from its pieces of integrated states (each with a ``mode`` column).

    ``columns(mode, rows)`` gives every column of the samples ``rows`` (the pieces' columns, all
    of that mode), vectorized: called once per mode of the run rather than once per segment, so
    that a run of many short segments pays numpy's per-call cost a few times, not per segment.
    Columns keep the order ``columns`` gives them.
    """
    raw = {c: np.concatenate([piece[c] for piece in pieces]) for c in pieces[0]}
    modes = raw["mode"]
    series: dict[str, np.ndarray] = {}
    for mode in sorted(set(modes.tolist())):  # np.unique's values, without loading numpy.ma (see samples)
        rows = np.flatnonzero(modes == mode)
        part = columns(int(mode), {c: v[rows] for c, v in raw.items()})
        for c, v in part.items():
            if c not in series:
                series[c] = np.empty(modes.size, dtype=np.asarray(v).dtype)
            series[c][rows] = v
    return series


def with_drive_u(piece: dict[str, np.ndarray], u: float) -> dict[str, np.ndarray]:
    """``piece`` with the speed controller's u [-] over it (drive = servo; constant between its ticks, which
    end segments) as the column ``drive_u``."""
    piece["drive_u"] = np.full(np.shape(piece["t"]), float(u))
    return piece


def truncate(piece: dict[str, np.ndarray], t_stop: float) -> dict[str, np.ndarray]:
    """The samples of ``piece`` at or before t_stop [s]."""
    keep = piece["t"] <= t_stop
    return {c: (v[keep] if np.ndim(v) else v) for c, v in piece.items()}
