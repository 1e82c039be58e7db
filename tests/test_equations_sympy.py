"""The equations of motion checked against an independent symbolic derivation.

Sympy builds the kinetic energy from the positions of the bodies (modules, crank,
rod centre of mass and rod angle), differentiating those positions itself, and
the potential energy of gravity along the pipe from the same positions; the
drive's torque is the constant M or the motor line M_stall (1 - omega /
omega_noload), written here from its definition. It applies Lagrange's equation
with the locked module removed (one module held) or with both free (both
sliding). Nothing from ``analytic`` is used except to evaluate the function
under test, so a sign slip or a wrong derivative in K, K', the rod
coefficients, the gravity terms or the torque shows up here.
"""

from __future__ import annotations

import functools

import numpy as np
import pytest
import sympy as sp

from ipir_mujoco.analytic.dynamics import OneDofDynamics
from ipir_mujoco.core.params import RobotParams
from ipir_mujoco.core.results import Mode

ph, w, al, v, a1, x1, c = sp.symbols("phi omega alpha v a1 x1 c", real=True)
m1, m2, J_A, mr, Ir, r, L, F1, F2 = sp.symbols("m1 m2 J_A m_rod I_rod r L F1 F2", positive=True)
tau0, damping = sp.symbols("tau0 damping", real=True)  # the drive's torque line: tau0 - damping * omega
ag = sp.Symbol("a_g", real=True)  # acceleration of gravity along the pipe axis x
SYMBOLS = (m1, m2, J_A, mr, Ir, r, L, F1, F2, tau0, damping, ag)


def _mechanism(geometry: str):
    """Kinetic energy T(v, omega, phi), potential V(x1, phi) and crank torque, from the bodies' positions."""
    if geometry == "approx":
        S = L + r * sp.cos(ph)  # the paper's first-order gap; the paper ignores the rod
        rod_T, rod_x = 0, 0
    else:
        S = r * sp.cos(ph) + sp.sqrt(L**2 - r**2 * sp.sin(ph) ** 2)
        Gx = (r * sp.cos(ph) + S) / 2  # rod centre relative to A: mid-point of B and C
        Gy = r * sp.sin(ph) / 2
        beta = sp.asin(-r * sp.sin(ph) / L)  # rod angle from +x
        rod_T = (mr * ((v + sp.diff(Gx, ph) * w) ** 2 + (sp.diff(Gy, ph) * w) ** 2)
                 + Ir * (sp.diff(beta, ph) * w) ** 2) / 2
        rod_x = mr * (x1 + Gx)
    x2_dot = v + sp.diff(S, ph) * w  # v = x1_dot
    T = m1 * v**2 / 2 + m2 * x2_dot**2 / 2 + J_A * w**2 / 2 + rod_T
    # gravity along x pulls every body's x with a_g: V = -a_g * (sum of mass * x), x2 = x1 + S
    V = -ag * (m1 * x1 + m2 * (x1 + S) + rod_x)
    return S, T, V, tau0 - damping * w


@functools.lru_cache(maxsize=None)
def derived(geometry: str, mode: Mode):
    """Lambdified (alpha, lambda_locked) of (phi, omega, *SYMBOLS), from first principles."""
    S, T, V, torque = _mechanism(geometry)
    if mode is Mode.CONTRACTION:  # front locked: x2_dot = 0, so x1 = c - S(phi)
        v_of, x1_of = -sp.diff(S, ph) * w, c - S
        F_moving = F1
        virtual_work = torque - F1 * (-sp.diff(S, ph))  # M dphi - F1 dx1
    else:  # rear locked: x1_dot = 0
        v_of, x1_of = sp.Integer(0), c
        F_moving = F2
        virtual_work = torque - F2 * sp.diff(S, ph)  # M dphi - F2 dx2
    T1, V1 = T.subs(v, v_of), V.subs(x1, x1_of)
    lagrange = sp.diff(T1, w, ph) * w + sp.diff(T1, w, 2) * al - sp.diff(T1, ph) + sp.diff(V1, ph) - virtual_work
    # Lagrange's equation is linear in alpha: alpha = -(its value at alpha=0) / (its alpha coefficient).
    alpha = -lagrange.subs(al, 0) / sp.diff(lagrange, al)
    # x1-row with the hold as the external force (it acts on module 1 or 2, both move with x1):
    # d/dt dT/dx1_dot + dV/dx1 = hold - F_moving
    momentum = sp.diff(T, v).subs(v, v_of)
    reaction = sp.diff(momentum, ph) * w + sp.diff(momentum, w) * al + sp.diff(V, x1) + F_moving
    args = (ph, w) + SYMBOLS
    alpha_fn, reaction_fn = sp.lambdify(args, alpha, "numpy"), sp.lambdify((al,) + args, reaction, "numpy")
    return alpha_fn, lambda *values: reaction_fn(alpha_fn(*values), *values)


