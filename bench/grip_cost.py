"""Benchmark: what finite grip costs a MuJoCo run: a skidding run against the same design's run where it does not
skid, and against the same design on unlimited grip.

Run on demand (not part of the test suite):

    python bench/grip_cost.py [--repeats R] [--smoke]

Each line is one design from rest at the engine's automatic settings, output every 1 ms, best of R runs (R = 3),
its MuJoCo runs timed alternately with the same design on unlimited grip in one process, so that machine load
affects both alike. A skidding run is the first of a family of runs extrapolated to the rigid limit
(ipir_mujoco/engine/kinds/slides_grip/rigid_limit.py): its cost is printed in *first runs*, its whole wall time over its first
run's (the run the same design makes where it does not skid: the same model at the same step), measured within
the one run, and in steps; beside it the ratio to the unlimited-grip run (finite grip adds two carriages and four
constraint rows per step). The compliant clutch on finite grip is not extrapolated: its ratio is its spring's
step on its skidding carriage (timestep.carriage_rate). Which loop steps: IPIR_MUJOCO_STEPPER=python forces the Python loop.
"""

from __future__ import annotations

import argparse
import time
from dataclasses import replace

from ipir_mujoco import registry
from ipir_mujoco.analytic import RobotParams
from ipir_mujoco.engine.loop.stepper import compiled_status

GRIP = dict(mu_wall=0.5, F_n1=10.0, F_n2=10.0)  # 5 N of grip per module: both skid every revolution
# name: (design on unlimited grip, its finite grip, t_end [s], until_steady)
DESIGNS = {
    "paper's case (torque 0.25 N m), 5 N of grip": (RobotParams(), GRIP, 1.0, False),
    "default motor, 5 N of grip": (RobotParams(drive="motor"), GRIP, 1.0, False),
    "motor riser (M_stall 1 N m), 6 N of grip": (RobotParams(drive="motor", M_stall=1.0, incline=90.0),
                                                 dict(mu_wall=0.3, F_n1=20.0, F_n2=20.0), 1.0, False),
    "60 deg, strong motor, 20 N of grip": (RobotParams(drive="motor", M_stall=1.5, incline=60.0),
                                           dict(mu_wall=0.5, F_n1=40.0, F_n2=40.0), 1.0, False),
    "30 deg motor, 13 N of grip, 2 s": (RobotParams(drive="motor", incline=30.0),
                                        dict(mu_wall=0.65, F_n1=20.0, F_n2=20.0), 2.0, False),
    "30 deg motor, 13 N of grip, to the steady state": (RobotParams(drive="motor", incline=30.0),
                                                        dict(mu_wall=0.65, F_n1=20.0, F_n2=20.0), 30.0, True),
    "motor, compliant 1e6 N/m, c 300 N s/m, 5 N of grip": (
        RobotParams(drive="motor", clutch_stiffness=1e6, clutch_damping=300.0), GRIP, 1.0, False),
}


def timed(params, t_end, until_steady):
    started = time.perf_counter()
    run = registry.run("mujoco-ratchet", params, t_end, dt_out=1e-3, until_steady=until_steady)
    return time.perf_counter() - started, run


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--smoke", action="store_true", help="two designs over 0.05 s, once (not a measurement)")
    args = parser.parse_args()
    designs = DESIGNS
    if args.smoke:
        args.repeats = 1
        designs = {k: (*v[:2], 0.05, False) for k, v in list(DESIGNS.items())[1:3]}
    print(f"MuJoCo loop: {compiled_status()[1]}; best of {args.repeats}")
    print(f"{'design':52s} {'unlimited [s]':>13} {'finite [s]':>10} {'first runs':>10} {'in steps':>8} "
          f"{'vs unlimited':>12}  how")
    ratios = []
    for name, (base, grip, t_end, steady) in designs.items():
        finite = replace(base, **grip)
        walls = {"unlimited": [], "finite": []}
        runs = {}
        for _ in range(args.repeats):  # alternately, so that load changes hit both
            for label, params in (("unlimited", base), ("finite", finite)):
                wall, runs[label] = timed(params, t_end, steady)
                walls[label].append((wall, runs[label]))
        plain = min(w for w, _ in walls["unlimited"])
        best, run = min(walls["finite"], key=lambda item: item[0])
        family = (run.settings.get("extrapolation") or {}).get("runs") or []
        first = next((r for r in family if r["ratio"] == 1.0), None)
        in_first = best / first["wall_s"] if first else 1.0
        in_steps = sum(r.get("steps", 0) for r in family) / first["steps"] if first else 1.0
        how = run.accuracy.get("rigid_limit", "")
        if first:
            how += f" ({run.settings['extrapolation']['plan']})"
            ratios.append(in_first)
        print(f"{name:52s} {plain:13.3f} {best:10.3f} {in_first:10.2f} {in_steps:8.2f} {best / plain:12.2f}  {how}",
              flush=True)
    if ratios:
        print(f"skidding runs: cost in first runs at most {max(ratios):.2f} (mean {sum(ratios) / len(ratios):.2f}); "
              "at most 3 asked")


if __name__ == "__main__":
    main()
