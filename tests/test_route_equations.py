"""The equations along a route checked against an independent symbolic derivation, hand calculations and today's
straight-pipe model.

SymPy builds the bodies' positions and frames along a route from the pieces' definitions (a straight's line, a
bend's circle and the pipe's frame turned about the bend's axis), differentiates them itself, forms the kinetic
energy from each body's own inertia (the crank as a disc, diag(J_A / 2, J_A / 2, J_A), through its frame's two
vectors in its plane: for principal inertias I_k, 1/2 sum I_k omega_k^2 = 1/2 sum (S - I_k) |e_k'|^2 with
S = sum I_k / 2, a form the kernels do not use), and applies Lagrange's equations in (s1, s2, phi) with
multipliers for the loop |C - B| = L and the held modules. Nothing from ``analytic`` is used but to evaluate the
kernel under test, so a slip in a derivative of the geometry, in the velocity terms, the loop's acceleration, the
gravity or the holds shows here.
"""

from __future__ import annotations

import functools
import math

import numpy as np
import pytest
import sympy as sp

from ipir_mujoco.analytic.grip_model import GripMode
from ipir_mujoco.analytic.route_geometry import centreline, module_pose, piece_at
from ipir_mujoco.analytic import route_kernels
from ipir_mujoco.analytic.route_kernels import LOOP_TOL, Q_COUNT, Q_PIECES
from ipir_mujoco.analytic.route_model import RouteModel, transverse_inertia
from ipir_mujoco.core.params import RobotParams
from ipir_mujoco.core.route import route_from_tables

s1, s2, ph = sp.symbols("s1 s2 phi", real=True)
Q = (s1, s2, ph)
QD = sp.symbols("v1 v2 omega", real=True)
PARAMS = RobotParams(m1=1.3, m2=0.8, r=0.05, L=0.2, J_A=2e-3, rod_mass=0.05, M=0.4, F_r1=1.2, F_r2=0.7,
                     mu_wall=0.6, F_n1=30.0, F_n2=40.0)
# an oblique bend after a straight, a bend in another plane right after it, a 0.06 m straight (shorter than the
# 0.1 m ring spacing) and a tight bend in a third plane, then the exit; the first straight climbs at 25 deg
ROUTE = route_from_tables([dict(kind="straight", length=0.5, incline=25.0),
                           dict(kind="bend", radius=0.6, angle=40.0, plane=37.0),
                           dict(kind="bend", radius=0.45, angle=-30.0, plane=120.0),
                           dict(kind="straight", length=0.06),
                           dict(kind="bend", radius=0.3, angle=50.0, plane=-70.0),
                           dict(kind="straight", length=0.4)])
H = 0.5 * PARAMS.ring_spacing


def _vec(values):
    return sp.Matrix([sp.Float(float(v), 30) for v in values])


def _piece_index(s: float) -> int:
    """The piece holding station s (the first behind the start, the last past the end: both straights)."""
    for k, piece in enumerate(ROUTE.pieces):
        if s < piece.s0 + piece.length:
            return k
    return len(ROUTE.pieces) - 1


def _centre(k: int, s):
    """(point, direction, left) of the centreline at the symbol or number s on piece k, from its definition."""
    piece = ROUTE.pieces[k]
    p0, t0, n0 = _vec(piece.point), _vec(piece.frame[0]), _vec(piece.frame[1])
    u = s - piece.s0
    if piece.kind == "straight":
        return p0 + u * t0, t0, n0
    d, axis, R = _vec(piece.toward), _vec(piece.axis), piece.radius
    a = u / R
    turn = lambda x: x * sp.cos(a) + axis.cross(x) * sp.sin(a) + axis * axis.dot(x) * (1 - sp.cos(a))  # noqa: E731
    return p0 + R * (sp.sin(a) * t0 + (1 - sp.cos(a)) * d), turn(t0), turn(n0)


def _least_turn(a, n, b):
    """n turned by the least rotation taking the unit a to the unit b."""
    c, v = a.dot(b), a.cross(b)
    return c * n + v.cross(n) + v.dot(n) * v / (1 + c)


def _rings(value: float) -> tuple[int, int]:
    """The pieces of a module's rings at station ``value`` [m]."""
    return _piece_index(value - H), _piece_index(value + H)


S = sp.Symbol("s", real=True)


