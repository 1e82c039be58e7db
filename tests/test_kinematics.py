"""Slider-crank kinematics: derivatives, limits, stroke and rod geometry."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from ipir_mujoco.analytic.kinematics import Linkage

PHI = np.linspace(-7.0, 7.0, 301)


def central_difference(f, x, h=1e-5):
    """Central difference; truncation error ~ h^2 f''' / 6, about 1e-10 relative here."""
    return (f(x + h) - f(x - h)) / (2 * h)


@given(r=st.floats(0.01, 0.2), ratio=st.floats(1.05, 30.0))
@settings(max_examples=60, deadline=None)
def test_exact_K_and_dK_are_the_derivatives_of_S(r, ratio):
    link = Linkage(r, r * ratio, "exact")
    tr = link.transfer(PHI)
    # h = 1e-5 rad: truncation ~ h^2 |S'''| / 6 and roundoff ~ eps |S| / h, both
    # below 1e-8 r even for L/r = 1.05, where S''' reaches ~1e2 r.
    np.testing.assert_allclose(central_difference(link.gap, PHI), tr.K, atol=1e-8 * r * (1 + 1 / (ratio - 1)) ** 3)
    dK = central_difference(lambda x: link.transfer(x).K, PHI)
    np.testing.assert_allclose(dK, tr.dK, atol=1e-7 * r * (1 + 1 / (ratio - 1)) ** 4)


def test_approx_is_the_papers_first_order_form():
    link = Linkage(0.05, 0.2, "approx")
    tr = link.transfer(PHI)
    np.testing.assert_allclose(tr.S, 0.2 + 0.05 * np.cos(PHI), rtol=0, atol=1e-15)
    np.testing.assert_allclose(tr.K, -0.05 * np.sin(PHI), rtol=0, atol=1e-15)
    np.testing.assert_allclose(tr.dK, -0.05 * np.cos(PHI), rtol=0, atol=1e-15)


@pytest.mark.parametrize("geometry", ["approx", "exact"])
@pytest.mark.parametrize("ratio", [1.1, 4.0, 20.0])
def test_stroke_is_2r_between_L_minus_r_and_L_plus_r(geometry, ratio):
    r = 0.05
    link = Linkage(r, r * ratio, geometry)
    S = link.gap(np.linspace(0, 2 * np.pi, 20001))
    assert S.max() == pytest.approx(r * ratio + r, abs=1e-15)
    assert S.min() == pytest.approx(r * ratio - r, abs=1e-12)


def test_exact_tends_to_first_order_as_the_rod_grows():
    """S_exact - S_approx = sqrt(L^2 - r^2 sin^2) - L = -r^2 sin^2 / (2L) + O(r^4 / L^3)."""
    r = 0.05
    for ratio in (4.0, 40.0, 400.0):
        L = r * ratio
        diff = Linkage(r, L, "exact").gap(PHI) - Linkage(r, L, "approx").gap(PHI)
        np.testing.assert_allclose(diff, -r**2 * np.sin(PHI) ** 2 / (2 * L), atol=r**4 / L**3)


def test_rod_keeps_its_length_and_its_centre_is_the_midpoint():
    r, L = 0.05, 0.12
    link = Linkage(r, L, "exact")
    bx, by = link.crank_pin(PHI)
    cx = link.gap(PHI)
    np.testing.assert_allclose(np.hypot(cx - bx, by), L, rtol=1e-14)
    gx, gy = link.rod_com(PHI)
    np.testing.assert_allclose(gx, (bx + cx) / 2, rtol=1e-14)
    np.testing.assert_allclose(gy, by / 2, rtol=1e-14)


def test_rod_velocity_coefficients_are_derivatives_of_its_position_and_angle():
    r, L = 0.05, 0.09
    link = Linkage(r, L, "exact")
    motion = link.rod_motion(PHI)
    angle = lambda x: np.arctan2(-link.crank_pin(x)[1], link.gap(x) - link.crank_pin(x)[0])  # noqa: E731
    pairs = (
        (lambda x: link.rod_com(x)[0], motion.a), (lambda x: link.rod_com(x)[1], motion.b), (angle, motion.g),
        (lambda x: link.rod_motion(x).a, motion.da), (lambda x: link.rod_motion(x).b, motion.db),
        (lambda x: link.rod_motion(x).g, motion.dg),
    )
    for f, coefficient in pairs:
        # central difference with h = 1e-5: error ~1e-10 of the coefficient's scale (<= ~10)
        np.testing.assert_allclose(central_difference(f, PHI), coefficient, atol=1e-8)


def test_exact_geometry_refuses_a_rod_shorter_than_the_crank():
    with pytest.raises(ValueError, match="L > r"):
        Linkage(0.05, 0.04, "exact")
    with pytest.raises(ValueError, match="exact"):
        Linkage(0.05, 0.2, "approx").rod_motion(0.3)
