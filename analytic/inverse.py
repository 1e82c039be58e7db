"""Inverse kinetostatics: the torque and forces a prescribed crank motion needs.

The crank follows phi(t) exactly (a constant speed, or samples the user gives);
the modules follow from the clutch rule. Under the paper's rule the sign of
K(phi) omega picks the moving module; with one-way clutches the modules have
their own dynamics (both can slide at once), integrated event by event as in
:mod:`ipir_mujoco.analytic.unilateral_run` but with the crank's motion given instead of
the torque. At every instant the motor torque is the phi-row of the two-DOF
equations (:meth:`OneDofDynamics.motor_torque`), and the clutch reactions,
rod and pin forces follow as in the forward models. Gravity along the pipe
(a_g) enters every equation as in the forward models; the drive parameters do
not (the torque is what this computes).
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass
from typing import Callable

import numpy as np
from scipy.interpolate import CubicSpline

from ipir_mujoco.core.errors import ParameterError, SimulationError
from ipir_mujoco.core.params import RobotParams
from ipir_mujoco.core.options import check_run_options
from ipir_mujoco.core.results import Mode, RunResult

from .dynamics import OneDofDynamics
from .solver_support import check_tolerances, sample_times
from .kinematics import Geometry
from .kinetostatics import add_kinetostatics

HELD = {Mode.CONTRACTION: (False, True), Mode.EXPANSION: (True, False), Mode.BOTH_MOVING: (False, False)}
_TOL = 1e-7  # relative tolerance of the sign tests (see unilateral_run)


@dataclass(frozen=True)
class CrankMotion:
    """A prescribed crank motion: vectorized phi(t) [rad], omega(t) [rad/s], alpha(t) [rad/s^2] on [0, t_end]."""

    phi: Callable
    omega: Callable
    alpha: Callable
    t_end: float
    description: str

    @classmethod
    def constant_speed(cls, omega: float, phi0: float = 0.0, revolutions: float = 1.0) -> "CrankMotion":
        """phi = phi0 + omega t for ``revolutions`` turns."""
        if not (math.isfinite(omega) and omega != 0):
            raise ParameterError(f"omega={omega} rad/s is out of range; allowed: a finite speed != 0")
        if not (math.isfinite(revolutions) and revolutions > 0):
            raise ParameterError(f"revolutions={revolutions} is out of range; allowed: > 0")
        t_end = 2 * math.pi * revolutions / abs(omega)
        return cls(lambda t: phi0 + omega * np.asarray(t, dtype=float), lambda t: omega + 0.0 * np.asarray(t),
                   lambda t: 0.0 * np.asarray(t, dtype=float), t_end, f"constant speed {omega:g} rad/s")

    @classmethod
    def from_samples(cls, t, phi) -> "CrankMotion":
        """An interpolating cubic spline through samples (t [s] from 0, strictly increasing; phi [rad])."""
        t, phi = np.asarray(t, dtype=float), np.asarray(phi, dtype=float)
        if t.ndim != 1 or t.shape != phi.shape or t.size < 4:
            raise ParameterError(f"crank samples need matching 1-D t and phi with at least 4 rows, got {t.shape}, {phi.shape}")
        if not (np.all(np.isfinite(t)) and np.all(np.isfinite(phi))):
            raise ParameterError("crank samples contain a value that is not finite")
        if t[0] != 0 or np.any(np.diff(t) <= 0):
            raise ParameterError(f"crank sample times must start at 0 and increase strictly; got t[0]={t[0]}")
        spline = CubicSpline(t, phi)
        return cls(spline, spline.derivative(1), spline.derivative(2), float(t[-1]), f"{t.size} samples")


class _Prescribed:
    """Module dynamics with the crank's motion given. State y = [x1, x2, v1, motor work]."""

    def __init__(self, params: RobotParams, geometry, motion: CrankMotion, clutch: str):
        self.p, self.motion, self.clutch = params, motion, clutch
        self.dyn = OneDofDynamics(params, geometry)

    def crank(self, t):
        return self.motion.phi(t), self.motion.omega(t), self.motion.alpha(t)

    def evaluate(self, t, y, mode: Mode) -> dict:
        """Velocities, accelerations, holding forces R (nan if moving) and motor torque."""
        p, a_g = self.p, self.dyn.a_g
        phi, omega, alpha = self.crank(t)
        mt = self.dyn.mass_terms(phi)
        K, dK = mt.transfer.K, mt.transfer.dK
        nan = np.nan * np.asarray(phi, dtype=float)
        if mode is Mode.CONTRACTION:
            v1, a1 = -K * omega, -(dK * omega**2 + K * alpha)
            # total momentum rate = hold - F_r1 + M11 a_g (Newton along x for the whole robot)
            R1, R2 = nan, mt.m11 * (a1 - a_g) + mt.m12 * alpha + mt.dm12 * omega**2 + p.F_r1
        elif mode is Mode.EXPANSION:
            v1, a1 = 0.0 * K, 0.0 * K
            R1, R2 = mt.m12 * alpha + mt.dm12 * omega**2 + p.F_r2 - mt.m11 * a_g, nan
        else:
            v1 = y[2]
            a1 = (-p.F_r1 - p.F_r2 + mt.m11 * a_g - mt.m12 * alpha - mt.dm12 * omega**2) / mt.m11
            R1, R2 = nan, nan
        v2, a2 = v1 + K * omega, a1 + dK * omega**2 + K * alpha
        front_external = np.where(np.isnan(R2), -p.F_r2, R2)
        torque = self.dyn.motor_torque(phi, omega, alpha, a1, front_external)
        return {"phi": phi, "omega": omega, "alpha": alpha, "v1": v1, "v2": v2, "a1": a1, "a2": a2,
                "R1": R1, "R2": R2, "torque": torque, "S": mt.transfer.S, "K": K, "dK": dK}

    def rhs(self, mode):
        def f(t, y):
            e = self.evaluate(t, y, mode)
            return [e["v1"], e["v2"], e["a1"], e["torque"] * e["omega"]]
        return f

    def events(self, mode):
        found = []
        if self.clutch == "kinematic":
            def gap_rate(t, y):
                phi, omega, _ = self.crank(t)
                return self.dyn.linkage.transfer(phi).K * omega
            gap_rate.terminal, gap_rate.direction = True, 1.0 if mode is Mode.CONTRACTION else -1.0
            return [(gap_rate, None)]
        F = (self.p.F_r1, self.p.F_r2)
        for i in (0, 1):
            if HELD[mode][i]:
                def margin(t, y, i=i):
                    return (self.evaluate(t, y, mode)["R1" if i == 0 else "R2"]) + F[i]
                margin.terminal, margin.direction = True, -1.0
                found.append((margin, ("margin", i)))
            else:
                def velocity(t, y, i=i):
                    return self.evaluate(t, y, mode)["v1" if i == 0 else "v2"]
                velocity.terminal, velocity.direction = True, -1.0
                found.append((velocity, ("velocity", i)))
        return found

    def choose(self, t, velocities, fired=None, previous=None) -> Mode:
        phi, omega, alpha = (float(v) for v in self.crank(t))
        tr = self.dyn.linkage.transfer(phi)
        if self.clutch == "kinematic":
            # the sign of S_dot, or of S_ddot = K' omega^2 + K alpha where S_dot = 0
            for value in (tr.K * omega, tr.dK * omega**2 + tr.K * alpha):
                if abs(value) > 1e-9 * self.p.r * (omega**2 + abs(alpha) + abs(omega)):
                    return Mode.CONTRACTION if value < 0 else Mode.EXPANSION
            if alpha != 0:  # at rest on a dead centre: S - S0 ~ K' (phi - phi0)^2 / 2
                return Mode.CONTRACTION if tr.dK < 0 else Mode.EXPANSION
            raise SimulationError(f"the prescribed crank rests on a dead centre at t={t:.6g} s: the paper's rule "
                                  "cannot tell which module moves")
        v_scale = self.p.r * abs(omega) + sum(abs(v) for v in velocities)
        at_rest = [abs(v) <= 1e-8 * v_scale + 1e-14 for v in velocities]
        p = self.p
        a_scale = p.r * (omega**2 + abs(alpha)) + (p.F_r1 + p.F_r2) / min(p.m1, p.m2) + abs(self.dyn.a_g) + 1e-300
        f_scale = p.F_r1 + p.F_r2 + (p.m1 + p.m2) * a_scale
        margins = {}
        for mode, held in HELD.items():
            if any(h and not z for h, z in zip(held, at_rest)):
                continue
            e = self.evaluate(t, np.array([0.0, 0.0, velocities[0], 0.0]), mode)
            tests = [((e["R1"], e["R2"])[i] + (p.F_r1, p.F_r2)[i]) / f_scale if held[i]
                     else (e["a1"], e["a2"])[i] / a_scale for i in (0, 1) if held[i] or at_rest[i]]
            margins[mode] = min(tests) if tests else math.inf
        consistent = [m for m, v in margins.items() if v >= -_TOL]
        if len(consistent) > 1 and previous in consistent and fired is not None:
            consistent.remove(previous)
        if len(consistent) > 1 and fired is not None:
            kind, i = fired
            consistent = [m for m in consistent if HELD[m][i] == (kind == "velocity")] or consistent
        if not consistent:
            raise SimulationError(f"no consistent clutch mode for the prescribed crank at t={t:.6g} s, "
                                  f"phi={phi:.6g} rad (both modules would have to be held while the crank turns)")
        return max(consistent, key=lambda m: margins[m])


