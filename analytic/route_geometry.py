"""Where the robot's modules are along a route, for the route's scalar kernels (:mod:`.route_kernels`).

A route (:class:`ipir_mujoco.core.route.Route`) travels to the kernels as floats (:func:`pack_route`): per piece
PIECE numbers, its kind, start s0 [m], length [m], start point P0 [m], direction t0, left n0 (the pipe's frame as
it arrives, parallel transported), and for a bend the direction d towards its centre, its turning axis k = t0 x d
and its radius R [m]; after the last piece an exit straight of infinite length, and behind the start the first
straight goes on backwards, so that a module's rings reaching beyond the route are still on a centreline.

The centreline at s (:func:`centreline`): in a straight P = P0 + u t0 (u = s - s0); in a bend, with
phi = u / R, P = P0 + R (sin phi t0 + (1 - cos phi) d), and every frame vector X turns about k:
X' = (1/R) k x X. So P' = t, P'' = t' (0 in a straight, d(s) / R in a bend) and the left n, n', n''.

A module (:func:`module_pose`) is a rigid body whose two rings, ``ring_spacing`` = 2 h apart along its axis, are
centred on the centreline by their legs: its station s puts the rings at the centreline points P(s - h) and
P(s + h); its point (A for module 1, C for module 2) is their midpoint, its axis e1 the unit chord between them.
In a straight that is P(s) and t; in a bend of radius R the point sits R (1 - cos(h / R)) inside the centreline
and e1 is the tangent at s. The rings are then 2 R sin(h / R), about h^3 / (3 R^2) less than 2 h, apart (0.4 mm of
the default 0.1 m at R / D 2): rings exactly 2 h apart, at s -+ R asin(h / R), would move the point by
h^4 / (6 R^3) (0.03 mm) and turn nothing.

Its left e2 (e3 = e1 x e2; the crank turns in the plane of e1, e2): a module does not roll about its own axis (its
wheels hold it), so its frame turns the least way that keeps e1 its axis, the rotation-minimizing frame of e1(s).
With both rings on one piece that is the pipe's frame at s; with the rings on two neighbouring pieces it is the
fore ring's piece's frame at that piece's start turned the least way onto e1 (:func:`turned`). Where the two
pieces share a plane (a straight and a bend) that is exactly the rotation-minimizing frame; wherever they meet, e2
and e2' are continuous as a ring crosses the joint (e1 and e1' lie in the uniform piece's plane there, where the
least rotation turns about that piece's axis as the pipe's frame does), so the crank pin's velocity is continuous
and the energy audit closes. Between two bends in different planes the module rolls a little on the way
(its frame's holonomy, of order (h / R1)(h / R2)) and comes out square with the pipe's frame again. With a piece
shorter than 2 h between the rings, e2 turns from the frame of the piece after the aft ring's to the fore ring's
piece's by a smooth step (:func:`blend`) while the rings span it, continuous with both; three or more pieces
under one module (two pieces shorter than 2 h in a row) are not blended so.
Each returned with its first and second derivatives with respect to s (numba-ready tuples).
"""

from __future__ import annotations

import math

import numpy as np

from .accel import jit

PIECE = 19  # floats per packed piece: kind, s0, length, P0 (3), t0 (3), n0 (3), d (3), k (3), R
K_KIND, K_S0, K_LEN, K_P, K_T, K_N, K_D, K_AX, K_R = 0, 1, 2, 3, 6, 9, 12, 15, 18


def pack_route(route) -> np.ndarray:
    """The route's pieces and its exit straight as the kernels' floats, (PIECE * (pieces + 1),)."""
    rows = []
    for piece in route.pieces:
        t, n = piece.frame[0], piece.frame[1]
        head = [0.0 if piece.kind == "straight" else 1.0, piece.s0, piece.length, *piece.point, *t, *n]
        if piece.kind == "straight":
            rows.append(head + [0.0] * 7)
        else:
            rows.append(head + [*piece.toward, *piece.axis, piece.radius])
    end, _ = route.at3(route.length)
    frame = route.frame_at(route.length)
    rows.append([0.0, route.length, math.inf, *end, *frame[0], *frame[1]] + [0.0] * 7)
    return np.array(rows, dtype=float).ravel()


