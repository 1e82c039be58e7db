"""How many samples read a module held while it moves back faster than SKID_SPEED (1 mm/s), per variant.

*Held* means one thing in every variant (docs/cli.md, "held"): the clutch carries the module and the module
stands. A user checks it on a run's series: no sample whose ``mode`` holds module k (``BOTH_LOCKED``, and
``EXPANSION`` for the rear, ``CONTRACTION`` for the front) has ``v_k`` below -SKID_SPEED (with rigid clutches: a
compliant clutch's module moves back on its spring while its clutch pushes). Issue 51 found the wheeled model
reading 171 of 1000 samples of a skidding design so (its hubs held while its body tipped and slid on its legs).
Run on demand from the repository root (about five minutes; ``--smoke``: the issue's design alone, 0.2 s):

    python bench/held_count.py [--smoke]

Prints, per run: the variant, its design, and the count of such samples of all its samples. The issue's design
first (``ipir-mujoco simulate --engine mujoco --mujoco-model wheels --drive motor --set mu_wall=0.5 --set F_n1=5
--set F_n2=5 --t-end 1``, sampled every 1e-3 s, then at the command line's 1e-4 s), then a riser, a 30 degree
incline and unlimited grip on the wheels, and the slide model's clutches (the ratchet on finite and unlimited
grip, the two locks).
"""

from __future__ import annotations

import sys

import numpy as np

from ipir_mujoco import registry
from ipir_mujoco.core.params import RobotParams
from ipir_mujoco.core.results import Mode
from ipir_mujoco.engine.loop.controller import SKID_SPEED

ISSUE = RobotParams(drive="motor", mu_wall=0.5, F_n1=5.0, F_n2=5.0)
# (variant, design, t_end [s], dt_out [s])
CASES = [
    ("mujoco-wheels", ISSUE, 1.0, 1e-3),
    ("mujoco-wheels", ISSUE, 1.0, 1e-4),
    ("mujoco-wheels", RobotParams(drive="motor"), 0.5, 1e-3),
    ("mujoco-wheels", RobotParams(drive="motor", mu_wall=0.18, incline=90.0), 0.5, 1e-3),
    ("mujoco-wheels", RobotParams(drive="motor", mu_wall=0.5, F_n1=10.0, F_n2=10.0, incline=30.0), 0.5, 1e-3),
    ("mujoco-ratchet", RobotParams(drive="motor", mu_wall=0.18, incline=90.0), 0.5, 1e-3),
    ("mujoco-ratchet", ISSUE, 1.0, 1e-3),
    ("mujoco-ratchet", RobotParams(drive="motor"), 1.0, 1e-3),
    ("mujoco-lock", RobotParams(), 1.0, 1e-3),
    ("mujoco-lock-unilateral", RobotParams(drive="motor"), 1.0, 1e-3),
]


def held_moving_back(series: dict) -> np.ndarray:
    """Per sample (bool, (n,)): whether the mode holds a module whose speed along the pipe is below -SKID_SPEED."""
    mode = series["mode"]
    held1 = np.isin(mode, (int(Mode.BOTH_LOCKED), int(Mode.EXPANSION)))
    held2 = np.isin(mode, (int(Mode.BOTH_LOCKED), int(Mode.CONTRACTION)))
    return (held1 & (series["v1"] < -SKID_SPEED)) | (held2 & (series["v2"] < -SKID_SPEED))


def main() -> int:
    if "-h" in sys.argv or "--help" in sys.argv:
        print(__doc__)
        return 0
    cases = [("mujoco-wheels", ISSUE, 0.2, 1e-3)] if "--smoke" in sys.argv else CASES
    for variant, params, t_end, dt_out in cases:
        run = registry.run(variant, params, t_end, dt_out=dt_out, accuracy="warn")
        bad = held_moving_back(run.series)
        grip = "unlimited" if params.mu_wall is None else f"mu_wall {params.mu_wall:g}, F_n {params.F_n1:g} N"
        print(f"{variant:24s} {params.drive:6s} {grip:23s} incline {params.incline:4g} deg, {t_end:g} s, dt_out "
              f"{dt_out:g} s: {int(bad.sum())} of {bad.size} samples held while moving back faster than "
              f"{SKID_SPEED * 1e3:g} mm/s", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
