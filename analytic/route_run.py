"""The analytic robot along a route (``route=``, ``--route FILE.toml``): the event-driven run loop of
:class:`.route_model.RouteModel` and the run's route keys.

Exact geometry only (the paper's first order has no linkage to span a bend's chord), with the paper's rule or
one-way clutches (finite grip where ``mu_wall`` is), rigid clutches, the drive's torque or the motor line. The run
ends where module 1's A reaches the route's end (``route_done``, ``route_time_s`` located as an event), where the
robot makes no progress (less than PROGRESS_M along the route in PROGRESS_S: the wheeled MuJoCo model's rule),
at a stall or at t_end. The summary's route keys are those of the MuJoCo route runs that the equations can give:
``route_done``, ``route_time_s``, ``route_s_m``, ``route_length_m``, ``route_stop``, ``route_piece_times_s``.
"""

from __future__ import annotations

import math
import time

import numpy as np

from ipir_mujoco.core.errors import ParameterError, SimulationError
from ipir_mujoco.core.options import RunOptions
from ipir_mujoco.core.params import RobotParams
from ipir_mujoco.core.results import REST_TIME, RunResult, stall_reason
from ipir_mujoco.core.route import PROGRESS_M, PROGRESS_S, Route

from .grip_model import GripMode
from .route_model import K2, RouteModel
from .solver_support import (MAX_SWITCHES, RunMonitor, assemble, check_finite, check_tolerances, first_event,
                             integrate_segment, raw_piece, switch_mode)
from .unilateral_run import integrate_mode

_STATES = ("phi", "omega", "x1", "s2", "state_v1", "motor_work", "scrub_work")  # y, as raw columns (x1 = s1)
_MAX_STALLED_SEGMENTS = 50  # zero-length segments in a row: chatter (as the one-way model's)
# a module leaving rest and turning back within a step's first 2^-40 .. 1/32 is looked for there too
# (:func:`.solver_support.spurious_start`): in a bend the linkage's loads change fast enough for a skid from rest
# to end 5e-5 s into a 3 ms step
_EARLY = 40


def check_route_run(params: RobotParams, route, geometry: str, clutch: str, options: dict) -> RobotParams:
    """``params`` for a run along ``route`` (its incline the route's first straight's); ParameterError (one line)
    for what the route model does not take: the first-order geometry, compliant clutches, the servo, a torque
    profile, --until-steady, an incline set apart from the route's, a bend tighter than the pipe."""
    if not isinstance(route, Route):
        raise ParameterError(f"route={route!r}; allowed: a Route (ipir_mujoco.core.route.read_route), or None")
    if geometry != "exact":
        raise ParameterError("--route with --geometry approx: the paper's first-order geometry has no linkage to span "
                             "a bend's chord; allowed: --geometry exact (analytic-exact, analytic-unilateral)")
    for refused, why in ((params.clutch_stiffness is not None, "clutch_stiffness: rigid clutches only"),
                         (params.drive == "servo", "drive servo: the torque or the motor"),
                         (options.get("torque") is not None, "a torque profile: the drive of the parameters"),
                         (options.get("until_steady"), "--until-steady: a run along a route ends at its end")):
        if refused:
            raise ParameterError(f"--route with {why.split(':')[0]}; allowed along a route: {why.split(': ')[1]}")
    if params.incline != 0.0 and params.incline != route.incline:
        raise ParameterError(f"incline={params.incline:g} deg with --route: the route's first straight sets the "
                             "incline; allowed: incline=0 (give it in the route)")
    route.check_pipe(params.pipe_diameter)
    return params.replace(incline=route.incline)


