"""The robot's speed controller (``drive = servo``): software both engines run, not physics.

The motor is each engine's own (MuJoCo: the crank actuator, gain M_stall, bias -M_stall / omega_noload *
omega, ctrl = u; the equations: :func:`ipir_mujoco.analytic.forces.drive_torque`): at a voltage fraction
u in [-1, 1] its torque is M_stall (u - omega / omega_noload), so the torque can never leave the band the
motor allows. This module decides u. It ticks at ``control_rate`` [Hz], at t_k = k / control_rate
(k = 0, 1, ...), reads the crank angle phi [rad] and speed omega [rad/s] there, and holds its u until the
next tick (a zero-order hold, as a microcontroller's PWM does):

    e = omega_ref(phi) - omega
    u = clip(u_ff(phi) + kp e + ki I, -1, 1)
    u_ff(phi) = tau_ff(phi) / M_stall + omega_ref(phi) / omega_noload     (0 without feedforward)

``omega_ref(phi)`` [rad/s] is omega_target, or with ``speed_dip`` = a > 0 a profile that slows through the
dead centres (phi = 0, pi, where the modules hand over) and makes up mid-stroke,
omega_ref = omega_0 (1 - a cos 2 phi), with omega_0 = omega_target / sqrt(1 - a^2) so that its mean crank
speed, 2 pi over the revolution's time (the integral of dphi / omega_ref), is omega_target.
``tau_ff(phi)`` [N m] is the torque a chosen model says a crank following omega_ref exactly needs at
angle phi (:class:`FeedforwardTable`, computed above the engines from the package's inverse kinetostatics:
``ipir_mujoco.registry.feedforward_table``), and omega_target / omega_noload the voltage that cancels the
motor's back-EMF at that speed. I is the integrated error, with anti-windup by conditional integration: a
tick whose u is clipped does not integrate an error that would push u further into the clip.

Default gains (:func:`default_gains`): the crank's speed as a first-order plant J_ref omega_dot =
M_stall (u - omega / omega_noload) + load, with J_ref = J_A + (m1 + m2) r^2 / 4 + rod_mass r^2 / 2
(the crank's inertia plus the moving module's mean m K^2 over a revolution, K^2 averaging r^2 / 2 in the
first order, the modules taking turns; the rod's end at the pin adds its mass there, half of it).
PI on it gives J_ref s^2 + M_stall (kp + 1 / omega_noload) s + M_stall ki = 0; both roots at -omega_c
(critical damping) give

    ki = J_ref omega_c^2 / M_stall,    kp = 2 J_ref omega_c / M_stall - 1 / omega_noload  (at least 0)

with the closed-loop bandwidth omega_c = 2 pi control_rate / BANDWIDTH_SHARE: a twentieth of the tick
rate, where the hold's half-period delay costs 9 degrees of phase.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .errors import ParameterError
from .params import RobotParams

BANDWIDTH_SHARE = 20.0  # the tick rate (rad/s) over the closed loop's bandwidth omega_c
TABLE_POINTS = 720  # crank angles of a feedforward table (every half degree)


@dataclass(frozen=True)
class FeedforwardTable:
    """The torque tau_ff [N m] a crank following the speed target needs, at TABLE_POINTS equally spaced crank
    angles ``phi0 + 2 pi j / n`` (j = 0..n-1, ``torque`` shape (n,)), periodic in phi; ``model`` says whose
    ('paper' | 'exact'), ``omega`` [rad/s] and ``dip`` which target (:func:`reference_speed`)."""

    phi0: float
    torque: tuple[float, ...]
    model: str
    omega: float
    dip: float = 0.0

    def __post_init__(self) -> None:
        if len(self.torque) < 4 or not all(math.isfinite(v) for v in self.torque):
            raise ParameterError(f"a feedforward table needs at least 4 finite torques, got {len(self.torque)}")

    @classmethod
    def from_samples(cls, phi, torque, model: str, omega: float, dip: float = 0.0,
                     points: int = TABLE_POINTS) -> "FeedforwardTable":
        """The table from one revolution's samples (phi (n,) ascending over 2 pi [rad], torque (n,) [N m]),
        resampled linearly onto ``points`` equally spaced angles from phi[0]."""
        phi, torque = np.asarray(phi, dtype=float), np.asarray(torque, dtype=float)
        keep = np.concatenate([np.diff(phi) > 0, [True]])  # of duplicated instants, the later sample
        phi, torque = phi[keep], torque[keep]
        grid = phi[0] + 2 * math.pi * np.arange(points) / points
        return cls(float(phi[0]), tuple(float(v) for v in np.interp(grid, phi, torque)), model, float(omega),
                   float(dip))

    def at(self, phi: float) -> float:
        """tau_ff [N m] at crank angle ``phi`` [rad] (linear between table angles, periodic)."""
        n = len(self.torque)
        x = ((phi - self.phi0) / (2 * math.pi) % 1.0) * n
        j = int(x)
        w = x - j
        return (1.0 - w) * self.torque[j % n] + w * self.torque[(j + 1) % n]


def reference_speed(omega_target: float, dip: float, phi):
    """omega_ref(phi) [rad/s] (float or ndarray like phi [rad]): omega_target, or with ``dip`` = a > 0
    omega_0 (1 - a cos 2 phi), omega_0 = omega_target / sqrt(1 - a^2) (the module docstring)."""
    if dip == 0.0:
        return omega_target + 0.0 * phi
    return omega_target / math.sqrt(1.0 - dip * dip) * (1.0 - dip * np.cos(2.0 * phi))


def reference_motion(omega_target: float, dip: float, phi0: float, revolutions: int, points: int = 4000):
    """(t (n,) [s], phi (n,) [rad]): the crank following omega_ref from phi0 for ``revolutions`` turns, t = the
    integral of dphi / omega_ref (closed form: omega_0 sqrt(1 - a^2) t = atan(sqrt((1 + a) / (1 - a)) tan
    phi), unwrapped), ``points`` samples per revolution."""
    phi = phi0 + 2 * math.pi * np.arange(revolutions * points + 1) / points
    if dip == 0.0:
        return (phi - phi0) / omega_target, phi
    k = math.sqrt((1 + dip) / (1 - dip))

    def clock(angle):  # omega_target t(angle) from angle 0, continuous: atan's branch plus a half turn per pi
        turns = np.floor(angle / math.pi + 0.5)
        return np.arctan(k * np.tan(angle - turns * math.pi)) + turns * math.pi
    return (clock(phi) - clock(np.array(phi0))) / omega_target, phi


def reference_inertia(params: RobotParams) -> float:
    """J_ref [kg m^2]: the crank's inertia plus its mean share of the linkage's (module docstring)."""
    r2 = params.r * params.r
    return params.J_A + 0.25 * (params.m1 + params.m2) * r2 + 0.5 * params.rod_mass * r2


def default_gains(params: RobotParams) -> tuple[float, float]:
    """(kp [s/rad], ki [1/rad]) from the model: both closed-loop poles at -omega_c (module docstring)."""
    omega_c = 2 * math.pi * params.control_rate / BANDWIDTH_SHARE
    J = reference_inertia(params)
    ki = J * omega_c * omega_c / params.M_stall
    kp = max(2.0 * J * omega_c / params.M_stall - 1.0 / params.omega_noload, 0.0)
    return kp, ki


def gains(params: RobotParams) -> tuple[float, float]:
    """(kp, ki) in use: the parameters' where given, else :func:`default_gains`."""
    kp, ki = default_gains(params)
    return (kp if params.speed_kp is None else params.speed_kp), (ki if params.speed_ki is None else params.speed_ki)


