"""Benchmark: what the speed controller (drive = servo) costs each engine against the open-loop motor.

Run on demand (not part of the test suite), from the repository root:

    python bench/servo_cost.py [--repeats R] [--smoke]

Every case runs to its periodic steady state (dt_out 1 ms) through the registry, in the exact one-way
equations and MuJoCo's ratchet: the motor at full voltage, the servo at 10 rad/s with the PI alone and with
the exact feedforward (its table computed once, before the timing: it is cached per parameter set). Each
time is the best of R runs, the cases interleaved so that machine load affects them alike. Printed per
engine: the wall time [s], the simulated time to steady state [s], wall per simulated second, and the
servo's wall per simulated second over the motor's (the ratio is what a controller tick costs: the
equations end a segment at every tick, MuJoCo returns to Python).
"""

from __future__ import annotations

import argparse
import time

from ipir_mujoco import registry
from ipir_mujoco.core.params import RobotParams

VARIANTS = ("analytic-unilateral", "mujoco-ratchet")
CASES = {"motor": RobotParams(drive="motor"), "servo PI": RobotParams(drive="servo"),
         "servo PI + exact ff": RobotParams(drive="servo", feedforward="exact")}


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--smoke", action="store_true", help="every code path once, in seconds (not a measurement)")
    args = parser.parse_args()
    t_cap, steady = (0.05, False) if args.smoke else (30.0, True)
    if args.smoke:
        args.repeats = 1
    for params in CASES.values():
        registry.feedforward_table(params)  # cached: the runs below time the engines, not the table
        for engine in VARIANTS:  # warm: the numba kernels, MuJoCo's import
            registry.run(engine, params, t_cap, dt_out=1e-3, until_steady=steady)
    best: dict[tuple[str, str], tuple[float, float]] = {}
    for _ in range(args.repeats):
        for name, params in CASES.items():
            for engine in VARIANTS:
                started = time.perf_counter()
                run = registry.run(engine, params, t_cap, dt_out=1e-3, until_steady=steady)
                wall = time.perf_counter() - started
                if (engine, name) not in best or wall < best[(engine, name)][0]:
                    best[(engine, name)] = (wall, run.t_end)
    print(f"{'engine':22s} {'case':22s} {'wall [s]':>9s} {'simulated [s]':>14s} {'wall/sim':>9s} {'/ motor':>8s}")
    for engine in VARIANTS:
        motor_rate = best[(engine, "motor")][0] / best[(engine, "motor")][1]
        for name in CASES:
            wall, simulated = best[(engine, name)]
            rate = wall / simulated
            print(f"{engine:22s} {name:22s} {wall:9.3f} {simulated:14.3f} {rate:9.4f} {rate / motor_rate:8.2f}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
