"""Scalar right-hand sides and event functions of the analytic models, for the compiled stepper.

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
hold margin R_k + F_rk while held), both with :class:`.columns.Mode` values as
modes, :data:`COMPLIANT` (compliant one-way clutches, see below) and :data:`GRIP`
(one-way clutches on wheels of finite grip, :mod:`.grip_model`: the one-way model's
right-hand sides, its own events).
Units: rad, rad/s, m, m/s, kg, N, N m, J.
"""

from __future__ import annotations

import math

import numpy as np

from .accel import jit
from .kernel_base import (P_AG, P_EXACT, P_FR1, P_FR2, P_JA, P_L, P_M, P_M1, P_M2, P_MOTOR,  # noqa: F401 (the
                          P_MSTALL, P_R, P_ROD, P_ROD_I, P_ROD_M, P_U, P_WNL, TINY, drive_torque)  # layout's names)
from .dynamics import OneDofDynamics
from .forces import gravity_along_pipe
from .route_kernels import ROUTE, route_guards, route_rhs

KINEMATIC, UNILATERAL = 0, 1  # COMPLIANT = 2 and GRIP = 3: see their sections below; ROUTE = 4: .route_kernels
CONTRACTION, EXPANSION, BOTH_MOVING = 1, 2, 3  # Mode values (BOTH_LOCKED is never integrated)


def pack(dyn: OneDofDynamics) -> np.ndarray:
    """The constants of ``dyn`` (its parameters, geometry, rod and drive) as the kernels' float array (17,).

    P_U is the motor's voltage fraction u: 1 (full voltage) for ``drive = motor``; with ``drive = servo``
    the run loop writes the speed controller's u there at each of its ticks (constant between them)."""
    p = dyn.params
    motor = p.drive in ("motor", "servo")
    return np.array([p.m1, p.m2, p.r, p.L, p.J_A, *dyn.resistance, p.M, p.rod_mass, p.rod_inertia_value,
                     float(dyn.geometry.value == "exact"), float(dyn.include_rod), float(motor),
                     p.M_stall if motor else 0.0, p.omega_noload if motor else 1.0, gravity_along_pipe(p), 1.0],
                    dtype=float)


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
def mode_motion(p, mode, phi, omega, M):
    """(alpha, a1, a2, R1, R2) in a moving mode of the one-way model (:meth:`.UnilateralModel.motion`:
    accelerations and each held module's hold, nan where it moves)."""
    w2 = omega * omega
    if mode == BOTH_MOVING:
        a1, alpha, K, dK = both_moving(p, phi, omega, M)
        return alpha, a1, a1 + dK * w2 + K * alpha, math.nan, math.nan
    alpha, hold, K, dK = one_dof(p, mode, phi, omega, M)
    if mode == CONTRACTION:  # front held: e = -K, f = 0
        return alpha, -dK * w2 + -K * alpha, 0.0 * w2 + 0.0 * alpha, math.nan, hold + p[P_FR1]
    return alpha, 0.0 * w2 + 0.0 * alpha, dK * w2 + K * alpha, hold + p[P_FR2], math.nan


@jit
def rhs(model, mode, t, y, p, out):
    """d/dt y into ``out`` (see the module docstring for the states)."""
    phi, omega = y[0], y[1]
    if not (abs(phi) < 1e300 and abs(omega) < 1e300):  # a trial step that overflowed: the controller rejects it
        for i in range(out.size):
            out[i] = math.nan
        return
    if model == COMPLIANT:
        compliant_rhs(y, p, out)
        return
    if model == ROUTE:
        route_rhs(mode, y, p, out)
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
    if model == COMPLIANT:
        return compliant_guard(mode, k, t, y, p)
    if model == GRIP:
        value = grip_guard(mode, k, y, p)
        return value if t > quiet[k] else max(value, TINY)
    if model == ROUTE:
        values = np.empty(3)
        route_guards(mode, y, p, values)
        return values[k] if t > quiet[k] else max(values[k], TINY)
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
def guards_at(model, mode, n_events, t, y, p, never, out):
    """Every event function of ``mode`` at (t, y), none quiet (``never``: -inf each), into ``out`` (n_events,):
    :func:`guard`'s values. A one-way mode evaluates its mass terms once for both events (the moving
    module's velocity needs only the K that comes with a held module's hold or with the gap rate)."""
    phi, omega = y[0], y[1]
    if model == UNILATERAL and abs(phi) < 1e300 and abs(omega) < 1e300 and t > -math.inf:
        if mode == BOTH_MOVING:
            out[0], out[1] = y[4], y[4] + mass_terms(p, phi)[5] * omega
            return
        _, hold, K, _ = one_dof(p, mode, phi, omega, drive_torque(p, omega))
        if mode == CONTRACTION:  # module 1 moves, module 2 is held
            out[0], out[1] = -K * omega, hold + p[P_FR1] + p[P_FR2]
        else:
            out[0], out[1] = hold + p[P_FR2] + p[P_FR1], K * omega
        return
    if model == ROUTE and abs(phi) < 1e300 and abs(omega) < 1e300:  # every event from one evaluation of the state
        route_guards(mode, y, p, out)
        return
    for k in range(n_events):
        out[k] = guard(model, mode, k, t, y, p, never)