def inverse_kinetostatics(params: RobotParams, motion: CrankMotion, geometry: Geometry | str = Geometry.EXACT,
                          clutch: str = "kinematic", *, dt_out: float | None = None, rtol: float = 1e-10,
                          atol: float = 1e-12, progress=None) -> RunResult:
    """Torque, clutch reactions and rod force for a prescribed crank motion.

    The run starts with both modules at rest (unless the paper's rule moves
    one with the crank). Its series has the shared columns plus
    ``motor_torque`` [N m] (and ``rod_force``, ``crank_pin_force``,
    ``motor_power``); ``params.M`` is not used. ``progress``: called with the
    simulated time reached [s] at every clutch-mode change and at the end.
    """
    if clutch not in ("kinematic", "unilateral"):
        raise ParameterError(f"clutch={clutch!r} is unknown; allowed: kinematic, unilateral")
    t_end = motion.t_end
    dt_out = dt_out or t_end / 2000
    t_end, dt_out = check_run_options(t_end, dt_out)
    rtol, atol = check_tolerances(rtol, atol)
    started = time.perf_counter()
    model = _Prescribed(params, geometry, motion, clutch)
    grid = np.linspace(0.0, t_end, max(1, math.ceil(t_end / dt_out - 1e-9)) + 1)
    phi0, omega0, _ = model.crank(0.0)
    K0 = float(model.dyn.linkage.transfer(phi0).K)
    start_velocities = (max(-K0 * omega0, 0.0), max(K0 * omega0, 0.0)) if clutch == "kinematic" else (0.0, 0.0)
    t, y = 0.0, np.array([0.0, 0.0, start_velocities[0], 0.0])
    mode = model.choose(t, start_velocities)
    pieces, short_run = [], 0
    while True:
        events = model.events(mode)
        from scipy.integrate import solve_ivp

        sol = solve_ivp(model.rhs(mode), (t, t_end), y, method="DOP853", rtol=rtol, atol=atol,
                        events=[e for e, _ in events], dense_output=True)
        if sol.status < 0:
            raise SimulationError(f"integration failed at t={sol.t[-1]:.6g} s: {sol.message}")
        times = sample_times(t, float(sol.t[-1]), grid)
        pieces.append(_piece(model, mode, times, sol.sol(times)))
        if progress is not None:
            progress(float(sol.t[-1]))
        if sol.status != 1:
            break
        hit = min((k for k in range(len(events)) if sol.t_events[k].size), key=lambda k: sol.t_events[k][0])
        short_run = short_run + 1 if sol.t[-1] - t <= 1e-12 * (1 + t) else 0
        if short_run > 50:
            raise SimulationError(f"the clutch modes chatter at t={t:.6g} s")
        t, y_event = float(sol.t_events[hit][0]), sol.y_events[hit][0]
        e = model.evaluate(t, y_event, mode)
        velocities = (float(e["v1"]), float(e["v2"]))
        mode = model.choose(t, velocities, events[hit][1], previous=mode)
        y = y_event.copy()
        y[2] = float(model.evaluate(t, y, mode)["v1"]) if mode is not Mode.BOTH_MOVING else velocities[0]
        if t >= t_end:
            break
    series = {c: np.concatenate([piece[c] for piece in pieces]) for c in pieces[0]}
    series.update(model.dyn.energy_columns(series))
    add_kinetostatics(series, model.dyn)
    energy = model.dyn.energy_audit(series)
    return RunResult(engine="analytic-inverse", geometry=model.dyn.geometry.value, clutch=clutch, params=params,
                     t_end=t_end, series=series, energy=energy, wall_time_s=time.perf_counter() - started,
                     settings={"motion": motion.description, "rtol": rtol, "atol": atol, "dt_out": dt_out})


