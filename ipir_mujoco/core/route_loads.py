"""The loads a route's bends add on the round-pipe robot's rings, sample by sample, for the lift-off and scrub
checks of a wheeled run along a route (:func:`.wall_summary.run_summary`).

A module rolling through a bend of centreline radius R turning towards the unit ``toward`` across the pipe (in
its own frame) carries, on top of the linkage's loads (the run's own, in its frame: the rod runs along the chord
between the modules there, so its tension is already in them) and its weight:

- its mass turning with the pipe: gravity less its acceleration v^2 / R towards the bend's centre, so half its
  sprung mass times v^2 / R outwards on each ring;
- its wheels' side force: rolling on a chord of the bend, each ring slips at a = asin(b / R) (b =
  ``ring_spacing`` / 2), its fore ring's wheels pushing it out and its aft ring's in. Two limits of it are
  taken. Entering the bend the slip arrives at once, and the wheels' force C_r a (C_r = cornering_coefficient P
  n / 2) goes through their cornering compliance as the module's heading does
  (:func:`.ring_motion.rings_motion`: at a walk the ring creeps onto its springs, at speed it is pushed as by a
  step and overshoots, and past the wheels' friction they slide). Settled in it, the module cocked on its springs
  by psi, the fore ring carries the steady G(a + psi) of the wheels' law with each wheel's own saturation
  (:func:`.wheel_legs.scrub_force`), held: leg j loses (2 / n) G |u_j . toward| of its press (the aft ring's,
  G(a - psi), is less). Rigid wheels slide in any bend: their whole sideways friction, both ways;
- the pipe's spread off the ring's plane (:func:`.pipe.bend_wheel_spread`), which unloads leg k by
  P (u_k . toward)^2 spread / (2 travel), P its preload.

The curvature where each module is comes from the run (its series' ``bend_x1`` .. ``bend_z2`` [1/m], the route
watch's), the module's frame from its pose (``roll1`` .. ``yaw2``). Statics of the bend's loads only; the ring's
motion under them is :mod:`.ring_motion`'s.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .wheel_checks import SCRUB_BINS, leg_frames
from .wheel_legs import in_module_frame, module_gravity, spread_unload



@dataclass
class BendLoads:
    """What a route's bends add on each module's rings, per sample (module docstring), in the shapes
    :func:`.wheel_checks.check` takes: ``gravity`` per module, gravity across the pipe in its frame less its turn
    [m/s^2], (samples, 2); ``pushes``, keyed '1aft' .. '2fore', rigid wheels' side force on each ring [N], (samples,
    2); ``slips``, keyed so, steer-compliant wheels' C_r a entering a bend [N], (samples, 2); ``spread`` per module,
    each leg's press lost to the spread [N], (samples, n); ``steady`` per module, each leg's press lost to the
    settled side force G(a + psi) held [N], (samples, n). Zeros where a module is in no bend or stands."""

    gravity: list
    pushes: dict
    slips: dict
    spread: list
    steady: list


def route_loads(params, series: dict, rolling) -> BendLoads:
    """The bends' loads (:class:`BendLoads`) from a wheeled run's ``series`` (the pose columns, ``v1``, ``v2``
    along the route [m/s] and, where it has them, the curvature ``bend_x1`` .. ``bend_z2`` [1/m]; without them a
    straight pipe's: gravity alone) and ``rolling`` (per module, bool (samples,))."""
    from .pipe import bend_wheel_spread
    from .wheel_legs import bend_slip_angle, rigid_wheels, ring_side_grip, scrub_force

    n = int(params.wheel_legs)
    u, _ = leg_frames(n)
    rigid = rigid_wheels(params)
    out = BendLoads([], {}, {}, [], [])
    for k in (1, 2):
        rotation = np.stack([np.asarray(series[f"{a}{k}"], dtype=float) for a in ("roll", "pitch", "yaw")], -1)
        across = module_gravity(params, rotation)
        count = across.shape[0]
        side, spread, steady = np.zeros((count, 2)), np.zeros((count, n)), np.zeros((count, n))
        P = (params.F_n1, params.F_n2)[k - 1] / (2 * n)
        if f"bend_x{k}" in series:
            world = np.stack([np.asarray(series[f"bend_{a}{k}"], dtype=float) for a in ("x", "y", "z")], -1)
            curvature = in_module_frame(rotation, world)[:, 1:]
            speed = np.asarray(series[f"v{k}"], dtype=float)
            across = across - speed[:, None] ** 2 * curvature
            size = np.hypot(curvature[:, 0], curvature[:, 1])
            inside = size > 0
            toward = np.where(inside[:, None], curvature / np.where(inside, size, 1.0)[:, None], 0.0)
            rolls = np.asarray(rolling[k - 1], dtype=bool) & inside
            # per (radius, direction) met: the bends' own radii (the world's curvature, exact per bend) and the
            # directions rounded to the steering scrub's SCRUB_BINS; a route has a few bends, its modules few
            # directions in them
            angle = np.round(np.arctan2(toward[:, 1], toward[:, 0]) / (2 * math.pi) * SCRUB_BINS).astype(int)
            bent = np.linalg.norm(world, axis=-1)
            radius = np.round(np.where(inside, 1.0 / np.where(inside, bent, 1.0), 0.0), 9)
            force, held = np.zeros(count), np.zeros(count)
            for key in set(zip(radius[inside].tolist(), angle[inside].tolist())):
                where = inside & (radius == key[0]) & (angle == key[1])
                a = 2 * math.pi * key[1] / SCRUB_BINS
                way = (math.cos(a), math.sin(a))
                force[where] = (ring_side_grip(params, k - 1, way) if rigid else
                                params.cornering_coefficient * P * n / 2 * bend_slip_angle(params, key[0]))
                held[where] = scrub_force(params, k - 1, way, key[0])
                gap = bend_wheel_spread(0.5 * params.ring_spacing, params.wheel_radius, key[0], params.pipe_diameter)
                spread[where] = spread_unload(params, P, u @ np.array(way), gap)[None, :]
            side = np.where(rolls[:, None], force[:, None] * toward, 0.0)
            steady = np.where(rolls[:, None], (2.0 / n) * held[:, None] * np.abs(toward @ u.T), 0.0)
        out.gravity.append(across)
        pushed, other = (out.pushes, out.slips) if rigid else (out.slips, out.pushes)
        pushed[f"{k}fore"], pushed[f"{k}aft"] = -side, side
        other[f"{k}fore"], other[f"{k}aft"] = np.zeros_like(side), np.zeros_like(side)
        out.spread.append(spread)
        out.steady.append(steady)
    return out
