"""The wheels' side-force law as MuJoCo builds it: one ring of the wheeled model's legs rolled at a slip angle.

Run on demand from the repository root (about a minute on 2 busy cores):

    python bench/wheels_side_force.py [--slips 0.01,0.02,0.05,0.1,0.3] [--steps 1e-4,5e-5,2.5e-5]
                                      [--set NAME=VALUE]... [--smoke]

The rig (:func:`ipir_mujoco.engine.kinds.wheels.rig.cornering_rig`): a ring of the default robot's legs (module
1's: their springs, steer hinges, hubs and wheels as :func:`ipir_mujoco.engine.builders.wheels_model.add_leg`
builds them) on a carriage driven at 0.3 m/s along a straight pipe, its axis turned off the pipe's by the slip
angle, gravity off, mu_wall 0.5 unless --set gives one; steady after 0.3 s, means over the next 0.1 s. Per slip
angle and step, for each wheel (leg 0 at the bottom, whose sideways direction is the slip's; legs 1 and 2, whose
sideways directions lie at 60 degrees to it): its slip angle alpha_k = atan(tan(slip) e_k . y), the law's side
force min(C |alpha_k|, mu_wall N_k) (docs/model.md, "The wheels' side force"; C = cornering_coefficient x the
leg's preload, N_k its measured press) against MuJoCo's, its steer angle, its contact's sideways slip speed, and
the force that drives the carriage against the law's: the wheels' rolling resistance along their paths plus
mu_wall N_k sin(|alpha_k| - mu_wall N_k / C) for each wheel that slides (the power its scrub takes over the speed).
"""

from __future__ import annotations

import argparse
import sys

from ipir_mujoco.core.params import RobotParams, parse_overrides
from ipir_mujoco.engine.kinds.wheels.rig import corner, cornering_law, cornering_rig
from ipir_mujoco.engine.builders.wheels_model import leg_count

SPEED = 0.3  # m/s


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--slips", default="0.01,0.02,0.05,0.1,0.3")
    parser.add_argument("--steps", default="1e-4,5e-5,2.5e-5")
    parser.add_argument("--set", action="append", default=[], metavar="NAME=VALUE")
    parser.add_argument("--smoke", action="store_true", help="one slip and step, 0.05 s")
    args = parser.parse_args(argv)
    params = RobotParams(**{"mu_wall": 0.5, **parse_overrides(args.set)})
    slips = [float(s) for s in args.slips.split(",")]
    steps = [float(s) for s in args.steps.split(",")]
    duration, window = 0.4, 0.1
    if args.smoke:
        slips, steps, duration, window = slips[:1], steps[:1], 0.05, 0.01
    coefficient = "rigid" if params.cornering_coefficient is None else f"{params.cornering_coefficient:g} /rad"
    print(f"one ring, {leg_count(params)} legs, preload {params.F_n1 / (2 * leg_count(params)):.3g} N, mu_wall "
          f"{params.mu_wall:g}, cornering_coefficient {coefficient}, {SPEED:g} m/s")
    print("| slip [rad] | step [s] | wheel | alpha_k [rad] | law [N] | MuJoCo [N] | steer [rad] | sideways slip "
          "[m/s] | drive: law / MuJoCo [N] |")
    print("|---|---|---|---|---|---|---|---|---|")
    for slip in slips:
        for dt in steps:
            run = corner(cornering_rig(params, slip, dt), params, SPEED, duration, window)
            angles, forces, drive = cornering_law(params, slip, run.normal)
            for k in range(len(angles)):
                last = f"{drive:.4f} / {run.drive:.4f}" if k == 0 else ""
                print(f"| {slip:g} | {dt:g} | {k} | {angles[k]:+.4f} | {forces[k]:.4f} | {abs(run.side[k]):.4f} | "
                      f"{run.steer[k]:+.4f} | {run.sideways[k]:+.5f} | {last} |", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