def _piece(model: _Prescribed, mode: Mode, times, y) -> dict[str, np.ndarray]:
    e = model.evaluate(times, y, mode)
    n = times.shape
    F = (model.p.F_r1, model.p.F_r2)
    paper_lock = model.clutch == "kinematic"  # the paper's lock takes the whole hold, pulling if need be
    clutch, resistance = [], []
    for i, R in enumerate((e["R1"], e["R2"])):
        held = HELD[mode][i]
        R = np.broadcast_to(R, n)
        if not held:
            clutch.append(np.zeros(n))
            resistance.append(np.full(n, -F[i]))
        elif paper_lock:
            clutch.append(R.astype(float))
            resistance.append(np.zeros(n))
        else:
            clutch.append(np.maximum(R, 0.0))
            resistance.append(np.minimum(R, 0.0))
    as_array = lambda v: np.broadcast_to(v, n).astype(float)  # noqa: E731
    return {"t": times, "phi": as_array(e["phi"]), "omega": as_array(e["omega"]), "alpha": as_array(e["alpha"]),
            "x1": y[0], "x2": y[1], "v1": as_array(e["v1"]), "v2": as_array(e["v2"]), "a1": as_array(e["a1"]),
            "a2": as_array(e["a2"]), "S": as_array(e["S"]), "S_dot": as_array(e["K"] * e["omega"]),
            "lambda1": clutch[0], "lambda2": clutch[1], "mode": np.full(n, int(mode)),
            "resistance1": resistance[0], "resistance2": resistance[1],
            "motor_torque": as_array(e["torque"]), "motor_work": y[3]}

