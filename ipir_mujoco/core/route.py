"""A pipeline route (``--route FILE.toml``): parsing, checking and its centreline in 3-D.

Shared and free of physics: what the route is, where its centreline runs, how far along it a point is; the
walls MuJoCo builds along it are the engine's (:mod:`ipir_mujoco.engine.builders.pipe_walls`).

A route is a list of ``[[segment]]`` tables, in order:

- ``kind = "straight"``: ``length`` [m] (0 < length <= 100), ``incline`` [deg] (optional, see below);
- ``kind = "bend"``: ``radius`` [m] of the centreline (pipe_diameter / 2 < radius <= 100), ``angle`` [deg]
  (-180 <= angle <= 180, not 0), ``plane`` [deg] (optional, -180..180, default 0): the bend's plane turned
  about the pipe's axis. With ``plane = 0`` a positive angle turns towards the route's left (+y at the start,
  the mechanism's top wall), a negative one towards its right; ``plane = 90`` turns a positive angle
  towards the route's up side (+z at the start: out of the mechanism's plane), and so on. The side a bend
  turns to is carried along the pipe (parallel transport), so ``plane`` is always relative to the pipe as it
  arrives at the bend.

Coordinates: the route starts at the origin with its first straight along +x, its left +y and its up +z.
Gravity keeps the package's convention: the first straight (where the robot starts) rises at its ``incline``
(default 0: level, gravity along -z; 90: a riser). A later straight's incline follows from the bends before
it, asin(t . up) with t its direction and up = (sin theta_0, 0, cos theta_0) the world's up in route
coordinates; it may be given, and must then equal that (else the route would need a kink). A vertical leg is
a straight whose direction is +-up: for a level start, a bend of ``angle = 90, plane = 90``.

Each segment placed in 3-D is a :class:`.route_piece.Piece` (re-exported here).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .errors import ParameterError, ParameterTypeError
from .route_piece import Piece

MAX_SEGMENTS = 100
MAX_LENGTH = 100.0  # m: a straight's length and a bend's radius at most
INCLINE_MATCH = 1e-6  # deg: how closely a later straight's given incline must match its heading's
MAX_ROUTE_BYTES = 1_000_000  # bytes of a route file: 100 segments take ~10 kB; a bound on what is read
MAX_ROUTE_DEPTH = 8  # how deep a route file's tables and arrays may nest ([[segment]] tables are 2 deep)
# a robot along a route that gets less than PROGRESS_M [m] further in PROGRESS_S [s] has stalled (a tenth of a
# stroke 2 r; the default motor makes ~7 revolutions in it): the analytic route model's stop
# (analytic/route_run.py), the wheeled MuJoCo model's route watch's
PROGRESS_M, PROGRESS_S = 0.01, 2.0


@dataclass(frozen=True, eq=False)
class Route:
    """A checked route (module docstring): its pieces in order, the first straight's ``incline`` [deg]
    (the gravity's tilt) and where it came from (``source``, for messages)."""

    pieces: tuple[Piece, ...]
    incline: float
    source: str = "route"

    @property
    def length(self) -> float:
        """The centreline's length [m]: how far the robot's rear module travels to the route's end."""
        last = self.pieces[-1]
        return last.s0 + last.length

    @property
    def bends(self) -> tuple[Piece, ...]:
        return tuple(p for p in self.pieces if p.kind == "bend")

    @property
    def planar(self) -> bool:
        """Whether the whole route lies in the xy plane (the planar model's mechanism plane)."""
        return all(p.in_plane for p in self.pieces)

    @property
    def up(self) -> np.ndarray:
        """The world's up in route coordinates (3,): the first straight rises at ``incline``."""
        th = math.radians(self.incline)
        return np.array([math.sin(th), 0.0, math.cos(th)])

    def _piece(self, s: float) -> tuple[Piece, float]:
        s = min(max(s, 0.0), self.length)
        for piece in self.pieces:
            if s <= piece.s0 + piece.length:
                return piece, s - piece.s0
        return self.pieces[-1], self.pieces[-1].length  # pragma: no cover (round-off at the end)

    def at3(self, s: float) -> tuple[np.ndarray, np.ndarray]:
        """(point [m] (3,), unit direction (3,)) of the centreline at ``s`` [m] (clamped to 0..length)."""
        piece, u = self._piece(s)
        return piece.at3(u)

    def frame_at(self, s: float) -> np.ndarray:
        """The pipe's frame (3, 3), rows its direction t, left n and up b, at ``s`` [m] (clamped)."""
        piece, u = self._piece(s)
        return piece.frame_at(u)

    def at(self, s: float) -> tuple[float, float, float]:
        """(x, y, heading) [m, m, rad] of the centreline at ``s`` [m] in the xy plane (clamped to 0..length)."""
        piece, u = self._piece(s)
        return piece.at(u)

    def project3(self, p, near: float | None = None) -> float:
        """How far along the centreline [m] the point ``p`` [m] (3,) is: its nearest centreline point's s; with
        ``near`` [m], of the pieces within 0.5 m of that s only (a route that passes near itself)."""
        px, py, pz = (float(v) for v in p)
        best = (math.inf, 0.0)
        for piece in self.pieces:
            if near is not None and not (piece.s0 - 0.5 <= near <= piece.s0 + piece.length + 0.5):
                continue
            distance, u = piece.nearest_xyz(px, py, pz)
            if distance < best[0]:
                best = (distance, piece.s0 + u)
        return best[1]

    def project(self, x: float, y: float, near: float | None = None) -> float:
        """:meth:`project3` of the point (x, y, 0)."""
        return self.project3((x, y, 0.0), near)

    def along(self, p, near: float) -> float:
        """A point's distance along the route [m] (near ``near`` [m]), beyond its end along the exit straight
        and before its start (negative) along the first straight; ``p`` [m] (3,), any sequence of numbers."""
        px, py, pz = (float(v) for v in p)
        s = self.project3((px, py, pz), near=near)
        if s <= 0.0:  # behind the start: along the first straight, backwards
            (ox, oy, oz), (tx, ty, tz) = self.pieces[0]._floats[:2]
            return min(0.0, (px - ox) * tx + (py - oy) * ty + (pz - oz) * tz)
        if s >= self.length:
            end, t = self.at3(self.length)
            s = self.length + max(0.0, float((np.array([px, py, pz]) - end) @ t))
        return s

    def direction_xyz(self, s: float) -> tuple[float, float, float]:
        """The centreline's unit direction at ``s`` [m] (clamped to 0..length), in Python floats (:meth:`at3`'s
        second, without numpy's per-call cost: a route run reads it at every sample)."""
        piece, u = self._piece(s)
        return piece.direction_xyz(u)

    def curvature_xyz(self, s: float) -> tuple[float, float, float]:
        """The centreline's curvature vector [1/m] at ``s`` [m] (clamped): 1 / R towards a bend's centre, zeros
        in a straight."""
        piece, u = self._piece(s)
        return piece.curvature_xyz(u)

    def piece_at(self, s: float) -> int:
        """Index of the piece at ``s`` [m] (the last for s beyond the end)."""
        for k, piece in enumerate(self.pieces):
            if s < piece.s0 + piece.length:
                return k
        return len(self.pieces) - 1

    def where(self, s: float) -> str:
        """``s`` [m] in words: 's = 1.23 m (bend 2 of 3, segment 3)'."""
        k = self.piece_at(s)
        piece = self.pieces[k]
        same = [p for p in self.pieces if p.kind == piece.kind]
        return f"s = {s:.3f} m of {self.length:.3f} m ({piece.kind} {same.index(piece) + 1}, segment {k + 1})"

    def check_pipe(self, diameter: float) -> None:
        """ParameterError (one line) for a bend tighter than the pipe allows: its inner wall's radius
        radius - diameter / 2 must be positive."""
        for k, piece in enumerate(self.pieces):
            if piece.kind == "bend" and not piece.radius > diameter / 2:
                raise ParameterError(f"{self.source}: segment {k + 1}: radius={piece.radius:g} m with "
                                     f"pipe_diameter={diameter:g} m; allowed: radius > pipe_diameter / 2 = "
                                     f"{diameter / 2:g} m")

    def as_dict(self) -> dict:
        """The route as a run's JSON records it: its segments as given (angles in degrees) and its length."""
        segments = []
        for p in self.pieces:
            if p.kind == "straight":
                segments.append({"kind": "straight", "length": p.length, "incline": p.incline})
            else:
                segments.append({"kind": "bend", "radius": p.radius, "angle": math.degrees(p.angle),
                                 "plane": math.degrees(p.plane)})
        return {"segments": segments, "length_m": self.length, "incline_deg": self.incline}


def _value(source: str, k: int, table: dict, key: str, low: float, high: float, unit: str, *,
           low_open: bool = True, default: float | None = None, nonzero: bool = False) -> float:
    """A segment's number, checked: one line naming it and its range."""
    if key not in table:
        if default is not None:
            return default
        raise ParameterError(f"{source}: segment {k + 1} ({table.get('kind')}) lacks {key!r}; allowed: "
                             f"{key} {'>' if low_open else '>='} {low:g} and <= {high:g} {unit}")
    value = table[key]
    ok = isinstance(value, (int, float)) and not isinstance(value, bool) and math.isfinite(value)
    if ok:
        value = float(value)
        ok = (value > low if low_open else value >= low) and value <= high and not (nonzero and value == 0)
    if not ok:
        bound = f"{'>' if low_open else '>='} {low:g} and <= {high:g}" + (", not 0" if nonzero else "")
        raise ParameterError(f"{source}: segment {k + 1}: {key}={value!r} is out of range; allowed: {key} "
                             f"{bound} {unit}")
    return value


def route_from_tables(tables: list, source: str = "route") -> Route:
    """A Route from a list of segment tables (dicts as TOML gives them); ParameterError on bad input."""
    if not isinstance(tables, (list, tuple)):
        raise ParameterTypeError(f"{source}: tables={tables!r} is not a list of [[segment]] tables; allowed: a list "
                                 "of dicts, e.g. [{'kind': 'straight', 'length': 0.4}]")
    if not 1 <= len(tables) <= MAX_SEGMENTS:
        raise ParameterError(f"{source}: needs [[segment]] tables; allowed: 1..{MAX_SEGMENTS} segments")
    pieces: list[Piece] = []
    s = 0.0
    point, frame = np.zeros(3), np.eye(3)
    point.setflags(write=False)
    frame.setflags(write=False)
    incline0 = 0.0
    up = np.array([0.0, 0.0, 1.0])
    for k, table in enumerate(tables):
        if not isinstance(table, dict):
            raise ParameterTypeError(f"{source}: segment {k + 1} is not a table; allowed: [[segment]] tables")
        kind = table.get("kind")
        allowed = {"straight": {"kind", "length", "incline"}, "bend": {"kind", "radius", "angle", "plane"}}
        if not isinstance(kind, str):
            raise ParameterTypeError(f"{source}: segment {k + 1}: kind={kind!r} is not a string; allowed: kind = "
                                     "\"straight\" or \"bend\"")
        if kind not in allowed:
            raise ParameterError(f"{source}: segment {k + 1}: kind={kind!r} is unknown; allowed: kind = "
                                 "\"straight\" or \"bend\"")
        extra = sorted(str(key) for key in set(table) - allowed[kind])
        if extra:
            raise ParameterError(f"{source}: segment {k + 1} ({kind}): {extra[0]!r} is unknown; allowed: "
                                 f"{', '.join(sorted(allowed[kind] - {'kind'}))}")
        if k == 0 and kind != "straight":
            raise ParameterError(f"{source}: segment 1 is a {kind}; allowed: a straight first (the robot starts in "
                                 "it)")
        if kind == "straight":
            length = _value(source, k, table, "length", 0.0, MAX_LENGTH, "m")
            if k == 0:
                incline0 = _value(source, k, table, "incline", -90.0, 90.0, "deg", low_open=False, default=0.0)
                incline = incline0
                th = math.radians(incline0)
                up = np.array([math.sin(th), 0.0, math.cos(th)])
            else:
                slope = float(frame[0] @ up)
                # to 1e-9 deg: the bends' round-off (a level pipe is 0, not 1.8e-15)
                incline = round(math.degrees(math.asin(max(-1.0, min(1.0, slope)))), 9) + 0.0
                if "incline" in table:
                    given = _value(source, k, table, "incline", -90.0, 90.0, "deg", low_open=False)
                    if abs(given - incline) > INCLINE_MATCH:
                        raise ParameterError(f"{source}: segment {k + 1}: incline={given:g} deg, but the bends "
                                             f"before it leave the pipe at {incline:.6g} deg; allowed: incline = "
                                             f"{incline:.6g} (or leave it out)")
            pieces.append(Piece("straight", s, length, point, frame, incline=incline))
        else:
            radius = _value(source, k, table, "radius", 0.0, MAX_LENGTH, "m")
            angle = math.radians(_value(source, k, table, "angle", -180.0, 180.0, "deg", low_open=False,
                                        nonzero=True))
            plane = math.radians(_value(source, k, table, "plane", -180.0, 180.0, "deg", low_open=False,
                                        default=0.0))
            length = abs(angle) * radius
            pieces.append(Piece("bend", s, length, point, frame, radius=radius, angle=angle, plane=plane))
        last = pieces[-1]
        point, _ = last.at3(last.length)
        frame = last.frame_at(last.length)
        frame.setflags(write=False)
        point.setflags(write=False)
        s += length
    return Route(tuple(pieces), incline0, source)


def read_route(path: str | Path) -> Route:
    """The route in the TOML file ``path`` (module docstring); ParameterError (one line) on bad input. Read as
    every file the package takes (:func:`.files.read_toml_file`: UTF-8 only, no device, nesting bounded), with a
    cap of MAX_ROUTE_BYTES: a route's 100 segments take a few kB."""
    from .files import read_toml_file

    source = str(path)
    data = read_toml_file(path, "--route", max_bytes=MAX_ROUTE_BYTES)
    extra = sorted(set(data) - {"segment"})
    if extra:
        raise ParameterError(f"{source}: {extra[0]!r} is unknown; allowed: [[segment]] tables only")
    return route_from_tables(data.get("segment"), source)
