"""The robot along a route: its equations of motion on scalars, model ROUTE of the compiled stepper (:mod:`.kernels`
dispatches to it; :mod:`.route_model` drives it). docs/model.md, "The equations along a route", derives them.

Coordinates q = (s1, s2, phi): each module's station along the centreline [m] (:func:`.route_geometry.module_pose`:
its point, A or C, and its axis) and the crank angle [rad] in module 1's plane (e1, e2). The crank pin is
B = A + r (cos phi e1 + sin phi e2); the rod, on a universal joint at B and a ball joint at C, closes the loop:

    Phi(q) = |C(s2) - B(s1, phi)|^2 - L^2 = 0,

one equation for the one dependent coordinate (s1 while module 2 is held, else s2), solved by Newton's method
from the integrated value at every evaluation, so that the loop is closed to round-off. The kinetic energy is
that of "points" X(q) of mass mu, 1/2 sum mu |X_dot|^2, plus the crank's spin 1/2 J_A psi_dot^2:

    A (m1), C (m2), the rod's centre (B + C) / 2 (m_rod), its direction (C - B) / L (I_rod), each module's axis
    e1 (its transverse inertia I_t,i: its yaw and pitch through a bend), module 1's e3 (J_A / 2: the crank's
    transverse inertia, carried by module 1's pitch); psi_dot = omega + (e1' . e2)(s1) v1 (the crank's spin: its
    rate relative to module 1 plus module 1's own turn about e3).

So with J_X = dX/dq (3 x 3) and h_X = the part of X_ddot quadratic in q_dot, the mass matrix is
M = sum mu J^T J and the velocity terms c = sum mu J^T h (Kane's form of Lagrange's equations), and

    M q_ddot + c = Q + g^T lambda + sum over held modules e_i R_i,      g = dPhi/dq,  g q_ddot + q_dot^T H q_dot = 0,

Q = (-f1, -f2, T(omega)) + sum m J^T g_vec: each moving module's force along the path f_i (F_ri rolling forward,
-G_i skidding back, plus the scrub hook :func:`scrub_force`), the drive's torque, gravity (g_vec = -g up) on the
three masses. A held module's R_i is its hold (clutch and resistance, + forward). In each mode the velocities are
the null space of the loop's row and the holds' rows: contraction (module 2 held) v1 = -(g_phi / g1) omega,
expansion (module 1 held) v2 = -(g_phi / g2) omega, both moving v2 = -(g1 v1 + g_phi omega) / g2; the free
accelerations solve the projected equations, the multipliers follow from the rest.

State y = [phi, omega, s1, s2, v1, motor work, scrub work] (module 1 starts at s1 = 0; v1 the rear module's
speed). Constants ``p``: :func:`.kernels.pack`'s (the robot, the drive), then the Q_* below,
then the packed route (:func:`.route_geometry.pack_route`). Units: rad, rad/s, m, m/s, kg, N, N m, J, W.
"""

from __future__ import annotations

import math

from .accel import jit
from .kernel_base import (P_FR1, P_FR2, P_JA, P_L, P_M1, P_M2, P_R, P_ROD_I, P_ROD_M, TINY,
                          drive_torque)
from .route_geometry import add, combine, cross, dot, module_pose, scale, sub
from .route_scrub import module_scrub

ROUTE = 4  # the kernels' model number
CONTRACTION, EXPANSION, BOTH_MOVING = 1, 2, 3  # columns.Mode; 0 (both held) is statics
# per mode: each module's grip G_i [N] (inf: unlimited), its state (+1 rolling, -1 skidding, 0 held), the clutch
# rule (RULE_ONE_WAY, RULE_PAPER); the robot: half its ring spacing h [m], the modules' transverse inertias
# [kg m^2]; gravity's acceleration vector g_vec [m/s^2] in route coordinates; the route's length [m], how many
# packed pieces follow (its exit straight included)
(Q_G1, Q_G2, Q_DIR1, Q_DIR2, Q_RULE, Q_H, Q_IT1, Q_IT2, Q_GX, Q_GY, Q_GZ, Q_END, Q_COUNT) = range(17, 30)
# the wheels (:mod:`.route_scrub`): mu_wall (0 with unlimited grip: the rails, no scrub), cornering_coefficient
# [1/rad] (inf: rigid), legs per ring, each module's legs' preload F_ni / (2 n) [N], the legs' deflection at preload
# [m], the hubs' distance from the axis pipe_diameter / 2 - wheel_radius [m]
(Q_MU, Q_CORNER, Q_LEGS, Q_P1, Q_P2, Q_TRAVEL, Q_RHO) = range(30, 37)
Q_PIECES = 37
RULE_ONE_WAY, RULE_PAPER = 0.0, 1.0
N_EVENTS = 3  # module 1, module 2 (a moving module's speed, a held one's margin), the route's end
NEWTON_STEPS = 30  # a bound: from the integrated value (within the solver's tolerance) it takes 1-2
# the loop counts as closed where |Phi| <= LOOP_TOL L (L + |s1| + |s2|): C within LOOP_TOL (L + |s1| + |s2|) / 2 of
# the rod's length (1e-15 m at the start, 3e-14 m 5 m on), some 20 roundings of the points' coordinates (eps times
# their size each), so that a state closed once reads as closed in every mode (a Newton step of round-off would
# turn a module held at exactly 0 into one creeping at 1e-16 m/s)
LOOP_TOL = 1e-14


