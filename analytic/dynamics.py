"""Equations of motion of the robot while one module is locked (one DOF).

With the front module locked (contraction, x2_dot = 0) or the rear one locked
(expansion, x1_dot = 0), every velocity is proportional to the crank speed:
x1_dot = e(phi) * omega with e = -K in contraction and e = 0 in expansion, and
x2_dot = (e + K) * omega. Lagrange's equation in phi then reads

    J_eff(phi) * alpha + 1/2 * J_eff'(phi) * omega^2 = Q(phi)

    J_eff = J_A + m1 e^2 + m2 (e + K)^2 + m_rod ((e + a)^2 + b^2) + I_rod g^2
    Q     = M - F_r1 e - F_r2 (e + K)

where (a, b, g) are the rod's velocity coefficients (see
:class:`analytic.kinematics.RodMotion`). With the first-order geometry the rod
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

from .kinematics import Geometry, Linkage
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

    def _terms(self, phi, mode: Mode):
        """J_eff, dJ_eff/dphi, Q, P, dP/dphi and the transfer (S, K, dK)."""
        p = self.params
        tr = self.linkage.transfer(phi)
        K, dK = tr.K, tr.dK
        if mode is Mode.CONTRACTION:
            e, de = -K, -dK
        elif mode is Mode.EXPANSION:
            e, de = 0.0 * K, 0.0 * dK
        else:
            raise ValueError(f"one-DOF dynamics needs a single locked module, got mode {mode.name}")
        f, df = e + K, de + dK  # front-module velocity coefficient and its derivative
        J = p.J_A + p.m1 * e**2 + p.m2 * f**2
        dJ = 2.0 * (p.m1 * e * de + p.m2 * f * df)
        P = p.m1 * e + p.m2 * f
        dP = p.m1 * de + p.m2 * df
        if self.include_rod:
            rod = self.linkage.rod_motion(phi)
            m, inertia = p.rod_mass, p.rod_inertia_value
            gx, dgx = e + rod.a, de + rod.da
            J = J + m * (gx**2 + rod.b**2) + inertia * rod.g**2
            dJ = dJ + 2.0 * (m * (gx * dgx + rod.b * rod.db) + inertia * rod.g * rod.dg)
            P = P + m * gx
            dP = dP + m * dgx
        Q = p.M - p.F_r1 * e - p.F_r2 * f
        return J, dJ, Q, P, dP, e, de, f, df, tr

    def acceleration(self, phi, omega, mode: Mode):
        """Crank angular acceleration alpha [rad/s^2] in ``mode``."""
        J, dJ, Q, *_ = self._terms(phi, mode)
        return (Q - 0.5 * dJ * omega**2) / J

    def state(self, phi, omega, mode: Mode) -> ModeState:
        """Accelerations, module velocities, reactions and energy in ``mode``."""
        J, dJ, Q, P, dP, e, de, f, df, tr = self._terms(phi, mode)
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

    def stalled_reactions(self, phi):
        """Clutch reactions holding a robot at rest with both modules locked [N].

        The linkage pushes module 2 with P = M / K and pulls module 1 with -P.
        The module pulled backward is held by its clutch (reaction |P|); the one
        pushed forward by its static resistance (a stall means |P| <= F_r), so
        its clutch carries nothing. At a dead centre with M = 0 nothing loads
        either clutch.
        """
        K = self.linkage.transfer(phi).K
        with np.errstate(divide="ignore", invalid="ignore"):
            push = np.where(K != 0, self.params.M / np.where(K != 0, K, 1.0), 0.0)
        return np.maximum(push, 0.0), np.maximum(-push, 0.0)