@functools.lru_cache(maxsize=None)
def derived_both_moving(geometry: str):
    """Lambdified (x1_ddot, alpha) of the two-DOF robot with both modules sliding, from Lagrange's equations."""
    S, T, V, torque = _mechanism(geometry)
    # virtual work of the resistances: -F1 dx1 - F2 dx2 with dx2 = dx1 + S' dphi
    rows = [sp.diff(T, v, v) * a1 + sp.diff(T, v, w) * al + sp.diff(T, v, ph) * w + sp.diff(V, x1) + F1 + F2,
            sp.diff(T, w, v) * a1 + sp.diff(T, w, w) * al + sp.diff(T, w, ph) * w - sp.diff(T, ph) + sp.diff(V, ph)
            - torque + F2 * sp.diff(S, ph)]
    # linear in (x1_ddot, alpha): coefficients and right-hand sides, solved numerically (Cramer's rule)
    coefficients = sp.lambdify((ph, w, v) + SYMBOLS, [sp.diff(row, a1) for row in rows]
                               + [sp.diff(row, al) for row in rows] + [-row.subs({a1: 0, al: 0}) for row in rows],
                               "numpy")

    def solve(*values):
        A, C, B, D, e, f = (np.broadcast_to(c, np.shape(values[0])) for c in coefficients(*values))
        det = A * D - B * C
        return (e * D - B * f) / det, (A * f - e * C) / det
    return solve


def _random_case(rng: np.random.Generator, drive: str = "torque"):
    r_val = rng.uniform(0.01, 0.1)
    params = RobotParams(
        m1=rng.uniform(0.2, 3), m2=rng.uniform(0.2, 3), r=r_val, L=r_val * rng.uniform(1.2, 10),
        J_A=rng.uniform(1e-4, 1e-2), F_r1=rng.uniform(0, 5), F_r2=rng.uniform(0, 5),
        M=rng.uniform(-1, 1), rod_mass=rng.uniform(0, 0.5), rod_inertia=rng.uniform(0, 1e-3),
        drive=drive, M_stall=rng.uniform(0.05, 2), omega_noload=rng.uniform(5, 100),
        incline=rng.uniform(-90, 90), g=rng.uniform(0, 20),
    )
    # speeds from backward through rest to past the motor's no-load speed
    return params, rng.uniform(-2 * np.pi, 4 * np.pi, 20), rng.uniform(-80, 120, 20)


def _values(params: RobotParams):
    """Numbers for SYMBOLS, from the definitions: the motor line M_stall (1 - omega / omega_noload)
    (or the constant M) and gravity's component along a pipe climbing at +incline."""
    line = (params.M_stall, params.M_stall / params.omega_noload) if params.drive == "motor" else (params.M, 0.0)
    a_g = -params.g * np.sin(np.radians(params.incline))
    return (params.m1, params.m2, params.J_A, params.rod_mass, params.rod_inertia_value, params.r, params.L,
            params.F_r1, params.F_r2, *line, a_g)