@jit
def scrub_force(p, module, s, v):
    """The wheels' scrub in a bend: the force [N] along the path, backward, on module ``module`` (0 rear, 1 front)
    rolling forward at station s [m] and speed v >= 0 [m/s], beside its rolling resistance F_ri; it dissipates
    scrub_force * v [W], booked as the audit's ``scrub_j``, and at v = 0 it is part of what a module at rest must
    overcome to roll off (its hold's margin, :func:`route_guards`, and the mode choice,
    :meth:`.route_model.RouteModel.choose`). A module skidding back on locked wheels meets its grip G_i, all of its
    wheels' friction. ``p``: the constants (the robot, its wheels and the route). The closed form
    (:func:`.route_scrub.module_scrub`) depends on the module's place alone: its wheels' slip angles are the
    geometry's, so their dissipated power is proportional to v."""
    return module_scrub(p, Q_PIECES, int(p[Q_COUNT]), s, p[Q_H], p[Q_MU], p[Q_CORNER], int(p[Q_LEGS]),
                        p[Q_P1 + module], p[Q_TRAVEL], p[Q_RHO])[0]


@jit
def crank_pin(r, phi, A, A1, A2, e1, e11, e12, e2, e21, e22):
    """(B, B_s, B_phi, B_ss, B_sphi, B_phiphi): the crank pin and its derivatives in s1 and phi."""
    c, s = math.cos(phi), math.sin(phi)
    return (add(A, combine(r * c, e1, r * s, e2)), add(A1, combine(r * c, e11, r * s, e21)),
            combine(-r * s, e1, r * c, e2), add(A2, combine(r * c, e12, r * s, e22)),
            combine(-r * s, e11, r * c, e21), combine(-r * c, e1, -r * s, e2))


