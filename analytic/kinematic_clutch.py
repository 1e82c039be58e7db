"""The paper's hybrid model: ideal clutches locked by the sign of S_dot.

The mode lives in the integration loop, not in the right-hand side: one mode
is integrated with ``solve_ivp`` until a terminal event (S_dot = K(phi) *
omega reaching zero), the next mode is chosen at that point, and integration
restarts. Each event function only watches the crossing that ends its mode
(direction +1 in contraction, -1 in expansion), so a restart on a root that
solve_ivp placed a hair on either side never re-triggers.

Choosing the next mode where S_dot = 0: a mode is consistent if the motion it
produces gives S_dot the sign it needs (negative in contraction, positive in
expansion). Its first non-vanishing time derivative decides:

* S_ddot = K' omega^2 + K alpha_mode, computed with each mode's own alpha.
  At a dead centre with the crank turning (K = 0) this is K' omega^2; with the
  crank at rest (omega = 0) it is K alpha_mode. For F_r1, F_r2 >= 0 at most
  one mode is consistent (shown in the module's tests), so no tie-break is
  ever needed.
* If S_ddot vanishes in both modes the crank is at rest on a dead centre
  (K = omega = 0; e.g. the start from rest at phi = 0). Both modes then give
  alpha = M / J_eff, and S - S0 = K' (phi - phi0)^2 / 2 + O(phi^3): the gap
  shrinks (contraction) where K' < 0, as at phi = 0, and grows where K' > 0.
* If no mode is consistent the robot stalls: both clutches hold, the crank
  stays at rest, and under constant loads it stays so (``BOTH_LOCKED``): the
  drive's torque at rest is constant (M, or the motor's M_stall), so the stall
  is final and reported in ``RunResult.stall``.

The drive's torque (:func:`.forces.drive_torque`) and gravity along the pipe
enter every mode through :class:`.dynamics.OneDofDynamics`. With the crank at
rest mid-stroke, both modes are consistent only if gravity alone could move
either module (a_g M_total > F_r1 + F_r2, a steep downhill): the paper's rule
cannot say which module then moves, and the run stops with a SimulationError.
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

from . import dop853, kernels
from .dynamics import OneDofDynamics
from .forces import drive_torque
from .kinematics import Geometry
from .kinetostatics import add_kinetostatics
from .solver_support import (MAX_SWITCHES, RunMonitor, assemble, check_finite, check_tolerances, raw_piece,
                             restart_step, truncate, with_drive_u)

# |S_ddot| below this fraction of r * (omega^2 + |alpha_c| + |alpha_e|) counts as
# zero: roundoff in K near a dead centre (sin(k pi) ~ 1e-16 k) is far below it,
# a real S_ddot far above.
_ZERO_SDD = 1e-9
# |S_dot| below this fraction of r * |omega| at the start counts as a dead centre.
_ZERO_SD = 1e-10
_STATES = ("phi", "omega", "x1", "x2", "motor_work")  # y, as series columns


def choose_mode_at_rest_gap(dyn: OneDofDynamics, phi: float, omega: float, M: float | None = None) -> Mode:
    """Next mode at a state where S_dot = 0 (see the module docstring); ``M`` overrides the drive's torque."""
    tr = dyn.linkage.transfer(phi)
    alpha_c = float(dyn.acceleration(phi, omega, Mode.CONTRACTION, M))
    alpha_e = float(dyn.acceleration(phi, omega, Mode.EXPANSION, M))
    sdd_c = tr.dK * omega**2 + tr.K * alpha_c
    sdd_e = tr.dK * omega**2 + tr.K * alpha_e
    tol = _ZERO_SDD * dyn.linkage.r * (omega**2 + abs(alpha_c) + abs(alpha_e))
    contraction_ok, expansion_ok = sdd_c < -tol, sdd_e > tol
    if contraction_ok and expansion_ok:  # only where gravity alone can move either module (docstring)
        p = dyn.params
        raise SimulationError(
            f"the paper's clutch rule cannot choose a module at phi={phi:.6g} rad, omega={omega:.6g} rad/s: "
            f"gravity along the pipe ({dyn.a_g:.4g} m/s^2) can move either module on its own, more than the "
            f"resistances hold ((F_r1 + F_r2) / total mass = {(p.F_r1 + p.F_r2) / dyn.mass_terms(phi).m11:.4g} "
            "m/s^2); use the one-way clutches (clutch='unilateral')")
    if contraction_ok:
        return Mode.CONTRACTION
    if expansion_ok:
        return Mode.EXPANSION
    if abs(sdd_c) <= tol and abs(sdd_e) <= tol and alpha_c != 0.0:
        return Mode.CONTRACTION if tr.dK < 0 else Mode.EXPANSION
    return Mode.BOTH_LOCKED


