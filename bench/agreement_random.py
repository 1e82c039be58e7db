"""Benchmark: do the two engines agree on random designs across the whole envelope, or say why not?

Run on demand (not part of the test suite):

    python bench/agreement_random.py [--designs 60] [--seed 1] [--t-end 1] [--budget 60] [--workers 2]
    python bench/agreement_random.py --smoke    # 2 designs of 0.05 s: a check that it runs

How designs are drawn and judged: :mod:`ipir_mujoco.studies.agreement`. Each
design's verdict prints as it finishes (with the design itself unless it
agrees), then the counts.
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from ipir_mujoco.studies.agreement import describe, draw, judged, run_pair


def run_one(index: int, params, t_end: float, budget: float) -> dict:
    return {"design": index, **run_pair(params, t_end, budget)}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--designs", type=int, default=60)
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--t-end", type=float, default=1.0, help="simulated time per design [s]")
    parser.add_argument("--budget", type=float, default=60.0, help="wall-time budget per engine and design [s]")
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--smoke", action="store_true", help="every code path once, in seconds (not a measurement)")
    args = parser.parse_args()
    if args.smoke:
        args.designs, args.t_end = 2, 0.05
    rng = np.random.default_rng(args.seed)
    designs = [draw(rng) for _ in range(args.designs)]
    counts: dict[str, int] = {}
    started = time.perf_counter()
    for row, verdict, detail in judged(designs, run_one, args.t_end, args.budget, args.workers):
        counts[verdict] = counts.get(verdict, 0) + 1
        print(f"[{row['design']:3d}] {verdict:9s} {detail}  (wall {row['analytic_wall']:.2f} / "
              f"{row['mujoco_wall']:.2f} s)", flush=True)
        if verdict != "agree":
            print(f"      {describe(row['params'])}", flush=True)
    print(f"\n{args.designs} designs, {time.perf_counter() - started:.0f} s wall: "
          + ", ".join(f"{k} {v}" for k, v in sorted(counts.items())))


if __name__ == "__main__":
    main()