@jit
def route_state(p, mode, y):
    """Everything the state y implies in ``mode`` (module docstring): (s1, s2 [m] with the loop closed, v1, v2,
    alpha, a1, a2, R1, R2 (nan where the module moves), kinetic [J], potential [J] (up to a constant), torque
    [N m], scrub power [W], K2 = dv2/domega with module 1 held [m/rad] and dK2/dphi [m/rad^2])."""
    base, count, h = Q_PIECES, int(p[Q_COUNT]), p[Q_H]
    r, L = p[P_R], p[P_L]
    phi, omega = y[0], y[1]
    s1, s2 = y[2], y[3]
    A, A1, A2, e1, e11, e12, e2, e21, e22 = module_pose(p, base, count, s1, h)
    C, C1, C2, f1, f11, f12, _, _, _ = module_pose(p, base, count, s2, h)
    B, Bs, Bp, Bss, Bsp, Bpp = crank_pin(r, phi, A, A1, A2, e1, e11, e12, e2, e21, e22)
    for _ in range(NEWTON_STEPS):  # close the loop in the dependent coordinate
        D = sub(C, B)
        f = dot(D, D) - L * L
        if not abs(f) > LOOP_TOL * L * (L + abs(s1) + abs(s2)):  # closed: a closed state is left exactly as it is
            break
        if mode == CONTRACTION:
            s1 -= f / (-2.0 * dot(D, Bs))
            A, A1, A2, e1, e11, e12, e2, e21, e22 = module_pose(p, base, count, s1, h)
            B, Bs, Bp, Bss, Bsp, Bpp = crank_pin(r, phi, A, A1, A2, e1, e11, e12, e2, e21, e22)
        else:
            s2 -= f / (2.0 * dot(D, C1))
            C, C1, C2, f1, f11, f12, _, _, _ = module_pose(p, base, count, s2, h)
    D = sub(C, B)
    g1, g2, gp = -2.0 * dot(D, Bs), 2.0 * dot(D, C1), -2.0 * dot(D, Bp)
    if mode == CONTRACTION:
        v1, v2 = -gp / g1 * omega, 0.0
    elif mode == EXPANSION:
        v1, v2 = 0.0, -gp / g2 * omega
    elif mode == BOTH_MOVING:  # v2 = 0 exactly where v1 is contraction's -(g_phi / g1) omega (a module at rest)
        v1 = y[4]
        v2 = -g1 / g2 * (v1 - -gp / g1 * omega)
    else:
        v1, v2 = 0.0, 0.0
    m1, m2, mr, Ir, JA = p[P_M1], p[P_M2], p[P_ROD_M], p[P_ROD_I], p[P_JA]
    It1, It2 = p[Q_IT1], p[Q_IT2]
    w1, w2, ww = v1 * v1, v2 * v2, omega * omega
    # the quadratic parts of each point's acceleration
    hA, hC = scale(w1, A2), scale(w2, C2)
    hB = add(add(scale(w1, Bss), scale(2.0 * v1 * omega, Bsp)), scale(ww, Bpp))
    hG, hU = scale(0.5, add(hB, hC)), scale(1.0 / L, sub(hC, hB))
    e3, e31 = cross(e1, e2), add(cross(e11, e2), cross(e1, e21))
    e32 = add(add(cross(e12, e2), scale(2.0, cross(e11, e21))), cross(e1, e22))
    tau, tau1 = dot(e11, e2), dot(e12, e2) + dot(e11, e21)
    # mass matrix and velocity terms: A, e1(s1), e3(s1), the crank's spin, C, e1(s2), the rod's centre and direction
    u, k2 = 0.25 * mr + Ir / (L * L), 0.25 * mr - Ir / (L * L)  # the rod's: same-end and cross-end products
    M11 = m1 * dot(A1, A1) + It1 * dot(e11, e11) + 0.5 * JA * dot(e31, e31) + JA * tau * tau + u * dot(Bs, Bs)
    M12 = k2 * dot(Bs, C1)
    M13 = JA * tau + u * dot(Bs, Bp)
    M22 = m2 * dot(C1, C1) + It2 * dot(f11, f11) + u * dot(C1, C1)
    M23 = k2 * dot(C1, Bp)
    M33 = JA + u * dot(Bp, Bp)
    # the rod's centre's and direction's columns: (B_s, C', B_phi) / 2 and (-B_s, C', -B_phi) / L
    rod_s, rod_c = 0.5 * mr, Ir / L
    c1 = (m1 * dot(A1, hA) + (It1 * dot(e11, e12) + 0.5 * JA * dot(e31, e32)) * w1 + JA * tau * tau1 * w1
          + rod_s * dot(Bs, hG) - rod_c * dot(Bs, hU))
    c2 = m2 * dot(C1, hC) + It2 * dot(f11, f12) * w2 + rod_s * dot(C1, hG) + rod_c * dot(C1, hU)
    c3 = JA * tau1 * w1 + rod_s * dot(Bp, hG) - rod_c * dot(Bp, hU)
    gv = (p[Q_GX], p[Q_GY], p[Q_GZ])
    torque = drive_torque(p, omega)
    forces = (0.0, 0.0)
    scrub = 0.0
    for i in range(2):
        state = p[Q_DIR1 + i]
        if state > 0.0:  # rolling forward: its resistance and its wheels' scrub
            s_i, v_i = (s1, v1) if i == 0 else (s2, v2)
            extra = scrub_force(p, i, s_i, v_i)
            scrub += extra * v_i
            f_i = (p[P_FR1] if i == 0 else p[P_FR2]) + extra
            forces = (f_i, forces[1]) if i == 0 else (forces[0], f_i)
        elif state < 0.0:  # skidding back on locked wheels: the grip, all of the wall's friction
            forces = (-p[Q_G1], forces[1]) if i == 0 else (forces[0], -p[Q_G2])
    b1 = -forces[0] + (m1 * dot(A1, gv) + rod_s * dot(Bs, gv)) - c1
    b2 = -forces[1] + (m2 * dot(C1, gv) + rod_s * dot(C1, gv)) - c2
    b3 = torque + rod_s * dot(Bp, gv) - c3
    # the loop's acceleration: g q_ddot = -kappa
    Dd = sub(scale(v2, C1), add(scale(v1, Bs), scale(omega, Bp)))
    kappa = 2.0 * dot(Dd, Dd) + 2.0 * dot(D, sub(hC, hB))
    nan = math.nan
    R1, R2 = nan, nan
    if mode == CONTRACTION or mode == EXPANSION:  # q_ddot = n alpha + w
        if mode == CONTRACTION:
            n, w = (-gp / g1, 0.0, 1.0), (-kappa / g1, 0.0, 0.0)
        else:
            n, w = (0.0, -gp / g2, 1.0), (0.0, -kappa / g2, 0.0)
        Mn = _times(M11, M12, M13, M22, M23, M33, n)
        Mw = _times(M11, M12, M13, M22, M23, M33, w)
        alpha = (dot(n, (b1, b2, b3)) - dot(n, Mw)) / dot(n, Mn)
        qdd = add(scale(alpha, n), w)
        rho = sub(_times(M11, M12, M13, M22, M23, M33, qdd), (b1, b2, b3))
        if mode == CONTRACTION:
            R2 = rho[1] - rho[0] / g1 * g2
        else:
            R1 = rho[0] - rho[1] / g2 * g1
    elif mode == BOTH_MOVING:  # q_ddot = N (a1, alpha) + w
        n1, n2, w = (1.0, -g1 / g2, 0.0), (0.0, -gp / g2, 1.0), (0.0, -kappa / g2, 0.0)
        Mn1 = _times(M11, M12, M13, M22, M23, M33, n1)
        Mn2 = _times(M11, M12, M13, M22, M23, M33, n2)
        Mw = _times(M11, M12, M13, M22, M23, M33, w)
        r1, r2 = b1 - Mw[0], b2 - Mw[1]
        rhs1, rhs2 = dot(n1, (r1, r2, b3 - Mw[2])), dot(n2, (r1, r2, b3 - Mw[2]))
        k11, k12, k22 = dot(n1, Mn1), dot(n1, Mn2), dot(n2, Mn2)
        det = k11 * k22 - k12 * k12
        a1_, alpha = (k22 * rhs1 - k12 * rhs2) / det, (k11 * rhs2 - k12 * rhs1) / det
        qdd = add(add(scale(a1_, n1), scale(alpha, n2)), w)
    else:  # statics: nothing moves; the loop's multiplier balances the torque
        alpha, qdd = 0.0, (0.0, 0.0, 0.0)
        loop = -b3 / gp if gp != 0.0 else 0.0
        R1, R2 = -b1 - loop * g1, -b2 - loop * g2
    kinetic = 0.5 * (M11 * w1 + M22 * w2 + M33 * ww) + M12 * v1 * v2 + M13 * v1 * omega + M23 * v2 * omega
    G = scale(0.5, add(B, C))
    potential = -dot(gv, add(add(scale(m1, A), scale(m2, C)), scale(mr, G)))
    K2 = -gp / g2
    pp = 2.0 * (dot(Bp, Bp) - dot(D, Bpp))
    p2, p22 = -2.0 * dot(C1, Bp), 2.0 * (dot(C1, C1) + dot(D, C2))
    dK2 = -(pp + 2.0 * p2 * K2 + p22 * K2 * K2) / g2
    return (s1, s2, v1, v2, alpha, qdd[0], qdd[1], R1, R2, kinetic, potential, torque, scrub, K2, dK2)


