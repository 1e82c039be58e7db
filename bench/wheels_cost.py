"""The wheeled MuJoCo model's cost per simulated second against the slide model's, as ratios measured in one run.

Run on demand from the repository root (about a minute; ``--smoke``: seconds):

    python bench/wheels_cost.py [--t-end SECONDS] [--repeat N] [--smoke]

Each at its defaults for ``--t-end`` simulated seconds, each run ``--repeat`` times, the best kept, the runs
interleaved so that a busy machine slows both alike:

- the slide model (``mujoco-ratchet``) on the default design (the paper's constant torque, unlimited grip) and
  with the default motor, stepped in C (its default) and in Python (``IPIR_MUJOCO_STEPPER=python``);
- the wheeled model (``mujoco-wheels``: the robot in a round pipe, 38 degrees of freedom, 12 sprung wheels on
  hub ratchets, stepped in Python) on the same designs, and with the default motor on a finite grip
  (mu_wall 0.5).

Prints wall seconds per simulated second and each wheeled run's ratio to the slide model's C loop on the same
design (the issue's target: at most 10 at the defaults).
"""

from __future__ import annotations

import argparse
import os
import sys
import time

from ipir_mujoco import registry
from ipir_mujoco.core.params import RobotParams
from ipir_mujoco.engine.loop.stepper import ENV


def once(variant: str, params: RobotParams, t_end: float, python: bool = False) -> float:
    """Wall time [s] per simulated second of one run."""
    before = os.environ.get(ENV)
    if python:
        os.environ[ENV] = "python"
    try:
        started = time.perf_counter()
        run = registry.run(variant, params, t_end, dt_out=1e-3)
        return (time.perf_counter() - started) / run.t_end
    finally:
        if before is None:
            os.environ.pop(ENV, None)
        else:
            os.environ[ENV] = before


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--t-end", type=float, default=1.0)
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--smoke", action="store_true", help="0.05 s, once: the script runs")
    args = parser.parse_args(argv)
    t_end, repeat = (0.05, 1) if args.smoke else (args.t_end, args.repeat)
    rows = [  # (label, variant, params, python loop, the slide row it is compared with)
        ("slides, defaults, C loop", "mujoco-ratchet", RobotParams(), False, None),
        ("slides, defaults, Python loop", "mujoco-ratchet", RobotParams(), True, None),
        ("wheels, defaults", "mujoco-wheels", RobotParams(), False, 0),
        ("slides, motor, C loop", "mujoco-ratchet", RobotParams(drive="motor"), False, None),
        ("wheels, motor", "mujoco-wheels", RobotParams(drive="motor"), False, 3),
        ("wheels, motor, mu_wall 0.5", "mujoco-wheels", RobotParams(drive="motor", mu_wall=0.5), False, 3),
    ]
    best = [float("inf")] * len(rows)
    for k in range(repeat):
        for i, (label, variant, params, python, _) in enumerate(rows):
            print(f"[{k + 1}/{repeat}] {label}", file=sys.stderr, flush=True)
            best[i] = min(best[i], once(variant, params, t_end, python))
    print(f"{'run':32s} {'wall s / sim s':>15s} {'/ slides C (same design)':>26s}")
    for (label, _, _, _, base), value in zip(rows, best):
        ratio = "" if base is None else f"{value / best[base]:.1f}"
        print(f"{label:32s} {value:15.3f} {ratio:>26s}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