@jit
def add(a, b):
    return (a[0] + b[0], a[1] + b[1], a[2] + b[2])


@jit
def sub(a, b):
    return (a[0] - b[0], a[1] - b[1], a[2] - b[2])


@jit
def scale(c, a):
    return (c * a[0], c * a[1], c * a[2])


@jit
def dot(a, b):
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


@jit
def cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


@jit
def combine(a, x, b, y):
    """a x + b y for scalars a, b and vectors x, y."""
    return (a * x[0] + b * y[0], a * x[1] + b * y[1], a * x[2] + b * y[2])


@jit
def _vector(q, at):
    return (q[at], q[at + 1], q[at + 2])


@jit
def piece_at(q, base, count, s):
    """Offset in q of the packed piece that holds station s [m] (the first piece before the start, the exit
    straight past the end)."""
    k = 0
    while k < count - 1 and s >= q[base + k * PIECE + K_S0] + q[base + k * PIECE + K_LEN]:
        k += 1
    return base + k * PIECE


@jit
def centreline(q, at, s):
    """(P, P', P'', n, n', n'') of the centreline at s [m] (derivatives in s) on the packed piece at offset ``at``."""
    u = s - q[at + K_S0]
    p0, t0, n0 = _vector(q, at + K_P), _vector(q, at + K_T), _vector(q, at + K_N)
    zero = (0.0, 0.0, 0.0)
    if q[at + K_KIND] == 0.0:
        return add(p0, scale(u, t0)), t0, zero, n0, zero, zero
    d, axis, R = _vector(q, at + K_D), _vector(q, at + K_AX), q[at + K_R]
    phi = u / R
    c, sn = math.cos(phi), math.sin(phi)
    P = add(p0, combine(R * sn, t0, R * (1.0 - c), d))
    t = combine(c, t0, sn, d)
    t1 = combine(-sn / R, t0, c / R, d)
    n = add(combine(c, n0, sn, cross(axis, n0)), scale(dot(axis, n0) * (1.0 - c), axis))
    n1 = scale(1.0 / R, cross(axis, n))
    n2 = scale(1.0 / R, cross(axis, n1))
    return P, t, t1, n, n1, n2


@jit
def unit(w, w1, w2):
    """(u, u', u'') of u = w / |w| from w and its derivatives w', w''."""
    rho = math.sqrt(dot(w, w))
    u = scale(1.0 / rho, w)
    rho1 = dot(u, w1)
    u1 = scale(1.0 / rho, sub(w1, scale(rho1, u)))
    rho2 = dot(u1, w1) + dot(u, w2)
    u2 = scale(1.0 / rho, sub(sub(w2, scale(2.0 * rho1, u1)), scale(rho2, u)))
    return u, u1, u2


@jit
def turned(a, n, b, b1, b2):
    """(x, x', x'') of x = the least rotation taking the unit vector a to b applied to n (a, n constant; b = b(s)
    with b', b''): x = c n + v x n + (v . n) v / (1 + c), c = a . b, v = a x b."""
    c, c1, c2 = dot(a, b), dot(a, b1), dot(a, b2)
    v, v1, v2 = cross(a, b), cross(a, b1), cross(a, b2)
    q, q1, q2 = dot(v, n), dot(v1, n), dot(v2, n)
    mu = 1.0 / (1.0 + c)
    mu1 = -c1 * mu * mu
    mu2 = -c2 * mu * mu + 2.0 * c1 * c1 * mu * mu * mu
    k, k1, k2 = q * mu, q1 * mu + q * mu1, q2 * mu + 2.0 * q1 * mu1 + q * mu2
    x = add(add(scale(c, n), cross(v, n)), scale(k, v))
    x1 = add(add(scale(c1, n), cross(v1, n)), combine(k1, v, k, v1))
    x2 = add(add(add(scale(c2, n), cross(v2, n)), combine(k2, v, 2.0 * k1, v1)), scale(k, v2))
    return x, x1, x2