@jit
def _times(M11, M12, M13, M22, M23, M33, x):
    """M x for the symmetric 3 x 3 M."""
    return (M11 * x[0] + M12 * x[1] + M13 * x[2], M12 * x[0] + M22 * x[1] + M23 * x[2],
            M13 * x[0] + M23 * x[1] + M33 * x[2])


@jit
def route_rhs(mode, y, p, out):
    """d/dt y into ``out`` (7,) in ``mode``."""
    m = route_state(p, mode, y)
    out[0], out[1], out[2], out[3] = y[1], m[4], m[2], m[3]
    out[4], out[5], out[6] = m[5], m[11] * y[1], m[12]


@jit
def route_guards(mode, y, p, out):
    """Every event function of ``mode`` at y into ``out`` (N_EVENTS,): per module its speed in its sense of motion
    while it moves (TINY where exactly 0), while held its smaller margin min(R_i + F_ri, G_i - R_i) (the one-way
    clutches and the grip; 1 under the paper's locks, which hold whatever the load); then the route's end less
    s1 (it falls through 0 where module 1 reaches it)."""
    m = route_state(p, mode, y)
    for i in range(2):
        state = p[Q_DIR1 + i]
        if state != 0.0:
            value = state * m[2 + i]
            out[i] = TINY if value == 0.0 else value
        elif p[Q_RULE] == RULE_PAPER:
            out[i] = 1.0
        else:  # a module that rolls off from rest meets its resistance and its scrub at v = 0
            R = m[7 + i]
            rolling = (p[P_FR1] if i == 0 else p[P_FR2]) + scrub_force(p, i, m[i], 0.0)
            out[i] = min(R + rolling, p[Q_G1 + i] - R)
    out[2] = p[Q_END] - y[2]


@jit
def route_table(p, mode, states, out):
    """:func:`route_state` of each row of ``states`` (n, 7) into the rows of ``out`` (n, 15)."""
    for i in range(states.shape[0]):
        m = route_state(p, mode, states[i])
        for j in range(15):
            out[i, j] = m[j]
