"""One piece of a pipeline route placed in 3-D: a straight or a bend, its centreline, its frame, nearest points.

:class:`Piece` is what :func:`.route.route_from_tables` places each checked segment as (route coordinates: the
first straight along +x, its left +y, its up +z; :mod:`.route` says how a route reads); a :class:`.route.Route`
is a tuple of them. Shared and free of physics.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numpy as np


def _rotate(v: np.ndarray, axis: np.ndarray, angle: float) -> np.ndarray:
    """``v`` turned by ``angle`` [rad] about the unit ``axis`` (Rodrigues)."""
    c, s = math.cos(angle), math.sin(angle)
    return v * c + np.cross(axis, v) * s + axis * float(axis @ v) * (1 - c)


@dataclass(frozen=True, eq=False)
class Piece:
    """One segment placed in 3-D: ``kind`` 'straight' | 'bend', its start ``s0`` [m] along the centreline,
    ``length`` [m] along it, start ``point`` [m] (3,), ``frame`` (3, 3): rows the pipe's direction t, its left
    n and its up b at the start; a bend's ``radius`` [m], ``angle`` [rad] as given (signed) and ``plane``
    [rad]; ``incline`` [deg] of a straight (its slope)."""

    kind: str
    s0: float
    length: float
    point: np.ndarray
    frame: np.ndarray
    radius: float = 0.0
    angle: float = 0.0
    plane: float = 0.0
    incline: float = 0.0

    @property
    def toward(self) -> np.ndarray:
        """A bend's unit direction from its start to its centre (3,): where it turns."""
        _, n, b = self.frame
        d = math.cos(self.plane) * n + math.sin(self.plane) * b
        return d if self.angle > 0 else -d

    @property
    def centre3(self) -> np.ndarray:
        """A bend's centre [m] (3,)."""
        return self.point + self.radius * self.toward

    @property
    def axis(self) -> np.ndarray:
        """A bend's turning axis (3,): t x toward; the pipe turns positively about it."""
        return np.cross(self.frame[0], self.toward)

    def at3(self, u: float) -> tuple[np.ndarray, np.ndarray]:
        """(point [m] (3,), unit direction (3,)) a distance ``u`` [m] (0..length) along the piece."""
        return np.array(self.point_xyz(u)), np.array(self.direction_xyz(u))

    def frame_at(self, u: float) -> np.ndarray:
        """The pipe's frame (rows t, n, b) ``u`` [m] along the piece (transported along a bend)."""
        if self.kind == "straight":
            return self.frame.copy()
        axis, phi = self.axis, u / self.radius
        return np.array([_rotate(row, axis, phi) for row in self.frame])

    @functools.cached_property
    def _floats(self) -> tuple:
        """The piece's constants as Python floats, for :meth:`point_xyz`, :meth:`direction_xyz` and :meth:`at3`
        built on them (a run's route watch projects two points
        per recorded sample: numpy's per-call cost on 3-vectors was most of a route run's time): (point, t, d, c,
        axis) each (x, y, z) [m or -], d and c a bend's :attr:`toward` and :attr:`centre3` (zeros for a
        straight)."""
        t = tuple(float(v) for v in self.frame[0])
        straight = self.kind == "straight"
        return (tuple(float(v) for v in self.point), t,
                (0.0, 0.0, 0.0) if straight else tuple(float(v) for v in self.toward),
                (0.0, 0.0, 0.0) if straight else tuple(float(v) for v in self.centre3),
                (0.0, 0.0, 0.0) if straight else tuple(float(v) for v in self.axis))

    def nearest_xyz(self, px: float, py: float, pz: float) -> tuple[float, float]:
        """(distance [m] from the point (px, py, pz) [m] to the piece's centreline, u [m] along it of the nearest
        point), in Python floats."""
        (ox, oy, oz), (tx, ty, tz), (dx, dy, dz), (cx, cy, cz), (ax, ay, az) = self._floats
        if self.kind == "straight":
            u = min(max((px - ox) * tx + (py - oy) * ty + (pz - oz) * tz, 0.0), self.length)
            qx, qy, qz = self.point_xyz(u)
        else:
            vx, vy, vz = px - cx, py - cy, pz - cz
            k = vx * ax + vy * ay + vz * az
            vx, vy, vz = vx - ax * k, vy - ay * k, vz - az * k  # into the bend's plane
            turned = math.atan2(vx * tx + vy * ty + vz * tz, -(vx * dx + vy * dy + vz * dz)) % (2 * math.pi)
            a = abs(self.angle)
            if turned > a:  # beyond the bend's end: clamp to the nearer end
                turned = a if turned - a < 2 * math.pi - turned else 0.0
            u = turned * self.radius
            qx, qy, qz = self.point_xyz(u)
        return math.sqrt((px - qx) ** 2 + (py - qy) ** 2 + (pz - qz) ** 2), u

    def point_xyz(self, u: float) -> tuple[float, float, float]:
        """The centreline's point [m] ``u`` [m] (0..length) along the piece, in Python floats."""
        (ox, oy, oz), (tx, ty, tz), (dx, dy, dz), _, _ = self._floats
        if self.kind == "straight":
            return ox + u * tx, oy + u * ty, oz + u * tz
        r = self.radius
        phi = u / r
        sin, cos_1 = math.sin(phi), 1 - math.cos(phi)
        return ox + r * (sin * tx + cos_1 * dx), oy + r * (sin * ty + cos_1 * dy), oz + r * (sin * tz + cos_1 * dz)

    def direction_xyz(self, u: float) -> tuple[float, float, float]:
        """The centreline's unit direction ``u`` [m] along the piece, in Python floats."""
        _, t, d, _, _ = self._floats
        if self.kind == "straight":
            return t
        phi = u / self.radius
        c, s = math.cos(phi), math.sin(phi)
        return c * t[0] + s * d[0], c * t[1] + s * d[1], c * t[2] + s * d[2]

    def curvature_xyz(self, u: float) -> tuple[float, float, float]:
        """The centreline's curvature vector [1/m] ``u`` [m] along the piece: 1 / radius towards the bend's centre,
        zeros along a straight; in Python floats."""
        if self.kind == "straight":
            return 0.0, 0.0, 0.0
        _, t, d, _, _ = self._floats
        phi = u / self.radius
        c, s = math.cos(phi), math.sin(phi)
        return tuple((c * d[k] - s * t[k]) / self.radius for k in range(3))

    def nearest3(self, p: np.ndarray) -> tuple[float, float]:
        """(distance [m] from the point ``p`` (3,) to the piece's centreline, u [m] along it of the nearest
        point)."""
        return self.nearest_xyz(float(p[0]), float(p[1]), float(p[2]))

    # the mechanism's plane (z = 0), for the planar model's walls: valid while every bend turns in it
    @property
    def x(self) -> float:
        return float(self.point[0])

    @property
    def y(self) -> float:
        return float(self.point[1])

    @property
    def heading(self) -> float:
        """[rad] the direction in the xy plane, from +x towards +y."""
        return math.atan2(float(self.frame[0][1]), float(self.frame[0][0]))

    @property
    def in_plane(self) -> bool:
        """Whether the piece lies in the xy plane (a straight along it, a bend turning in it)."""
        return abs(float(self.frame[0][2])) < 1e-9 and (self.kind == "straight" or abs(float(self.axis[2])) > 1 - 1e-9)

    @property
    def centre(self) -> tuple[float, float]:
        """A bend's centre [m] in the xy plane."""
        c = self.centre3
        return float(c[0]), float(c[1])

    def at(self, u: float) -> tuple[float, float, float]:
        """(x, y, heading) [m, m, rad] a distance ``u`` [m] (0..length) along the piece, in the xy plane."""
        p, t = self.at3(u)
        return float(p[0]), float(p[1]), math.atan2(float(t[1]), float(t[0]))

    def nearest(self, px: float, py: float) -> tuple[float, float]:
        """:meth:`nearest3` of the point (px, py, 0)."""
        return self.nearest3(np.array([px, py, 0.0]))
