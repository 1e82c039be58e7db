"""Equations of motion of the robot while one module is locked (one DOF).

With the front module locked (contraction, x2_dot = 0) or the rear one locked
(expansion, x1_dot = 0), every velocity is proportional to the crank speed:
x1_dot = e(phi) * omega with e = -K in contraction and e = 0 in expansion, and
x2_dot = (e + K) * omega. Lagrange's equation in phi then reads

    J_eff(phi) * alpha + 1/2 * J_eff'(phi) * omega^2 = Q(phi, omega)

    J_eff = J_A + m1 e^2 + m2 (e + K)^2 + m_rod ((e + a)^2 + b^2) + I_rod g^2
    Q     = M(omega) - F_r1 e - F_r2 (e + K) + a_g P

with M(omega) the drive's torque (:func:`.forces.drive_torque`) and a_g the
acceleration gravity gives every body along the pipe
(:func:`.forces.gravity_along_pipe`). Gravity along x is a uniform field, so
its generalized force is a_g times the first column of the mass matrix in
(x1, phi): a_g [M11, M12]; with x1_dot = e omega that is a_g P (P below, the
momentum coefficient). The crank is balanced: gravity loads only its bearing.

where (a, b, g) are the rod's velocity coefficients (see
:class:`ipir_mujoco.analytic.kinematics.RodMotion`). With the first-order geometry the rod
is ignored, as in the paper, and this is exactly the paper's (20)-(22):
J_eff = J_A + m K^2, and 1/2 J_eff' = m K K'.

Kinetostatics: the external forces along x are the resistance of the moving
module, gravity on the whole robot (M11 a_g) and the reaction of the locked
clutch, so that reaction is the rate of change of the total momentum
p = P(phi) * omega plus the resistance, less gravity:
lambda_locked = P' omega^2 + P alpha + F_moving - M11 a_g.

All methods are vectorized: ``phi`` and ``omega`` may be floats or ndarrays of
one shape; results have that shape. Units: rad, rad/s, m, kg, N, J.
"""

from __future__ import annotations

import copy
from typing import NamedTuple

import numpy as np

from ipir_mujoco.core import energy
from ipir_mujoco.core.params import RobotParams
from ipir_mujoco.core.results import Mode

