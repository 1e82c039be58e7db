"""Scalar right-hand sides and event functions of the rigid-clutch models, for the compiled stepper.

The same equations as :mod:`.kinematics`, :mod:`.dynamics` and :mod:`.forces`
(the reference, vectorized over samples, and what the output columns are
computed with), written once more on floats with :mod:`math` so that an
integration step pays no numpy overhead and the stepper (:mod:`.dop853`) can
be compiled (:mod:`.accel`). The test suite holds the two to roundoff
(``tests/test_fast_kernels.py``), and through them to the symbolic derivation.

A model's constants travel as one float array ``p`` (:func:`pack`, the
``P_*`` indices below). Models: :data:`KINEMATIC` (the paper's rule; state
[phi, omega, x1, x2, motor work]; one event, S_dot = K omega) and
:data:`UNILATERAL` (one-way clutches; state [phi, omega, x1, x2, v1, motor
work]; event k of a mode watches module k: its velocity while it moves, its
hold margin R_k + F_rk while held). Modes are :class:`.results.Mode` values.
Units: rad, rad/s, m, m/s, kg, N, N m, J.
"""

from __future__ import annotations

import math

import numpy as np

from .accel import jit
from .dynamics import OneDofDynamics
from .forces import gravity_along_pipe

KINEMATIC, UNILATERAL = 0, 1
CONTRACTION, EXPANSION, BOTH_MOVING = 1, 2, 3  # Mode values (BOTH_LOCKED is never integrated)
(P_M1, P_M2, P_R, P_L, P_JA, P_FR1, P_FR2, P_M, P_ROD_M, P_ROD_I, P_EXACT, P_ROD, P_MOTOR, P_MSTALL, P_WNL,
 P_AG) = range(16)
TINY = float(np.finfo(float).tiny)  # what a quiet guard reads at least (see unilateral_clutch.events)


def pack(dyn: OneDofDynamics) -> np.ndarray:
    """The constants of ``dyn`` (its parameters, geometry, rod and drive) as the kernels' float array (16,)."""
    p = dyn.params
    motor = p.drive == "motor"
    return np.array([p.m1, p.m2, p.r, p.L, p.J_A, p.F_r1, p.F_r2, p.M, p.rod_mass, p.rod_inertia_value,
                     float(dyn.geometry.value == "exact"), float(dyn.include_rod), float(motor),
                     p.M_stall if motor else 0.0, p.omega_noload if motor else 1.0, gravity_along_pipe(p)],
                    dtype=float)


@jit
def drive_torque(p, omega):
    """The drive's torque [N m] at crank speed omega (:func:`.forces.drive_torque`)."""
    if p[P_MOTOR] != 0.0:
        return p[P_MSTALL] * (1.0 - omega / p[P_WNL])
    return p[P_M]


@jit
def mass_terms(p, phi):
    """(M11, M12, M22, dM12, dM22, K, dK) at crank angle phi (:meth:`.OneDofDynamics.mass_terms`)."""
    r, L = p[P_R], p[P_L]
    s, c = math.sin(phi), math.cos(phi)
    m2 = p[P_M2]
    D = L  # the rod's projection on x (exact geometry)
    if p[P_EXACT] == 0.0:
        K, dK = -r * s, -r * c
    else:
        D = math.sqrt(L * L - (r * s) * (r * s))
        K = -r * s - r * r * s * c / D
        dK = -r * c - r * r * (c * c - s * s) / D - r * r * r * r * s * s * c * c / (D * D * D)
    m11 = p[P_M1] + m2
    m12, dm12 = m2 * K, m2 * dK
    m22, dm22 = p[P_JA] + m2 * (K * K), 2.0 * m2 * K * dK
    if p[P_ROD] != 0.0:
        m, inertia = p[P_ROD_M], p[P_ROD_I]
        a, b, da, db = 0.5 * (-r * s + K), 0.5 * r * c, 0.5 * (-r * c + dK), -0.5 * r * s
        g = -r * c / D
        dg = r * s / D - r * r * r * s * c * c / (D * D * D)
        m11 = m11 + m
        m12, dm12 = m12 + m * a, dm12 + m * da
        m22 = m22 + m * (a * a + b * b) + inertia * (g * g)
        dm22 = dm22 + 2.0 * (m * (a * da + b * db) + inertia * g * dg)
    return m11, m12, m22, dm12, dm22, K, dK


