"""One-way clutches that can only push: the event-driven unilateral model (its run loop; the modes themselves,
:class:`.unilateral_model.UnilateralModel`).

Coordinates (x1, phi); x2 follows through S(phi). Each module either slides
forward (v_i > 0, resistance -F_ri) or stands still, held by a total force R_i
from its clutch (pushing forward, no limit) and its resistance (holding back a
forward push up to F_ri; a module at rest pushed forward by less than F_ri
cannot move, since sliding would brake it at once). So with mu_i = R_i + F_ri:

    moving:  v_i > 0, mu_i = 0          at rest:  mu_i >= 0,  a_i >= 0,  mu_i * a_i = 0

Four modes: ``CONTRACTION`` (front held, rear moves), ``EXPANSION`` (rear
held, front moves), ``BOTH_MOVING``, ``BOTH_LOCKED`` (a static stall). Within
a mode the motion is smooth and is integrated with ``solve_ivp``; terminal
events end it where a moving module's velocity reaches zero or a held module's
margin mu_i does. At each event the next mode solves the complementarity
problem on accelerations and holding forces by enumeration: every mode whose
held modules are at rest is a candidate, and a candidate is consistent if its
held modules have mu_i >= 0 and its free modules at rest have a_i >= 0.

Ties (a condition exactly zero) are broken by what the event says and by the
next order, never by an arbitrary choice:

* the mode whose own event just fired is dropped when another is consistent
  (its condition is crossing zero in the wrong direction);
* a hold whose margin just reached zero is released; a module whose velocity
  just reached zero is held, where both choices are consistent;
* at rest on a dead centre (K = omega = 0) both single-hold modes have zero
  module acceleration; the gap then moves as K' (phi - phi0)^2 / 2, so it
  shrinks (contraction) where K' < 0 and grows where K' > 0;
* a robot at rest that statics can hold (both margins >= 0) stays at rest:
  nothing drives it out.

Reported clutch reaction: lambda_i = max(R_i, 0) while held (a clutch only
pushes; a backward hold is the resistance's), 0 while moving; the resistance
force is in ``resistance1/2`` (-F_ri moving, min(R_i, 0) held).

The drive's torque (:func:`.forces.drive_torque`, constant or a motor line) and
gravity along the pipe enter every mode through :class:`.dynamics.OneDofDynamics`.
Uphill, a held module's R_i includes the share of the robot's weight its clutch
carries; downhill, gravity can pull a module forward (R_i < -F_ri): it is then
released and runs, since no one-way clutch can stop forward motion.
"""

from __future__ import annotations

import math
import time
from typing import Callable

import numpy as np

from ipir_mujoco.core.control import SpeedController
from ipir_mujoco.core.errors import SimulationError
from ipir_mujoco.core.options import RunOptions
from ipir_mujoco.core.params import RobotParams
from ipir_mujoco.core.results import REST_TIME, Mode, RunResult, stall_reason

from . import dop853
from .kinematics import Geometry
from .kinetostatics import add_kinetostatics
from .solver_support import (MAX_SWITCHES, RunMonitor, assemble, check_finite, check_tolerances, first_event,
                             integrate_segment, raw_piece, switch_mode, truncate, with_drive_u)
from .unilateral_model import _STATES, _TOL_F, _TOL_V, HELD, UnilateralModel  # the tests import it from here too

# more zero-length segments in a row than this is chatter, not motion
_MAX_STALLED_SEGMENTS = 50


