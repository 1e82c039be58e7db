"""Benchmark: optimize's evaluations per second against the sweep's designs per second, one engine.

Run on demand (not part of the test suite):

    python bench/optimize_throughput.py [--designs N] [--workers W] [--smoke]

One run each, on this machine, of N designs of ``analytic-unilateral`` under the motor to its steady state
over L and m2: ``sweep --sample N`` (every design at once on the pool), ``optimize`` with one objective
(a Sobol start on the pool, then COBYQA one design at a time: bound by the latency of one design plus
a pool round trip) and with two (NSGA-II, a population of 20 at a time on the pool). Verification off.
Prints one line per study: designs, seconds, designs per second.
"""

from __future__ import annotations

import argparse
import tempfile
import time
from pathlib import Path

from ipir_mujoco.core.params import RobotParams
from ipir_mujoco.studies.optimize import Problem, parse_objective, run_optimize
from ipir_mujoco.studies.sweep import run_sweep
from ipir_mujoco.studies.sweep_space import Study, parse_vary


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--designs", type=int, default=200)
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--smoke", action="store_true", help="every code path once, in seconds (not a measurement)")
    args = parser.parse_args()
    if args.smoke:
        args.designs = 4
    base = RobotParams().replace(drive="motor")
    axes = (parse_vary("L=0.06:0.5"), parse_vary("m2=0.2:3"))
    with tempfile.TemporaryDirectory() as tmp:
        start = time.perf_counter()
        run_sweep(Study(axes, base, ("analytic-unilateral",), 10.0, sample=args.designs, until_steady=True),
                  Path(tmp) / "sweep", workers=args.workers, progress=False)
        elapsed = time.perf_counter() - start
        print(f"sweep              {args.designs:5d} designs {elapsed:7.2f} s {args.designs / elapsed:8.1f} designs/s")
        for label, objectives in (("optimize 1 obj.", ("max:steady_speed_m_s",)),
                                  ("optimize 2 obj.", ("max:steady_speed_m_s", "min:peak_clutch_force_n"))):
            problem = Problem(axes, tuple(parse_objective(o) for o in objectives), base=base, verify=None,
                              t_end=10.0, until_steady=True, budget=args.designs)
            start = time.perf_counter()
            record = run_optimize(problem, Path(tmp) / label.replace(" ", "_"), workers=args.workers, progress=False)
            elapsed = time.perf_counter() - start
            n = record["evaluations"]
            print(f"{label:18s} {n:5d} designs {elapsed:7.2f} s {n / elapsed:8.1f} designs/s")


if __name__ == "__main__":
    main()
