"""The wheeled MuJoCo model's cost per simulated second against the slide model's, as ratios measured in one run.

Run on demand from the repository root:

    python bench/wheels_cost.py [--t-end SECONDS] [--repeat N] [--smoke]

The default motor on the default design (mu_wall 0.8, F_n 50 N for the wheels; the slide model with
unlimited grip, its default) for ``--t-end`` simulated seconds, each run ``--repeat`` times, the best kept:

- the slide model (``mujoco-ratchet``) stepped in C (its default) and in Python (``IPIR_MUJOCO_STEPPER=python``);
- the wheeled model (``mujoco-wheels``, always stepped in Python) at the slide model's step, 1e-4 s, and at
  its own automatic step with finite grip (2.5e-5 s, where a skid converges).

Prints wall seconds per simulated second and the ratios to the slide model's C loop and its Python loop.
"""

from __future__ import annotations

import argparse
import os
import sys
import time

from ipir_mujoco import registry
from ipir_mujoco.core.params import RobotParams
from ipir_mujoco.engine.stepper import ENV


def cost(variant: str, params: RobotParams, t_end: float, repeat: int, python: bool = False, **options) -> float:
    """Best wall time [s] per simulated second over ``repeat`` runs."""
    before = os.environ.get(ENV)
    if python:
        os.environ[ENV] = "python"
    try:
        best = float("inf")
        for _ in range(repeat):
            started = time.perf_counter()
            run = registry.run(variant, params, t_end, dt_out=1e-3, **options)
            best = min(best, (time.perf_counter() - started) / run.t_end)
        return best
    finally:
        if before is None:
            os.environ.pop(ENV, None)
        else:
            os.environ[ENV] = before


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--t-end", type=float, default=1.0)
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--smoke", action="store_true", help="every code path once, in seconds (not a measurement)")
    args = parser.parse_args(argv)
    if args.smoke:
        args.t_end, args.repeat = 0.01, 1
    slides, wheels = RobotParams(drive="motor"), RobotParams(drive="motor", mu_wall=0.8)
    rows = [
        ("slide model, C loop, 1e-4 s", cost("mujoco-ratchet", slides, args.t_end, args.repeat, timestep=1e-4)),
        ("slide model, Python loop, 1e-4 s", cost("mujoco-ratchet", slides, args.t_end, args.repeat, python=True,
                                                  timestep=1e-4)),
        ("wheeled model, 1e-4 s", cost("mujoco-wheels", wheels, args.t_end, args.repeat, timestep=1e-4)),
        ("wheeled model, automatic step (2.5e-5 s)", cost("mujoco-wheels", wheels, args.t_end, args.repeat)),
    ]
    c_loop, py_loop = rows[0][1], rows[1][1]
    print(f"{'run':44s} {'wall s / sim s':>15s} {'/ slides C':>11s} {'/ slides Python':>16s}")
    for label, value in rows:
        print(f"{label:44s} {value:15.3f} {value / c_loop:11.1f} {value / py_loop:16.1f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