@functools.lru_cache(maxsize=None)
def _layer(build, sizes: tuple[int, ...]):
    """(value, first, second derivative in s) of build(s, *inputs) for inputs that are unknown functions of s, each
    a vector (size 3) or a number (size 1), lambdified over (s, then each input's value, first and second
    derivative): sympy differentiates one step of a module's pose through the chain rule, which keeps each step's
    expression small."""
    inputs, second, first, value, args = [], {}, {}, {}, [S]
    for k, size in enumerate(sizes):
        f = sp.Matrix([sp.Function(f"u{k}{c}")(S) for c in "xyz"[:size]])
        inputs.append(f if size == 3 else f[0])
        plain = [sp.symbols(" ".join(f"w{k}_{order}_{c}" for c in "xyz"[:size]), real=True, seq=True)
                 for order in range(3)]
        for c in range(size):
            second[sp.Derivative(f[c], (S, 2))], first[sp.Derivative(f[c], S)] = plain[2][c], plain[1][c]
            value[f[c]] = plain[0][c]
        args += [*plain[0], *plain[1], *plain[2]]
    out = sp.Matrix([build(S, *inputs)])
    exprs = [e.xreplace(second).xreplace(first).xreplace(value) for e in (out, out.diff(S), out.diff(S, 2))]
    return sp.lambdify(args, exprs, "numpy")


def _apply(fn, s: float, *inputs) -> list[np.ndarray]:
    """A _layer at station s [m] of ``inputs``, each a (value, first, second derivative) triple."""
    args = [s] + [x for triple in inputs for v in triple for x in np.atleast_1d(np.asarray(v, dtype=float)).ravel()]
    return [np.asarray(v, dtype=float).ravel() for v in fn(*args)]


@functools.lru_cache(maxsize=None)
def _explicit(k: int, offset: float, index: int):
    """Lambdified (value, first, second derivative) at S of piece k's centreline point (``index`` 0) or left (2)
    at S + offset."""
    vector = _centre(k, S + offset)[index]
    return sp.lambdify(S, [vector, vector.diff(S), vector.diff(S, 2)], "numpy")


def _at(fn, s: float) -> list[np.ndarray]:
    return [np.asarray(v, dtype=float).ravel() for v in fn(s)]


def _unit(s, w):
    return w / sp.sqrt(w.dot(w))


def _turn(t, n, s, e1):
    return _least_turn(_vec(t), _vec(n), e1)


def _angle(s, b, c, e1):
    """The angle about e1 from b to c."""
    return sp.atan2(b.cross(c).dot(e1), b.dot(c))


def _step(start, span, s, gamma, b, e1):
    """b turned about e1 by (3 sigma^2 - 2 sigma^3) gamma, sigma = (s - start) / span."""
    sigma = (s - start) / span
    theta = sigma**2 * (3 - 2 * sigma) * gamma
    return sp.cos(theta) * b + sp.sin(theta) * e1.cross(b)


@functools.lru_cache(maxsize=None)
def pose(station: float) -> tuple[np.ndarray, ...]:
    """A module's point, e1, e2 at ``station`` [m], each followed by its first and second derivatives in the station
    (9 arrays (3,)), from the pieces' definitions, differentiated by sympy step by step: the rings' points, the unit
    chord, the frame turned onto it (and the smooth step while the rings span a short piece)."""
    ka, kf = _rings(station)
    aft, fore_point = _at(_explicit(ka, -H, 0), station), _at(_explicit(kf, H, 0), station)
    X = [(a + f) / 2 for a, f in zip(aft, fore_point)]
    e1 = _apply(_layer(_unit, (3,)), station, [f - a for a, f in zip(aft, fore_point)])
    if ka == kf:
        return (*X, *e1, *_at(_explicit(ka, 0.0, 2), station))
    fore = ROUTE.pieces[kf]
    e2 = _apply(_layer(functools.partial(_turn, tuple(fore.frame[0]), tuple(fore.frame[1])), (3,)), station, e1)
    if kf > ka + 1:  # a short piece between: a smooth step from the next piece's frame to the fore ring's
        nxt = ROUTE.pieces[ka + 1]
        b = _apply(_layer(functools.partial(_turn, tuple(nxt.frame[0]), tuple(nxt.frame[1])), (3,)), station, e1)
        gamma = _apply(_layer(_angle, (3, 3, 3)), station, b, e2, e1)
        step = functools.partial(_step, fore.s0 - H, nxt.s0 + 2 * H - fore.s0)
        e2 = _apply(_layer(step, (1, 3, 3)), station, gamma, b, e1)
    return (*X, *e1, *e2)


GEOMETRY = (("A", s1), ("E", s1), ("N", s1), ("C", s2), ("F", s2))  # module 1's A, e1, e2; module 2's C, e1


