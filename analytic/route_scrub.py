"""The wheels' scrub in a bend, in closed form: the force along the path that a module rolling through a bend
meets from its wheels' side forces (:func:`.route_kernels.scrub_force` calls :func:`module_scrub`).

Written from docs/model.md, "The wheels' side force" (the law per wheel, and a module in a bend); docs/model.md,
"The equations along a route", "The wheels' scrub", states this form and where it departs from that text.

**Per wheel.** A wheel rolling at slip angle alpha (from its rolling direction to its hub's velocity w, in the
wall's tangent plane) is pushed across its path by F = min(C |alpha|, mu N) against the slip, C = c P its
cornering stiffness (c = ``cornering_coefficient`` [1/rad], P its leg's preload F_ni / (2 n) [N]), N its press
(P: the equations' constant press). Below the limit it steers to its path and dissipates nothing; at and beyond it
it steers by alpha_s = mu N / C and slides across at |w| sin(|alpha| - alpha_s), dissipating mu N |w|
sin(|alpha| - alpha_s). Rigid wheels are C = infinity (alpha_s = 0). The force lies along the wheel's axle, at
alpha (below the limit) or alpha_s (beyond it) off the module's: its share across the module's axis is F cos of
that angle.

**The module.** Its rings ride on the centreline (:func:`.route_geometry.module_pose`: at P(s -+ h), the module
the chord between them, axis e1, frame e2, e3), each moving at v along the centreline's tangent t_j at its own
point. Leg k of n (k = 0 .. n-1) points out along u_k = cos(a_k) e2 + sin(a_k) e3, a_k = -90 deg + 360 deg k / n
(leg 0 down at the start: :func:`ipir_mujoco.core.wheel_legs.leg_direction` in the module's frame), its wheel rolling
along e1 and sideways along e_k = e1 x u_k, its hub rho = pipe_diameter / 2 - wheel_radius off the axis. The
module turns as its axis does (its frame is rotation-minimizing: no roll about e1), so the hub of leg k on ring j
moves at w = v (t_j - rho (e1' . u_k) e1) (e1' = d e1 / ds): the inside wheels of a bend slower than the outside
ones. The rings' side forces, pushing the fore ring out of the bend and the aft ring in, are a couple that the legs'
springs carry as the module cocks, nose out, by psi about e1 x d (d the unit direction of the fore ring's slip
less the aft ring's, across the pipe: the bend's inside). Cocked, the wheels roll along a' = cos(psi) e1 -
sin(psi) d, sideways along e_k turned with it, and psi solves the couple's balance

    2 k_r b psi = -(F_fore - F_aft) . d'     (d' = sin(psi) e1 + cos(psi) d),

k_r = n P / (2 ``suspension_travel``) [N/m] a ring's legs' stiffness across the pipe, b half the rings' chord, F_j
ring j's side forces summed. The right side does not grow with psi (the fore ring's slip grows as the aft ring's
falls, and a wheel's force is concave in its slip), so the root is one, bracketed by |psi| <= psi_max (the rings'
whole sideways friction over 2 k_r b) and found by regula falsi (Illinois) to PSI_TOL. The scrub force is the
wheels' dissipated power over v: nothing while no wheel reaches its limit.

Units: m, rad, N, N/m; every function on floats (numba-ready).
"""

from __future__ import annotations

import math

from .accel import jit
from .route_geometry import centreline, cross, dot, module_pose, piece_at, scale, sub

PSI_TOL = 1e-14  # rad: the cock's root to round-off of its own size (psi <= 0.1 rad; the slip angles' ~1e-17)
MAX_ROOT_STEPS = 200  # a bound: regula falsi (Illinois) on a piecewise smooth function takes 10-40


@jit
def wheel_side(alpha, stiffness, limit):
    """(the wheel's side force across the module's axis [N], signed against ``alpha``; its dissipated power per unit
    of its hub's speed [N]) at slip angle ``alpha`` [rad] with cornering stiffness ``stiffness`` [N/rad]
    (inf: rigid) and friction limit ``limit`` = mu N [N]."""
    x = abs(alpha)
    if x == 0.0 or limit <= 0.0:
        return 0.0, 0.0
    if stiffness * x < limit:  # below the limit: steered by alpha, rolling along its path
        return -math.copysign(stiffness * x * math.cos(x), alpha), 0.0
    steer = limit / stiffness  # alpha_s (0 for rigid wheels)
    return -math.copysign(limit * math.cos(steer), alpha), limit * math.sin(x - steer)


