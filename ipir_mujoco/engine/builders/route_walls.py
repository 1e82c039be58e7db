"""The pipe's walls along a route (``--route``) for the wheeled MuJoCo model, and the closed-form fit beside them.

:func:`write_route_walls` replaces the straight model's two planes (``wall_top``, ``wall_bottom``) by walls
along the route's centreline (:mod:`ipir_mujoco.core.route`), with the planes' friction, solref, solimp and
condim:

- a straight (consecutive straights merged: they are collinear): one box per wall, its inner face at D/2
  from the centreline (one box per straight wall: boxes side by side bump at their seams). The first
  straight's walls reach LEAD_IN behind the route's start, the last piece is followed by an exit straight
  of the robot's length plus LEAD_IN, so that the whole robot is in the pipe from start to end;
- a bend's inner wall (convex towards the pipe): one capsule with its axis along z, radius R - D/2, at the
  bend's centre: a smooth circle, no seams (capsule-capsule contacts are MuJoCo's exact ones). It collides
  only (group 3, not drawn); a cylinder of the same radius, colliding with nothing, draws it;
- the housings, the crank and the rod collide with the route's walls too (in the straight model they never
  reach the planes and collide with nothing), so that a bend too tight for the linkage binds it;
- a bend's outer wall (concave towards the pipe): N boxes, each with its inner face tangent to the circle of
  radius R + D/2 at angles (k + 1/2) angle / N, overlapping their neighbours: the pipe sees a polygon with
  no edge of a box in it (every box's end lies behind its neighbours' faces), whose corners stand at most
  SAGITTA out from the circle (N from it). A straight's wall on a bend's outer side runs on past the bend's
  start or end by one box width, behind the bend's first box; on the inner side it ends at the capsule's
  tangent point.

:func:`fit_prediction` gives the closed-form check of each bend (:mod:`ipir_mujoco.core.pipe`) with this
model's geometry, reported beside MuJoCo's outcome.
"""

from __future__ import annotations

import math

import mujoco

from ipir_mujoco.core.errors import ParameterError
from ipir_mujoco.core.params import RobotParams
from ipir_mujoco.core.pipe import bend_max_length, bend_rod_clearance, bend_wheel_spread
from ipir_mujoco.core.route import Piece, Route

THICKNESS = 0.02  # m: a wall box's thickness (outward from its inner face)
HEIGHT = 0.05  # m: a wall's half-height along z (as the planes are drawn); the wheels reach |z| <= 0.02
SAGITTA = 2e-6  # m: how far a bend's outer polygon's corners stand out of the circle (2 % of the spring travel)
LEAD_IN = 0.3  # m: the walls behind the route's start and beyond the robot at its end
HOUSING_HALF = 0.03  # m: the housing's half-size (inchworm_wheels.xml), the module's rigid part
ROD_RADIUS = 0.004  # m: the rod's capsule radius (inchworm_wheels.xml)
WALL_RGBA = (0.35, 0.4, 0.5, 0.8)
COLLIDING = ("rear_housing", "front_housing", "crank_arm", "rod_bar")  # besides the wheels, along a route


def _quat(heading: float) -> list[float]:
    return [math.cos(heading / 2), 0.0, 0.0, math.sin(heading / 2)]


def outer_boxes(radius: float, diameter: float, angle: float) -> int:
    """How many boxes make a bend's outer wall (radius + diameter / 2 [m], ``angle`` [rad]): corners within
    SAGITTA of the circle, at least 4."""
    outer = radius + diameter / 2
    step = 2 * math.acos(1 / (1 + SAGITTA / outer))  # the corner of tangents dtheta apart stands R (sec - 1) out
    return max(4, math.ceil(abs(angle) / step))


def outer_box_width(radius: float, diameter: float, angle: float) -> tuple[int, float]:
    """(how many boxes, each one's face length [m]) of a bend's outer wall (centreline radius [m], pipe
    diameter [m], ``angle`` [rad]): the face between its neighbours' tangent points on radius + diameter / 2."""
    n = outer_boxes(radius, diameter, angle)
    return n, 2 * (radius + diameter / 2) * math.tan(abs(angle) / n / 2)


MAX_WALL_BOXES = 10_000  # the planar walls' boxes a route may need (measured: one 100 m half turn, 7,860 boxes,
# builds in 1.2 s to 91 MB of the process and steps in 0.8 ms; cost grows faster than the count beyond)
BOX_BYTES = 6_000  # bytes per wall box in the compiled model and its data (measured: 137 MB at 15,720 boxes)


