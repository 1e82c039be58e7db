"""The wheels' side-force law (docs/model.md, "The wheels' side force") as MuJoCo builds it: one ring of the
wheeled model's legs (module 1's, built by ``kinds.wheels.model.add_leg``) on a carriage driven along a straight
pipe with its axis turned off the pipe's by a slip angle (``ipir_mujoco.engine.kinds.wheels.rig.cornering_rig``),
gravity off.

Wheel k slips at alpha_k = atan(tan(slip) e_k . y) and is pushed across its rolling direction with
min(C |alpha_k|, mu_wall N_k), C = cornering_coefficient x its leg's preload; below the limit it steers by alpha_k
and rolls along its path (no scrub: the carriage's drive meets the rolling resistance only), beyond it it slides
sideways against mu_wall N_k. Rigid wheels slide at any slip angle.

Tolerances: the steer-compliant wheel is the law to first order in its geometry. The wheel its steer swings e delta
sideways sits where the round wall's normal leans by e delta / rho (rho = D / 2), which adds a share of order
N e / (C rho) = e / (cornering_coefficient rho) to its side force (0.6 % at the defaults), and a leg that leans off
the wall's normal by a tilt (here the carriage's slip, times the side legs' 0.87) moves its contact by R tilt along
its trail e, changing that wheel's side force by R tilt / e (7 % here, opposite for the two side legs) and their
sum by the square of it (0.5 %). So each wheel is held to its own share of those and the two side legs' sum to 2 %.
Sliding: the wheel's friction cone shares mu_wall N with its rolling resistance f (1 - sqrt(1 - (f / mu N)^2) =
0.1 %) and the sliding soft contact converges at first order in the step (the steer's angle moved by 4 % from 1e-4
to 5e-5 s at a slip of 0.3 rad: bench/wheels_side_force.py): 1 % on the force, 2 % on the drive.
"""

from __future__ import annotations

import math

import pytest

from ipir_mujoco.analytic import RobotParams
from ipir_mujoco.engine.kinds.wheels.rig import corner, cornering_law, cornering_rig
from ipir_mujoco.engine.builders.wheels_model import cornering_stiffness, trail

DT, SPEED, DURATION, WINDOW = 5e-5, 0.3, 0.2, 0.05


def run(p: RobotParams, slip: float):
    result = corner(cornering_rig(p, slip, DT), p, SPEED, DURATION, WINDOW)
    return result, cornering_law(p, slip, result.normal)


def test_below_the_limit_a_wheel_pushes_C_alpha_and_steers_to_its_path():
    p = RobotParams(mu_wall=0.5)
    slip = 0.02
    result, (angles, forces, drive) = run(p, slip)
    C, rho, R, e = cornering_stiffness(p, 0), p.pipe_diameter / 2, p.wheel_radius, trail(p)
    offset = max(result.normal) * e / (C * rho)  # the round wall under a wheel steered e delta sideways
    tilt = R * slip * math.cos(math.radians(30)) / e  # the side legs' lean off the wall's normal, over the trail
    assert abs(abs(result.side[0]) / forces[0] - 1) <= 2 * offset
    for k in (1, 2):
        assert abs(abs(result.side[k]) / forces[k] - 1) <= 2 * (offset + tilt)
    assert abs(abs(result.side[1] + result.side[2]) / (forces[1] + forces[2]) - 1) <= 0.02
    for k in range(3):
        assert result.steer[k] == pytest.approx(angles[k], abs=0.02 * abs(angles[k]))  # it steers to its path
        assert abs(result.sideways[k]) < 1e-3 * SPEED * abs(angles[k])  # and rolls along it: no scrub
    assert result.drive == pytest.approx(drive, rel=1e-3)  # the rolling resistance only


def test_beyond_the_limit_a_wheel_slides_against_mu_N():
    p = RobotParams(mu_wall=0.5)
    result, (angles, forces, drive) = run(p, 0.3)
    for k in range(3):
        assert abs(result.side[k]) == pytest.approx(forces[k], rel=0.01)  # mu_wall N_k
        assert abs(result.sideways[k]) > 0.01 * SPEED  # it slides
    assert result.drive == pytest.approx(drive, rel=0.02)  # the scrub's power over the speed on top


def test_rigid_wheels_slide_at_any_slip_angle():
    p = RobotParams(mu_wall=0.5, cornering_coefficient=None)
    result, (angles, forces, drive) = run(p, 0.02)
    for k in range(3):
        assert abs(result.side[k]) == pytest.approx(p.mu_wall * result.normal[k], rel=0.01)
        assert result.steer[k] == 0.0
    assert result.drive == pytest.approx(drive, rel=0.02)
