"""The loads a route's bends add on the round-pipe robot's rings (core.route_loads), and the module frames they are
taken in (core.wheel_legs): closed forms against their definitions, no simulation."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from ipir_mujoco.core import wheel_checks as W
from ipir_mujoco.core.params import RobotParams
from ipir_mujoco.core.pipe import bend_wheel_spread, leg_direction
from ipir_mujoco.core.route_loads import route_loads
from ipir_mujoco.core.wheel_legs import (bend_slip_angle, in_module_frame, module_gravity, ring_side_grip,
                                         scrub_force)

GRIP = RobotParams(mu_wall=0.5, F_n1=30.0, F_n2=40.0)


def test_world_vectors_are_turned_into_the_modules_frame():
    """R^T v for the rotation vector's rotation (scipy's), to round-off, one rotation per sample; at no turn gravity
    across the pipe is the straight pipe's (0, -g cos(incline)) at any incline."""
    rng = np.random.default_rng(48)
    turns, vectors = rng.normal(size=(50, 3)), rng.normal(size=(50, 3))
    expected = np.einsum("nji,nj->ni", Rotation.from_rotvec(turns).as_matrix(), vectors)
    assert np.abs(in_module_frame(turns, vectors) - expected).max() < 1e-14
    p = RobotParams(incline=35.0)
    assert module_gravity(p, np.zeros((3, 3))) == pytest.approx(
        np.tile([0.0, -p.g * math.cos(math.radians(35.0))], (3, 1)), abs=1e-12)
    # a module yawed 90 deg about the pipe's z: the world's up is still its z
    assert module_gravity(RobotParams(), [0.0, 0.0, math.pi / 2]) == pytest.approx([0.0, -9.81], abs=1e-12)


def bend_series(samples: int, speed: float, radius: float, toward=(0.0, 1.0, 0.0)) -> dict:
    """Both modules unturned, rolling at ``speed`` [m/s] in a bend of ``radius`` [m] towards world ``toward``."""
    zero, ones = np.zeros(samples), np.ones(samples)
    out = {f"{a}{k}": zero for a in ("roll", "pitch", "yaw") for k in (1, 2)}
    for k in (1, 2):
        out[f"v{k}"] = speed * ones
        for a, c in zip("xyz", toward):
            out[f"bend_{a}{k}"] = c / radius * ones
    return out


def test_a_bend_turns_the_modules_mass_slips_their_wheels_and_spreads_their_legs():
    """In a bend of R towards +y at v: gravity across less v^2 / R along +y; entering, the steer-compliant wheels'
    slip of the bend, C_r a (C_r = cornering_coefficient P n / 2, a = asin(b / R)), out on the fore ring and in on
    the aft one, while the module rolls; settled, each leg j loses (2 / n) G |u_j . toward| of its press, G the
    wheels' law's steady side force (scrub_force); each leg's press lost to the spread, P (u . toward)^2 spread /
    (2 travel); in a straight pipe (no curvature columns) nothing but gravity. Rigid wheels push the rings' whole
    sideways friction instead, as a load."""
    p, R, v = GRIP, 0.4, 2.0
    series = bend_series(4, v, R)
    rolling = (np.array([True, True, False, False]), np.ones(4, dtype=bool))
    bends = route_loads(p, series, rolling)
    assert bends.gravity[0] == pytest.approx(np.tile([-v * v / R, -p.g], (4, 1)), rel=1e-12)
    n, P = 3, p.F_n1 / 6
    C_r = p.cornering_coefficient * P * n / 2
    a = bend_slip_angle(p, R)
    assert bends.slips["1fore"][:2] == pytest.approx(np.tile([-C_r * a, 0.0], (2, 1)), rel=1e-12)
    assert bends.slips["1aft"][:2] == pytest.approx(np.tile([C_r * a, 0.0], (2, 1)), rel=1e-12)
    assert not bends.slips["1fore"][2:].any() and not bends.steady[0][2:].any()  # standing
    assert not any(e.any() for e in bends.pushes.values())  # compliant wheels: no load pushed as such
    u = np.array([leg_direction(k, n)[1:] for k in range(n)])
    G = scrub_force(p, 0, (1.0, 0.0), R)
    assert bends.steady[0][0] == pytest.approx(2 / n * G * np.abs(u[:, 0]), rel=1e-12) and G > 0
    spread = bend_wheel_spread(0.5 * p.ring_spacing, p.wheel_radius, R, p.pipe_diameter)
    assert bends.spread[0][0] == pytest.approx(P * u[:, 0] ** 2 * spread / (2 * p.suspension_travel), rel=1e-12)
    straight = route_loads(p, {k: s for k, s in series.items() if not k.startswith("bend_")}, rolling)
    assert straight.gravity[1] == pytest.approx(np.tile([0.0, -p.g], (4, 1))) and not straight.spread[1].any()
    assert not any(s.any() for s in straight.slips.values()) and not straight.steady[0].any()
    rigid = p.replace(cornering_coefficient=None)
    stiff = route_loads(rigid, series, rolling)
    assert stiff.pushes["2fore"][0] == pytest.approx([-ring_side_grip(rigid, 1, (1.0, 0.0)), 0.0], rel=1e-12)
    assert not any(s.any() for s in stiff.slips.values())


def test_a_slip_the_pipe_gives_the_wheels_moves_a_ring_as_the_same_load_would_within_their_friction():
    """Without an end to the wheels' friction a slip's side force acts as a load on the ring does (the cornering
    compliance's force, added to the heading's); at rest on its springs a couple of slips +-S yaws the module as
    a couple of loads does (the fore ring carries (1 + 2 sigma) S). With the friction's end a slip beyond it
    slides the wheels for good, their force capped at their friction, where the same load ends on the springs."""
    steps, omega, dt = 3000, 70.0, 1e-3
    sigma = GRIP.cornering_coefficient * GRIP.suspension_travel / GRIP.ring_spacing
    slip = np.zeros((steps, 2))
    slip[200:, 0] = 1.5
    still, damping, zero = np.zeros(steps, dtype=bool), np.full(steps, 150.0), np.zeros((steps, 2))
    by_slip, _ = W.rings_motion([zero, zero], [still, still], [damping, damping], omega, dt, sigma, None, [slip, -slip])
    by_load, _ = W.rings_motion([slip, -slip], [still, still], [damping, damping], omega, dt, sigma)
    assert np.abs(by_slip[0] - by_load[0]).max() < 1e-12 and np.abs(by_slip[1] - by_load[1]).max() < 1e-12
    assert by_slip[1][-1, 0] == pytest.approx(-(1 + 2 * sigma) * 1.5, rel=1e-6)
    walls = W.wheel_walls(GRIP.replace(g=0.0), 0)  # along y the ring's wheels give 2 mu P = 5 N at the preload
    big = np.zeros((steps, 2))
    big[:, 0] = 8.0
    slipped, slid = W.rings_motion([zero, zero], [still, still], [damping, damping], omega, dt, 0.0, walls,
                                   [big, zero])
    loaded, _ = W.rings_motion([big, zero], [still, still], [damping, damping], omega, dt, 0.0, walls)
    # the wheels' 5 N pushes the ring, undamped while they slide: about 5 N on its springs, at most twice it
    assert slid[0][-1] and slipped[0][:, 0].max() <= 10.0 + 1e-9 and abs(slipped[0][-1000:, 0].mean() - 5.0) < 0.5
    assert loaded[0][-1, 0] == pytest.approx(8.0, rel=1e-6)  # a load ends on the springs, whatever the friction
