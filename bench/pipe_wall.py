"""The round pipe's wall (ipir_mujoco.engine.builders.pipe_walls): the normal-force ripple a sprung wheel sees and the
cost per mj_step, measured on the test rig (ipir_mujoco.engine.builders.pipe_rig).

Run on demand from the repository root:

    python bench/pipe_wall.py [--smoke]

The rig: three sphere wheels (15 mm, 20 g) about the axis of a 0.16 m pipe, each on a radial spring of 3 mm
travel preloaded to 10 N, carried along the centreline at 0.5 m/s (frictionless contacts, step 1e-4 s, wall
solref 1e-3 s). Walls: three planes tangent at the wheels' tracks (the reference, straight only); the exact
pipe in a straight; the exact pipe along a route with a 90-degree bend out of the mechanism's plane (R/D 2.5)
and a 60-degree bend in another plane. Prints, per wall: the ripple (the largest wheel's normal-force standard
deviation over its mean, over the whole roll, bends and their joints included), its peak-to-peak over the mean,
and the cost of one mj_step with the carriage at rest (MuJoCo's own loop, ``nstep``, best of 5), with the
route's pieces in the model; and with 40 bends of 100 m radius in the model (pieces far from the wheels cost
only their broad-phase test). Then the rig on joints, its wheels rolling on hub hinges with friction 0.5 (the
carriage on a slide along a straight, or on a hinge about a bend's axis at R/D 2.5 and 1.25, driven at 0.5 m/s;
the cost here includes the Python loop's contact reading): the ripple with rolling, and each wheel's mean force
(in a bend the wheels' own m v^2 / R, 0.0125 N at R 0.4 m, shifts them apart: physics, not the wall).
"""

from __future__ import annotations

import argparse
import math
import time

import mujoco
import numpy as np

from ipir_mujoco.core.route import route_from_tables
from ipir_mujoco.engine.builders.pipe_rig import build_rig, ripple, roll, roll_on_joints, rolling_rig

ROUTE = [dict(kind="straight", length=0.3), dict(kind="bend", radius=0.4, angle=90, plane=90),
         dict(kind="straight", length=0.2), dict(kind="bend", radius=0.3, angle=-60, plane=30),
         dict(kind="straight", length=0.3)]
LONG = [dict(kind="straight", length=1.0)] + [dict(kind="bend", radius=100.0, angle=(-1) ** k * 90.0, plane=0)
                                                for k in range(40)]


def step_cost(model: mujoco.MjModel, steps: int) -> float:
    """Best of 5 [us] per mj_step, the carriage at rest at the start."""
    data = mujoco.MjData(model)
    mujoco.mj_step(model, data, nstep=100)
    best = float("inf")
    for _ in range(5):
        started = time.perf_counter()
        mujoco.mj_step(model, data, nstep=steps)
        best = min(best, (time.perf_counter() - started) / steps)
    return 1e6 * best


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--smoke", action="store_true", help="a short roll and few steps (seconds)")
    args = parser.parse_args()
    speed, steps = (2.0, 500) if args.smoke else (0.5, 20000)
    route = route_from_tables(ROUTE)
    cases = [("3 planes tangent at the tracks (straight)", None, "plane"), ("exact pipe, straight", None, "pipe"),
             ("exact pipe, route with 2 bends in 3-D", route, "pipe")]
    print(f"{'wall':44s} {'ripple std/mean':>16s} {'peak-peak/mean':>15s} {'us/step':>8s} {'contacts/wheel':>15s}")
    for label, r, wall in cases:
        model = build_rig(r, wall=wall)
        run = roll(model, r, speed, 0.3 if r is None else r.length)
        ptp = max(np.ptp(run.force[:, k]) / np.mean(run.force[:, k]) for k in range(run.force.shape[1]))
        print(f"{label:44s} {ripple(run):16.2e} {ptp:15.2e} {step_cost(model, steps):8.2f} {run.contacts:15d}")
    model = build_rig(route_from_tables(LONG))
    print(f"{'exact pipe, 40 bends of R 100 m in the model':44s} {'':16s} {'':15s} {step_cost(model, steps):8.2f}")
    duration = 0.1 if args.smoke else 1.0
    for label, radius in (("rolling (mu 0.5), straight", None), ("rolling (mu 0.5), in a bend of R/D 2.5", 0.4),
                          ("rolling (mu 0.5), in a bend of R/D 1.25", 0.2)):
        within = duration if radius is None else min(duration, 0.8 * (math.pi * radius - 0.3 * 0.5) / 0.5)
        run = roll_on_joints(rolling_rig(bend_radius=radius), 0.5, within)  # the carriage stays in the half turn
        ptp = max(np.ptp(run.force[:, k]) / np.mean(run.force[:, k]) for k in range(run.force.shape[1]))
        means = ", ".join(f"{v:.4f}" for v in run.force.mean(axis=0))
        print(f"{label:44s} {ripple(run):16.2e} {ptp:15.2e} {run.us_per_step:8.2f} {run.contacts:15d}   "
              f"mean forces {means} N")


if __name__ == "__main__":
    main()