@jit
def ring_load(t, e1, e1s, e2, e3, d, psi, n, rho, stiffness, limit):
    """(the ring's side force along d' [N], the power its wheels dissipate per unit of the module's speed [N]) of
    the ring whose point moves along the unit ``t`` on a module of axis ``e1`` (``e1s`` = d e1 / ds [1/m]), frame
    ``e2``, ``e3``, cocked by ``psi`` [rad] about e1 x ``d`` (module docstring); ``n`` legs, hubs ``rho`` [m] off
    the axis."""
    q = cross(e1, d)
    d2, d3 = dot(d, e2), dot(d, e3)
    t1, td, tq = dot(t, e1), dot(t, d), dot(t, q)
    cp, sp = math.cos(psi), math.sin(psi)
    side, power = 0.0, 0.0
    for k in range(n):
        ak = -0.5 * math.pi + 2.0 * math.pi * k / n
        ca, sa = math.cos(ak), math.sin(ak)
        wa = t1 - rho * (ca * dot(e1s, e2) + sa * dot(e1s, e3))  # the hub's velocity along e1 (per unit v)
        ed, eq = -sa * d2 + ca * d3, sa * d3 + ca * d2  # e_k along d and q
        along = wa * cp - td * sp  # w . a'
        across = ed * (wa * sp + td * cp) + eq * tq  # w . e_k'
        alpha = math.atan2(across, along)
        force, drag = wheel_side(alpha, stiffness, limit)
        side += force * ed
        power += drag * math.sqrt(along * along + across * across)
    return side, power


@jit
def _slip_vector(t, e1):
    """The ring's slip as a vector across the pipe: its angle off e1 [rad] along the unit direction of t's part
    across e1 (zero where t is e1)."""
    across = sub(t, scale(dot(t, e1), e1))
    size = math.sqrt(dot(across, across))
    if size == 0.0:
        return (0.0, 0.0, 0.0)
    return scale(math.atan2(size, dot(t, e1)) / size, across)


@jit
def module_scrub(q, base, count, s, h, mu, corner, n, preload, travel, rho):
    """(the scrub force [N] along the path on a module rolling forward, the cock psi [rad]) of the module at
    station ``s`` [m] whose rings are ``h`` [m] either side along the centreline (the packed route ``q`` from
    ``base``, ``count`` pieces), on ``n`` legs per ring each preloaded with ``preload`` [N], wall friction ``mu``,
    cornering coefficient ``corner`` [1/rad] (inf: rigid wheels), legs' deflection at preload ``travel`` [m],
    hubs ``rho`` [m] off the axis (module docstring)."""
    if mu <= 0.0 or preload <= 0.0:
        return 0.0, 0.0
    A, _, _, e1, e1s, _, e2, _, _ = module_pose(q, base, count, s, h)
    Pa, ta, _, _, _, _ = centreline(q, piece_at(q, base, count, s - h), s - h)
    Pf, tf, _, _, _, _ = centreline(q, piece_at(q, base, count, s + h), s + h)
    turn = sub(_slip_vector(tf, e1), _slip_vector(ta, e1))
    size = math.sqrt(dot(turn, turn))
    if size == 0.0:  # both rings move along the module's axis: a straight
        return 0.0, 0.0
    d = scale(1.0 / size, turn)
    e3 = cross(e1, e2)
    chord = sub(Pf, Pa)
    b = 0.5 * math.sqrt(dot(chord, chord))
    stiffness, limit = corner * preload, mu * preload
    couple = 2.0 * (n * preload / (2.0 * travel)) * b  # 2 k_r b [N/rad]
    bound = 2.0 * n * limit / couple * (1.0 + 1e-12)  # both rings' whole sideways friction over 2 k_r b
    # h(psi) = couple psi + (F_fore - F_aft) . d': h(-bound) < 0 < h(bound)
    lo, hi = -bound, bound
    f_lo = couple * lo + ring_load(tf, e1, e1s, e2, e3, d, lo, n, rho, stiffness, limit)[0] \
        - ring_load(ta, e1, e1s, e2, e3, d, lo, n, rho, stiffness, limit)[0]
    f_hi = couple * hi + ring_load(tf, e1, e1s, e2, e3, d, hi, n, rho, stiffness, limit)[0] \
        - ring_load(ta, e1, e1s, e2, e3, d, hi, n, rho, stiffness, limit)[0]
    side = 0  # which end was kept last (Illinois: halve the other's value when one end is kept twice)
    psi = 0.0
    for _ in range(MAX_ROOT_STEPS):
        psi = hi - f_hi * (hi - lo) / (f_hi - f_lo)
        if not lo < psi < hi:
            psi = 0.5 * (lo + hi)
        f = couple * psi + ring_load(tf, e1, e1s, e2, e3, d, psi, n, rho, stiffness, limit)[0] \
            - ring_load(ta, e1, e1s, e2, e3, d, psi, n, rho, stiffness, limit)[0]
        if f == 0.0:
            break
        if f < 0.0:
            lo, f_lo = psi, f
            if side == -1:
                f_hi *= 0.5
            side = -1
        else:
            hi, f_hi = psi, f
            if side == 1:
                f_lo *= 0.5
            side = 1
        if hi - lo <= PSI_TOL:
            break
    power = ring_load(tf, e1, e1s, e2, e3, d, psi, n, rho, stiffness, limit)[1] \
        + ring_load(ta, e1, e1s, e2, e3, d, psi, n, rho, stiffness, limit)[1]
    return power, psi
