"""The wheels' scrub in a bend (analytic/route_scrub.py) against hand calculations from docs/model.md's text.

A module with both rings in one bend of radius R (the default robot's legs: 3 per ring, leg 0 down, a bend in the
plane 0, so that the bend's inside d is the module's left e2 and the wheels' sideways directions e_k have
e_k . d = 1, -1/2, -1/2): its rings' chord subtends 2 h / R, so each ring moves at a = h / R off the module's axis,
the fore ring's velocity turned in, the aft ring's out. Cocked nose out by psi, the fore ring slips at a + psi and
the aft ring at a - psi, and a wheel k at alpha_k = atan(tan(a +- psi) e_k . d) (the hubs on the axis, rho = 0).
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.optimize import brentq

from ipir_mujoco.analytic.route_geometry import pack_route
from ipir_mujoco.analytic.route_model import wheel_constants
from ipir_mujoco.analytic.route_scrub import module_scrub, wheel_side
from ipir_mujoco.core.params import RobotParams
from ipir_mujoco.core.route import route_from_tables

ED = (1.0, -0.5, -0.5)  # e_k . d of the default three legs in a bend of plane 0
H = 0.05  # m: half the default ring spacing


def bend(R: float, plane: float = 0.0):
    """A straight, a bend of radius R [m] long enough to hold a module, a straight; and the station [m] of a module
    in the bend's middle."""
    angle = min(170.0, math.degrees(0.6 / R) + 20.0)
    route = route_from_tables([dict(kind="straight", length=0.5), dict(kind="bend", radius=R, angle=angle,
                                                                        plane=plane), dict(kind="straight", length=0.5)])
    return route, 0.5 + 0.5 * math.radians(angle) * R


