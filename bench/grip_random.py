"""Benchmark: do the two engines agree on random designs on wheels of finite grip, or say why not?

Run on demand (not part of the test suite):

    python bench/grip_random.py [--designs 40] [--seed 3] [--t-end 1] [--budget 60] [--workers 2] [--compliant]
    python bench/grip_random.py --smoke    # 2 designs of 0.05 s: a check that it runs

Designs: ipir_mujoco.studies.agreement.draw (geometry, masses, resistances, drive, incline over wide
ranges; see its docstring) with rigid one-way clutches, or with ``--compliant`` compliant ones (k log-uniform
in 1e4-1e7 N/m, a damper log-uniform in 1-100 N s/m half the time, play up to 2 % of the stroke half the time:
draw's own ranges; MuJoCo's step then follows the spring on the skidding carriage, timestep.clutch_step), on a
grip drawn per design: mu_wall uniform in [0, 1] and each F_ni log-uniform
in [1, 200] N, so that grips run from none to far above the demand. Each design runs the analytic one-way
model and MuJoCo's ratchet at their default settings and is judged as the agreement study judges
(revolutions and travel within 0.1 %, 1 %, refused, failed, DISAGREE); the skids are compared against
max(skid, 1e-2 stroke), and the worst skid difference is printed with the design.
"""

from __future__ import annotations

import argparse
import math
import time
from dataclasses import replace

import numpy as np

from ipir_mujoco.studies.agreement import describe, draw, judged, run_pair


def grip_design(rng: np.random.Generator, compliant: bool = False):
    base = replace(draw(rng), clutch_stiffness=None, clutch_damping=0.0, clutch_backlash=0.0)
    log = lambda lo, hi: float(math.exp(rng.uniform(math.log(lo), math.log(hi))))  # noqa: E731
    grip = dict(mu_wall=float(rng.uniform(0, 1)), F_n1=log(1, 200), F_n2=log(1, 200))
    if compliant:
        grip.update(clutch_stiffness=log(1e4, 1e7), clutch_damping=log(1, 100) if rng.uniform() < 0.5 else 0.0,
                    clutch_backlash=float(rng.uniform(0, 0.02 * 2 * base.r)) if rng.uniform() < 0.5 else 0.0)
    return replace(base, **grip)


def run_one(index: int, params, t_end: float, budget: float) -> dict:
    row = {"design": index, **run_pair(params, t_end, budget)}
    row["slips"] = {name: None if row[name + "_summary"] is None
                    else (row[name + "_summary"]["slip1_m"], row[name + "_summary"]["slip2_m"])
                    for name in ("analytic", "mujoco")}
    return row


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--designs", type=int, default=40)
    parser.add_argument("--seed", type=int, default=3)
    parser.add_argument("--t-end", type=float, default=1.0, help="simulated time per design [s]")
    parser.add_argument("--budget", type=float, default=60.0, help="wall-time budget per engine and design [s]")
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--compliant", action="store_true", help="compliant one-way clutches (module docstring)")
    parser.add_argument("--smoke", action="store_true", help="every code path once, in seconds (not a measurement)")
    args = parser.parse_args()
    if args.smoke:
        args.designs, args.t_end = 2, 0.05
    rng = np.random.default_rng(args.seed)
    designs = [grip_design(rng, args.compliant) for _ in range(args.designs)]
    counts: dict[str, int] = {}
    worst = 0.0
    started = time.perf_counter()
    for row, verdict, detail in judged(designs, run_one, args.t_end, args.budget, args.workers):
        counts[verdict] = counts.get(verdict, 0) + 1
        skid = ""
        a, m = row["slips"]["analytic"], row["slips"]["mujoco"]
        if a is not None and m is not None:
            floor = 1e-2 * 2 * row["params"].r
            rel = max(abs(mj - an) / max(an, floor) for an, mj in zip(a, m))
            worst = max(worst, rel)
            skid = f", skids {1e3 * a[0]:.3g} / {1e3 * a[1]:.3g} mm, worst difference {rel:.1e}"
        print(f"[{row['design']:3d}] {verdict:9s} {detail}{skid}  (wall {row['analytic_wall']:.2f} / "
              f"{row['mujoco_wall']:.2f} s)", flush=True)
        if verdict != "agree":
            p = row["params"]
            print(f"      {describe(p)}, mu_wall {p.mu_wall:.3g}, F_n {p.F_n1:.3g} / {p.F_n2:.3g} N", flush=True)
    print(f"\n{args.designs} designs, {time.perf_counter() - started:.0f} s wall: "
          + ", ".join(f"{k} {v}" for k, v in sorted(counts.items())) + f"; worst skid difference {worst:.1e}")


if __name__ == "__main__":
    main()
