"""A pipeline route for the wheeled MuJoCo model (``--route FILE.toml``): parsing, checking and its centreline.

Shared and free of physics: what the route is, where its centreline runs, how far along it a point is; the
walls MuJoCo builds along it are the engine's (:mod:`ipir_mujoco.engine.route_walls`).

A route is a list of ``[[segment]]`` tables, in order:

- ``kind = "straight"``: ``length`` [m] (0 < length <= 100), ``incline`` [deg] (optional);
- ``kind = "bend"``: ``radius`` [m] of the centreline (pipe_diameter / 2 < radius <= 100), ``angle`` [deg]
  (-180 <= angle <= 180, not 0; positive turns towards the top wall, +y, negative towards the bottom one).

The model is planar, so the whole route lies in the mechanism's plane and every bend turns in it. Gravity
keeps today's convention: the plane is tilted about its across-the-pipe axis (y) so that the first
segment (a straight, where the robot starts) rises at its ``incline`` (default 0: the plane horizontal,
gravity normal to it, the bends horizontal; 90: the plane vertical, the route starts as a riser and a bend of
+-90 degrees turns it horizontal). A later straight's incline follows from the bends before it, asin(sin
theta_0 cos psi) with psi its heading in the plane; it may be given, and must then equal that (else the route
would need a kink). Coordinates: the plane's x along the first straight, y across it, the route starting
at the origin.
"""

from __future__ import annotations

import math
import tomllib
from dataclasses import dataclass
from pathlib import Path

from .errors import ParameterError

MAX_SEGMENTS = 100
MAX_LENGTH = 100.0  # m: a straight's length and a bend's radius at most
INCLINE_MATCH = 1e-6  # deg: how closely a later straight's given incline must match its heading's


@dataclass(frozen=True)
class Piece:
    """One segment placed in the plane: ``kind`` 'straight' | 'bend', its start ``s0`` [m] along the
    centreline, ``length`` [m] along it, start point ``x``, ``y`` [m] and ``heading`` [rad] (from +x towards +y);
    a bend's ``radius`` [m] and signed ``angle`` [rad]; ``incline`` [deg] of a straight (its slope)."""

    kind: str
    s0: float
    length: float
    x: float
    y: float
    heading: float
    radius: float = 0.0
    angle: float = 0.0
    incline: float = 0.0

    @property
    def centre(self) -> tuple[float, float]:
        """A bend's centre [m]: radius to the left (+angle) or right (-angle) of its start heading."""
        side = 1.0 if self.angle > 0 else -1.0
        return (self.x - side * self.radius * math.sin(self.heading),
                self.y + side * self.radius * math.cos(self.heading))

    def at(self, u: float) -> tuple[float, float, float]:
        """(x, y, heading) [m, m, rad] a distance ``u`` [m] (0..length) along the piece."""
        if self.kind == "straight":
            return (self.x + u * math.cos(self.heading), self.y + u * math.sin(self.heading), self.heading)
        cx, cy = self.centre
        side = 1.0 if self.angle > 0 else -1.0
        turned = self.heading + side * u / self.radius
        return (cx + side * self.radius * math.sin(turned), cy - side * self.radius * math.cos(turned), turned)

    def nearest(self, px: float, py: float) -> tuple[float, float]:
        """(distance [m] from the point to the piece's centreline, u [m] along it of the nearest point)."""
        if self.kind == "straight":
            c, s = math.cos(self.heading), math.sin(self.heading)
            u = min(max((px - self.x) * c + (py - self.y) * s, 0.0), self.length)
        else:
            cx, cy = self.centre
            side = 1.0 if self.angle > 0 else -1.0
            start = math.atan2(self.y - cy, self.x - cx)
            turned = math.atan2(py - cy, px - cx) - start
            turned = side * ((side * turned) % (2 * math.pi))  # 0..2 pi in the bend's sense
            if abs(turned) > abs(self.angle):  # beyond the bend's end: clamp to the nearer end
                over = abs(turned) - abs(self.angle)
                turned = self.angle if over < (2 * math.pi - abs(turned)) else 0.0
            u = abs(turned) * self.radius
        x, y, _ = self.at(u)
        return math.hypot(px - x, py - y), u


