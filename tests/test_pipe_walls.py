"""The round pipe's walls (ipir_mujoco.engine.builders.pipe_walls): exact contacts in straights and bends, a round wall
without ripple, routes in 3-D, route files read safely.

Tolerances: contact distances are computed in double precision from a few products and square roots of
numbers below 10 m, so they match the closed form to 1e-12 m; the rig's forces are the springs' (the contact
solver converges to ~1e-10 N here), so a perfectly round wall holds each wheel's force constant to 1e-6 of it,
far inside the 1 % the wall must meet."""

from __future__ import annotations

import math

import mujoco
import numpy as np
import pytest

from ipir_mujoco.analytic import ParameterError
from ipir_mujoco.core.route import read_route, route_from_tables
from ipir_mujoco.engine.builders.pipe_rig import build_rig, ripple, roll
from ipir_mujoco.engine.builders.pipe_walls import PIPE_BIT, WallContact, add_pipe_walls, touch_wall

CONTACT = WallContact(friction=0.5, solref=(1e-3, 1.0))
OUT_OF_PLANE = [dict(kind="straight", length=0.3), dict(kind="bend", radius=0.4, angle=90, plane=90),
                dict(kind="straight", length=0.2), dict(kind="bend", radius=0.3, angle=-60, plane=30),
                dict(kind="straight", length=0.3)]


@pytest.mark.parametrize("tables", [None, OUT_OF_PLANE])
def test_a_ball_touches_the_wall_at_its_exact_distance_from_the_centreline(tables):
    """Random points near the wall along the route: MuJoCo's contact distance is D/2 - (rho + r), rho the
    point's distance from the centreline (the route's own geometry), its normal radial."""
    route = None if tables is None else route_from_tables(tables)
    D, r = 0.16, 0.015
    spec = mujoco.MjSpec()
    add_pipe_walls(spec, route, D, CONTACT, draw=False)
    ball = spec.worldbody.add_body(name="ball")
    ball.add_freejoint()
    ball.add_geom(type=mujoco.mjtGeom.mjGEOM_SPHERE, size=[r, 0, 0], contype=PIPE_BIT, conaffinity=0)
    model = spec.compile()
    data = mujoco.MjData(model)
    rng = np.random.default_rng(3)
    length = 2.0 if route is None else route.length
    for _ in range(200):
        s = rng.uniform(0.0, length)
        centre, t = (np.array([s, 0, 0]), np.array([1.0, 0, 0])) if route is None else route.at3(s)
        frame = np.eye(3) if route is None else route.frame_at(s)
        phi = rng.uniform(0, 2 * math.pi)
        radial = math.cos(phi) * frame[1] + math.sin(phi) * frame[2]
        rho = rng.uniform(D / 2 - r - 0.004, D / 2 - r + 0.002)
        data.qpos[:3] = centre + rho * radial
        mujoco.mj_forward(model, data)
        expected = D / 2 - (rho + r)
        if expected >= 0:
            assert data.ncon == 0
            continue
        assert data.ncon == 1
        assert data.contact.dist[0] == pytest.approx(expected, abs=1e-12)
        assert np.allclose(data.contact.frame[0, :3], radial, atol=1e-9)


@pytest.mark.parametrize("tables", [None, OUT_OF_PLANE])
@pytest.mark.slow
def test_a_wheel_carried_along_the_pipe_presses_with_a_constant_force(tables):
    """The rig's three sprung wheels (10 N preload, 3 mm travel) carried at 2 m/s through straights and bends: the
    normal force stays constant (the wall is round; its construction adds no ripple), one contact per wheel."""
    route = None if tables is None else route_from_tables(tables)
    model = build_rig(route)
    run = roll(model, route, speed=2.0, distance=0.3 if route is None else route.length)
    assert run.contacts == 1
    assert run.force.min() > 9.9  # pressing, within the contact's own sinking (< 1 % of the preload)
    assert ripple(run) < 1e-6


def test_only_spheres_capsules_and_boxes_touch_the_wall():
    spec = mujoco.MjSpec()
    body = spec.worldbody.add_body(name="b")
    body.add_geom(name="cyl", type=mujoco.mjtGeom.mjGEOM_CYLINDER, size=[0.01, 0.01, 0])
    body.add_geom(name="box", type=mujoco.mjtGeom.mjGEOM_BOX, size=[0.01, 0.01, 0.01])
    touch_wall(spec, ["box"])
    assert (spec.geom("box").contype, spec.geom("box").conaffinity) == (PIPE_BIT, 0)
    with pytest.raises(ParameterError, match="allowed: a sphere, capsule or box"):
        touch_wall(spec, ["cyl"])


def test_a_housing_box_rests_on_its_deepest_corner():
    """A box sunk into the wall of a straight pipe: one contact at its deepest corner, normal inward (from the
    wall, geom 1, to the box)."""
    spec = mujoco.MjSpec()
    add_pipe_walls(spec, None, 0.16, CONTACT, draw=False)
    body = spec.worldbody.add_body(name="housing", pos=[0.0, 0.0, -0.065])
    body.add_freejoint()
    body.add_geom(type=mujoco.mjtGeom.mjGEOM_BOX, size=[0.03, 0.02, 0.02], contype=PIPE_BIT, conaffinity=0)
    model = spec.compile()
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    corner = math.hypot(0.02, 0.085)  # a lower corner's distance from the axis
    assert data.ncon == 1
    assert data.contact.dist[0] == pytest.approx(0.08 - corner, abs=1e-12)
    assert data.contact.frame[0, 2] > 0.9  # inward: up, from the wall below to the box