@jit
def module_pose(q, base, count, s, h):
    """(X, X', X'', e1, e1', e1'', e2, e2', e2'') of a module at station s [m] whose rings are h [m] either side of
    it along the centreline (module docstring); derivatives in s."""
    at_a, at_f = piece_at(q, base, count, s - h), piece_at(q, base, count, s + h)
    Pa, ta, ta1, _, _, _ = centreline(q, at_a, s - h)
    Pf, tf, tf1, _, _, _ = centreline(q, at_f, s + h)
    X, X1, X2 = scale(0.5, add(Pa, Pf)), scale(0.5, add(ta, tf)), scale(0.5, add(ta1, tf1))
    e1, e11, e12 = unit(sub(Pf, Pa), sub(tf, ta), sub(tf1, ta1))
    if at_a == at_f:  # both rings on one piece: e1 is the tangent at s, the module's frame the pipe's there
        _, _, _, e2, e21, e22 = centreline(q, at_a, s)
        return X, X1, X2, e1, e11, e12, e2, e21, e22
    # across a joint: the fore ring's piece's frame where it starts, turned the least way onto e1
    e2, e21, e22 = turned(_vector(q, at_f + K_T), _vector(q, at_f + K_N), e1, e11, e12)
    at_b = at_a + PIECE  # the piece after the aft ring's: the same as the fore ring's unless a piece lies between
    if at_b != at_f:  # from its frame's turn (the fore ring crossed its end) to the fore ring's piece's
        b, b1, b2 = turned(_vector(q, at_b + K_T), _vector(q, at_b + K_N), e1, e11, e12)
        start, span = q[at_f + K_S0] - h, q[at_b + K_S0] + 2.0 * h - q[at_f + K_S0]
        e2, e21, e22 = blend(b, b1, b2, e2, e21, e22, e1, e11, e12, (s - start) / span, 1.0 / span)
    return X, X1, X2, e1, e11, e12, e2, e21, e22


@jit
def _triple(a, b, c):
    return dot(cross(a, b), c)


@jit
def blend(b, b1, b2, c, c1, c2, e, e1, e2, sigma, rate):
    """(x, x', x'') turning the unit vector b (square to the unit e) about e towards c (also square to e) by
    w(sigma) of the angle gamma between them, w = 3 sigma^2 - 2 sigma^3 (0 at sigma <= 0, 1 at sigma >= 1,
    w' = 0 at both ends: x and x' are b's at sigma = 0 and c's at 1); sigma' = ``rate``; each with its
    derivatives."""
    x, y = dot(b, c), _triple(b, c, e)
    x1 = dot(b1, c) + dot(b, c1)
    x2 = dot(b2, c) + 2.0 * dot(b1, c1) + dot(b, c2)
    y1 = _triple(b1, c, e) + _triple(b, c1, e) + _triple(b, c, e1)
    y2 = (_triple(b2, c, e) + _triple(b, c2, e) + _triple(b, c, e2)
          + 2.0 * (_triple(b1, c1, e) + _triple(b1, c, e1) + _triple(b, c1, e1)))
    r2, num = x * x + y * y, x * y1 - y * x1
    gamma, gamma1 = math.atan2(y, x), num / r2
    gamma2 = ((x * y2 - y * x2) * r2 - num * 2.0 * (x * x1 + y * y1)) / (r2 * r2)
    sigma = min(max(sigma, 0.0), 1.0)
    w, w1 = sigma * sigma * (3.0 - 2.0 * sigma), 6.0 * sigma * (1.0 - sigma) * rate
    w2 = (6.0 - 12.0 * sigma) * rate * rate
    if sigma == 0.0 or sigma == 1.0:
        w2 = 0.0
    th, th1 = w * gamma, w1 * gamma + w * gamma1
    th2 = w2 * gamma + 2.0 * w1 * gamma1 + w * gamma2
    p, p1 = cross(e, b), add(cross(e1, b), cross(e, b1))
    p2 = add(add(cross(e2, b), scale(2.0, cross(e1, b1))), cross(e, b2))
    cs, sn = math.cos(th), math.sin(th)
    out = combine(cs, b, sn, p)
    turn = combine(-sn, b, cs, p)  # d out / d th
    out1 = add(combine(cs, b1, sn, p1), scale(th1, turn))
    out2 = add(add(combine(cs, b2, sn, p2), scale(2.0 * th1, combine(-sn, b1, cs, p1))),
               sub(scale(th2, turn), scale(th1 * th1, out)))
    return out, out1, out2
