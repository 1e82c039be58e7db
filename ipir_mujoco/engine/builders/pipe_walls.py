"""The inside of a round pipe for MuJoCo: a straight pipe, or straights and bends along a route, with exact walls.

MuJoCo collides meshes as convex hulls, so a pipe's inside cannot be a mesh; facets (boxes) bump at their seams
or corners, and MuJoCo's own SDF collision tilts its normals and drops contacts (mjcf/README.md, "The round
pipe", has the measurements). Here each piece of the pipe is one CYLINDER geom marked as a pipe by its user
data, and the compiled part (``_pipewall.c``) puts exact contact functions in MuJoCo's collision table
(``mjCOLLISIONFUNC``, public in mujoco.h) for the pairs (sphere, cylinder), (capsule, cylinder) and (cylinder,
box): a marked pipe against a sphere (a wheel), a capsule or a box (a housing) gets the contact from the exact
distance to the pipe's centreline (normal radial, depth D/2 - (rho + r), one contact per pair: its deepest
point), every other pair MuJoCo's own function, unchanged. A wheel rolling along the pipe sees a perfectly
round wall: no seam, no facet, no ripple from the construction, through straights and bends alike (the
pieces meet tangentially; each covers a half-open stretch of the centreline, so exactly one of them answers
for a point).

Pieces (:func:`wall_pieces`): consecutive straights of a route merge into one; the first reaches LEAD_IN behind
the route's start and an exit straight of the robot's length plus LEAD_IN follows its end. A straight
geom's frame sits at its middle with z along the pipe; a bend's at the bend's centre, z its turning axis, x
towards the bend's start. Without a route, one straight along the world's x axis through the origin,
STRAIGHT_HALF either side.

Contacts: the walls have ``priority`` 1, so their friction, solref, solimp and condim (:class:`WallContact`)
are every wall contact's, whatever the robot's geoms say. solref is (time constant [s], damping ratio): a
property of the model in physical time, not a multiple of the step. Parts that touch the wall need contype
with PIPE_BIT (:func:`touch_wall`); the walls have contype 0 and conaffinity PIPE_BIT.

The replaced collision functions act process-wide, in MuJoCo's C engine (not MJX or MuJoCo Warp); the
compiled part is built against the installed mujoco's headers and checked against the running library
(:func:`install`). An MJCF file saved from such a model shows each piece as a plain cylinder: outside this
package, MuJoCo would collide the robot with a solid cylinder.
"""

from __future__ import annotations

import functools
import importlib
import math
from dataclasses import dataclass

import mujoco
import numpy as np

from ipir_mujoco.core.errors import ParameterError

from .pipe_drawing import _quat, draw_pipe

PIPE_BIT = 1  # the collision bit of the wall (geom conaffinity) and of the parts that touch it (their contype)
LEAD_IN = 0.3  # m: the walls behind a route's start, and beyond the robot at its end
STRAIGHT_HALF = 1000.0  # m: the straight pipe's half-length (no run gets near its ends)
STRAIGHT, BEND = 1.0, 2.0  # a piece's kind in its user data
MAGIC, NUSER = 7310.5, 5  # the marker in a pipe geom's user data (first value), and how many values (_pipewall.c)
WALL_RGBA = (0.55, 0.6, 0.7, 0.25)
MAX_PIECES = 1000  # wall pieces a model may have: a 100-segment route needs at most 102
TOUCHING_TYPES = (mujoco.mjtGeom.mjGEOM_SPHERE, mujoco.mjtGeom.mjGEOM_CAPSULE, mujoco.mjtGeom.mjGEOM_BOX)