from .forces import drive_torque, gravity_along_pipe
from .kinematics import Geometry, Linkage, Transfer


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
        self.a_g = gravity_along_pipe(params)  # [m/s^2], + forward (downhill)
        # [N] the backward force on each module while it moves: its resistance F_ri (rolling forward); a
        # module skidding back on locked wheels has -G_i here (its grip pushes it forward, see with_resistance)
        self.resistance = (params.F_r1, params.F_r2)

    def with_resistance(self, resistance: tuple[float, float]) -> "OneDofDynamics":
        """The same robot (sharing its linkage) with ``resistance`` (R1, R2) [N], the backward force on each
        module while it moves, in place of (F_r1, F_r2): -G_i for a module skidding back with grip G_i."""
        other = copy.copy(self)
        other.resistance = (float(resistance[0]), float(resistance[1]))
        return other

    def torque(self, omega, M=None):
        """The crank torque [N m]: ``M`` if given, else the drive's torque at crank speed ``omega``."""
        return drive_torque(self.params, omega) if M is None else M

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

    def _terms(self, phi, omega, mode: Mode, M=None):
        """J_eff, dJ_eff/dphi, Q, P, dP/dphi, e, de, f, df, M11 and the transfer.

        With x1_dot = e omega the locked-module system has J_eff = [e, 1] M [e, 1]^T
        and total momentum P omega with P = M11 e + M12.
        """
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
        F1, F2 = self.resistance
        Q = self.torque(omega, M) - F1 * e - F2 * f + self.a_g * P
        return J, dJ, Q, P, dP, e, de, f, df, mt.m11, mt.transfer

    def both_moving(self, phi, omega, M=None):
        """(x1_ddot [m/s^2], alpha [rad/s^2]) with both modules sliding forward against F_r1, F_r2.

        M [x1_ddot, alpha]^T + [M12' omega^2, 1/2 M22' omega^2]^T
            = [-F_r1 - F_r2 + M11 a_g, M - F_r2 K + M12 a_g]^T.
        """
        F1, F2 = self.resistance
        mt = self.mass_terms(phi)
        rhs1 = -F1 - F2 + mt.m11 * self.a_g - mt.dm12 * omega**2
        rhs2 = self.torque(omega, M) - F2 * mt.transfer.K + mt.m12 * self.a_g - 0.5 * mt.dm22 * omega**2
        det = mt.m11 * mt.m22 - mt.m12**2
        return (mt.m22 * rhs1 - mt.m12 * rhs2) / det, (mt.m11 * rhs2 - mt.m12 * rhs1) / det

    def acceleration(self, phi, omega, mode: Mode, M=None):
        """Crank angular acceleration alpha [rad/s^2] in ``mode``; ``M`` [N m] overrides the drive's torque."""
        J, dJ, Q, *_ = self._terms(phi, omega, mode, M)
        return (Q - 0.5 * dJ * omega**2) / J

    def state(self, phi, omega, mode: Mode, M=None) -> ModeState:
        """Accelerations, module velocities, reactions and energy in ``mode`` (``M`` overrides the drive)."""
        J, dJ, Q, P, dP, e, de, f, df, m11, tr = self._terms(phi, omega, mode, M)
        alpha = (Q - 0.5 * dJ * omega**2) / J
        hold = dP * omega**2 + P * alpha - m11 * self.a_g  # momentum rate less gravity on the robot
        zero = 0.0 * alpha
        if mode is Mode.CONTRACTION:
            lambda1, lambda2 = zero, hold + self.resistance[0]
        else:
            lambda1, lambda2 = hold + self.resistance[1], zero
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

    def potential_energy(self, phi, x1, x2):
        """Gravitational potential energy [J], up to a constant: -a_g (m1 x1 + m2 x2 + m_rod G_x).

        G_x = x1 + (the rod centre's x relative to A); the rod counts only where it is
        modelled. dV/dx1 = -a_g M11 and dV/dphi = -a_g M12: the generalized gravity forces
        above. Zero in a horizontal pipe.
        """
        p = self.params
        moment = p.m1 * x1 + p.m2 * x2
        if self.include_rod:
            moment = moment + p.rod_mass * (x1 + self.linkage.rod_com(phi)[0])
        return -self.a_g * moment

    def energy_columns(self, series: dict) -> dict[str, np.ndarray]:
        """The cumulative energy columns [J] of a run's series: kinetic, potential, friction_work.

        Needs phi, omega, v1, x1, x2 (x_i from 0 at t = 0). ``potential`` is relative to t = 0.
        ``friction_work`` = F_r1 x1 + F_r2 x2 is exact, not an approximation of the integral of
        F_r1 |v1| + F_r2 |v2|: with rigid clutches (the paper's locks or one-way clutches) a module
        never moves backward, so |v_i| = v_i and the integral is F_ri times the displacement.
        """
        p = self.params
        phi, x1, x2 = series["phi"], series["x1"], series["x2"]
        potential = self.potential_energy(phi, x1, x2)
        return {"kinetic": self.kinetic_energy(phi, series["v1"], series["omega"]),
                "potential": potential - potential[0],
                "friction_work": p.F_r1 * x1 + p.F_r2 * x2}

    def energy_audit(self, series: dict, motor_work: float | None = None) -> dict[str, float]:
        """The run's energy audit [J] ({audit key: J}, :func:`ipir_mujoco.core.energy.audit`): motor work = kinetic
        + potential energy gained + friction work (+ every other term of the table whose column the series has:
        clutch springs and dampers, skid) + residual.

        Reads the columns ``kinetic``, ``potential``, ``friction_work`` (computed with
        :meth:`energy_columns` where absent) and ``motor_work`` unless ``motor_work`` is given.
        """
        columns = {t.column: series[t.column] for t in energy.ENERGY_TERMS if t.column in series}
        if not all(c in columns for c in ("kinetic", "potential", "friction_work")):
            ends = {c: np.asarray(series[c])[[0, -1]] for c in ("phi", "omega", "v1", "x1", "x2")}
            columns.update(self.energy_columns(ends))
        if motor_work is not None:
            columns["motor_work"] = np.array([0.0, float(motor_work)])
        return energy.audit(columns)

    def motor_torque(self, phi, omega, alpha, a1, front_external):
        """Torque [N m] the motor must apply for crank motion (omega, alpha) and module-1 acceleration a1.

        The phi-row of the two-DOF equations:
        M = M12 a1 + M22 alpha + 1/2 M22' omega^2 - K H2 - M12 a_g,
        with H2 [N] the external force on module 2 but gravity (its hold, or -F_r2 while it moves).
        """
        mt = self.mass_terms(phi)
        return (mt.m12 * (a1 - self.a_g) + mt.m22 * alpha + 0.5 * mt.dm22 * omega**2
                - mt.transfer.K * front_external)

    def static_push(self, phi, M=None):
        """Force [N] with which the linkage, crank at rest, pushes module 2 forward (and module 1 back).

        Virtual work on the linkage: M dphi = P dS, so P = M / K, with M the drive's
        torque at rest unless given; at a dead centre (K = 0) the torque loads neither module.
        """
        K = self.linkage.transfer(phi).K
        M = self.torque(0.0, M)
        with np.errstate(divide="ignore", invalid="ignore", over="ignore"):  # K ~ 1e-308: inf, no hold
            return np.where(K != 0, M / np.where(K != 0, K, 1.0), 0.0)

    def static_holds(self, phi, M=None):
        """(R1, R2) [N]: the forces that hold each module of a robot at rest, + forward.

        Each is its clutch's and its resistance's together. Statics in (x1, phi) with
        omega = 0: x1-row R1 + R2 + M11 a_g = 0, phi-row M + K R2 + M12 a_g = 0, so
        R2 = -M / K - a_g M12 / K and R1 = -M11 a_g - R2. M12 / K = m2 + m_rod dG_x/dS stays
        finite at a dead centre (dG_x/dS = (1 + D / S) / 2 in the exact geometry, D the rod's
        projection on x), where the rod's weight splits between the pins as in the limit.
        """
        p = self.params
        push = self.static_push(phi, M)
        on_front = np.full(np.shape(push), p.m2)  # mass whose weight module 2's hold carries at rest
        if self.include_rod:
            tr = self.linkage.transfer(phi)
            projection = tr.S - p.r * np.cos(phi)  # D = sqrt(L^2 - r^2 sin^2 phi)
            on_front = on_front + p.rod_mass * 0.5 * (1.0 + projection / tr.S)
        total = self.mass_terms(phi).m11
        R2 = -push - self.a_g * on_front
        return -total * self.a_g - R2, R2

    def stalled_reactions(self, phi):
        """Clutch reactions and resistance forces holding a robot at rest (both locked) [N].

        Returns (lambda1, lambda2, resistance1, resistance2). Each module's hold R_i
        (:meth:`static_holds`) is split as in every clutch model: a clutch only
        pushes, so a hold pulling backward (R_i < 0) is the static resistance's, up to
        F_ri; beyond that (only possible under the paper's bilateral locks) the lock pulls.
        """
        holds = self.static_holds(phi)
        out = []
        for R, F in zip(holds, (self.params.F_r1, self.params.F_r2)):
            resistance = np.maximum(np.minimum(R, 0.0), -F)
            out.append((R - resistance, resistance))
        return out[0][0], out[1][0], out[0][1], out[1][1]