@jit
def guard_table(model, mode, n_events, p, times, states, out):
    """Every event function of ``mode`` (none quiet) at ``times`` (n,) and ``states`` (n, d), into out (n_events, n)."""
    never = np.full(max(n_events, 1), -math.inf)
    values = np.empty(max(n_events, 1))
    for i in range(times.size):
        guards_at(model, mode, n_events, times[i], states[i], p, never, values)
        for k in range(n_events):
            out[k, i] = values[k]


# --- compliant one-way clutches (:mod:`.compliant_model`) -------------------------------------------
# state [phi, omega, x1, v1, motor work, friction work, damper work]; the regime and the segment's events
# travel in ``p`` after the robot's constants (:meth:`.CompliantModel.constants`); the "mode" argument
# of rhs/guard says whether an event reads its raw value (RAW) or what the root search sees (GUARDED).
COMPLIANT = 2
RAW, GUARDED = 0, 1
TRACKING, FREE, ENGAGED, CLIPPED, SLIDING = 0, 1, 2, 3, 4  # .compliant_state.Clutch
P_K, P_C, P_DELTA, P_S0, P_S1, P_S2, P_C1, P_C2, P_PK1, P_PK2, P_T0 = range(17, 28)
# finite grip (:mod:`.compliant_grip`): each module's grip [N] (inf: unlimited), and while its clutch's
# anchor slides the slide's start [s] and the overlap then [m]
P_GR1, P_GR2, P_TS1, P_DS1, P_TS2, P_DS2 = range(28, 34)
P_EVENTS = 34  # then four numbers per event: kind, module, direction, offset
EV_MARGIN, EV_VELOCITY, EV_OVERLAP, EV_TRACK, EV_PUSH, EV_PHI, EV_GRIP, EV_STICK = range(8)


@jit
def gap(p, phi):
    """S(phi) [m] (:meth:`.Linkage.gap`)."""
    r, L, s, c = p[P_R], p[P_L], math.sin(phi), math.cos(phi)
    if p[P_EXACT] == 0.0:
        return L + r * c
    return r * c + math.sqrt(L * L - (r * s) * (r * s))


@jit
def compliant_motion(p, y):
    """:meth:`.CompliantModel.motion` at one state: (alpha, a1, a2, x2, v2, f1, f2, d1, d2, friction1,
    friction2, torque, M11, M12, M22, dM12, dM22, S, K, dK)."""
    phi, omega, x1, v1 = y[0], y[1], y[2], y[3]
    m11, m12, m22, dm12, dm22, K, dK = mass_terms(p, phi)
    S = gap(p, phi)
    x2, v2 = x1 + S - p[P_S0], v1 + K * omega
    k, c, delta = p[P_K], p[P_C], p[P_DELTA]
    d1 = -delta if p[P_C1] == TRACKING else p[P_PK1] - delta - x1
    d2 = -delta if p[P_C2] == TRACKING else p[P_PK2] - delta - x2
    f1 = k * d1 - c * v1 if p[P_C1] == ENGAGED else (p[P_GR1] if p[P_C1] == SLIDING else 0.0)
    f2 = k * d2 - c * v2 if p[P_C2] == ENGAGED else (p[P_GR2] if p[P_C2] == SLIDING else 0.0)
    s1, s2 = p[P_S1], p[P_S2]
    sliding1, sliding2 = -s1 * p[P_FR1], -s2 * p[P_FR2]
    torque = drive_torque(p, omega)
    w2, g = omega * omega, p[P_AG]
    F1, F2 = f1 + sliding1, f2 + sliding2
    b1 = F1 + F2 + m11 * g - dm12 * w2
    b2 = torque + K * F2 + m12 * g - 0.5 * dm22 * w2
    if s1 != 0.0 and s2 != 0.0:
        det = m11 * m22 - m12 * m12
        a1, alpha = (m22 * b1 - m12 * b2) / det, (m11 * b2 - m12 * b1) / det
        r1, r2 = sliding1, sliding2
    elif s2 != 0.0:  # module 1 stuck
        a1, alpha = 0.0, b2 / m22
        r1, r2 = m12 * alpha - b1, sliding2
    elif s1 != 0.0:  # module 2 stuck
        jeff = m11 * (K * K) - 2.0 * m12 * K + m22
        alpha = (b2 - K * b1 + (m12 - K * m11) * dK * w2) / jeff
        a1 = -K * alpha - dK * w2
        r1, r2 = sliding1, m11 * a1 + m12 * alpha - b1
    else:  # both stuck: statics
        a1, alpha = 0.0, 0.0
        R2 = -b2 / K if K != 0 else 0.0
        r1, r2 = -b1 - R2, R2
    a2 = a1 + dK * w2 + K * alpha
    return alpha, a1, a2, x2, v2, f1, f2, d1, d2, r1, r2, torque, m11, m12, m22, dm12, dm22, S, K, dK