def simulate_route(params: RobotParams, route: Route, clutch: str, t_end: float, *, rtol: float = 1e-10,
                   atol: float = 1e-12, **run) -> RunResult:
    """The robot with ``clutch`` ('kinematic' | 'unilateral') along ``route`` (checked: :func:`check_route_run`)
    from t = 0 to its end or ``t_end`` [s]; ``run``: the run options (:class:`.RunOptions`)."""
    options = RunOptions.given(t_end, run)
    rtol, atol = check_tolerances(rtol, atol)
    t_end, dt_out = options.t_end, options.dt_out
    monitor = RunMonitor(options, params.phi0, MAX_SWITCHES)
    model = RouteModel(params, route, clutch)
    grid = np.linspace(0.0, t_end, max(1, math.ceil(t_end / dt_out - 1e-9)) + 1)
    y = model.start()
    velocities = (y[4], y[4] + model.state(y, GripMode.EXPANSION)[K2] * params.omega0)
    mode = model.choose(0.0, y, velocities)
    y = model.project(y, mode, velocities)
    watch = _Progress(route, params.phi0)

    def integrate(model, mode, events, t0, t1, y0, first_step, quiet=None):
        return integrate_mode(model, mode, events, t0, t1, y0, rtol, atol, first_step, quiet)

    t, pieces, switches, short_run, stall, stop, done_at, h0 = 0.0, [], 0, 0, None, None, None, None
    while True:
        if mode == GripMode.BOTH_LOCKED:  # at rest, held by statics, under a torque constant at rest: final
            stall = stall_reason(t, float(y[0]), float(model.motor(t, y[0], 0.0)), _climbs(route))
            pieces.append(raw_piece(mode, monitor.samples(t, min(t + REST_TIME, t_end), grid),
                                    lambda ts: np.repeat(y[:, None], np.size(ts), axis=1), _STATES))
            break
        events, sol, t_stop, h0, grazed, piece = integrate_segment(model, mode, integrate, t, t_end, y, h0, t_end,
                                                                  monitor, grid, _STATES, early=_EARLY)
        stop = watch.observe(piece)
        pieces.append(piece if stop is None else {c: v[piece["t"] <= stop[1]] for c, v in piece.items()})
        if stop is not None:
            stop = stop[0]
            break
        if grazed is None and sol.status != 1:
            break
        t_event, hit, y_event = first_event(sol, events, grazed)
        if events[hit][1][0] == "end":
            done_at = t_event
            break
        short_run = short_run + 1 if t_stop - t <= 1e-12 * (1.0 + t) else 0
        if short_run > _MAX_STALLED_SEGMENTS:
            raise SimulationError(f"the clutch modes chatter at t={t:.6g} s (phi={y[0]:.6g} rad), at "
                                  f"{route.where(float(y[2]))}")
        t = t_event
        y_event = model.past_joints(y_event, mode)
        mode, y, switches = switch_mode(model, mode, t, y_event, events[hit][1], monitor, switches)
        if t >= t_end:
            break
    series = assemble(pieces, model.columns)
    series.update(model.energy_columns(series))
    monitor.report(float(series["t"][-1]), final=True)
    check_finite(series)
    keys = route_keys(route, series, model.s20, done_at, stop, stall, float(series["t"][-1]))
    return RunResult(engine="analytic", geometry="exact", clutch=clutch, params=params,
                     t_end=float(series["t"][-1]), series=series, energy=model.energy_audit(series),
                     wall_time_s=time.perf_counter() - monitor.started, stall=stall,
                     settings={"method": "DOP853", "rtol": rtol, "atol": atol, "dt_out": dt_out, "rod_modelled": True,
                               "route": route.as_dict(), **monitor.settings}, route=keys)


def _climbs(route: Route) -> bool:
    """Whether gravity pulls along the pipe anywhere on ``route`` (a stall's words)."""
    up = route.up
    return any(abs(float(p.frame[0] @ up)) > 1e-12 or p.kind == "bend" and abs(float(p.axis @ up)) < 1 - 1e-12
               for p in route.pieces)


class _Progress:
    """The route's no-progress stop: module 1's furthest station must grow by PROGRESS_M in every PROGRESS_S."""

    def __init__(self, route: Route, phi0: float):
        self.route, self.s_max, self.at = route, 0.0, (0.0, 0.0, float(phi0))

    def observe(self, piece: dict) -> tuple[str, float] | None:
        """(the stop's line, its time [s]) once the robot has made no progress, else None."""
        for t, s, phi in zip(piece["t"].tolist(), piece["x1"].tolist(), piece["phi"].tolist()):
            self.s_max = max(self.s_max, s)
            if self.s_max - self.at[1] >= PROGRESS_M:
                self.at = (t, self.s_max, phi)
            elif t - self.at[0] >= PROGRESS_S:
                turns = (phi - self.at[2]) / (2 * math.pi)
                why = (f"the crank turned {turns:.2f} revolutions" if abs(turns) >= 0.05 else "the crank stood")
                return (f"stalled: less than {PROGRESS_M * 1e3:g} mm of progress in {PROGRESS_S:g} s ({why}; module 1 "
                        f"now at s = {s:.3f} m), at {self.route.where(self.s_max)}, t = {t:.4f} s", t)
        return None


def route_keys(route: Route, series: dict, s20: float, done_at: float | None, stop: str | None, stall: str | None,
               t_end: float) -> dict:
    """The summary's route keys (module docstring) of a run's ``series``: ``route_piece_times_s`` when the robot's
    centre, midway along the route between A (s1) and C (s2 = s20 + x2), first reached each segment's start and
    the route's end [s] (interpolated between samples, as MuJoCo's route watch does), else None."""
    t = series["t"]
    centre = 0.5 * (series["x1"] + series["x2"] + s20)
    reached = np.maximum.accumulate(centre)
    times = []
    for mark in [p.s0 for p in route.pieces] + [route.length]:
        k = int(np.searchsorted(reached, mark))
        if k >= reached.size:
            times.append(None)
        elif k == 0:
            times.append(float(t[0]))
        else:
            share = (mark - reached[k - 1]) / (reached[k] - reached[k - 1])
            times.append(float(t[k - 1] + share * (t[k] - t[k - 1])))
    s_max = float(series["x1"].max())
    if done_at is not None:
        stop = f"reached the route's end ({route.length:.3f} m) at t = {done_at:.4f} s"
    elif stop is None:
        where = route.where(s_max)
        stop = (f"stalled: {stall}, at {where}" if stall else
                f"t_end {t_end:g} s reached before the route's end, at {where}")
    return {"route_done": done_at is not None, "route_time_s": done_at, "route_s_m": s_max,
            "route_length_m": route.length, "route_stop": stop, "route_piece_times_s": times}