def check_wall_count(route: Route, diameter: float) -> int:
    """How many boxes the planar walls of ``route`` need (two per merged straight, the outer polygon of each
    bend); ParameterError (one line) for a route out of the mechanism's plane, or (with the count and the memory
    it would take) one above MAX_WALL_BOXES, before anything is built."""
    if not route.planar:
        raise ParameterError(f"{route.source}: a bend turns out of the mechanism's plane (plane not 0 or 180 deg), "
                             "which the planar walls cannot build; allowed: plane = 0 or 180 on this model")
    count = 2 * (len(route.pieces) + 1) + sum(outer_boxes(b.radius, diameter, b.angle) for b in route.bends)
    if count > MAX_WALL_BOXES:
        worst = max(route.bends, key=lambda b: outer_boxes(b.radius, diameter, b.angle))
        raise ParameterError(f"{route.source}: the planar walls of this route need {count} boxes (about "
                             f"{count * BOX_BYTES / 1e6:.0f} MB, each bend's outer wall a polygon within {SAGITTA:g} m "
                             f"of its circle; the largest, radius {worst.radius:g} m, "
                             f"{outer_boxes(worst.radius, diameter, worst.angle)}); allowed: at most {MAX_WALL_BOXES} "
                             "boxes: fewer, shorter or tighter bends")
    return count


def _wall_straights(route: Route, robot_length: float, diameter: float) -> list[dict]:
    """The straights the walls need: merged collinear route straights, the exit straight; each with its
    start (x, y, heading), length, and per side ('top' +1, 'bottom' -1) how far it reaches into a bend on that
    side's outer wall before and after it [m]."""
    pieces = list(route.pieces)
    last = pieces[-1]
    end, _ = last.at3(last.length)
    pieces.append(Piece("straight", route.length, robot_length + LEAD_IN, end, last.frame_at(last.length)))
    walls: list[dict] = []
    for k, piece in enumerate(pieces):
        if piece.kind != "straight":
            continue
        if walls and walls[-1]["end"] == k - 1:  # collinear with the one before: one wall
            walls[-1]["length"] += piece.length
            walls[-1]["end"] = k
            continue
        walls.append(dict(x=piece.x, y=piece.y, heading=piece.heading, length=piece.length, start=k, end=k))
    for w in walls:
        if w["start"] == 0:  # behind the route's start
            w["x"] -= LEAD_IN * math.cos(w["heading"])
            w["y"] -= LEAD_IN * math.sin(w["heading"])
            w["length"] += LEAD_IN
        w["reach"] = {}
        for side in (1.0, -1.0):
            before = after = 0.0
            for neighbour, which in ((w["start"] - 1, "before"), (w["end"] + 1, "after")):
                if 0 <= neighbour < len(pieces) and pieces[neighbour].kind == "bend":
                    bend = pieces[neighbour]
                    if (1.0 if bend.angle > 0 else -1.0) == -side:  # this side is the bend's outer wall
                        _, box = outer_box_width(bend.radius, diameter, bend.angle)
                        if which == "before":
                            before = box
                        else:
                            after = box
            w["reach"][side] = (before, after)
    return walls


def write_route_walls(spec: mujoco.MjSpec, params: RobotParams, route: Route) -> None:
    """Replace the planes of a wheeled model's spec by the route's walls (module docstring); the planes'
    friction, condim, solref and solimp carry over."""
    D = params.pipe_diameter
    route.check_pipe(D)
    check_wall_count(route, D)
    template = spec.geom("wall_top")
    style = dict(contype=0, conaffinity=1, condim=int(template.condim), friction=list(template.friction),
                 solref=list(template.solref), solimp=list(template.solimp), margin=float(template.margin))
    for name in ("wall_top", "wall_bottom"):
        spec.delete(spec.geom(name))
    for name in COLLIDING:  # the rigid parts meet the route's walls (each other and the wheels never)
        geom = spec.geom(name)
        geom.contype, geom.conaffinity, geom.condim = 1, 0, style["condim"]
        geom.friction, geom.solref, geom.solimp = style["friction"], style["solref"], style["solimp"]
    world = spec.worldbody
    robot_length = params.L + params.r + 0.1  # A to the front module's fore wheels and beyond
    half = D / 2
    for k, w in enumerate(_wall_straights(route, robot_length, D)):
        c, s = math.cos(w["heading"]), math.sin(w["heading"])
        for side, name in ((1.0, "top"), (-1.0, "bottom")):
            before, after = w["reach"][side]
            length = w["length"] + before + after
            mid = w["length"] / 2 + (after - before) / 2
            off = side * (half + THICKNESS / 2)
            world.add_geom(name=f"route_straight{k + 1}_{name}", type=mujoco.mjtGeom.mjGEOM_BOX,
                           size=[length / 2, THICKNESS / 2, HEIGHT], quat=_quat(w["heading"]),
                           pos=[w["x"] + mid * c - off * s, w["y"] + mid * s + off * c, 0.0], group=1,
                           rgba=list(WALL_RGBA), **style)
    for k, bend in enumerate(route.bends):
        cx, cy = bend.centre
        inner, outer = bend.radius - half, bend.radius + half
        world.add_geom(name=f"route_bend{k + 1}_inner", type=mujoco.mjtGeom.mjGEOM_CAPSULE, size=[inner, HEIGHT, 0],
                       pos=[cx, cy, 0.0], group=3, rgba=list(WALL_RGBA), **style)
        world.add_geom(name=f"route_bend{k + 1}_inner_drawn", type=mujoco.mjtGeom.mjGEOM_CYLINDER,
                       size=[inner, HEIGHT, 0], pos=[cx, cy, 0.0], contype=0, conaffinity=0, group=1,
                       rgba=list(WALL_RGBA))
        n, box = outer_box_width(bend.radius, D, bend.angle)
        step = bend.angle / n
        side = 1.0 if bend.angle > 0 else -1.0
        start = math.atan2(bend.y - cy, bend.x - cx)  # the bend's start, seen from its centre
        for j in range(n):
            theta = start + (j + 0.5) * step  # direction of the tangent point from the centre
            r = outer + THICKNESS / 2
            world.add_geom(name=f"route_bend{k + 1}_outer{j + 1}", type=mujoco.mjtGeom.mjGEOM_BOX,
                           size=[box, THICKNESS / 2, HEIGHT], quat=_quat(theta + side * math.pi / 2),
                           pos=[cx + r * math.cos(theta), cy + r * math.sin(theta), 0.0], group=1,
                           rgba=list(WALL_RGBA), **style)
    _place_floor(spec, route, robot_length)


