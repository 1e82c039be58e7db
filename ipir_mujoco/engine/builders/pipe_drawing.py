"""Drawings of the round pipe's walls (:mod:`.pipe_walls`): translucent tubes, colliding with nothing.

Each wall piece gets a mesh geom (group 1, contype and conaffinity 0, massless in the world body): rings of
AROUND points about the centreline, one ring per straight's end and one every RING_STEP of a bend's turn, the
faces drawn from both sides (the camera looks from outside the pipe and, in the viewer, may look from inside).
A straight without a route is drawn over DRAWN_STRAIGHT along x (its walls reach much further). With a view
direction (``facing``, the camera's), only the wall's far half is drawn: a cutaway, so that nothing of the wall
stands between the camera and the robot.
"""

from __future__ import annotations

import math

import mujoco
import numpy as np

AROUND = 32  # points per ring
RING_STEP = math.radians(5.0)  # rad: a bend's rings at most this far apart
DRAWN_STRAIGHT = (-0.5, 4.0)  # m: the stretch of x drawn of a straight pipe without a route
RGBA = (0.55, 0.6, 0.7, 0.22)


def _rings(piece: dict, diameter: float) -> list[tuple[np.ndarray, np.ndarray]]:
    """The piece's rings in the piece's own frame [m]: each (points (AROUND, 3), centre (3,))."""
    a = diameter / 2
    phi = np.linspace(0.0, 2 * np.pi, AROUND, endpoint=False)
    if piece["kind"] == "straight":
        h = piece["size"][1]
        ends = (-h, h)
        if piece["length"] > 2 * DRAWN_STRAIGHT[1]:  # the straight pipe without a route
            ends = DRAWN_STRAIGHT
        return [(np.column_stack([a * np.cos(phi), a * np.sin(phi), np.full(AROUND, z)]), np.array([0.0, 0.0, z]))
                for z in ends]
    n = max(2, math.ceil(piece["angle"] / RING_STEP) + 1)
    rings = []
    for theta in np.linspace(0.0, piece["angle"], n):
        radial = np.array([math.cos(theta), math.sin(theta), 0.0])
        centre = piece["radius"] * radial
        rings.append((centre + a * (np.cos(phi)[:, None] * radial + np.sin(phi)[:, None] * np.array([0.0, 0.0, 1.0])),
                      centre))
    return rings


def _quat(rotation: np.ndarray) -> list[float]:
    """The quaternion of a rotation matrix (3, 3) whose columns are the geom's axes in the world."""
    q = np.zeros(4)
    mujoco.mju_mat2Quat(q, np.ascontiguousarray(rotation, dtype=float).ravel())
    return [float(v) for v in q]


def draw_pipe(spec: mujoco.MjSpec, pieces: list[dict], diameter: float, prefix: str = "pipe", facing=None,
              rgba=RGBA) -> list[str]:
    """Add a translucent tube per wall piece (``pieces`` from :func:`.pipe_walls.wall_pieces`) to ``spec``;
    ``facing``: the camera's view direction (3,) in the world, to draw only the far half (module docstring);
    returns the drawing geoms' names (``{prefix}_drawn{k}``)."""
    names = []
    for k, piece in enumerate(pieces):
        rings = _rings(piece, diameter)
        verts = np.concatenate([points for points, _ in rings])
        # each wall point's outward direction in the world: far from the camera where it points along the view
        outward = np.concatenate([points - centre for points, centre in rings]) @ np.asarray(piece["rotation"]).T
        far = np.ones(len(verts), dtype=bool) if facing is None else outward @ np.asarray(facing, float) > -1e-9
        faces = []
        for i in range(len(rings) - 1):
            for j in range(AROUND):
                a, b = i * AROUND + j, i * AROUND + (j + 1) % AROUND
                c, d = a + AROUND, b + AROUND
                if far[[a, b, c, d]].all():
                    faces += [(a, b, d), (a, d, c), (a, d, b), (a, c, d)]  # both sides
        if not faces:
            continue
        used, faces = np.unique(np.asarray(faces, dtype=int), return_inverse=True)  # only the drawn half's points
        verts, faces = verts[used], faces.reshape(-1, 3)
        mesh = spec.add_mesh(name=f"{prefix}_mesh{k + 1}", uservert=verts.ravel().tolist(),
                             userface=np.asarray(faces, dtype=int).ravel().tolist())
        mesh.inertia = mujoco.mjtMeshInertia.mjMESH_INERTIA_SHELL
        name = f"{prefix}_drawn{k + 1}"
        spec.worldbody.add_geom(name=name, type=mujoco.mjtGeom.mjGEOM_MESH, meshname=mesh.name,
                                pos=[float(v) for v in piece["pos"]], quat=_quat(piece["rotation"]),
                                contype=0, conaffinity=0, group=1, rgba=list(rgba), mass=0.0, density=0.0)
        names.append(name)
    return names
