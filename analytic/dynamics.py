"""Equations of motion of the robot while one module is locked (one DOF).

With the front module locked (contraction, x2_dot = 0) or the rear one locked
(expansion, x1_dot = 0), every velocity is proportional to the crank speed:
x1_dot = e(phi) * omega with e = -K in contraction and e = 0 in expansion, and
x2_dot = (e + K) * omega. Lagrange's equation in phi then reads

    J_eff(phi) * alpha + 1/2 * J_eff'(phi) * omega^2 = Q(phi)

    J_eff = J_A + m1 e^2 + m2 (e + K)^2 + m_rod ((e + a)^2 + b^2) + I_rod g^2
    Q     = M - F_r1 e - F_r2 (e + K)

where (a, b, g) are the rod's velocity coefficients (see
:class:`ipir_mujoco.analytic.kinematics.RodMotion`). With the first-order geometry the rod
is ignored, as in the paper, and this is exactly the paper's (20)-(22):
J_eff = J_A + m K^2, and 1/2 J_eff' = m K K'.

Kinetostatics: the only external forces along x are the resistance of the
moving module and the reaction of the locked clutch, so that reaction is the
rate of change of the total momentum p = P(phi) * omega plus the resistance:
lambda_locked = P' omega^2 + P alpha + F_moving.

All methods are vectorized: ``phi`` and ``omega`` may be floats or ndarrays of
one shape; results have that shape. Units: rad, rad/s, m, kg, N, J.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from .kinematics import Geometry, Linkage, Transfer
from .params import RobotParams
from .results import Mode


class ModeState(NamedTuple):
    """Everything the state (phi, omega) implies in one mode; arrays of one shape."""

    alpha: np.ndarray  # crank angular acceleration [rad/s^2]
    S: np.ndarray  # gap [m]
    S_dot: np.ndarray  # gap rate [m/s]
    v1: np.ndarray  # module velocities [m/s]
    v2: np.ndarray
    a1: np.ndarray  # module accelerations [m/s^2]
    a2: np.ndarray
    lambda1: np.ndarray  # clutch reactions, + pushes forward [N]
    lambda2: np.ndarray
    kinetic: np.ndarray  # kinetic energy [J]


class MassTerms(NamedTuple):
    """Mass matrix entries in the coordinates (x1, phi) and their phi-derivatives."""

    m11: np.ndarray  # total translating mass [kg]
    m12: np.ndarray  # [kg m/rad]
    m22: np.ndarray  # [kg m^2]
    dm12: np.ndarray  # dM12/dphi (M11 is constant)
    dm22: np.ndarray  # dM22/dphi
    transfer: Transfer


class OneDofDynamics:
    """The robot with one clutch locked, in a given geometry.

    ``include_rod`` (default: only for the exact geometry, where the rod is a
    rigid body of length L) adds the rod's mass and inertia.
    """

    def __init__(self, params: RobotParams, geometry: Geometry | str, include_rod: bool | None = None):
        self.params = params
        self.geometry = Geometry(geometry)
        self.linkage = Linkage(params.r, params.L, self.geometry)
        if include_rod is None:
            include_rod = self.geometry is Geometry.EXACT
        if include_rod and self.geometry is not Geometry.EXACT:
            raise ValueError("rod mass needs the exact geometry; the first-order model has no rigid rod")
        self.include_rod = include_rod and (params.rod_mass > 0 or params.rod_inertia_value > 0)

    def mass_terms(self, phi) -> MassTerms:
        """The 2x2 mass matrix in (x1, phi) and its derivatives in phi.

        T = 1/2 [x1_dot, omega] M [x1_dot, omega]^T with
        M11 = m1 + m2 + m_rod, M12 = m2 K + m_rod a,
        M22 = J_A + m2 K^2 + m_rod (a^2 + b^2) + I_rod g^2.
        """
        p = self.params
        tr = self.linkage.transfer(phi)
        K, dK = tr.K, tr.dK
        m11 = p.m1 + p.m2 + 0.0 * K
        m12, dm12 = p.m2 * K, p.m2 * dK
        m22, dm22 = p.J_A + p.m2 * K**2, 2.0 * p.m2 * K * dK
        if self.include_rod:
            rod = self.linkage.rod_motion(phi)
            m, inertia = p.rod_mass, p.rod_inertia_value
            m11 = m11 + m
            m12, dm12 = m12 + m * rod.a, dm12 + m * rod.da
            m22 = m22 + m * (rod.a**2 + rod.b**2) + inertia * rod.g**2
            dm22 = dm22 + 2.0 * (m * (rod.a * rod.da + rod.b * rod.db) + inertia * rod.g * rod.dg)
        return MassTerms(m11, m12, m22, dm12, dm22, tr)

    def _terms(self, phi, mode: Mode, M=None):
        """J_eff, dJ_eff/dphi, Q, P, dP/dphi, e, de, f, df and the transfer.

        With x1_dot = e omega the locked-module system has J_eff = [e, 1] M [e, 1]^T
        and total momentum P omega with P = M11 e + M12.
        """
        p = self.params
        mt = self.mass_terms(phi)
        K, dK = mt.transfer.K, mt.transfer.dK
        if mode is Mode.CONTRACTION:
            e, de = -K, -dK
        elif mode is Mode.EXPANSION:
            e, de = 0.0 * K, 0.0 * dK
        else:
            raise ValueError(f"one-DOF dynamics needs a single locked module, got mode {mode.name}")
        f, df = e + K, de + dK  # front-module velocity coefficient and its derivative
        J = mt.m11 * e**2 + 2.0 * mt.m12 * e + mt.m22
        dJ = 2.0 * mt.m11 * e * de + 2.0 * (mt.dm12 * e + mt.m12 * de) + mt.dm22
        P = mt.m11 * e + mt.m12
        dP = mt.m11 * de + mt.dm12
        Q = (p.M if M is None else M) - p.F_r1 * e - p.F_r2 * f
        return J, dJ, Q, P, dP, e, de, f, df, mt.transfer

    def both_moving(self, phi, omega, M=None):
        """(x1_ddot [m/s^2], alpha [rad/s^2]) with both modules sliding forward against F_r1, F_r2.

        M [x1_ddot, alpha]^T + [M12' omega^2, 1/2 M22' omega^2]^T = [-F_r1 - F_r2, M - F_r2 K]^T.
        """
        p = self.params
        mt = self.mass_terms(phi)
        rhs1 = -p.F_r1 - p.F_r2 - mt.dm12 * omega**2
        rhs2 = (p.M if M is None else M) - p.F_r2 * mt.transfer.K - 0.5 * mt.dm22 * omega**2
        det = mt.m11 * mt.m22 - mt.m12**2
        return (mt.m22 * rhs1 - mt.m12 * rhs2) / det, (mt.m11 * rhs2 - mt.m12 * rhs1) / det

    def acceleration(self, phi, omega, mode: Mode, M=None):
        """Crank angular acceleration alpha [rad/s^2] in ``mode``; ``M`` [N m] overrides params.M."""
        J, dJ, Q, *_ = self._terms(phi, mode, M)
        return (Q - 0.5 * dJ * omega**2) / J

    def state(self, phi, omega, mode: Mode, M=None) -> ModeState:
        """Accelerations, module velocities, reactions and energy in ``mode`` (``M`` overrides params.M)."""
        J, dJ, Q, P, dP, e, de, f, df, tr = self._terms(phi, mode, M)
        alpha = (Q - 0.5 * dJ * omega**2) / J
        momentum_rate = dP * omega**2 + P * alpha
        zero = 0.0 * alpha
        if mode is Mode.CONTRACTION:
            lambda1, lambda2 = zero, momentum_rate + self.params.F_r1
        else:
            lambda1, lambda2 = momentum_rate + self.params.F_r2, zero
        return ModeState(
            alpha=alpha,
            S=tr.S,
            S_dot=tr.K * omega,
            v1=e * omega,
            v2=f * omega,
            a1=de * omega**2 + e * alpha,
            a2=df * omega**2 + f * alpha,
            lambda1=lambda1,
            lambda2=lambda2,
            kinetic=0.5 * J * omega**2,
        )

    def kinetic_energy(self, phi, v1, omega):
        """Kinetic energy [J] at crank angle phi with module-1 speed v1 and crank speed omega, any mode."""
        mt = self.mass_terms(phi)
        return 0.5 * (mt.m11 * v1**2 + 2.0 * mt.m12 * v1 * omega + mt.m22 * omega**2)

    def energy_audit(self, series: dict, motor_work: float) -> dict[str, float]:
        """Motor work = kinetic energy gained + friction work + residual [J] over a run's series.

        Modules only move forward (or, in the free mechanism, feel no resistance),
        so the work against the constant resistances is F_r times the displacements.
        """
        p = self.params
        phi, v1, omega = series["phi"], series["v1"], series["omega"]
        gained = float(self.kinetic_energy(phi[-1], v1[-1], omega[-1]) - self.kinetic_energy(phi[0], v1[0], omega[0]))
        friction = float(p.F_r1 * series["x1"][-1] + p.F_r2 * series["x2"][-1])
        return {"motor_work_j": float(motor_work), "kinetic_j": gained, "friction_j": friction,
                "residual_j": float(motor_work - gained - friction)}

    def motor_torque(self, phi, omega, alpha, a1, front_external):
        """Torque [N m] the motor must apply for crank motion (omega, alpha) and module-1 acceleration a1.

        The phi-row of the two-DOF equations: M = M12 a1 + M22 alpha + 1/2 M22' omega^2 - K H2,
        with H2 [N] the external force on module 2 (its hold, or -F_r2 while it moves).
        """
        mt = self.mass_terms(phi)
        return mt.m12 * a1 + mt.m22 * alpha + 0.5 * mt.dm22 * omega**2 - mt.transfer.K * front_external

    def static_push(self, phi, M=None):
        """Force [N] with which the linkage, crank at rest, pushes module 2 forward (and module 1 back).

        Virtual work on the massless-at-rest linkage: M dphi = P dS, so P = M / K;
        at a dead centre (K = 0) the torque loads neither module.
        """
        K = self.linkage.transfer(phi).K
        M = self.params.M if M is None else M
        with np.errstate(divide="ignore", invalid="ignore"):
            return np.where(K != 0, M / np.where(K != 0, K, 1.0), 0.0)

    def stalled_reactions(self, phi):
        """Clutch reactions holding a robot at rest with both modules locked [N].

        The linkage pushes module 2 with P = M / K and pulls module 1 with -P
        (:meth:`static_push`). The module pulled backward is held by its clutch
        (reaction |P|); the one pushed forward by its static resistance (a stall
        means |P| <= F_r), so its clutch carries nothing.
        """
        push = self.static_push(phi)
        return np.maximum(push, 0.0), np.maximum(-push, 0.0)
