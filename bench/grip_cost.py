"""Benchmark: what finite grip costs a MuJoCo run, against the same run on unlimited grip.

Run on demand (not part of the test suite):

    python bench/grip_cost.py [--t-end SECONDS] [--repeats R] [--smoke]

Each line times one design over t_end (default 1 s) from rest, output every 1 ms, the engine's automatic
timestep: on unlimited grip and on finite grip (the carriages, grip_model.py), best of R runs each, and
prints the finite-grip run's wall time as a ratio to the unlimited one's, measured alternately in one
process so machine load affects both alike, with each run's steps and the skids. The rigid designs keep the
unlimited step; the compliant one takes the carriage's spring rule (timestep.clutch_rate), hence its larger
ratio. Which loop steps: IPIR_MUJOCO_STEPPER=python forces the Python loop.
"""

from __future__ import annotations

import argparse
import time
from dataclasses import replace

from ipir_mujoco.analytic import RobotParams
from ipir_mujoco.engine import simulate_mujoco
from ipir_mujoco.engine.loop.stepper import compiled_status

GRIP = dict(mu_wall=0.5, F_n1=10.0, F_n2=10.0)  # 5 N of grip per module: both skid every revolution
DESIGNS = {
    "paper's case (torque 0.25 N m)": RobotParams(),
    "default motor": RobotParams(drive="motor"),
    "motor, riser (M_stall 1 N m, 6 N of grip)": RobotParams(drive="motor", M_stall=1.0, incline=90.0),
    "motor, compliant 1e6 N/m, c 300 N s/m": RobotParams(drive="motor", clutch_stiffness=1e6, clutch_damping=300.0),
}
RISER_GRIP = dict(mu_wall=0.3, F_n1=20.0, F_n2=20.0)


def timed(params, t_end):
    started = time.perf_counter()
    run = simulate_mujoco(params, "unilateral", "ratchet", t_end, dt_out=1e-3)
    return time.perf_counter() - started, run


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--t-end", type=float, default=1.0)
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--smoke", action="store_true", help="every code path once, in seconds (not a measurement)")
    args = parser.parse_args()
    if args.smoke:
        args.t_end, args.repeats = 0.02, 1
    print(f"MuJoCo loop: {compiled_status()[1]}; t_end = {args.t_end:g} s, best of {args.repeats}")
    print(f"{'design':44s} {'unlimited [s]':>13} {'finite [s]':>10} {'ratio':>6} {'steps':>17} {'slip1, slip2 [mm]':>18}")
    for name, base in DESIGNS.items():
        grip = replace(base, **(RISER_GRIP if base.incline == 90.0 else GRIP))
        walls = {"unlimited": [], "finite": []}
        runs = {}
        for _ in range(args.repeats):  # alternately, so that load changes hit both
            for label, params in (("unlimited", base), ("finite", grip)):
                wall, runs[label] = timed(params, args.t_end)
                walls[label].append(wall)
        plain, finite = min(walls["unlimited"]), min(walls["finite"])
        steps = [round(runs[k].t_end / runs[k].settings["timestep"]) for k in ("unlimited", "finite")]
        s = runs["finite"].summary
        print(f"{name:44s} {plain:13.3f} {finite:10.3f} {finite / plain:6.2f} {steps[0]:>8d}/{steps[1]:<8d} "
              f"{1e3 * s['slip1_m']:8.2f}, {1e3 * s['slip2_m']:.2f}")


if __name__ == "__main__":
    main()