def _bodies():
    """The unknown functions of GEOMETRY, and the crank's vectors, the pin B, the rod's centre and direction."""
    p = PARAMS
    functions = {name: [sp.Function(f"{name}{c}")(arg) for c in "xyz"] for name, arg in GEOMETRY}
    A, e1, e2, C, f1 = (sp.Matrix(functions[name]) for name, _ in GEOMETRY)
    crank1 = sp.cos(ph) * e1 + sp.sin(ph) * e2
    crank2 = -sp.sin(ph) * e1 + sp.cos(ph) * e2
    B = A + p.r * crank1
    return functions, (A, e1, e2, C, f1, crank1, crank2, B, (B + C) / 2, (C - B) / p.L)


def _lambdify(functions, exprs):
    """``exprs`` lambdified over (s1, s2, phi, v1, v2, omega, then per vector of GEOMETRY its three components'
    values, first and second derivatives)."""
    second, first, value, symbols = {}, {}, {}, []
    for name, arg in GEOMETRY:
        for f in functions[name]:
            plain = sp.symbols(f"{f.func}_0 {f.func}_1 {f.func}_2", real=True)
            second[sp.Derivative(f, (arg, 2))], first[sp.Derivative(f, arg)], value[f] = plain[2], plain[1], plain[0]
            symbols += plain
    return tuple(sp.lambdify((*Q, *QD, *symbols), e.xreplace(second).xreplace(first).xreplace(value), "numpy")
                 for e in exprs)


@functools.lru_cache(maxsize=None)
def loop_terms():
    """Lambdified (the loop's row dPhi/dq (1, 3), its Hessian (3, 3)) of Phi = |C - B|^2 - L^2 (:func:`_lambdify`'s
    arguments), the modules' points and frames unknown functions of their stations."""
    functions, (A, e1, e2, C, f1, *_, B, G, U) = _bodies()
    loop = (C - B).dot(C - B) - PARAMS.L**2
    return _lambdify(functions, (sp.Matrix([loop]).jacobian(Q), sp.hessian(loop, Q)))


@functools.lru_cache(maxsize=None)
def lagrange():
    """Lambdified (M, the velocity and gravity terms) of Lagrange's equations in (s1, s2, phi) (:func:`_lambdify`'s
    arguments): sympy's chain rule through the unknown geometry is the derivation."""
    p = PARAMS
    functions, (A, e1, e2, C, f1, crank1, crank2, B, G, U) = _bodies()
    qd = sp.Matrix(QD)

    def rate(X):
        return X.jacobian(Q) * qd

    inertia = (transverse_inertia(p, p.m1), transverse_inertia(p, p.m2))
    T = (p.m1 * rate(A).dot(rate(A)) + inertia[0] * rate(e1).dot(rate(e1))
         + p.J_A / 2 * (rate(crank1).dot(rate(crank1)) + rate(crank2).dot(rate(crank2)))
         + p.m2 * rate(C).dot(rate(C)) + inertia[1] * rate(f1).dot(rate(f1))
         + p.rod_mass * rate(G).dot(rate(G)) + p.rod_inertia_value * rate(U).dot(rate(U))) / 2
    gravity = -p.g * _vec(ROUTE.up)
    V = -gravity.dot(p.m1 * A + p.m2 * C + p.rod_mass * G)
    momentum = sp.Matrix([sp.diff(T, v) for v in QD])
    terms = momentum.jacobian(Q) * qd - sp.Matrix([sp.diff(T, q) for q in Q]) + sp.Matrix([sp.diff(V, q) for q in Q])
    return _lambdify(functions, (sp.hessian(T, QD), terms))


def geometry(station1: float, station2: float) -> list[float]:
    """The values of lagrange()'s geometry arguments at the stations (module 2's e2 is not needed)."""
    m1, m2 = pose(station1), pose(station2)
    out = []
    for triple in (m1[0:3], m1[3:6], m1[6:9], m2[0:3], m2[3:6]):
        for c in range(3):
            out += [triple[0][c], triple[1][c], triple[2][c]]
    return out


def loop_gap(station1: float, station2: float, phi: float) -> float:
    """|C - B|^2 - L^2 from the definitions."""
    A, e1, e2 = pose(station1)[0::3]
    C = pose(station2)[0]
    B = A + PARAMS.r * (math.cos(phi) * e1 + math.sin(phi) * e2)
    return float((C - B) @ (C - B) - PARAMS.L**2)


