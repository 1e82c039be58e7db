"""The wheeled run's sideways-grip check (its summary's ``side_use1``, ``side_use2``) against MuJoCo's outcome.

Run on demand from the repository root (about a minute for 30 designs on 2 cores; ``--smoke``: seconds):

    python bench/wheels_side_check.py [--designs 30] [--seed 5] [--t-end 0.6] [--smoke]

Random designs over the agreement benchmark's envelope (``bench/wheels_agreement.py``'s ``design``: masses,
crank, rod, inertia, resistances, drive, incline -90..90 deg, mu_wall 0.1-1, F_n 5-200 N), each run on the wheeled
model for ``--t-end`` s at a given 1e-4 s step (no skid check: the outcome looked at is the rings' slide across the
pipe, not the skid's length). Per design: the summary's closed-form check (:func:`ipir_mujoco.core.wheel_checks.check`
on the run's own loads: the largest ring load over what its wheels hold across the pipe while they grip along it),
how far MuJoCo's rings moved across the pipe (``across1_m``, ``across2_m``),
the larger skid along the pipe and how long a wheel was off its wall. The designs fall in:

- ``held``: no skid (< 0.1 mm), no wheel off, check below 1 in both modules: the check says the wheels hold across
  the pipe; the rings must move less than SCRUB_FLOOR (1 mm);
- ``predicted``: no skid, no wheel off, a check above 1: the loads go beyond the wheels' sideways grip;
- ``skid or lift``: a module skidded along the pipe or a wheel was off its wall: its wheels hold nothing across the
  pipe then, whatever the check says.

Prints one line per design and the counts; ``held`` designs whose rings slid (a miss of the check) are counted apart.
"""

from __future__ import annotations

import argparse
import random
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

from wheels_agreement import design  # noqa: E402

from ipir_mujoco import registry  # noqa: E402
from ipir_mujoco.core.errors import ParameterError, SimulationError  # noqa: E402
from ipir_mujoco.core.pipe import SCRUB_FLOOR  # noqa: E402

SKID_NONE = 1e-4  # m: a skid below this counts as none (a held module's creep is far below it)


def judge(params, t_end: float) -> tuple[str, str]:
    """(class, the design's line) of one design (module docstring)."""
    try:
        s = registry.run("mujoco-wheels", params, t_end, dt_out=1e-3, timestep=1e-4, wall_budget_s=120).summary
    except (ParameterError, SimulationError) as exc:
        return "stopped", f"stopped: {' '.join(str(exc).split())[:100]}"
    skid = max(s["slip1_m"] or 0.0, s["slip2_m"] or 0.0)
    if skid >= SKID_NONE or s["wheel_off_s"] > 0:
        kind = "skid or lift"
    elif max(s["side_use1"], s["side_use2"]) > 1:
        kind = "predicted"
    else:
        kind = "held" if max(s["across1_m"], s["across2_m"]) < SCRUB_FLOOR else "held, but slid"
    return kind, (f"check {s['side_use1']:.2f}/{s['side_use2']:.2f} across {1e3 * s['across1_m']:.2f}/"
                  f"{1e3 * s['across2_m']:.2f} mm skid {1e3 * skid:.2f} mm wheel off {s['wheel_off_s']:.3f} s")


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--designs", type=int, default=30)
    parser.add_argument("--seed", type=int, default=5)
    parser.add_argument("--t-end", type=float, default=0.6)
    parser.add_argument("--smoke", action="store_true", help="3 designs of 0.1 s (a check that it runs)")
    args = parser.parse_args(argv)
    count, t_end = (3, 0.1) if args.smoke else (args.designs, args.t_end)
    rng = random.Random(args.seed)
    counts: dict[str, int] = {}
    for k in range(count):
        params, _ = design(rng)
        kind, line = judge(params, t_end)
        counts[kind] = counts.get(kind, 0) + 1
        print(f"#{k:3d} {kind:14s} {line}", flush=True)
    print(" ".join(f"{kind}: {n}" for kind, n in sorted(counts.items())))
    return 0


if __name__ == "__main__":
    sys.exit(main())