class SpeedController:
    """One run's speed controller (it keeps state: make one per run).

    ``table``: the feedforward (:class:`FeedforwardTable`), required unless ``params.feedforward`` is
    'none'. :meth:`tick` at each tick time (:attr:`period` [s] apart, from t = 0) returns u; ``ticks`` is
    the number taken, ``next_tick`` [s] the time of the next.
    """

    def __init__(self, params: RobotParams, table: FeedforwardTable | None = None):
        if params.drive != "servo":
            raise ParameterError(f"a speed controller needs drive='servo', not drive={params.drive!r}")
        if params.feedforward == "none":
            if table is not None:
                raise ParameterError("a feedforward table with feedforward='none'; allowed: no table, or "
                                     "feedforward='paper' or 'exact'")
        else:
            if not isinstance(table, FeedforwardTable) or table.model != params.feedforward:
                raise ParameterError(f"feedforward={params.feedforward!r} needs its table (a FeedforwardTable of "
                                     f"that model); run through ipir_mujoco.registry.run, which computes it")
            if not (math.isclose(table.omega, params.omega_target, rel_tol=1e-12) and table.dip == params.speed_dip):
                raise ParameterError(f"the feedforward table is for {table.omega:g} rad/s and speed_dip "
                                     f"{table.dip:g}, not omega_target={params.omega_target:g} rad/s and speed_dip "
                                     f"{params.speed_dip:g}")
        self.table = table
        self.target, self.dip = params.omega_target, params.speed_dip
        self.kp, self.ki = gains(params)
        self.m_stall, self.omega_noload = params.M_stall, params.omega_noload
        self.with_ff = table is not None
        self.period = 1.0 / params.control_rate
        self.integral = 0.0  # rad
        self.ticks = 0
        self.u = 0.0

    @property
    def next_tick(self) -> float:
        """Time [s] of the next tick."""
        return self.ticks * self.period

    def tick(self, phi: float, omega: float) -> float:
        """u in [-1, 1] from the crank angle phi [rad] and speed omega [rad/s] at this tick; held to the next."""
        reference = self.target if self.dip == 0.0 else float(reference_speed(self.target, self.dip, phi))
        error = reference - omega
        ff = reference / self.omega_noload + self.table.at(phi) / self.m_stall if self.with_ff else 0.0
        trial = ff + self.kp * error + self.ki * (self.integral + error * self.period)
        if -1.0 <= trial <= 1.0 or (trial > 1.0) != (error > 0.0):  # anti-windup: no integration into the clip
            self.integral += error * self.period
        raw = ff + self.kp * error + self.ki * self.integral
        self.u = min(1.0, max(-1.0, raw))
        self.ticks += 1
        return self.u


def tick_step(k: int, period: float, dt: float) -> int:
    """The step (of ``dt`` [s]) at whose start a fixed-step engine applies tick k (at k ``period`` [s]): the
    first step boundary at or after the tick time (the tick itself where the step divides the period)."""
    return math.ceil(k * period / dt - 1e-9)