@dataclass(frozen=True)
class WallContact:
    """The wall's contact settings: ``friction`` (the sliding coefficient, mu_wall), ``solref`` (time constant
    [s], damping ratio), ``solimp`` (MuJoCo's five impedance numbers), ``condim`` (3: sliding friction, the
    rolling is the wheels' hinges'), ``margin`` [m]."""

    friction: float
    solref: tuple[float, float]
    solimp: tuple[float, float, float, float, float] = (0.99, 0.999, 0.001, 0.5, 2.0)
    condim: int = 3
    margin: float = 0.0

    def __post_init__(self) -> None:
        if not (math.isfinite(self.friction) and self.friction >= 0):
            raise ParameterError(f"friction={self.friction!r} is out of range; allowed: friction >= 0")
        if not (len(self.solref) == 2 and all(math.isfinite(v) and v > 0 for v in self.solref)):
            raise ParameterError(f"solref={self.solref!r} is out of range; allowed: (time constant > 0 s, damping "
                                 "ratio > 0)")
        if self.condim not in (1, 3, 4, 6):
            raise ParameterError(f"condim={self.condim!r} is unknown; allowed: 1, 3, 4, 6")


@functools.lru_cache(maxsize=None)
def _install() -> str | None:
    """Install the compiled contact functions once per process; None, or the one line saying why not."""
    try:
        native = importlib.import_module(f"{__package__}._pipewall")
    except ImportError as exc:
        return ("the round pipe needs the package's compiled part (_pipewall), which is not built "
                f"({' '.join(str(exc).split())}); reinstall ipir-mujoco with a C compiler")
    if native.MJVERSION_HEADER != mujoco.mj_version():
        return (f"the round pipe's compiled part was built for MuJoCo {native.MJVERSION_HEADER}, the running one is "
                f"{mujoco.mj_version()}; reinstall ipir-mujoco with pip's --no-build-isolation")
    if (native.PIPE_MAGIC, native.PIPE_NUSER) != (MAGIC, NUSER):
        return "the round pipe's compiled part was built from other sources than this package's; reinstall it"
    native.install()
    # the probe: a ball 0.07 m off the axis of a 0.16 m straight pipe, radius 0.02 m, sinks 0.01 m into the wall
    spec = mujoco.MjSpec()
    add_pipe_walls(spec, None, 0.16, WallContact(0.5, (0.01, 1.0)), draw=False, _probe=True)
    body = spec.worldbody.add_body(pos=[0.0, 0.07, 0.0])
    body.add_freejoint()
    body.add_geom(type=mujoco.mjtGeom.mjGEOM_SPHERE, size=[0.02, 0, 0], contype=PIPE_BIT, conaffinity=0)
    model = spec.compile()
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    if data.ncon != 1 or abs(data.contact.dist[0] + 0.01) > 1e-12:
        return ("the round pipe's compiled part does not act in the libmujoco the mujoco bindings use; reinstall "
                "ipir-mujoco with pip's --no-build-isolation")
    return None


def install() -> None:
    """Put the pipe's exact contact functions in MuJoCo's collision table (once per process, checked with a
    probe model); ParameterError (one line) if the compiled part is missing or does not fit the running mujoco."""
    why = _install()
    if why is not None:
        raise ParameterError(why)