@dataclass(frozen=True)
class Route:
    """A checked route (module docstring): its pieces in order, the first straight's ``incline`` [deg]
    (the plane's tilt) and where it came from (``source``, for messages)."""

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

    def at(self, s: float) -> tuple[float, float, float]:
        """(x, y, heading) [m, m, rad] of the centreline at ``s`` [m] (clamped to 0..length)."""
        s = min(max(s, 0.0), self.length)
        for piece in self.pieces:
            if s <= piece.s0 + piece.length:
                return piece.at(s - piece.s0)
        return self.pieces[-1].at(self.pieces[-1].length)  # pragma: no cover (round-off at the end)

    def project(self, x: float, y: float, near: float | None = None) -> float:
        """How far along the centreline [m] the point (x, y) [m] is: its nearest centreline point's s; with
        ``near`` [m], of the pieces within 0.5 m of that s only (a route that passes near itself)."""
        best = (math.inf, 0.0)
        for piece in self.pieces:
            if near is not None and not (piece.s0 - 0.5 <= near <= piece.s0 + piece.length + 0.5):
                continue
            distance, u = piece.nearest(x, y)
            if distance < best[0]:
                best = (distance, piece.s0 + u)
        return best[1]

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
                segments.append({"kind": "bend", "radius": p.radius, "angle": math.degrees(p.angle)})
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
    if not isinstance(tables, list) or not 1 <= len(tables) <= MAX_SEGMENTS:
        raise ParameterError(f"{source}: needs [[segment]] tables; allowed: 1..{MAX_SEGMENTS} segments")
    pieces: list[Piece] = []
    s = x = y = heading = 0.0
    incline0 = 0.0
    for k, table in enumerate(tables):
        if not isinstance(table, dict):
            raise ParameterError(f"{source}: segment {k + 1} is not a table; allowed: [[segment]] tables")
        kind = table.get("kind")
        allowed = {"straight": {"kind", "length", "incline"}, "bend": {"kind", "radius", "angle"}}
        if kind not in allowed:
            raise ParameterError(f"{source}: segment {k + 1}: kind={kind!r} is unknown; allowed: kind = "
                                 "\"straight\" or \"bend\"")
        extra = sorted(set(table) - allowed[kind])
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
            else:
                slope = math.sin(math.radians(incline0)) * math.cos(heading)
                # to 1e-9 deg: the bends' round-off (a level pipe is 0, not 1.8e-15)
                incline = round(math.degrees(math.asin(max(-1.0, min(1.0, slope)))), 9) + 0.0
                if "incline" in table:
                    given = _value(source, k, table, "incline", -90.0, 90.0, "deg", low_open=False)
                    if abs(given - incline) > INCLINE_MATCH:
                        raise ParameterError(f"{source}: segment {k + 1}: incline={given:g} deg, but the bends "
                                             f"before it leave the pipe at {incline:.6g} deg; allowed: incline = "
                                             f"{incline:.6g} (or leave it out)")
            pieces.append(Piece("straight", s, length, x, y, heading, incline=incline))
        else:
            radius = _value(source, k, table, "radius", 0.0, MAX_LENGTH, "m")
            angle = math.radians(_value(source, k, table, "angle", -180.0, 180.0, "deg", low_open=False,
                                        nonzero=True))
            length = abs(angle) * radius
            pieces.append(Piece("bend", s, length, x, y, heading, radius=radius, angle=angle))
        x, y, heading = pieces[-1].at(pieces[-1].length)
        s += length
    return Route(tuple(pieces), incline0, source)


def read_route(path: str | Path) -> Route:
    """The route in the TOML file ``path`` (module docstring); ParameterError (one line) on bad input."""
    source = str(path)
    try:
        with open(path, "rb") as f:
            data = tomllib.load(f)
    except FileNotFoundError:
        raise ParameterError(f"--route {source}: no such file") from None
    except (OSError, tomllib.TOMLDecodeError) as exc:
        raise ParameterError(f"--route {source}: not a readable TOML file ({' '.join(str(exc).split())})") from None
    extra = sorted(set(data) - {"segment"})
    if extra:
        raise ParameterError(f"{source}: {extra[0]!r} is unknown; allowed: [[segment]] tables only")
    return route_from_tables(data.get("segment"), source)
