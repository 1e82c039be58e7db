"""Which ring base carries a real motor: the wheeled robot with a 2 N m motor on 20 N of press, by grip and geometry.

Run on demand from the repository root (a few minutes on 2 busy cores; ``--smoke``: one design of 0.2 s):

    python bench/wheels_ring_base.py [--mu unlimited,0.8,0.5] [--spacing 0.1,0.15,0.2,0.3] [--legs 3]
                                     [--t-end 2] [--smoke]

Each design is the defaults with the motor (M_stall 2 N m), F_n1 = F_n2 = 20 N, and the given grip ``mu_wall``,
``ring_spacing`` and ``wheel_legs``, run on the wheeled MuJoCo model (its automatic settings) for ``--t-end`` s.
Per design: how long a wheel was off its wall (``wheel_off_s``), the least-pressed legs of the summary's check on
the run's own loads, and the design rules that bind (``ipir-mujoco design-check``: ``stall_push_1``,
``lift_at_stall``, ``lift_at_speed``, ``tightest_bend``), and whether the two modules' rings stay apart along the
pipe (``ring_spacing`` <= L - r, the least gap between the crank's bearing A and the rod's pin C, each at its
module's rings' middle: beyond it the model's rings pass through each other at the inner dead centre, which a
real robot's cannot; the model's modules do not collide). docs/model.md, "The round pipe: design rules", quotes
this script's output.
"""

from __future__ import annotations

import argparse
import sys
import time

from ipir_mujoco import registry
from ipir_mujoco.core.params import RobotParams
from ipir_mujoco.studies.design.design_rules import design_rules


def grip_value(text: str) -> float | None:
    return None if text == "unlimited" else float(text)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--mu", default="unlimited,0.8,0.5", help="mu_wall values, comma-separated ('unlimited')")
    parser.add_argument("--spacing", default="0.1,0.15,0.2,0.3", help="ring_spacing values [m], comma-separated")
    parser.add_argument("--legs", default="3", help="wheel_legs values, comma-separated")
    parser.add_argument("--t-end", type=float, default=2.0, help="simulated time [s]")
    parser.add_argument("--smoke", action="store_true", help="one design (mu_wall 0.8, the default geometry), 0.2 s")
    args = parser.parse_args(argv)
    mus = [grip_value(t) for t in args.mu.split(",")]
    spacings = [float(t) for t in args.spacing.split(",")]
    legs = [float(t) for t in args.legs.split(",")]
    if args.smoke:
        mus, spacings, legs, args.t_end = [0.8], [RobotParams().ring_spacing], [RobotParams().wheel_legs], 0.2
    print("motor M_stall 2 N m, F_n1 = F_n2 = 20 N, the other parameters the defaults; wheel_off_s over "
          f"{args.t_end:g} s")
    for mu in mus:
        for n in legs:
            for s in spacings:
                p = RobotParams(drive="motor", M_stall=2.0, F_n1=20.0, F_n2=20.0, mu_wall=mu, ring_spacing=s,
                                wheel_legs=n)
                started = time.perf_counter()
                w = registry.run("mujoco-wheels", p, args.t_end, dt_out=1e-3).summary
                rules = {r["name"]: r for r in design_rules(p)["rules"]}
                bend = rules["tightest_bend"]["value"]
                print(f"mu_wall {'unlimited' if mu is None else f'{mu:g}':9s} wheel_legs {n:.0f} ring_spacing "
                      f"{s:.3g} m ({'rings apart' if s <= p.L - p.r else 'rings cross'}): wheel_off_s "
                      f"{w['wheel_off_s']:.3f} s, least press (run's loads) {w['least_press1_n']:+.2f}/"
                      f"{w['least_press2_n']:+.2f} N | design-check: stall_push_1 "
                      f"{'holds' if rules['stall_push_1']['holds'] else 'fails'}, lift_at_stall "
                      f"{rules['lift_at_stall']['value']:+.2f} N, lift_at_speed {rules['lift_at_speed']['value']:+.2f}"
                      f" N, tightest_bend R/D {'-' if bend is None else f'{bend:.3g}'} | "
                      f"{time.perf_counter() - started:.0f} s wall", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