def choose_initial_mode(dyn: OneDofDynamics, phi: float, omega: float, M: float | None = None) -> Mode:
    """Mode at the start: by the sign of S_dot, or by the next order where it is zero."""
    S_dot = float(dyn.linkage.transfer(phi).K) * omega
    if abs(S_dot) > _ZERO_SD * dyn.linkage.r * abs(omega):
        return Mode.CONTRACTION if S_dot < 0 else Mode.EXPANSION
    return choose_mode_at_rest_gap(dyn, phi, omega, M)


def simulate_kinematic(params: RobotParams, geometry: Geometry | str = Geometry.APPROX, t_end: float = 1.0, *,
                       rtol: float = 1e-10, atol: float = 1e-12, torque: Callable | None = None,
                       feedforward=None, **run) -> RunResult:
    """Simulate the robot with the paper's clutch rule.

    ``geometry`` 'approx' is the paper's model (rod ignored); 'exact' uses the
    exact slider-crank with the rod's mass and inertia. ``rtol``/``atol``: the
    DOP853 tolerances on the state (phi [rad], omega [rad/s], x1 [m], x2 [m],
    motor work [J]). ``torque(t, phi, omega)`` [N m], vectorized, replaces the
    drive of ``params`` (e.g. a torque from inverse kinetostatics); a stall under
    it is an error, since a stall is only final where the torque at rest is
    constant. ``run``: the run options every engine takes
    (:class:`ipir_mujoco.core.options.RunOptions`: ``dt_out``, ``until_steady``,
    ``steady_tol``, ``steady_cycles``, ``progress``, ``wall_budget_s``,
    ``max_switches``, default :data:`.solver_support.MAX_SWITCHES`), run by
    :class:`.solver_support.RunMonitor`. The output grid gets each mode-switch
    instant (twice: once per mode) and each revolution's end. ``drive = servo``: the speed controller
    (:class:`ipir_mujoco.core.control.SpeedController`, ``feedforward`` its table) ticks at exact times, each
    a segment's end, its u held in the kernels' constants between ticks (the paper's rule picks the module
    by S_dot, which a torque step does not change; at rest the mode is chosen again at each tick); the
    series then also has ``drive_u`` and ``motor_torque``.
    """
    options = RunOptions.given(t_end, run)
    speed = SpeedController(params, feedforward) if params.drive == "servo" else None
    rtol, atol = check_tolerances(rtol, atol)
    t_end, dt_out = options.t_end, options.dt_out
    monitor = RunMonitor(options, params.phi0, MAX_SWITCHES)
    dyn = OneDofDynamics(params, geometry)
    constants = kernels.pack(dyn)
    n_out = max(1, math.ceil(t_end / dt_out - 1e-9))
    grid = np.linspace(0.0, t_end, n_out + 1)

    t = 0.0
    y = np.array([params.phi0, params.omega0, 0.0, 0.0, 0.0])
    start_torque = _torque_at(torque, 0.0, y)
    if speed is not None:  # the controller's tick at t = 0
        constants[kernels.P_U] = speed.tick(params.phi0, params.omega0)
        start_torque = float(drive_torque(params, params.omega0, constants[kernels.P_U]))
    mode = choose_initial_mode(dyn, params.phi0, params.omega0, start_torque)
    pieces: list[dict[str, np.ndarray]] = []
    switches, stall, h0 = 0, None, None
    while True:
        stop = t_end if speed is None else min(t_end, speed.next_tick)  # a segment ends at the next tick
        if mode is Mode.BOTH_LOCKED and speed is not None and constants[kernels.P_U] < 1.0:  # to the next tick
            pieces.append(with_drive_u(raw_piece(Mode.BOTH_LOCKED, monitor.samples(t, stop, grid),
                                                 lambda ts: np.repeat(y[:, None], np.size(ts), axis=1), _STATES),
                                       constants[kernels.P_U]))
            t = stop
            if t >= t_end:
                break
            constants[kernels.P_U] = speed.tick(float(y[0]), float(y[1]))
            mode = choose_initial_mode(dyn, float(y[0]), float(y[1]),
                                       float(drive_torque(params, float(y[1]), constants[kernels.P_U])))
            continue
        if mode is Mode.BOTH_LOCKED:
            if torque is not None:
                raise SimulationError(f"the robot stalls at t={t:.6g} s under the given torque profile; "
                                      "restarting from a stall is modelled only for a constant torque at rest")
            # Everything at rest under a torque that is constant at rest: nothing changes any more (the servo's
            # too once it asks for full voltage: at rest its error is the whole target, none integrated in the clip)
            stall = stall_reason(t, float(y[0]), float(drive_torque(params, 0.0)), dyn.a_g != 0)
            # at rest for good: the run goes on REST_TIME at rest and ends, as every engine's does
            rest = raw_piece(Mode.BOTH_LOCKED, monitor.samples(t, min(t + REST_TIME, t_end), grid),
                             lambda ts: np.repeat(y[:, None], np.size(ts), axis=1), _STATES)
            pieces.append(rest if speed is None else with_drive_u(rest, constants[kernels.P_U]))
            break
        sol = _integrate_mode(dyn, mode, t, stop, y, rtol, atol, torque, h0, constants)
        t_stop, h0 = float(sol.t[-1]), restart_step(sol, h0, t_end)
        piece = raw_piece(mode, monitor.samples(t, t_stop, grid, sol.t, sol.sol), sol.sol, _STATES)
        if speed is not None:
            piece = with_drive_u(piece, constants[kernels.P_U])
        steady_at = monitor.observe(piece)
        pieces.append(piece if steady_at is None else truncate(piece, steady_at))
        if steady_at is None and sol.status == 0 and stop < t_end:  # the controller's tick: the mode stays
            t, y = stop, np.array(sol.y[:, -1], dtype=float)
            constants[kernels.P_U] = speed.tick(float(y[0]), float(y[1]))
            monitor.check_budget(t, float(y[0]))
            monitor.report(t)
            continue
        if steady_at is not None or sol.status != 1:
            break
        t, y = float(sol.t_events[0][0]), sol.y_events[0][0].copy()
        switches += 1
        monitor.after_switch(t, switches, float(y[0]))
        mode = choose_mode_at_rest_gap(dyn, float(y[0]), float(y[1]), _torque_at(torque, t, y))
        if t >= t_end:
            break

    series = assemble(pieces, lambda mode, rows: _mode_columns(dyn, Mode(mode), rows, torque))
    monitor.report(float(series["t"][-1]), final=True)
    series.update(dyn.energy_columns(series))
    add_kinetostatics(series, dyn)
    if speed is None:
        del series["motor_torque"]  # folded into motor_power (the servo's is kept beside its drive_u)
    check_finite(series)
    return RunResult(
        engine="analytic",
        geometry=dyn.geometry.value,
        clutch="kinematic",
        params=params,
        t_end=float(series["t"][-1]),  # the end of the run: t_end, or where it reached steady state
        series=series,
        energy=dyn.energy_audit(series),
        wall_time_s=time.perf_counter() - monitor.started,
        settings={"method": "DOP853", "rtol": rtol, "atol": atol, "dt_out": dt_out,
                  "rod_modelled": dyn.include_rod, **monitor.settings},
        stall=stall,
    )