def closed(model: RouteModel, station: float, phi: float) -> float:
    """Module 2's station [m] with module 1's at ``station`` and the crank at phi: the kernel's Newton solve (from
    the straight pipe's gap), checked against the definitions: |C - B|^2 - L^2 within what the kernel counts as
    closed (LOOP_TOL L (L + s1 + s2), a few roundings of the points' coordinates), twice that for this side's own
    round-off."""
    y = np.array([phi, 0.0, station, station + PARAMS.L + PARAMS.r * math.cos(phi), 0.0, 0.0, 0.0])
    s2v = model.state(y, GripMode.EXPANSION)[1]
    assert abs(loop_gap(station, s2v, phi)) <= 2 * LOOP_TOL * PARAMS.L * (PARAMS.L + station + s2v)
    return s2v


def symbolic(mode: GripMode, station1: float, s2v: float, phi: float, omega: float, v1: float, scrub=(0.0, 0.0)):
    """(v1, v2, alpha, a1, a2, R1, R2) from the symbolic equations in ``mode`` at s1 = station1, s2 = s2v; ``scrub``
    [N]: each module's scrub force, added to its rolling resistance while it rolls (its closed form is
    tests/test_route_scrub.py's)."""
    p = PARAMS
    mass_f, terms_f = lagrange()
    row_f, hessian_f = loop_terms()
    g = geometry(station1, s2v)
    row = np.asarray(row_f(station1, s2v, phi, 0, 0, 0, *g), dtype=float).ravel()
    hessian = np.asarray(hessian_f(station1, s2v, phi, 0, 0, 0, *g), dtype=float)
    held = mode.states
    if held == (1, 0):  # contraction: module 2 stands
        v = (-row[2] / row[0] * omega, 0.0)
    elif held == (0, 1):
        v = (0.0, -row[2] / row[1] * omega)
    else:
        v = (v1, -(row[0] * v1 + row[2] * omega) / row[1])
    state = (station1, s2v, phi, v[0], v[1], omega, *g)
    M = np.asarray(mass_f(*state), dtype=float)
    h = np.asarray(terms_f(*state), dtype=float).ravel()
    rolling = (p.F_r1 + scrub[0], p.F_r2 + scrub[1])
    forces = np.array([-rolling[i] if held[i] == 1 else 0.0 for i in (0, 1)] + [p.M])
    rows = [row] + [np.eye(3)[i] for i in (0, 1) if held[i] == 0]
    A = np.array(rows)
    kkt = np.block([[M, -A.T], [A, np.zeros((len(rows), len(rows)))]])
    qd = np.array(v + (omega,))
    rhs = np.concatenate([forces - h, [-float(qd @ hessian @ qd)] + [0.0] * (len(rows) - 1)])
    solution = np.linalg.solve(kkt, rhs)
    qdd, multipliers = solution[:3], list(solution[4:])
    holds = [multipliers.pop(0) if held[i] == 0 else math.nan for i in (0, 1)]
    return v[0], v[1], qdd[2], qdd[0], qdd[1], holds[0], holds[1]


@pytest.fixture(scope="module")
def model():
    return RouteModel(PARAMS.replace(incline=25.0), ROUTE, "unilateral")


# stations [m] with a module's rings in the first straight, across the straight-bend joint, in the oblique bend,
# across the joint of two bends in different planes, across the bend-short-straight joint, across the short
# straight-bend joint; and (slow) spanning the short straight, rings either side of it
STATIONS = (0.3, 0.47, 0.7, 0.93, 1.13, 1.25)
SPANNING = 1.18


def test_the_kernels_centreline_is_the_routes(model):
    """The kernels' centreline point, direction and the pipe's left (parallel transported) at stations all along the
    route against the route's own geometry (ipir_mujoco.core.route, written apart), to round-off; behind the start
    and past the end it runs straight on along the first and the last direction."""
    p = model.constants[GripMode.BOTH_MOVING]
    count = int(p[Q_COUNT])
    for s in np.linspace(0.0, ROUTE.length, 97):
        point, direction, _, left, _, _ = centreline(p, piece_at(p, Q_PIECES, count, s), s)
        expected, along = ROUTE.at3(s)
        assert np.array(point) == pytest.approx(expected, abs=1e-12)
        assert np.array(direction) == pytest.approx(along, abs=1e-12)
        assert np.array(left) == pytest.approx(ROUTE.frame_at(s)[1], abs=1e-12)
    end, along = ROUTE.at3(ROUTE.length)
    for s, expected in ((ROUTE.length + 0.3, end + 0.3 * along), (-0.2, np.array([-0.2, 0.0, 0.0]))):
        assert np.array(centreline(p, piece_at(p, Q_PIECES, count, s), s)[0]) == pytest.approx(expected, abs=1e-12)