def wall_pieces(route, diameter: float, robot_length: float) -> list[dict]:
    """The wall's pieces (module docstring) as dicts: ``kind`` 'straight' | 'bend', ``pos`` [m] (3,),
    ``rotation`` (3, 3) (columns: the geom's axes in the world), ``user`` (the marker and shape), ``size`` (the
    cylinder's radius and half-height [m], its bounding volume), ``length`` [m] along the centreline, and for
    drawing a bend's ``radius`` [m] and ``angle`` [rad]. Route coordinates are the world's."""
    a = diameter / 2
    if route is None:
        rot = np.column_stack([[0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [1.0, 0.0, 0.0]])  # z along x
        return [dict(kind="straight", pos=np.zeros(3), rotation=rot, user=[0.0, STRAIGHT, a, STRAIGHT_HALF, 0.0],
                     size=[a, STRAIGHT_HALF], length=2 * STRAIGHT_HALF)]
    from ipir_mujoco.core.route import Piece

    last = route.pieces[-1]
    end, _ = last.at3(last.length)
    pieces = list(route.pieces) + [Piece("straight", route.length, robot_length + LEAD_IN, end,
                                         last.frame_at(last.length))]
    runs: list[list] = []  # merged straights: [start point, frame, length] or a bend
    for k, piece in enumerate(pieces):
        if piece.kind == "straight":
            if runs and isinstance(runs[-1], list):
                runs[-1][2] += piece.length
            else:
                start = piece.point - (LEAD_IN * piece.frame[0] if k == 0 else 0.0)
                runs.append([start, piece.frame, piece.length + (LEAD_IN if k == 0 else 0.0)])
        else:
            runs.append(piece)
    out = []
    for run in runs:
        if isinstance(run, list):
            start, frame, length = run
            t, n, b = frame
            out.append(dict(kind="straight", pos=start + t * length / 2, rotation=np.column_stack([n, b, t]),
                            user=[0.0, STRAIGHT, a, length / 2, 0.0], size=[a, length / 2], length=length))
        else:
            t, d, w = run.frame[0], run.toward, run.axis
            angle = abs(run.angle)
            out.append(dict(kind="bend", pos=run.centre3, rotation=np.column_stack([-d, t, w]),
                            user=[0.0, BEND, a, run.radius, angle], size=[run.radius + a, a], length=run.length,
                            radius=run.radius, angle=angle))
    return out


def add_pipe_walls(spec: mujoco.MjSpec, route, diameter: float, contact: WallContact, robot_length: float = 0.5,
                   draw: bool = True, prefix: str = "pipe", _probe: bool = False) -> list[str]:
    """Add the pipe's walls (module docstring) to ``spec`` (before it compiles): ``route`` a
    :class:`ipir_mujoco.core.route.Route` or None (a straight pipe along x), ``diameter`` [m] the bore,
    ``contact`` the wall's contact settings, ``robot_length`` [m] how far the robot reaches ahead of the point
    that runs along the route (the exit straight's length, with LEAD_IN), ``draw``: translucent drawings of
    the walls (group 1, colliding with nothing; :mod:`.pipe_drawing`). Returns the colliding geoms' names
    (``{prefix}_straight{k}``, ``{prefix}_bend{k}``, in order along the route); ParameterError (one line) if
    the compiled part cannot be installed, the diameter is not positive or a bend is tighter than the pipe."""
    if not _probe:
        install()
    if not (math.isfinite(diameter) and diameter > 0):
        raise ParameterError(f"pipe_diameter={diameter!r} m is out of range; allowed: > 0")
    if route is not None:
        route.check_pipe(diameter)
    pieces = wall_pieces(route, diameter, robot_length)
    if len(pieces) > MAX_PIECES:  # pragma: no cover (a route has at most 100 segments)
        raise ParameterError(f"the pipe needs {len(pieces)} wall pieces; allowed: at most {MAX_PIECES}")
    spec.nuser_geom = max(int(spec.nuser_geom), NUSER)
    names, counts = [], {"straight": 0, "bend": 0}
    for piece in pieces:
        counts[piece["kind"]] += 1
        name = f"{prefix}_{piece['kind']}{counts[piece['kind']]}"
        user = list(piece["user"])
        user[0] = MAGIC
        spec.worldbody.add_geom(name=name, type=mujoco.mjtGeom.mjGEOM_CYLINDER, size=[*piece["size"], 0.0],
                                pos=[float(v) for v in piece["pos"]], quat=_quat(piece["rotation"]),
                                contype=0, conaffinity=PIPE_BIT, priority=1, condim=contact.condim,
                                friction=[contact.friction, 0.0, 0.0], solref=list(contact.solref),
                                solimp=list(contact.solimp), margin=contact.margin, group=3,
                                rgba=[0.0, 0.0, 0.0, 0.0], userdata=user)
        names.append(name)
    if draw:
        draw_pipe(spec, pieces, diameter, prefix)
    return names


def touch_wall(spec: mujoco.MjSpec, names) -> None:
    """Let the geoms ``names`` touch the wall (contype PIPE_BIT, conaffinity 0: they still do not collide
    with each other); ParameterError for a geom the wall cannot collide with (allowed: sphere, capsule, box)."""
    for name in names:
        geom = spec.geom(name)
        if geom is None:
            raise ParameterError(f"touch_wall: no geom {name!r} in the model")
        if geom.type not in TOUCHING_TYPES:
            raise ParameterError(f"touch_wall: geom {name!r} is a {geom.type.name}; allowed: a sphere, capsule or "
                                 "box (the pipe's contacts are exact for these)")
        geom.contype, geom.conaffinity = PIPE_BIT, 0