def _torque_at(torque, t, y):
    return None if torque is None else float(torque(t, y[0], y[1]))


def mode_rhs(dyn: OneDofDynamics, mode: Mode, torque: Callable | None = None) -> Callable:
    """d/dt of y = [phi, omega, x1, x2, motor work] in ``mode``: the drive's torque, or ``torque(t, phi, omega)``."""
    linkage, params = dyn.linkage, dyn.params

    def rhs(t, y):
        phi, omega = y[0], y[1]
        K = linkage.transfer(phi).K
        e = -K if mode is Mode.CONTRACTION else 0.0
        M = drive_torque(params, omega) if torque is None else torque(t, phi, omega)
        return [omega, dyn.acceleration(phi, omega, mode, M), e * omega, (e + K) * omega, M * omega]
    return rhs


def _integrate_mode(dyn, mode, t0, t_end, y0, rtol, atol, torque=None, first_step=None, constants=None):
    """Integrate one mode from t0 until its switch event or t_end (``first_step`` [s]: see restart_step).

    The drive of ``params`` runs on the scalar kernels (``constants``: :func:`.kernels.pack` of ``dyn``);
    a ``torque`` profile, a Python function, on solve_ivp with :func:`mode_rhs`: the same method.
    """
    direction = 1.0 if mode is Mode.CONTRACTION else -1.0
    if torque is None:
        constants = kernels.pack(dyn) if constants is None else constants
        sol = dop853.solve(kernels.KINEMATIC, int(mode), t0, t_end, y0, constants, rtol, atol, first_step,
                           [direction])
        if sol.status < 0:
            raise SimulationError(f"integration failed at t={sol.t[-1]:.6g} s in {mode.name.lower()}: "
                                  f"{sol.message}")
        return sol
    linkage, rhs = dyn.linkage, mode_rhs(dyn, mode, torque)

    def gap_rate(_t, y):
        return linkage.transfer(y[0]).K * y[1]

    gap_rate.terminal = True
    gap_rate.direction = direction
    from scipy.integrate import solve_ivp  # a torque profile's path only: not the compiled DOP853's

    with np.errstate(over="ignore", invalid="ignore"):  # trial steps of a fast crank can overflow; the step
        # controller rejects them, and the output is checked finite
        sol = solve_ivp(rhs, (t0, t_end), y0, method="DOP853", rtol=rtol, atol=atol,
                        events=gap_rate, dense_output=True, first_step=first_step)
    if sol.status < 0:
        raise SimulationError(f"integration failed at t={sol.t[-1]:.6g} s in {mode.name.lower()}: {sol.message}")
    return sol


