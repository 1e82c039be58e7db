"""Drawings of the round pipe's walls (:mod:`.pipe_walls`): translucent tubes, colliding with nothing.

Each wall piece gets a mesh geom (group 1, contype and conaffinity 0, massless in the world body): rings of
AROUND points about the centreline, one ring per straight's end and one every RING_STEP of a bend's turn, the
faces drawn from both sides (the camera looks from outside the pipe and, in the viewer, may look from inside).
A straight without a route is drawn over DRAWN_STRAIGHT along x (its walls reach much further).
"""

from __future__ import annotations

import math

import mujoco
import numpy as np

AROUND = 32  # points per ring
RING_STEP = math.radians(5.0)  # rad: a bend's rings at most this far apart
DRAWN_STRAIGHT = (-0.5, 4.0)  # m: the stretch of x drawn of a straight pipe without a route
RGBA = (0.55, 0.6, 0.7, 0.22)


def _rings(piece: dict, diameter: float) -> list[np.ndarray]:
    """The piece's rings in the piece's own frame [m]: each (AROUND, 3)."""
    a = diameter / 2
    phi = np.linspace(0.0, 2 * np.pi, AROUND, endpoint=False)
    if piece["kind"] == "straight":
        h = piece["size"][1]
        ends = (-h, h)
        if piece["length"] > 2 * DRAWN_STRAIGHT[1]:  # the straight pipe without a route
            ends = DRAWN_STRAIGHT
        return [np.column_stack([a * np.cos(phi), a * np.sin(phi), np.full(AROUND, z)]) for z in ends]
    n = max(2, math.ceil(piece["angle"] / RING_STEP) + 1)
    rings = []
    for theta in np.linspace(0.0, piece["angle"], n):
        radial = np.array([math.cos(theta), math.sin(theta), 0.0])
        centre = piece["radius"] * radial
        rings.append(centre + a * (np.cos(phi)[:, None] * radial + np.sin(phi)[:, None] * np.array([0.0, 0.0, 1.0])))
    return rings


def draw_pipe(spec: mujoco.MjSpec, pieces: list[dict], diameter: float, prefix: str = "pipe") -> list[str]:
    """Add a translucent tube per wall piece (``pieces`` from :func:`.pipe_walls.wall_pieces`) to ``spec``;
    returns the drawing geoms' names (``{prefix}_drawn{k}``)."""
    from .pipe_walls import _quat

    names = []
    for k, piece in enumerate(pieces):
        rings = _rings(piece, diameter)
        verts = np.concatenate(rings)
        faces = []
        for i in range(len(rings) - 1):
            for j in range(AROUND):
                a, b = i * AROUND + j, i * AROUND + (j + 1) % AROUND
                c, d = a + AROUND, b + AROUND
                faces += [(a, b, d), (a, d, c), (a, d, b), (a, c, d)]  # both sides
        mesh = spec.add_mesh(name=f"{prefix}_mesh{k + 1}", uservert=verts.ravel().tolist(),
                             userface=np.asarray(faces, dtype=int).ravel().tolist())
        mesh.inertia = mujoco.mjtMeshInertia.mjMESH_INERTIA_SHELL
        name = f"{prefix}_drawn{k + 1}"
        spec.worldbody.add_geom(name=name, type=mujoco.mjtGeom.mjGEOM_MESH, meshname=mesh.name,
                                pos=[float(v) for v in piece["pos"]], quat=_quat(piece["rotation"]),
                                contype=0, conaffinity=0, group=1, rgba=list(RGBA), mass=0.0, density=0.0)
        names.append(name)
    return names
