"""The wheeled MuJoCo model against the analytic finite-grip model in straight pipes, measured in one run.

Run on demand from the repository root (about 40 s on 2 idle cores, several times that on a loaded machine):

    python bench/wheels_agreement.py [--smoke]

``--smoke``: the first case over 0.02 s, no steady state (a check that it runs, not a measurement).

Horizontal and inclined pipes, ample and finite grip, the default motor from rest for 1 s (and, where the
grip is ample, to the periodic steady state): each module's travel and skid, the crank's revolutions, the
steady speed; ``analytic-unilateral`` (the one-way equations with finite grip) against ``mujoco-wheels`` at
its automatic settings. Prints one row per case and figure with the relative difference. The table in
mjcf/README.md ("Wheels in contact", how far to trust it) is this script's output.
"""

from __future__ import annotations

import argparse
import sys
import time

from ipir_mujoco import registry
from ipir_mujoco.core.params import RobotParams

CASES = {
    "horizontal, ample grip (mu 0.8)": RobotParams(drive="motor", mu_wall=0.8),
    "30 deg, ample grip (mu 0.8)": RobotParams(drive="motor", mu_wall=0.8, incline=30.0),
    "horizontal, finite grip (mu 0.1)": RobotParams(drive="motor", mu_wall=0.1),
    "30 deg, finite grip (mu 0.15)": RobotParams(drive="motor", mu_wall=0.15, incline=30.0),
    "riser, grip below the weight (mu 0.18)": RobotParams(drive="motor", mu_wall=0.18, incline=90.0),
}
FIGURES = ("x1_final", "x2_final", "revolutions", "slip1_m", "slip2_m")
STEADY = ("horizontal, ample grip (mu 0.8)", "30 deg, ample grip (mu 0.8)")


def relative(a: float, b: float) -> str:
    return "" if abs(a) < 1e-9 else f"{100 * (b / a - 1):+.2f} %"


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--smoke", action="store_true", help="every code path once, in seconds (not a measurement)")
    smoke = parser.parse_args().smoke
    cases, t_end = (dict(list(CASES.items())[:1]), 0.02) if smoke else (CASES, 1.0)
    print("| case | figure | analytic | MuJoCo wheels | difference |")
    print("|---|---|---|---|---|")
    for name, params in cases.items():
        analytic = registry.run("analytic-unilateral", params, t_end, dt_out=1e-3)
        started = time.perf_counter()
        wheels = registry.run("mujoco-wheels", params, t_end, dt_out=1e-3)
        wall = time.perf_counter() - started
        for key in FIGURES:
            a, w = analytic.summary[key], wheels.summary[key]
            print(f"| {name} | {key} ({t_end:g} s) | {a:.5f} | {w:.5f} | {relative(a, w)} |")
        print(f"| {name} | MuJoCo step, wall time | | {wheels.settings['timestep']:g} s, {wall:.1f} s | |")
        if name in STEADY and not smoke:
            a = registry.run("analytic-unilateral", params, 30.0, dt_out=1e-3, until_steady=True)
            w = registry.run("mujoco-wheels", params, 30.0, dt_out=1e-3, until_steady=True, timestep=1e-4)
            va, vw = a.summary["steady_speed_m_s"], w.summary["steady_speed_m_s"]
            if va is None or vw is None:
                shown = [f"{v:.5f}" if v is not None else "not steady by the cap" for v in (va, vw)]
                print(f"| {name} | steady speed [m/s] (MuJoCo at 1e-4 s) | {shown[0]} | {shown[1]} | |")
            else:
                print(f"| {name} | steady speed [m/s] (MuJoCo at 1e-4 s) | {va:.5f} | {vw:.5f} | {relative(va, vw)} |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
