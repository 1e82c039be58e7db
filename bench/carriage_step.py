"""What the step on the skidding carriage's mode costs and changes (compliant clutches on finite grip).

MuJoCo's compliant clutch on finite grip acts between a module and its carriage, an inertia of 1e-3 of the
module's that the model adds (the analytic anchor has none); the spring's mode on it is ~32 times the module's.
``ipir_mujoco.engine.kinds.timestep`` resolves it at CARRIAGE_STEP_SHARE / omega_s. This bench runs each design
at that share and at the others given (0.1: the module's own rule), beside the analytic compliant model, and
prints per run the step, the relative differences from the analytic run (revolutions, x1, x2, each module's
slip, relative to at least 1 mm), the peak clutch force (the analytic peak is capped at the grip G_i; MuJoCo's exceeds it by the carriage's
inertia force), the energy residual ratio and the wall time; with ``--study`` it then times ``clutch-study --quick
--workers 1`` with ``--set mu_wall=0.5`` and without (unlimited grip), each in a process of its own, best of
``--repeats``, and prints the ratios of wall time and peak memory (ru_maxrss of the child).

    python bench/carriage_step.py [--shares 0.1,0.3] [--study] [--repeats 3]   # ~3 min, --study ~2 min more
    python bench/carriage_step.py --smoke                                     # one design, seconds

Designs: the clutch-study's quick grid (k 1e4, 1e5, 1e6 N/m; backlash 0, 1 mm) on mu_wall 0.5 (the default press,
G_i 25 N) under the paper's constant torque and the default motor, 1 s each; and the default motor at 1e6 N/m on
5 N of grip with dampers 0, 30, 300 N s/m (300 also with 0.5 mm of play).
"""

from __future__ import annotations

import argparse
import subprocess
import sys
import time

import numpy as np

from ipir_mujoco import registry
from ipir_mujoco.core.params import RobotParams
from ipir_mujoco.engine.kinds import timestep

T_END = 1.0  # s


def designs(smoke: bool) -> list[RobotParams]:
    """The designs of the module docstring."""
    grid = [RobotParams(drive=drive, mu_wall=0.5, clutch_stiffness=k, clutch_backlash=b)
            for drive in ("torque", "motor") for k in (1e4, 1e5, 1e6) for b in (0.0, 1e-3)]
    damped = [RobotParams(drive="motor", clutch_stiffness=1e6, clutch_damping=c, clutch_backlash=b, mu_wall=0.5,
                          F_n1=10.0, F_n2=10.0) for c, b in ((0.0, 0.0), (30.0, 0.0), (300.0, 0.0), (300.0, 5e-4))]
    return grid[:1] if smoke else grid + damped


def peak(series) -> float:
    """The largest clutch force of a run [N]."""
    return float(max(np.max(series["lambda1"]), np.max(series["lambda2"])))


def compare(params: RobotParams, shares: list[float]) -> None:
    """One design: the analytic run, then MuJoCo at each carriage share, one line each."""
    an = registry.run("analytic-unilateral", params, T_END, dt_out=1e-4)
    a = an.summary
    print(f"{params.drive:6s} k {params.clutch_stiffness:.0e} N/m c {params.clutch_damping:g} N s/m play "
          f"{params.clutch_backlash * 1e3:g} mm G {params.grip[0]:g} N | analytic: rev {a['revolutions']:.5f} slip "
          f"{a['slip1_m'] * 1e3:.3f}/{a['slip2_m'] * 1e3:.3f} mm peak {peak(an.series):.3f} N", flush=True)
    for share in shares:
        timestep.CARRIAGE_STEP_SHARE = share
        step = registry.timestep("mujoco-ratchet", params, T_END, 1e-4)
        started = time.perf_counter()
        run = registry.run("mujoco-ratchet", params, T_END, dt_out=step)  # every step: the peak force
        wall = time.perf_counter() - started
        m = run.summary

        def rel(key: str, floor: float = 1e-6) -> str:
            return f"{(m[key] - a[key]) / max(abs(a[key]), floor):+.1e}"

        print(f"    share {share:g}: step {run.settings['timestep']:.3g} s | rev {rel('revolutions')} x1 "
              f"{rel('x1_final')} x2 {rel('x2_final')} slip {rel('slip1_m', 1e-3)} {rel('slip2_m', 1e-3)} | peak "
              f"{peak(run.series):.3f} N | residual {run.accuracy['residual_ratio']:.1e} | {wall:.2f} s", flush=True)


def study(mu: str | None, repeats: int) -> tuple[float, float]:
    """(best wall time [s], the largest peak memory [MB]) of clutch-study --quick --workers 1 (``mu``: mu_wall or
    None), each run in a wrapper process of its own (its children's ru_maxrss is that study's)."""
    command = [sys.executable, "-m", "ipir_mujoco", "clutch-study", "--quick", "--workers", "1", "--out",
               f"/tmp/carriage_step_study_{mu or 'unlimited'}"] + (["--set", f"mu_wall={mu}"] if mu else [])
    wrapper = ("import resource, subprocess, sys; subprocess.run(sys.argv[1:], check=True, capture_output=True); "
               "print(resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss)")
    walls, rss = [], []
    for _ in range(repeats):
        started = time.perf_counter()
        out = subprocess.run([sys.executable, "-c", wrapper, *command], check=True, capture_output=True, text=True)
        walls.append(time.perf_counter() - started)
        rss.append(int(out.stdout.split()[-1]) / 1e3)  # kB on Linux
    return min(walls), max(rss)


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--shares", default=None, help="carriage step shares to compare (default: 0.1 and the "
                        "package's)")
    parser.add_argument("--study", action="store_true", help="also time clutch-study --quick with and without grip")
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--smoke", action="store_true", help="one design, no study")
    args = parser.parse_args()
    default = timestep.CARRIAGE_STEP_SHARE
    shares = [float(s) for s in args.shares.split(",")] if args.shares else sorted({0.1, default})
    print(f"CARRIAGE_STEP_SHARE = {default:g} (the package's); differences are MuJoCo's relative to the analytic "
          f"model's, over {T_END:g} s")
    for params in designs(args.smoke):
        compare(params, shares)
    timestep.CARRIAGE_STEP_SHARE = default
    if args.study and not args.smoke:
        unlimited = study(None, args.repeats)
        finite = study("0.5", args.repeats)
        print(f"clutch-study --quick --workers 1, best of {args.repeats}: unlimited grip {unlimited[0]:.1f} s, "
              f"mu_wall 0.5 {finite[0]:.1f} s: time {finite[0] / unlimited[0]:.2f}x; peak memory "
              f"{unlimited[1]:.0f} MB and {finite[1]:.0f} MB: {finite[1] / unlimited[1]:.2f}x")
    return 0


if __name__ == "__main__":
    sys.exit(main())