@jit
def one_dof(p, mode, phi, omega, M):
    """(alpha [rad/s^2], momentum rate less gravity [N], K, dK) with one module held
    (:meth:`.OneDofDynamics.state`: the held clutch's reaction is that rate plus the moving module's F_r)."""
    m11, m12, m22, dm12, dm22, K, dK = mass_terms(p, phi)
    if mode == CONTRACTION:
        e, de = -K, -dK
    else:
        e, de = 0.0, 0.0
    f = e + K
    J = m11 * (e * e) + 2.0 * m12 * e + m22
    dJ = 2.0 * m11 * e * de + 2.0 * (dm12 * e + m12 * de) + dm22
    P = m11 * e + m12
    dP = m11 * de + dm12
    a_g = p[P_AG]
    Q = M - p[P_FR1] * e - p[P_FR2] * f + a_g * P
    w2 = omega * omega
    alpha = (Q - 0.5 * dJ * w2) / J
    return alpha, dP * w2 + P * alpha - m11 * a_g, K, dK


@jit
def both_moving(p, phi, omega, M):
    """(x1_ddot [m/s^2], alpha [rad/s^2], K, dK) with both modules sliding (:meth:`.OneDofDynamics.both_moving`)."""
    m11, m12, m22, dm12, dm22, K, dK = mass_terms(p, phi)
    a_g, w2 = p[P_AG], omega * omega
    rhs1 = -p[P_FR1] - p[P_FR2] + m11 * a_g - dm12 * w2
    rhs2 = M - p[P_FR2] * K + m12 * a_g - 0.5 * dm22 * w2
    det = m11 * m22 - m12 * m12
    return (m22 * rhs1 - m12 * rhs2) / det, (m11 * rhs2 - m12 * rhs1) / det, K, dK


@jit
def rhs(model, mode, t, y, p, out):
    """d/dt y into ``out`` (see the module docstring for the states)."""
    phi, omega = y[0], y[1]
    if not (abs(phi) < 1e300 and abs(omega) < 1e300):  # a trial step that overflowed: the controller rejects it
        for i in range(out.size):
            out[i] = math.nan
        return
    M = drive_torque(p, omega)
    out[0] = omega
    if model == KINEMATIC:
        alpha, _, K, _ = one_dof(p, mode, phi, omega, M)
        e = -K if mode == CONTRACTION else 0.0
        out[1], out[2], out[3], out[4] = alpha, e * omega, (e + K) * omega, M * omega
        return
    if mode == BOTH_MOVING:
        a1, alpha, K, _ = both_moving(p, phi, omega, M)
        v1 = y[4]
        out[1], out[2], out[3], out[4] = alpha, v1, v1 + K * omega, a1
    elif mode == CONTRACTION:  # front held: x1_dot = -K omega
        alpha, _, K, dK = one_dof(p, mode, phi, omega, M)
        out[1], out[2], out[3], out[4] = alpha, -K * omega, 0.0, -(dK * omega * omega + K * alpha)
    else:  # expansion: rear held
        alpha, _, K, _ = one_dof(p, mode, phi, omega, M)
        out[1], out[2], out[3], out[4] = alpha, 0.0, K * omega, 0.0
    out[5] = M * omega


@jit
def guard(model, mode, k, t, y, p, quiet):
    """Event function k of ``mode`` at (t, y); ``quiet[k]``: until that time [s] it reads at least TINY."""
    phi, omega = y[0], y[1]
    if not (abs(phi) < 1e300 and abs(omega) < 1e300):
        return math.nan
    if model == KINEMATIC:
        return mass_terms(p, phi)[5] * omega
    if mode == BOTH_MOVING:
        value = y[4] if k == 0 else y[4] + mass_terms(p, phi)[5] * omega
    elif (mode == CONTRACTION) == (k == 0):  # the moving module's velocity
        K = mass_terms(p, phi)[5]
        value = -K * omega if k == 0 else K * omega
    else:  # the held module's margin R_k + F_rk: its reaction plus both resistances
        hold = one_dof(p, mode, phi, omega, drive_torque(p, omega))[1]
        value = hold + p[P_FR1] + p[P_FR2] if k == 1 else hold + p[P_FR2] + p[P_FR1]
    if t > quiet[k]:
        return value
    return max(value, TINY)


@jit
def guard_table(model, mode, n_events, p, times, states, out):
    """Every event function of ``mode`` (none quiet) at ``times`` (n,) and ``states`` (n, d), into out (n_events, n)."""
    never = np.full(max(n_events, 1), -math.inf)
    for i in range(times.size):
        for k in range(n_events):
            out[k, i] = guard(model, mode, k, times[i], states[i], p, never)