def scrub(params: RobotParams, R: float, plane: float = 0.0, rho: float | None = None) -> tuple[float, float]:
    """(scrub force [N], cock [rad]) of module 1 in the bend's middle, the hubs ``rho`` [m] off the axis (None: the
    robot's)."""
    route, s = bend(R, plane)
    q = pack_route(route)
    mu, corner, n, p1, _, travel, hubs = wheel_constants(params)
    return module_scrub(q, 0, q.size // 19, s, H, mu, corner, int(n), p1, travel, hubs if rho is None else rho)


def test_a_wheel_below_its_limit_steers_and_dissipates_nothing_beyond_it_slides():
    """The law per wheel: F = C |alpha| below mu N, no power; beyond, F = mu N and the power per unit speed
    mu N sin(|alpha| - alpha_s), alpha_s = mu N / C; rigid wheels (C infinite) mu N sin |alpha|; the force's share
    across the module's axis the cosine of the wheel's steer, against the slip."""
    C, limit = 66.67, 4.0  # N/rad, N: alpha_s = 0.06 rad
    force, power = wheel_side(0.05, C, limit)
    assert force == pytest.approx(-C * 0.05 * math.cos(0.05), rel=1e-15) and power == 0.0
    force, power = wheel_side(-0.2, C, limit)
    assert force == pytest.approx(limit * math.cos(limit / C), rel=1e-15)
    assert power == pytest.approx(limit * math.sin(0.2 - limit / C), rel=1e-15)
    force, power = wheel_side(0.2, math.inf, limit)
    assert force == -limit and power == pytest.approx(limit * math.sin(0.2), rel=1e-15)
    assert wheel_side(0.0, math.inf, limit) == (0.0, 0.0)  # a rigid wheel rolling straight holds, and slides not


def test_rigid_wheels_scrub_with_the_whole_friction_as_a_hand_calculation_says():
    """Rigid wheels: each ring's wheels all slide, their side force along d is mu P sum_k |e_k . d| = 2 mu P
    whatever the slip, so psi = 2 mu P / (k_r b) (k_r = 3 P / (2 travel), b the rings' half chord R sin(h / R)),
    or a where that is more (the aft ring then rolls straight, its wheels holding what it needs: mu_wall 0.8 at R/D
    3); a wheel's power per unit speed mu P |w . e_k| (its sideways speed), mu P |e_k . d| sin(a -+ psi) for rho =
    0: the module's 4 mu P sin(a) cos(psi). R/D 2 and 3, mu_wall 0.3 and 0.8: exact to round-off (the cock's root
    to 1e-14 rad where it is a)."""
    for mu in (0.3, 0.8):
        params = RobotParams(mu_wall=mu, cornering_coefficient=None)
        P = params.F_n1 / 6
        for R in (0.32, 0.48):
            a, b = H / R, R * math.sin(H / R)
            psi = min(2 * mu * P / (3 * P / (2 * params.suspension_travel) * b), a)
            force, cock = scrub(params, R, rho=0.0)
            assert cock == pytest.approx(psi, rel=1e-12)
            assert force == pytest.approx(4 * mu * P * math.sin(a) * math.cos(psi), rel=1e-12)


def test_steering_wheels_below_their_limit_scrub_nothing_and_cock_as_the_springs_say():
    """Steering wheels (c = 8 /rad) in a gentle bend, R/D 20 and 50: every wheel below its limit (the fore ring's
    bottom wheel at about 1.8 a, below mu / c), so no power at all; the cock balances the rings' side forces on
    the springs, psi = C_r a / (k_r b) = c travel a / b to first order in the angles (C_r = 3 C / 2 = 1.5 c P),
    0.8 a at the defaults: to the angles' squares, (2 a)^2 < 1e-3."""
    params = RobotParams(mu_wall=0.5)
    for R in (3.2, 8.0):
        a = H / R
        assert 1.8 * a < 0.5 / 8.0
        force, cock = scrub(params, R)
        assert force == 0.0
        assert cock == pytest.approx(8.0 * params.suspension_travel * a / H, rel=1e-3)


def _doc_planar(params: RobotParams, R: float, rho: float) -> tuple[float, float]:
    """docs/model.md's module in a bend, planar (plane 0), by its own steps: (scrub force [N], psi [rad]). The hubs'
    velocities w = t -+ rho (u_k . d) / R e1 (u_k . d = 0, +sqrt(3)/2 (inside), -sqrt(3)/2), seen from the module
    cocked by psi; psi from the couple's balance by bracketing (scipy); a wheel's force across the axis C alpha
    cos(alpha) below its limit, mu P cos(alpha_s) beyond it."""
    P, mu, c = params.F_n1 / 6, params.mu_wall, params.cornering_coefficient
    C = math.inf if c is None else c * P
    limit, a, b = mu * P, H / R, R * math.sin(H / R)
    kr = 3 * P / (2 * params.suspension_travel)
    ud = (0.0, math.sqrt(3) / 2, -math.sqrt(3) / 2)

    def ring(sign: float, psi: float) -> tuple[float, float]:  # sign +1 fore, -1 aft: (side force along d', power)
        side = power = 0.0
        for ed, u in zip(ED, ud):
            along_axis = math.cos(a) - rho * u / R  # the hub's velocity along e1 and along d
            along_d = sign * math.sin(a)
            along = along_axis * math.cos(psi) - along_d * math.sin(psi)
            across = ed * (along_axis * math.sin(psi) + along_d * math.cos(psi))
            alpha = math.atan2(across, along)
            steer = min(abs(alpha), limit / C)
            f = (C * abs(alpha) if C * abs(alpha) < limit else limit) * math.cos(steer)
            side -= math.copysign(f, alpha) * ed
            if C * abs(alpha) >= limit:
                power += limit * math.sin(abs(alpha) - limit / C) * math.hypot(along, across)
        return side, power

    bound = 2 * 3 * limit / (2 * kr * b) * 1.001
    psi = brentq(lambda x: 2 * kr * b * x + ring(1.0, x)[0] - ring(-1.0, x)[0], -bound, bound, xtol=1e-15)
    return ring(1.0, psi)[1] + ring(-1.0, psi)[1], psi


@pytest.mark.parametrize("mu", (0.3, 0.8))
@pytest.mark.parametrize("ratio", (1.5, 3.0, 5.0, 10.0))
@pytest.mark.parametrize("corner", (8.0, 3.0, None))
def test_the_closed_form_is_the_docs_module_in_a_bend(mu, ratio, corner):
    """Below, at and beyond saturation (R/D 1.5 .. 10, mu_wall 0.3 and 0.8, c 8 and 3 /rad and rigid), with the
    hubs off the axis: the kernel's scrub force and cock against the doc's steps written out for a planar bend
    (:func:`_doc_planar`), to the root's tolerance (1e-12 relative, and 1e-12 N where both are 0)."""
    params = RobotParams(mu_wall=mu, cornering_coefficient=corner)
    R = ratio * params.pipe_diameter
    rho = 0.5 * params.pipe_diameter - params.wheel_radius
    want_force, want_psi = _doc_planar(params, R, rho)
    force, cock = scrub(params, R)
    assert cock == pytest.approx(want_psi, rel=1e-10, abs=1e-14)
    assert force == pytest.approx(want_force, rel=1e-10, abs=1e-12)


def test_a_bend_turning_up_scrubs_as_its_legs_see_it():
    """The legs' arrangement turns with the bend's plane: rigid wheels in a bend turning up (plane 90: d = e3,
    e_k . d = 0, cos 30, -cos 30) push with mu P sum |e_k . d| = sqrt(3) mu P per ring, and their power per unit
    speed is 2 sqrt(3) mu P sin(a) cos(psi) (rho = 0); in a straight, nothing."""
    params = RobotParams(mu_wall=0.5, cornering_coefficient=None)
    P, R = params.F_n1 / 6, 0.4
    a, b = H / R, R * math.sin(H / R)
    psi = math.sqrt(3) * 0.5 * P / (3 * P / (2 * params.suspension_travel) * b)
    force, cock = scrub(params, R, plane=90.0, rho=0.0)
    assert cock == pytest.approx(psi, rel=1e-12)
    assert force == pytest.approx(2 * math.sqrt(3) * 0.5 * P * math.sin(a) * math.cos(psi), rel=1e-12)
    q = pack_route(route_from_tables([dict(kind="straight", length=1.0)]))
    assert module_scrub(q, 0, q.size // 19, 0.5, H, 0.5, math.inf, 3, P, 0.005, 0.065) == (0.0, 0.0)


def test_unlimited_grip_runs_on_the_equations_rails():
    """With unlimited grip (mu_wall None) the equations keep their rails: no scrub (the constants say mu 0)."""
    params = RobotParams()
    assert wheel_constants(params)[0] == 0.0
    assert scrub(params, 0.3) == (0.0, 0.0)
    assert np.isinf(wheel_constants(RobotParams(mu_wall=0.5, cornering_coefficient=None))[1])