def _place_floor(spec: mujoco.MjSpec, route: Route, robot_length: float) -> None:
    """The floor drawn under the route (it collides with nothing)."""
    points = [route.at(route.length * i / 200)[:2] for i in range(201)]
    xs, ys = [p[0] for p in points], [p[1] for p in points]
    floor = spec.geom("pipe_floor")
    if floor is None:
        return
    floor.pos = [(min(xs) + max(xs)) / 2, (min(ys) + max(ys)) / 2, floor.pos[2]]
    floor.size = [(max(xs) - min(xs)) / 2 + robot_length + 1.0, (max(ys) - min(ys)) / 2 + robot_length + 1.0,
                  floor.size[2]]


def fit_prediction(route: Route, params: RobotParams, half_base: float, spring_travel: float,
                   housing: tuple[float, float] = (2 * HOUSING_HALF, 2 * HOUSING_HALF)) -> dict:
    """The closed-form check of each bend beside MuJoCo's outcome: the rigid housing (``housing``: its width
    across the pipe and its length [m]) against :func:`.pipe.bend_max_length`, and the spread the wheels of a station (``half_base`` [m] either side
    of the module's middle) need against their springs' reach (2 ``spring_travel`` [m] per pair: each of the
    pair's springs reaches its free length), :func:`.pipe.bend_wheel_spread`. Returns ``{"bends": [...],
    "predicted": one line}``; a figure with no finite value (the rod's clearance where it is longer than the
    centreline's diameter) is None."""
    D, Rw = params.pipe_diameter, params.wheel_radius
    bends, worst = [], None
    for k, bend in enumerate(route.bends):
        rigid = bend_max_length(housing[0], bend.radius, D)
        spread = bend_wheel_spread(half_base, Rw, bend.radius, D)
        press = 1.0 - spread / (2 * spring_travel)
        clearance = bend_rod_clearance(params.L, ROD_RADIUS, bend.radius, D)
        bends.append({"bend": k + 1, "radius_m": bend.radius, "R_over_D": bend.radius / D,
                      "housing_max_length_m": rigid, "housing_fits": rigid >= housing[1],
                      "wheel_spread_m": spread, "spring_reach_m": 2 * spring_travel,
                      "wall_press_share": press, "wheels_keep_wall": press > 0,
                      "rod_clearance_m": clearance, "rod_clears": clearance > 0})
        if worst is None or press < worst["wall_press_share"]:
            worst = bends[-1]
    tightest = min(bends, key=lambda b: b["rod_clearance_m"]) if bends else None
    if worst is None:
        predicted = "no bend: the straight pipe's fit"
    elif not worst["housing_fits"]:
        predicted = f"jams: the housing does not pass bend {worst['bend']}"
    elif not tightest["rod_clears"]:
        by = ("it is longer than the centreline's diameter" if math.isinf(tightest["rod_clearance_m"]) else
              f"as a chord of the centreline it would cross the inner wall by "
              f"{-tightest['rod_clearance_m'] * 1e3:.3g} mm")
        predicted = f"the linkage may bind in bend {tightest['bend']} (R/D {tightest['R_over_D']:.3g}): the rod {by}"
    elif not worst["wheels_keep_wall"]:
        predicted = (f"a wheel leaves the wall in bend {worst['bend']} (R/D {worst['R_over_D']:.3g}): the wheels "
                     f"need {worst['wheel_spread_m'] * 1e3:.3g} mm more spread, their springs reach "
                     f"{2 * spring_travel * 1e3:.3g} mm")
    else:
        predicted = (f"passes: in bend {worst['bend']} (R/D {worst['R_over_D']:.3g}) the wheels press with "
                     f"{100 * worst['wall_press_share']:.0f} % of their preload")
    for b in bends:  # JSON has no infinity: a rod longer than the centreline's diameter has no clearance (None)
        b.update({key: None for key, value in b.items() if isinstance(value, float) and not math.isfinite(value)})
    return {"bends": bends, "predicted": predicted}
