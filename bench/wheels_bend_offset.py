"""How far each module's point (A on module 1, C on module 2) rides off the pipe's centreline through a bend.

Run on demand from the repository root (each case 1-3 min on 2 busy cores):

    python bench/wheels_bend_offset.py [--ratio 2.5] [--planes 0,90] [--t-end 5] [--set NAME=VALUE]...
                                       [--timestep S] [--smoke]

The wheeled MuJoCo model (the motor, mu_wall 0.8 unless --set gives one) along a 0.45 m straight, a 90 degree bend
of R/D ``--ratio`` in each plane of ``--planes`` (0: horizontal, across gravity; 90: turning up, into a riser) and a
0.4 m straight. Prints, per plane, how the run ended, how long a wheel was off its wall, the closed-form fit, and
each point's distance from the centreline [mm] in the first straight and inside the bend (mean and largest). The
numbers in mjcf/README.md ("Routes") are this script's output.
"""

from __future__ import annotations

import argparse
import sys

import numpy as np

from ipir_mujoco import registry
from ipir_mujoco.core.params import RobotParams, parse_overrides
from ipir_mujoco.core.route import route_from_tables

LEAD, EXIT = 0.45, 0.4  # m: the straights before and after the bend


def offsets(run, route) -> dict:
    """Per point, its distances from the centreline [m] and its distance along the route [m] at every sample."""
    s = run.series
    out = {}
    for name, k in (("A", "1"), ("C", "2")):
        points = np.stack([s[f"x{k}_world"], s[f"y{k}_world"], s[f"z{k}_world"]], axis=1)
        distance = np.array([min(piece.nearest3(p)[0] for piece in route.pieces) for p in points])
        along = np.array([route.project3(p) for p in points])
        out[name] = (distance, along)
    return out


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--ratio", type=float, default=2.5)
    parser.add_argument("--planes", default="0,90")
    parser.add_argument("--t-end", type=float, default=5.0)
    parser.add_argument("--set", action="append", default=[], metavar="NAME=VALUE")
    parser.add_argument("--timestep", type=float, default=None, help="the step [s] (default: the automatic one)")
    parser.add_argument("--smoke", action="store_true", help="one plane, 0.05 s: the script runs")
    args = parser.parse_args(argv)
    if args.smoke:
        args.planes, args.t_end = "0", 0.05
    params = RobotParams(**{"drive": "motor", "mu_wall": 0.8, **parse_overrides(args.set)})
    radius = args.ratio * params.pipe_diameter
    for plane in (float(p) for p in args.planes.split(",")):
        route = route_from_tables([dict(kind="straight", length=LEAD),
                                   dict(kind="bend", radius=radius, angle=90.0, plane=plane),
                                   dict(kind="straight", length=EXIT)], "bend")
        print(f"R/D {args.ratio:g}, plane {plane:g} deg: running", file=sys.stderr, flush=True)
        run = registry.run("mujoco-wheels", params, args.t_end, dt_out=2e-3, route=route, accuracy="warn",
                           **({} if args.timestep is None else {"timestep": args.timestep}))
        summary = run.summary
        print(f"R/D {args.ratio:g}, plane {plane:g} deg ({', '.join(args.set) or 'defaults'}; step "
              f"{run.settings['timestep']:g} s): "
              f"{summary['route_stop']}")
        print(f"  a wheel off its wall {summary['route_wheel_off_s']:.3f} s; closed form: "
              f"{summary['route_fit']['predicted']}")
        bend = route.pieces[1]
        for name, (distance, along) in offsets(run, route).items():
            straight = along < LEAD - 0.05
            inside = (along > bend.s0) & (along < bend.s0 + bend.length)
            mean = f"{1e3 * distance[inside].mean():.2f}" if inside.any() else "-"
            most = f"{1e3 * distance[inside].max():.2f}" if inside.any() else "-"
            first = f"{1e3 * distance[straight].max():.2f}" if straight.any() else "-"
            print(f"  {name}: off the centreline in the straight at most {first} mm; "
                  f"in the bend mean {mean} mm, at most {most} mm", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