@pytest.mark.parametrize("station", STATIONS)
def test_a_modules_pose_and_its_derivatives_match_sympys(model, station):
    """The kernels' point, axis and left of a module and their first and second derivatives in the station, against
    sympy's differentiation of the definitions, to 1e-11 (round-off of a few hundred operations on lengths of order
    1 m; a wrong derivative is off by its own size, 1e-2 or more)."""
    p = model.constants[GripMode.BOTH_MOVING]
    got = module_pose(p, Q_PIECES, int(p[Q_COUNT]), station, H)
    for value, expected in zip(got, pose(station)):
        assert np.asarray(value) == pytest.approx(expected, abs=1e-11)


@pytest.mark.parametrize("station", STATIONS)
def test_the_loops_row_and_curvature_match_sympys(model, station):
    """The loop Phi = |C - B|^2 - L^2 closed at random crank angles (:func:`closed`): each mode's velocities (the null
    space of dPhi/dq and the holds) and dK2/dphi, the gap's second-order motion at a dead centre (from Phi's
    Hessian), against sympy's derivatives."""
    rng = np.random.default_rng(int(station * 100))
    row_f, hessian_f = loop_terms()
    for _ in range(3):
        phi, omega, v1 = rng.uniform(0, 2 * math.pi), rng.uniform(-20, 20), rng.uniform(0.0, 1.0)
        s2v = closed(model, station, phi)
        g = geometry(station, s2v)
        row = np.asarray(row_f(station, s2v, phi, 0, 0, 0, *g), dtype=float).ravel()
        hessian = np.asarray(hessian_f(station, s2v, phi, 0, 0, 0, *g), dtype=float)
        y = np.array([phi, omega, station, s2v, v1, 0.0, 0.0])
        K2 = -row[2] / row[1]
        assert model.state(y, GripMode.CONTRACTION)[2] == pytest.approx(-row[2] / row[0] * omega, rel=1e-10)
        assert model.state(y, GripMode.EXPANSION)[3] == pytest.approx(K2 * omega, rel=1e-10)
        assert model.state(y, GripMode.BOTH_MOVING)[3] == pytest.approx(-(row[0] * v1 + row[2] * omega) / row[1],
                                                                        rel=1e-10, abs=1e-13)
        expansion = model.state(y, GripMode.EXPANSION)
        assert expansion[13] == pytest.approx(K2, rel=1e-10)
        dK2 = -(hessian[2, 2] + 2 * hessian[1, 2] * K2 + hessian[1, 1] * K2 * K2) / row[1]
        assert expansion[14] == pytest.approx(dK2, rel=1e-9, abs=1e-12)


@pytest.mark.slow
@pytest.mark.parametrize("station", (*STATIONS, SPANNING))
@pytest.mark.parametrize("mode", (GripMode.CONTRACTION, GripMode.EXPANSION, GripMode.BOTH_MOVING))
def test_the_route_kernels_match_lagrange_at_random_states(model, station, mode):
    """At random crank angles and speeds: the module velocities, accelerations and holds against Lagrange's
    equations with multipliers, to 1e-9 of their scale (the two evaluate the same sums in different orders, with
    the loop closed by different solvers to 1e-15 m; the mass matrix's conditioning amplifies round-off to ~1e-12;
    a wrong term is of the order of the terms themselves)."""
    rng = np.random.default_rng(int(station * 1000) + int(mode))
    for _ in range(2):
        phi, omega, v1 = rng.uniform(0, 2 * math.pi), rng.uniform(-20, 20), rng.uniform(0.0, 1.0)
        s2v = closed(model, station, phi)
        scrub = [route_kernels.scrub_force(model.constants[mode], i, s, 0.0) for i, s in enumerate((station, s2v))]
        want = symbolic(mode, station, s2v, phi, omega, v1, scrub)
        y = np.array([phi, omega, station, s2v, v1, 0.0, 0.0])
        got = model.state(y, mode)
        # scales: accelerations r omega^2 + g, forces (m1 + m2) times that
        accel = PARAMS.r * omega**2 + PARAMS.g + 10.0
        scales = (1.0, 1.0, accel / PARAMS.r, accel, accel, 3 * accel, 3 * accel)
        for value, expected, scale in zip(got[2:9], want, scales):
            if math.isnan(expected):
                assert math.isnan(value)
            else:
                assert value == pytest.approx(expected, abs=1e-9 * scale)