def simulate_unilateral(params: RobotParams, geometry: Geometry | str = Geometry.EXACT, t_end: float = 1.0, *,
                        rtol: float = 1e-10, atol: float = 1e-12, torque: Callable | None = None,
                        feedforward=None, **run) -> RunResult:
    """Simulate the robot with one-way clutches (see the module docstring).

    Initial module velocities from (phi0, omega0) follow the MuJoCo engine's
    start: module 1 at rest unless the gap shrinks. ``torque(t, phi, omega)``
    [N m], vectorized, replaces the drive of ``params``; a stall under it is an
    error (a stall is only final where the torque at rest is constant, as for the
    constant torque and the motor). ``rtol``/``atol``: the DOP853 tolerances.
    ``run``: the run options every engine takes
    (:class:`ipir_mujoco.core.options.RunOptions`: ``dt_out``, ``until_steady``,
    ``steady_tol``, ``steady_cycles``, ``progress``, ``wall_budget_s``,
    ``max_switches``, default :data:`.solver_support.MAX_SWITCHES`), run by
    :class:`.solver_support.RunMonitor`. Each revolution's end is an exact sample.

    ``drive = servo``: the speed controller (:class:`ipir_mujoco.core.control.SpeedController`, with the
    ``feedforward`` table where ``params.feedforward`` is not 'none') ticks at exact times, each an end of
    a segment: its u goes into the drive's torque (:meth:`UnilateralModel.set_u`) and the clutch mode is
    chosen again for the new torque; the series then also has ``drive_u`` and ``motor_torque``.
    """
    options = RunOptions.given(t_end, run)
    speed = SpeedController(params, feedforward) if params.drive == "servo" else None
    rtol, atol = check_tolerances(rtol, atol)
    t_end, dt_out = options.t_end, options.dt_out
    monitor = RunMonitor(options, params.phi0, MAX_SWITCHES)
    if params.grip is None:
        model = UnilateralModel(params, geometry, torque)
    else:  # wheels of finite grip: a held module may skid back
        from .grip_model import GripModel
        model = GripModel(params, geometry, torque)
    n_out = max(1, math.ceil(t_end / dt_out - 1e-9))
    grid = np.linspace(0.0, t_end, n_out + 1)

    K0 = float(model.linkage.transfer(params.phi0).K)
    S_dot0 = K0 * params.omega0
    v1_0 = max(-S_dot0, 0.0)
    y = np.array([params.phi0, params.omega0, 0.0, 0.0, v1_0, 0.0])
    if speed is not None:  # the controller's tick at t = 0
        model.set_u(speed.tick(params.phi0, params.omega0))
    mode = model.choose(0.0, y, (v1_0, v1_0 + S_dot0))
    y = model.project(y, mode, (v1_0, v1_0 + S_dot0))
    t, pieces, switches, short_run, stall, h0 = 0.0, [], 0, 0, None, None

    def integrate(model, mode, events, t0, t1, y0, first_step, quiet=None):
        return integrate_mode(model, mode, events, t0, t1, y0, rtol, atol, first_step, quiet)

    while True:
        stop = t_end if speed is None else min(t_end, speed.next_tick)  # a segment ends at the next tick
        if mode == Mode.BOTH_LOCKED and speed is not None and model.u < 1.0:  # at rest until the next tick
            pieces.append(with_drive_u(raw_piece(Mode.BOTH_LOCKED, monitor.samples(t, stop, grid),
                                                 lambda ts: np.repeat(y[:, None], np.size(ts), axis=1), _STATES),
                                       model.u))
            t = stop
            if t >= t_end:
                break
            mode, y = _tick(model, speed, monitor, t, y, mode)
            continue
        if mode == Mode.BOTH_LOCKED:
            if torque is not None:
                raise SimulationError(f"the robot stalls at t={t:.6g} s under the given torque profile; "
                                      "restarting from a stall is modelled only for a constant torque at rest")
            # at rest, held by statics, under a torque that is constant at rest: final (the servo's too once it
            # asks for full voltage: at rest its error is the whole target and it integrates none into the clip)
            stall = stall_reason(t, float(y[0]), float(model.motor(t, y[0], 0.0)), model.dyn.a_g != 0)
            # at rest for good: the run goes on REST_TIME at rest and ends, as every engine's does
            rest = raw_piece(Mode.BOTH_LOCKED, monitor.samples(t, min(t + REST_TIME, t_end), grid),
                             lambda ts: np.repeat(y[:, None], np.size(ts), axis=1), _STATES)
            pieces.append(rest if speed is None else with_drive_u(rest, model.u))
            break
        events, sol, t_stop, h0, grazed, piece = integrate_segment(model, mode, integrate, t, stop, y, h0, t_end,
                                                                  monitor, grid, _STATES)
        if speed is not None:
            piece = with_drive_u(piece, model.u)
        steady_at = monitor.observe(piece)
        pieces.append(piece if steady_at is None else truncate(piece, steady_at))
        if steady_at is None and grazed is None and sol.status == 0 and stop < t_end:  # at the next tick
            t = stop
            mode, y = _tick(model, speed, monitor, t, np.asarray(sol.y[:, -1], dtype=float), mode)
            continue
        if steady_at is not None or grazed is None and sol.status != 1:
            break
        short_run = short_run + 1 if t_stop - t <= 1e-12 * (1.0 + t) else 0
        if short_run > _MAX_STALLED_SEGMENTS:
            raise SimulationError(f"the clutch modes chatter at t={t:.6g} s (phi={y[0]:.6g} rad)")
        t, hit, y_event = first_event(sol, events, grazed)
        mode, y, switches = switch_mode(model, mode, t, y_event, events[hit][1], monitor, switches)
        if t >= t_end:
            break

    with model.linkage.reusing():  # the same samples' kinematics, asked for by every column
        series = assemble(pieces, model.columns)
        series.update(model.energy_columns(series))
        add_kinetostatics(series, model.dyn)
    monitor.report(float(series["t"][-1]), final=True)
    if speed is None:
        del series["motor_torque"]  # folded into motor_power (the servo's is kept beside its drive_u)
    check_finite(series)
    return RunResult(engine="analytic", geometry=model.dyn.geometry.value, clutch="unilateral", params=params,
                     t_end=float(series["t"][-1]), series=series, energy=model.energy_audit(series),
                     wall_time_s=time.perf_counter() - monitor.started, stall=stall,
                     settings={"method": "DOP853", "rtol": rtol, "atol": atol, "dt_out": dt_out,
                               "rod_modelled": model.dyn.include_rod, **monitor.settings})


