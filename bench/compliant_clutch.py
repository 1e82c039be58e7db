"""Benchmark: the analytic compliant clutch on the paper's case, by stiffness and integrator.

Run on demand (not part of the test suite):

    python bench/compliant_clutch.py [--t-end SECONDS] [--repeats R] [--radau] [--smoke]

For clutch stiffness 1e3..1e8 N/m (no damping, no backlash) it reports the
crank revolutions and robot travel at t_end, their difference from the rigid
one-way clutch (the limit k -> infinity), the number of clutch and friction
switches, and the wall time (best of R runs) as a ratio to the rigid model's,
measured in one run so machine load affects all alike. With --radau it also
times Radau (rtol 1e-8) beside DOP853 (rtol 1e-10, the default) at 1e5 and
1e7 N/m, with and without near-critical damping.
"""

from __future__ import annotations

import argparse
import time

from ipir_mujoco import analytic
from ipir_mujoco.analytic import RobotParams


def best_of(repeats, action):
    times, result = [], None
    for _ in range(repeats):
        started = time.perf_counter()
        result = action()
        times.append(time.perf_counter() - started)
    return min(times), result


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--t-end", type=float, default=1.0)
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--radau", action="store_true")
    parser.add_argument("--smoke", action="store_true", help="every code path once, in seconds (not a measurement)")
    args = parser.parse_args()
    if args.smoke:
        args.t_end, args.repeats = 0.02, 1

    rigid_time, rigid = best_of(args.repeats, lambda: analytic.simulate(RobotParams(), "exact", "unilateral",
                                                                         args.t_end))
    r = rigid.summary
    rigid_travel = 0.5 * (r["x1_final"] + r["x2_final"])
    print(f"paper's case, exact geometry, t_end = {args.t_end:g} s; rigid one-way clutch: "
          f"{r['revolutions']:.6f} rev, travel {rigid_travel:.6f} m, {rigid_time:.3f} s wall")
    print(f"{'k [N/m]':>8} {'rev':>10} {'rev error':>10} {'travel [m]':>11} {'travel err':>10} {'switches':>8} "
          f"{'wall [s]':>8} {'/rigid':>6} {'peak [N]':>9}")
    for k in (1e3, 1e4, 1e5, 1e6, 1e7, 1e8):
        wall, run = best_of(args.repeats, lambda: analytic.simulate(RobotParams(clutch_stiffness=k), "exact",
                                                                     "unilateral", args.t_end))
        s = run.summary
        trav = 0.5 * (s["x1_final"] + s["x2_final"])
        print(f"{k:8.0e} {s['revolutions']:10.6f} {s['revolutions'] - r['revolutions']:+10.2e} {trav:11.6f} "
              f"{trav - rigid_travel:+10.2e} {run.settings['switches']:8d} {wall:8.3f} {wall / rigid_time:6.1f} "
              f"{s['peak_clutch_force_n']:9.2f}")
    if args.radau:
        print("integrators (wall time, best of repeats):")
        for k, c in ((1e5, 0.0), (1e7, 0.0), (1e7, 1e4)):
            for method, rtol in (("DOP853", 1e-10), ("Radau", 1e-8)):
                params = RobotParams(clutch_stiffness=k, clutch_damping=c)
                wall, run = best_of(args.repeats, lambda: analytic.simulate(params, "exact", "unilateral",
                                                                             args.t_end, method=method, rtol=rtol))
                print(f"  k={k:.0e} N/m c={c:g} N s/m {method:6} rtol={rtol:g}: {wall:7.3f} s, "
                      f"{run.summary['revolutions']:.6f} rev")


if __name__ == "__main__":
    main()