def test_a_bend_across_the_plane_makes_a_vertical_leg():
    """From a level start, a 90-degree bend with plane = 90 turns up: the next straight is a riser (incline 90),
    its end straight above the bend's end; a second bend with plane = 90 relative to the riser turns towards the
    route's left side, not back to the start's (the side is carried along the pipe)."""
    route = route_from_tables([dict(kind="straight", length=0.4), dict(kind="bend", radius=0.5, angle=90, plane=90),
                               dict(kind="straight", length=0.3), dict(kind="bend", radius=0.5, angle=90, plane=90),
                               dict(kind="straight", length=0.2)])
    assert route.pieces[2].incline == 90.0 and route.pieces[4].incline == 0.0
    p, t = route.at3(0.4 + math.pi / 4 + 0.3)
    assert np.allclose(p, [0.9, 0.0, 0.8], atol=1e-12) and np.allclose(t, [0, 0, 1], atol=1e-12)
    # the riser's frame: t = +z, its left n still +y, its up b = t x n = -x; plane 90 turns towards b
    p, t = route.at3(route.length)
    assert np.allclose(t, [-1, 0, 0], atol=1e-12) and np.allclose(p, [0.2, 0.0, 1.3], atol=1e-12)
    assert not route.planar
    assert route.project3(p + [0.0, 0.01, 0.0]) == pytest.approx(route.length, abs=1e-12)


@pytest.mark.parametrize("content, word", [
    (b"\x00\x01\xff\xfe binary", "not UTF-8"),
    ('[[segment]]\nkind = "straight"\nlength = 1\n'.encode("utf-16"), "not UTF-8"),
    (b"x = " + b"[" * 5000 + b"]" * 5000, "nests"),
    (b"# " + b"x" * 1_100_000, "larger than 1 MB"),
])
def test_a_route_file_that_cannot_be_read_is_refused_in_one_line(tmp_path, content, word):
    path = tmp_path / "route.toml"
    path.write_bytes(content)
    with pytest.raises(ParameterError, match=word) as info:
        read_route(path)
    assert "\n" not in str(info.value)


@pytest.mark.parametrize("radius", [None, 0.2])
def test_wheels_rolling_with_friction_see_a_round_wall(radius):
    """The rig on joints, wheels rolling with friction 0.5 at 0.5 m/s along a straight and inside a bend of
    R/D 1.25: each wheel's force holds constant to 1e-6 of it (the contact solver's convergence, as above), and
    its mean is the preload but for the wheel's own centripetal load in the bend, m v^2 / R = 0.02 x 0.25 / 0.2 =
    0.025 N spread over the legs by their directions (at most that much off 10 N), and the contact's sinking
    (the spring's 0.1 % of travel at most)."""
    from ipir_mujoco.engine.builders.pipe_rig import WHEEL_MASS, roll_on_joints, rolling_rig

    run = roll_on_joints(rolling_rig(bend_radius=radius), 0.5, 0.1, settle=0.2)
    assert run.contacts == 1 and ripple(run) < 1e-6
    centripetal = 0.0 if radius is None else WHEEL_MASS * 0.5 ** 2 / radius
    assert np.all(np.abs(run.force.mean(axis=0) - 10.0) <= centripetal + 0.01)


def test_a_housing_capsule_tilted_in_a_bend_rests_on_its_deepest_point():
    """A capsule (the round-pipe robot's housing) inside a bend of R 0.4 m, tilted so one end sinks into the
    outer wall: one contact, at that end, its depth the end's distance from the centreline past D/2."""
    route = route_from_tables([dict(kind="straight", length=0.3), dict(kind="bend", radius=0.4, angle=90)])
    spec = mujoco.MjSpec()
    add_pipe_walls(spec, route, 0.16, CONTACT, draw=False)
    centre, t = route.at3(0.3 + 0.2)  # 0.5 rad into the bend
    body = spec.worldbody.add_body(name="housing", pos=centre.tolist())
    body.add_freejoint()
    outward = (centre - route.pieces[1].centre3) / 0.4  # the bend's outer side there
    ends = -0.05 * t, 0.05 * t + 0.06 * outward  # from the housing's centre: its far end sunk in the outer wall
    body.add_geom(type=mujoco.mjtGeom.mjGEOM_CAPSULE, fromto=[*ends[0], *ends[1]], size=[0.03, 0, 0],
                  contype=PIPE_BIT, conaffinity=0)
    model = spec.compile()
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    depths = []
    for end in ends:
        p = centre + end
        depths.append(0.08 - (np.linalg.norm(p - route.at3(route.project3(p))[0]) + 0.03))
    assert data.ncon == 1
    assert data.contact.dist[0] == pytest.approx(min(depths), abs=1e-12)