def _tick(model: UnilateralModel, speed, monitor: RunMonitor, t: float, y: np.ndarray, mode: Mode):
    """The speed controller's tick at time t [s] in state ``y``: its u into the drive, then the clutch mode
    for the new torque (a held module's margin moves with it) and the state projected onto it. Where every
    event function of the mode stays clearly positive under the new torque (each moving module moving, each
    held one's margin above zero by the sign tests' tolerance), the mode's conditions hold strictly and it
    is the complementarity problem's one solution: kept, without solving it again."""
    model.set_u(speed.tick(float(y[0]), float(y[1])))
    monitor.check_budget(t, float(y[0]))
    monitor.report(t)
    if mode is not Mode.BOTH_LOCKED:
        guards = model.guards(np.array([t]), y[:, None], mode)[:, 0]  # module i's: margin if held, else speed
        p, r, omega = model.params, model.linkage.r, abs(float(y[1]))
        clear = (_TOL_F * (p.F_r1 + p.F_r2 + (p.m1 + p.m2) * r * omega * omega), _TOL_V * r * omega)  # N, m/s
        if all(g > clear[0 if held else 1] for g, held in zip(guards, HELD[mode])):
            return mode, y
    velocities = model.velocities(y, mode)
    new = model.choose(t, y, velocities, previous=mode)
    return new, model.project(y, new, velocities)


def integrate_mode(model, mode: Mode, events, t0, t_end, y0, rtol, atol, first_step, quiet=None):
    """Integrate ``mode`` of ``model`` (its ``kernel_call``, ``torque``, ``rhs``; the route's too) from t0 [s] until
    one of ``events`` or t_end.

    The drive of ``params`` runs on the scalar kernels (:mod:`.kernels`: the same events, event k
    quiet until ``quiet[k]`` [s]); a ``torque`` profile, a Python function, on solve_ivp: the same method.
    """
    if model.torque is None:
        quiet = quiet or {}
        kernel, kernel_mode, constants = model.kernel_call(mode)
        sol = dop853.solve(kernel, kernel_mode, t0, t_end, y0, constants, rtol, atol, first_step,
                           [e.direction for e, _ in events], [quiet.get(k, -math.inf) for k in range(len(events))])
        if sol.status < 0:
            raise SimulationError(f"integration failed at t={sol.t[-1]:.6g} s in {mode.name.lower()}: "
                                  f"{sol.message}")
        return sol
    from scipy.integrate import solve_ivp  # a torque profile's path only: not the compiled DOP853's

    with np.errstate(over="ignore", invalid="ignore"):  # trial steps of a fast crank can overflow; the step
        # controller rejects them, and the output is checked finite
        sol = solve_ivp(model.rhs(mode), (t0, t_end), y0, method="DOP853", rtol=rtol, atol=atol,
                        events=[e for e, _ in events], dense_output=True, first_step=first_step)
    if sol.status < 0:
        raise SimulationError(f"integration failed at t={sol.t[-1]:.6g} s in {mode.name.lower()}: {sol.message}")
    return sol
