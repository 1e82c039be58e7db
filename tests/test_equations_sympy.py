"""The equations of motion checked against an independent symbolic derivation.

Sympy builds the kinetic energy from the positions of the bodies (modules, crank,
rod centre of mass and rod angle), differentiating those positions itself, and
applies Lagrange's equation with the locked module removed. Nothing from
``analytic`` is used except to evaluate the function under test, so a sign slip
or a wrong derivative in K, K', or the rod coefficients shows up here.
"""

from __future__ import annotations

import functools

import numpy as np
import pytest
import sympy as sp

from ipir_mujoco.analytic.dynamics import OneDofDynamics
from ipir_mujoco.analytic.params import RobotParams
from ipir_mujoco.analytic.results import Mode

ph, w, al, v = sp.symbols("phi omega alpha v", real=True)
m1, m2, J_A, mr, Ir, r, L, M, F1, F2 = sp.symbols("m1 m2 J_A m_rod I_rod r L M F1 F2", positive=True)
SYMBOLS = (m1, m2, J_A, mr, Ir, r, L, M, F1, F2)


@functools.lru_cache(maxsize=None)
def derived(geometry: str, mode: Mode):
    """Lambdified (alpha, lambda_locked) of (phi, omega, *SYMBOLS), from first principles."""
    if geometry == "approx":
        S = L + r * sp.cos(ph)  # the paper's first-order gap; the paper ignores the rod
        rod_T = 0
    else:
        S = r * sp.cos(ph) + sp.sqrt(L**2 - r**2 * sp.sin(ph) ** 2)
        Gx = (r * sp.cos(ph) + S) / 2  # rod centre relative to A: mid-point of B and C
        Gy = r * sp.sin(ph) / 2
        beta = sp.asin(-r * sp.sin(ph) / L)  # rod angle from +x
        rod_T = (mr * ((v + sp.diff(Gx, ph) * w) ** 2 + (sp.diff(Gy, ph) * w) ** 2)
                 + Ir * (sp.diff(beta, ph) * w) ** 2) / 2
    x2_dot = v + sp.diff(S, ph) * w  # v = x1_dot
    T = m1 * v**2 / 2 + m2 * x2_dot**2 / 2 + J_A * w**2 / 2 + rod_T
    if mode is Mode.CONTRACTION:  # front locked: x2_dot = 0
        v_of = -sp.diff(S, ph) * w
        F_moving = F1
        virtual_work = M - F1 * (-sp.diff(S, ph))  # M dphi - F1 dx1
    else:  # rear locked: x1_dot = 0
        v_of = sp.Integer(0)
        F_moving = F2
        virtual_work = M - F2 * sp.diff(S, ph)  # M dphi - F2 dx2
    T1 = T.subs(v, v_of)
    lagrange = sp.diff(T1, w, ph) * w + sp.diff(T1, w, 2) * al - sp.diff(T1, ph) - virtual_work
    # Lagrange's equation is linear in alpha: alpha = -(its value at alpha=0) / (its alpha coefficient).
    alpha = -lagrange.subs(al, 0) / sp.diff(lagrange, al)
    momentum = sp.diff(T, v).subs(v, v_of)  # dT/dx1_dot: the total momentum along x
    reaction = sp.diff(momentum, ph) * w + sp.diff(momentum, w) * al + F_moving
    args = (ph, w) + SYMBOLS
    return sp.lambdify(args, alpha, "numpy"), sp.lambdify(args, reaction.subs(al, alpha), "numpy")


def _random_case(rng: np.random.Generator):
    r_val = rng.uniform(0.01, 0.1)
    params = RobotParams(
        m1=rng.uniform(0.2, 3), m2=rng.uniform(0.2, 3), r=r_val, L=r_val * rng.uniform(1.2, 10),
        J_A=rng.uniform(1e-4, 1e-2), F_r1=rng.uniform(0, 5), F_r2=rng.uniform(0, 5),
        M=rng.uniform(-1, 1), rod_mass=rng.uniform(0, 0.5), rod_inertia=rng.uniform(0, 1e-3),
    )
    return params, rng.uniform(-2 * np.pi, 4 * np.pi, 20), rng.uniform(-80, 80, 20)


@pytest.mark.parametrize("geometry", ["approx", "exact"])
@pytest.mark.parametrize("mode", [Mode.CONTRACTION, Mode.EXPANSION])
def test_rhs_and_reaction_match_symbolic_lagrange(geometry, mode):
    alpha_fn, reaction_fn = derived(geometry, mode)
    rng = np.random.default_rng(20261122 + 7 * int(mode) + len(geometry))
    for _ in range(10):
        params, phis, omegas = _random_case(rng)
        values = (params.m1, params.m2, params.J_A, params.rod_mass, params.rod_inertia_value,
                  params.r, params.L, params.M, params.F_r1, params.F_r2)
        dyn = OneDofDynamics(params, geometry)
        state = dyn.state(phis, omegas, mode)
        expected_alpha = alpha_fn(phis, omegas, *values)
        expected_reaction = reaction_fn(phis, omegas, *values)
        locked = state.lambda2 if mode is Mode.CONTRACTION else state.lambda1
        # Both sides are closed-form double-precision expressions of the same
        # quantities; they differ only by roundoff, a few ulp amplified by
        # cancellation in terms of size ~ m r omega^2 (at most ~1e4 here).
        scale_alpha = np.abs(expected_alpha) + abs(params.M) / params.J_A + 1.0
        scale_force = np.abs(expected_reaction) + (params.m1 + params.m2) * params.r * omegas**2 + 1.0
        np.testing.assert_array_less(np.abs(state.alpha - expected_alpha), 1e-10 * scale_alpha)
        np.testing.assert_array_less(np.abs(locked - expected_reaction), 1e-10 * scale_force)


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
