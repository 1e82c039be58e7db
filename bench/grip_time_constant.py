"""Benchmark: the finite-grip slide model's grip rows' time constant, in seconds, and the family it is extrapolated from.

Run on demand (not part of the test suite; about a minute):

    python bench/grip_time_constant.py
    python bench/grip_time_constant.py --smoke     # one design, three runs: a check that it runs

Two skidding designs over 1 s (the 60 deg strong motor of tests/test_grip_accuracy.py, module 2 skidding 0.136 m
while it climbs 0.059 m; the issue's 30 deg incline, motor, mu_wall 0.65, F_n 20 N), each figure printed as
MuJoCo's relative difference from the equations (revolutions relative to at least 0.1, travel to at least a tenth
of a stroke):

1. the grip rows' time constant held at 8e-4 s while the step halves from 1e-4 s: the runs converge to one soft
   model (first order in the step), whose distance from the equations is the time constant's;
2. the family the rigid limit is extrapolated from, time constant K steps and the carriage's inertia share
   3e-4 h / 1e-4 s, for K = 2, 4, 8 and h = 4e-4 .. 2.5e-5 s: each halving's ratio of successive differences
   (2 for first order) and the first-order extrapolation from each pair of neighbours. K = 2 (MuJoCo's floor,
   the time constant of two steps before the round) and K = 4 give ratios far from any order; K = 8 gives ratios
   near 2 and extrapolations that agree with each other and with the equations; beside them the extrapolation
   with the order the three runs measure, which amplifies their scatter;
3. the carriage's share of its module's mass at one time constant and step, and the family's extrapolation with
   the share held against the share scaled with h (held, its bias stays).
"""

from __future__ import annotations

import argparse
import math

from ipir_mujoco import registry
from ipir_mujoco.analytic import RobotParams
from ipir_mujoco.engine import SolverSettings
from ipir_mujoco.engine.builders.grip_model import CARRIAGE_SHARE

DESIGNS = {
    "60 deg, strong motor": RobotParams(drive="motor", M_stall=1.5, incline=60.0, mu_wall=0.5, F_n1=40.0, F_n2=40.0),
    "30 deg, mu_wall 0.65, F_n 20 N": RobotParams(drive="motor", incline=30.0, mu_wall=0.65, F_n1=20.0, F_n2=20.0),
}
KEYS = ("revolutions", "x1_final", "x2_final")


def relative(m: dict, a: dict, p: RobotParams) -> list[float]:
    return [(m[k] - a[k]) / max(abs(a[k]), 0.1 if k == "revolutions" else 0.2 * p.r) for k in KEYS]


def mujoco(p: RobotParams, t_end: float, h: float, tau: float, share: float) -> dict:
    settings = SolverSettings(timestep=h, grip_time_constant=tau, carriage_share=share)
    return registry.run("mujoco-ratchet", p, t_end, dt_out=h * math.ceil(1e-3 / h - 1e-9), settings=settings,
                        accuracy="warn").summary


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--smoke", action="store_true")
    args = parser.parse_args()
    designs = dict(list(DESIGNS.items())[:1]) if args.smoke else DESIGNS
    t_end = 0.2 if args.smoke else 1.0
    for name, p in designs.items():
        a = registry.run("analytic-unilateral", p, t_end, dt_out=1e-3).summary
        print(f"\n{name}, {t_end:g} s (the equations: skids {a['slip1_m']:.4f} / {a['slip2_m']:.4f} m)")
        print("  1. time constant 8e-4 s, the step halved (MuJoCo - equations, relative):")
        for h in ((1e-4, 5e-5) if args.smoke else (1e-4, 5e-5, 2.5e-5, 1.25e-5)):
            d = relative(mujoco(p, t_end, h, 8e-4, CARRIAGE_SHARE), a, p)
            print(f"     step {h:.3g} s: " + "  ".join(f"{k} {v:+.3e}" for k, v in zip(KEYS, d)))
        steps = (2e-4, 1e-4) if args.smoke else (4e-4, 2e-4, 1e-4, 5e-5, 2.5e-5)
        for K in ((8,) if args.smoke else (2, 4, 8)):
            print(f"  2. K = {K}: time constant {K} steps, carriage share 3e-4 h / 1e-4 s")
            values = {h: relative(mujoco(p, t_end, h, K * h, CARRIAGE_SHARE * h / 1e-4), a, p) for h in steps}
            for i, h in enumerate(steps):
                line = f"     h {h:.3g} s: " + "  ".join(f"{k} {v:+.3e}" for k, v in zip(KEYS, values[h]))
                if i >= 1:  # the first-order extrapolation from this run and the coarser one
                    e = [2 * f - g for f, g in zip(values[h], values[steps[i - 1]])]
                    line += "   E " + " ".join(f"{v:+.1e}" for v in e)
                if i >= 2:  # the ratio of successive differences (2: first order)
                    r = [(g2 - g1) / (g1 - f) if g1 != f else math.nan
                         for f, g1, g2 in zip(values[h], values[steps[i - 1]], values[steps[i - 2]])]
                    line += "   ratio " + " ".join(f"{v:.2f}" for v in r)
                    # extrapolated with the order the three runs measure (Aitken) instead of first order
                    aitken = [f - (g1 - f) / (q - 1) if q > 1 else math.nan
                              for f, g1, q in zip(values[h], values[steps[i - 1]], r)]
                    line += "   measured-order extrapolation " + " ".join(f"{v:+.1e}" for v in aitken)
                print(line, flush=True)
        if not args.smoke:
            share_effect(p, a, t_end)


def share_effect(p: RobotParams, a: dict, t_end: float) -> None:
    """3. The carriage's share at one time constant and step (4e-4 s, 5e-5 s), and the family extrapolated with
    the share held at 3e-4 against the share scaled with h."""
    print("  3. the carriage's share (time constant 4e-4 s, step 5e-5 s):")
    for share in (1e-3, 3e-4, 1e-4, 3e-5):
        d = relative(mujoco(p, t_end, 5e-5, 4e-4, share), a, p)
        print(f"     share {share:.0e}: " + "  ".join(f"{k} {v:+.3e}" for k, v in zip(KEYS, d)))
    for label, scaled in (("held at 3e-4", False), ("scaled with h", True)):
        f1, f2 = (relative(mujoco(p, t_end, h, 8 * h, CARRIAGE_SHARE * (h / 1e-4 if scaled else 1.0)), a, p)
                  for h in (1e-4, 2e-4))
        print(f"     K = 8, h 1e-4 and 2e-4 s, share {label}: first-order extrapolation "
              + " ".join(f"{k} {2 * x - y:+.1e}" for k, x, y in zip(KEYS, f1, f2)), flush=True)


if __name__ == "__main__":
    main()