@jit
def compliant_rhs(y, p, out):
    """:meth:`.CompliantModel.rhs`: d/dt y into ``out``."""
    m = compliant_motion(p, y)
    v1, v2, k, c = y[3], m[4], p[P_K], p[P_C]
    damper = 0.0
    if p[P_C1] == ENGAGED:
        damper += c * v1 * v1
    elif p[P_C1] == CLIPPED:
        damper += k * m[7] * v1
    if p[P_C2] == ENGAGED:
        damper += c * v2 * v2
    elif p[P_C2] == CLIPPED:
        damper += k * m[8] * v2
    out[0], out[1], out[2], out[3], out[4] = y[1], m[0], v1, m[1], m[11] * y[1]
    out[5], out[6] = p[P_S1] * p[P_FR1] * v1 + p[P_S2] * p[P_FR2] * v2, damper


@jit
def slide_rate(p, i, t):
    """d(overlap)/dt [m/s] of module i's clutch while its anchor slides (:func:`.compliant_grip.slide_overlap`):
    the spring relaxes towards G / k through the damper, (G - k d(t)) / c; 0 without a damper (d = G / k)."""
    k, c = p[P_K], p[P_C]
    if c == 0.0:
        return 0.0
    G, ts, d0 = (p[P_GR1], p[P_TS1], p[P_DS1]) if i == 0 else (p[P_GR2], p[P_TS2], p[P_DS2])
    return (G - k * d0) / c * math.exp(-(t - ts) * k / c)


@jit
def compliant_guard(guarded, k, t, y, p):
    """Event k of the segment (:meth:`.CompliantModel.events`): its raw value, or (``guarded``) as solve_ivp sees it."""
    base = P_EVENTS + 4 * k
    kind, i, direction, offset = p[base], p[base + 1], p[base + 2], p[base + 3]
    if kind == EV_PHI:
        value = y[0] + offset
    elif kind == EV_MARGIN:
        value = offset - abs(compliant_motion(p, y)[9 if i == 0 else 10])
    else:
        K = mass_terms(p, y[0])[5] if i == 1 else 0.0
        v = y[3] if i == 0 else y[3] + K * y[1]
        position = y[2] if i == 0 else y[2] + gap(p, y[0]) - p[P_S0]
        peak = p[P_PK1] if i == 0 else p[P_PK2]
        if kind == EV_VELOCITY:
            value = (p[P_S1] if i == 0 else p[P_S2]) * v + offset
        elif kind == EV_TRACK:
            value = position - peak + offset
        elif kind == EV_OVERLAP:
            value = peak - p[P_DELTA] - position + offset
        elif kind == EV_PUSH:
            value = p[P_K] * (peak - p[P_DELTA] - position) - p[P_C] * v + offset
        elif kind == EV_GRIP:  # the grip less the force the clutch would push with: its anchor slides at 0
            value = offset - (p[P_K] * (peak - p[P_DELTA] - position) - p[P_C] * v)
        else:  # EV_STICK: the sliding anchor's speed backward (+ offset)
            value = offset - v - slide_rate(p, i, t)
    if guarded != 0 and (value == 0 or (t == p[P_T0] and direction * value > 0)):
        return -direction * 1e-300
    return value


# --- one-way clutches with finite grip (:mod:`.grip_model`) ------------------------------------------------
# the one-way model's state and right-hand sides; ``p`` is :func:`pack` of the dynamics whose resistance of
# a module skidding back is -G_i (its grip pushes it forward), then the grips and each module's state
GRIP = 3
P_G1, P_G2, P_DIR1, P_DIR2 = range(17, 21)  # grips [N]; per module +1 rolling forward, -1 skidding back, 0 held


@jit
def grip_guard(mode, k, y, p):
    """Event k of a finite-grip mode (:meth:`.GripModel.events`): a moving module's speed in its own sense of
    motion (falls to 0 where it stops), a held module's smaller margin, min(R_k + F_rk, G_k - R_k)."""
    phi, omega = y[0], y[1]
    direction = p[P_DIR1] if k == 0 else p[P_DIR2]
    if direction != 0.0:
        if mode == BOTH_MOVING:
            v = y[4] if k == 0 else y[4] + mass_terms(p, phi)[5] * omega
        else:
            K = mass_terms(p, phi)[5]
            v = -K * omega if k == 0 else K * omega
        value = direction * v
        return TINY if value == 0.0 else value  # exactly 0, a start from rest (:meth:`.GripModel.project`): safe
    hold = one_dof(p, mode, phi, omega, drive_torque(p, omega))[1]
    other = p[P_FR2] if k == 0 else p[P_FR1]  # the moving module's backward force
    own, grip = (p[P_FR1], p[P_G1]) if k == 0 else (p[P_FR2], p[P_G2])
    R = hold + other
    return min(R + own, grip - R)
