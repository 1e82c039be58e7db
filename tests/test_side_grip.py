"""The closed-form sideways-grip check of the wheeled model (:func:`ipir_mujoco.core.side_check.side_grip_check`) and
the linkage's forces across the pipe it reads (:func:`ipir_mujoco.analytic.kinetostatics.pin_forces`).

Tolerances: the hand cases are exact up to round-off (1e-12 relative); the run's decomposition is the same
arithmetic on the same columns (1e-9 relative to the largest force, round-off of the products)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from ipir_mujoco import registry
from ipir_mujoco.analytic import RobotParams
from ipir_mujoco.analytic.dynamics import OneDofDynamics
from ipir_mujoco.analytic.kinetostatics import pin_forces
from ipir_mujoco.core.pipe import ring_side_grip, side_grip_check


def test_the_sideways_grip_check_against_hand_cases():
    """3 legs, leg 0 down: the circumferential directions are (1, 0) and (-1/2, +-sqrt(3)/2) in (y, z), so a ring
    gives mu P (1 + 1/2 + 1/2) = 2 mu P across a level pipe (y) and mu P sqrt(3) up or down (z). Module 1's ring
    load is half its side force plus the couple over the ring spacing, module 2's half its side force."""
    p = RobotParams(mu_wall=0.5, F_n1=60.0, F_n2=30.0, wheel_legs=3, ring_spacing=0.1)
    G1, G2 = 2 * 0.5 * 10.0, 2 * 0.5 * 5.0
    assert ring_side_grip(p, 0, (1.0, 0.0)) == pytest.approx(G1, rel=1e-12)
    assert ring_side_grip(p, 1, (0.0, 1.0)) == pytest.approx(math.sqrt(3) * 0.5 * 5.0, rel=1e-12)
    side1, side2 = np.array([0.0, -4.0, 2.0]), np.array([1.0, 3.0, -6.0])
    torque = np.array([0.3, 0.2, 0.1])
    check = side_grip_check(p, side1, side2, torque)
    assert check["side_use1"] == pytest.approx(max(0.5 * 4.0 + 0.2 / 0.1, 0.5 * 2.0 + 0.1 / 0.1, 0.3 / 0.1) / G1,
                                               rel=1e-12)
    assert check["side_use2"] == pytest.approx(3.0 / G2, rel=1e-12)
    assert check["scrub_predicted"] is False
    # either side of the grip: module 2's ring load 5 N +- 1 %
    for load, slides in ((0.99 * 2 * G2, False), (1.01 * 2 * G2, True)):
        assert side_grip_check(p, side1, np.array([load]), torque)["scrub_predicted"] is slides
    assert side_grip_check(p.replace(mu_wall=None), side1, 1e6 * side2, torque)["scrub_predicted"] is False
    # a module holding with 60 % of its grip keeps sqrt(1 - 0.36) = 80 % of it across the pipe; one that skids,
    # none: any side load then slides it, and no load none
    use = (np.array([0.0, 0.6, 0.0]), np.array([0.6, 0.6, 1.0]))
    check = side_grip_check(p, side1, np.array([1.0, 3.0, 0.0]), torque, use)
    assert check["side_use1"] == pytest.approx((0.5 * 4.0 + 0.2 / 0.1) / (0.8 * G1), rel=1e-12)
    assert check["side_use2"] == pytest.approx(1.5 / (0.8 * G2), rel=1e-12)
    assert side_grip_check(p, side1, np.array([1.0, 3.0, 1e-9]), torque, use)["side_use2"] == math.inf


@pytest.mark.parametrize("rod_mass", [0.0, 0.01])
def test_the_linkage_forces_across_the_pipe_agree_with_the_rod_force(rod_mass):
    """A run's side forces: with a massless rod the pin force at C lies along the rod, so module 2's force across
    the pipe is the rod's force times its slope, r sin(phi) / sqrt(L^2 - r^2 sin^2 phi), and the crank's at B is
    its opposite; with the rod's mass the two differ by the rod's mass times its acceleration across the pipe,
    which the rod's own column (its force along itself at C) does not see."""
    p = RobotParams(drive="motor", mu_wall=0.5, F_n1=20.0, F_n2=20.0, rod_mass=rod_mass,
                    rod_inertia=0.0 if rod_mass == 0 else None)
    run = registry.run("analytic-unilateral", p, 0.5, dt_out=1e-3)
    series = run.series
    on_rod_x, on_rod_y, pin_x, pin_y = pin_forces(series, OneDofDynamics(p, run.geometry))
    s = p.r * np.sin(series["phi"])
    scale = np.abs(series["rod_force"]).max()
    # the rod force (along the rod at C) recomposed from the two components, as add_kinetostatics writes it
    along = (on_rod_x * np.sqrt(p.L ** 2 - s ** 2) - on_rod_y * s) / p.L
    np.testing.assert_allclose(along, series["rod_force"], rtol=0, atol=1e-9 * scale)
    if rod_mass == 0.0:
        np.testing.assert_allclose(on_rod_y, -s / np.sqrt(p.L ** 2 - s ** 2) * on_rod_x, rtol=0, atol=1e-9 * scale)
        np.testing.assert_allclose(pin_y, -on_rod_y, rtol=0, atol=1e-9 * scale)
    else:
        assert np.abs(pin_y + on_rod_y).max() > 1e-6 * scale  # the rod's inertia across the pipe