def _mode_columns(dyn, mode, rows, torque=None) -> dict[str, np.ndarray]:
    """Every column of the samples ``rows`` (:data:`_STATES` and ``mode``) of one mode."""
    times, phi, omega = rows["t"], rows["phi"], rows["omega"]
    if mode is Mode.BOTH_LOCKED:
        return _stalled_columns(dyn, rows)
    if "drive_u" in rows:  # drive = servo: each sample's u, held between the controller's ticks
        M = drive_torque(dyn.params, omega, rows["drive_u"])
    else:
        M = drive_torque(dyn.params, omega) if torque is None else torque(times, phi, omega)
    M = np.broadcast_to(M, times.shape).astype(float)
    st = dyn.state(phi, omega, mode, M)
    return {
        "t": times, "phi": phi, "omega": omega, "alpha": st.alpha, "x1": rows["x1"], "x2": rows["x2"],
        "v1": st.v1, "v2": st.v2, "a1": st.a1, "a2": st.a2, "S": st.S, "S_dot": st.S_dot,
        "lambda1": st.lambda1, "lambda2": st.lambda2,
        "mode": rows["mode"],
        # the paper's lock takes the whole holding force; a moving module feels -F_r
        "resistance1": np.zeros(times.shape) if mode is Mode.EXPANSION else np.full(times.shape, -dyn.params.F_r1),
        "resistance2": np.zeros(times.shape) if mode is Mode.CONTRACTION else np.full(times.shape, -dyn.params.F_r2),
        "motor_work": rows["motor_work"], "motor_torque": M, **_drive_u(rows),
    }


def _stalled_columns(dyn, rows) -> dict[str, np.ndarray]:
    n = rows["t"].shape
    phi = float(rows["phi"][0])  # at rest: one crank angle
    lam1, lam2, res1, res2 = dyn.stalled_reactions(phi)
    zeros = np.zeros(n)
    return {
        "t": rows["t"], "phi": np.full(n, phi), "omega": zeros, "alpha": zeros,
        "x1": rows["x1"], "x2": rows["x2"], "v1": zeros, "v2": zeros,
        "a1": zeros, "a2": zeros, "S": np.full(n, dyn.linkage.gap(phi)), "S_dot": zeros,
        "lambda1": np.full(n, lam1), "lambda2": np.full(n, lam2),
        "mode": rows["mode"],
        # a hold pulling a module back is its resistance's (see stalled_reactions)
        "resistance1": np.full(n, res1), "resistance2": np.full(n, res2),
        "motor_work": rows["motor_work"], **_drive_u(rows),
        "motor_torque": (drive_torque(dyn.params, zeros, rows["drive_u"]) if "drive_u" in rows
                         else np.full(n, float(drive_torque(dyn.params, 0.0)))),
    }


def _drive_u(rows: dict) -> dict:
    """The servo's ``drive_u`` column of ``rows`` where it has one (drive = servo), else nothing."""
    return {"drive_u": rows["drive_u"]} if "drive_u" in rows else {}