@pytest.mark.parametrize("geometry", ["approx", "exact"])
@pytest.mark.parametrize("mode", [Mode.CONTRACTION, Mode.EXPANSION])
def test_rhs_and_reaction_match_symbolic_lagrange(geometry, mode):
    alpha_fn, reaction_fn = derived(geometry, mode)
    rng = np.random.default_rng(20261122 + 7 * int(mode) + len(geometry))
    for case in range(12):
        params, phis, omegas = _random_case(rng, ("torque", "motor")[case % 2])
        values = _values(params)
        dyn = OneDofDynamics(params, geometry)
        state = dyn.state(phis, omegas, mode)  # the drive's own torque and gravity from params
        expected_alpha = alpha_fn(phis, omegas, *values)
        expected_reaction = reaction_fn(phis, omegas, *values)
        locked = state.lambda2 if mode is Mode.CONTRACTION else state.lambda1
        # Both sides are closed-form double-precision expressions of the same
        # quantities; they differ only by roundoff, a few ulp amplified by
        # cancellation in terms of size ~ m r omega^2 (at most ~1e4 here) and m g.
        torque = max(abs(params.M), params.M_stall * (1 + 120 / params.omega_noload))
        weight = (params.m1 + params.m2 + params.rod_mass) * params.g
        scale_alpha = np.abs(expected_alpha) + (torque + weight * params.r) / params.J_A + 1.0
        scale_force = np.abs(expected_reaction) + (params.m1 + params.m2) * params.r * omegas**2 + weight + 1.0
        np.testing.assert_array_less(np.abs(state.alpha - expected_alpha), 1e-10 * scale_alpha)
        np.testing.assert_array_less(np.abs(locked - expected_reaction), 1e-10 * scale_force)


@pytest.mark.parametrize("geometry", ["approx", "exact"])
def test_both_moving_matches_symbolic_lagrange(geometry):
    solve = derived_both_moving(geometry)
    rng = np.random.default_rng(7 + len(geometry))
    for case in range(12):
        params, phis, omegas = _random_case(rng, ("torque", "motor")[case % 2])
        values = _values(params)
        x1dd, alpha = OneDofDynamics(params, geometry).both_moving(phis, omegas)
        v_any = rng.uniform(0, 3, phis.shape)  # T is quadratic in velocities: x1_dot drops out of the result
        torque = max(abs(params.M), params.M_stall * (1 + 120 / params.omega_noload))
        weight = (params.m1 + params.m2 + params.rod_mass) * params.g
        # roundoff of terms of size m r omega^2, m g and torque / r, divided by the masses (as above)
        scale_a = (params.r * omegas**2 + weight / min(params.m1, params.m2)
                   + (torque / params.r + params.F_r1 + params.F_r2) / min(params.m1, params.m2) + 1.0)
        expected_x1dd, expected_alpha = solve(phis, omegas, v_any, *values)
        np.testing.assert_array_less(np.abs(x1dd - expected_x1dd), 1e-9 * scale_a)
        np.testing.assert_array_less(np.abs(alpha - expected_alpha), 1e-9 * scale_a / params.r)


def test_approx_geometry_is_the_papers_equation_13_and_19():
    """The paper's printed form: (J_A + m r^2 sin^2) alpha + m r^2 sin cos omega^2 = M -/+ F r sin."""
    p = RobotParams(m1=1.3, m2=0.7, F_r1=0.8, F_r2=1.9)
    dyn = OneDofDynamics(p, "approx")
    phi, omega = np.linspace(0.1, 6.0, 13), np.linspace(-30, 40, 13)
    s, c = np.sin(phi), np.cos(phi)
    for mode, m, q in ((Mode.CONTRACTION, p.m1, p.M - p.F_r1 * p.r * s),
                       (Mode.EXPANSION, p.m2, p.M + p.F_r2 * p.r * s)):
        paper = (q - m * p.r**2 * s * c * omega**2) / (p.J_A + m * p.r**2 * s**2)
        np.testing.assert_allclose(dyn.acceleration(phi, omega, mode), paper, rtol=1e-12)
