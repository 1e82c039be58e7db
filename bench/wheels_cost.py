"""The wheeled MuJoCo model's cost per simulated second against the slide model's, as ratios measured in one run.

Run on demand from the repository root (about a minute; ``--smoke``: seconds):

    python bench/wheels_cost.py [--t-end SECONDS] [--repeat N] [--smoke] [--profile]

Each at its defaults for ``--t-end`` simulated seconds, each run ``--repeat`` times, the best kept, the runs
interleaved so that a busy machine slows both alike:

- the slide model (``mujoco-ratchet``) on the default design (the paper's constant torque, unlimited grip) and
  with the default motor, stepped in C (its default) and in Python (``IPIR_MUJOCO_STEPPER=python``);
- the wheeled model (``mujoco-wheels``: the robot in a round pipe, 12 sprung wheels on hub ratchets, stepped in C
  as the slide model) on the same designs, and with the default motor on a finite grip (mu_wall 0.5), where its
  wheels steer (51 degrees of freedom; with unlimited grip they are rigid, 39), also with rigid wheels
  (``cornering_coefficient=rigid``). (A run that skids is rerun at finer steps by its skid check: its cost is that
  check's, not the model's; these do not skid.)

Prints wall seconds per simulated second, each wheeled run's ratio to the slide model's C loop on the same
design (the issue's target: at most 10 at the defaults) and to the same run with rigid wheels.

``--profile`` prints instead where a wheeled step's time goes, with the default motor on mu_wall 0.5, its wheels
steer-compliant and rigid, interleaved ``--repeat`` times, the best kept: the compiled loop's cost per step and
``mj_step``'s (its timer), MuJoCo's own timers per stage, and the steering wheels' cost per step over the rigid
ones'.
"""

from __future__ import annotations

import argparse
import os
import sys
import time

import mujoco
import numpy as np

from ipir_mujoco import registry
from ipir_mujoco.core.params import RobotParams
from ipir_mujoco.engine.loop.stepper import ENV


def once(variant: str, params: RobotParams, t_end: float, python: bool = False) -> float:
    """Wall time [s] per simulated second of one run."""
    before = os.environ.get(ENV)
    if python:
        os.environ[ENV] = "python"
    try:
        started = time.perf_counter()
        run = registry.run(variant, params, t_end, dt_out=1e-3)
        return (time.perf_counter() - started) / run.t_end
    finally:
        if before is None:
            os.environ.pop(ENV, None)
        else:
            os.environ[ENV] = before


def profile_once(params: RobotParams, nstep: int) -> tuple[dict, str]:
    """One profile of the wheeled loop: {"loop", "mj_step", stage: cost per step [us]} and a line on the model."""
    from ipir_mujoco.engine.modelkinds import kinds
    from ipir_mujoco.engine.run.run_setup import RunSetup

    variant = registry.variant("mujoco-wheels")
    kind = kinds.kind_for(variant.model, params)
    params = kind.check(params, variant.clutch, variant.rule)
    settings, _ = kind.settings(params, 1.0, 1e-3, None, variant.clutch)
    setup = RunSetup(kind, params, settings, implementation=variant.clutch, rule=variant.rule)
    setup.start()
    model, data = setup.model, setup.data
    steps, _ = setup.steps(np.empty((2, model.nv)))
    steps.run(nstep)  # under way (the start is a transient)
    for timer in data.timer:  # MuJoCo's timers count inside every mj_step, the compiled loop's too
        timer.duration, timer.number = 0.0, 0
    started = time.perf_counter()
    steps.run(nstep)
    out = {"loop": (time.perf_counter() - started) / nstep * 1e6,
           "mj_step": data.timer[int(mujoco.mjtTimer.mjTIMER_STEP)].duration / nstep * 1e6}
    for i, timer in enumerate(data.timer):
        if timer.number and i != int(mujoco.mjtTimer.mjTIMER_STEP):
            out[mujoco.mjtTimer(i).name[8:].lower()] = timer.duration / nstep * 1e6
    return out, (f"timestep {model.opt.timestep:g} s, nv {model.nv}, {data.ncon} contacts, {data.nefc} constraint "
                 f"rows; {'compiled' if steps.compiled else 'Python'} loop")


def profile(nstep: int = 2000, repeat: int = 3) -> None:
    """Print the wheeled loop's cost per step [us], steering and rigid wheels, and MuJoCo's timers per stage."""
    base = RobotParams(drive="motor", mu_wall=0.5)
    cases = (("steer-compliant", base), ("rigid", base.replace(cornering_coefficient=None)))
    best, about = {}, {}
    for _ in range(repeat):
        for label, params in cases:
            costs, about[label] = profile_once(params, nstep)
            best[label] = {k: min(v, best.get(label, {}).get(k, float("inf"))) for k, v in costs.items()}
    for label, _ in cases:
        print(f"{label} wheels: {about[label]}")
    print(f"{'per step [us]':34s} {'steer-compliant':>16s} {'rigid':>10s} {'ratio':>7s}")
    for key in best[cases[0][0]]:
        a, b = best[cases[0][0]][key], best[cases[1][0]].get(key, float("nan"))
        name = {"loop": "the loop", "mj_step": "  of which mj_step"}.get(key, f"    {key}")
        print(f"{name:34s} {a:16.1f} {b:10.1f} {a / b:7.2f}")


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--t-end", type=float, default=1.0)
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--smoke", action="store_true", help="0.05 s, once: the script runs")
    parser.add_argument("--profile", action="store_true", help="where a wheeled step's time goes (module docstring)")
    args = parser.parse_args(argv)
    if args.profile:
        profile(nstep=200 if args.smoke else 2000, repeat=1 if args.smoke else args.repeat)
        return 0
    t_end, repeat = (0.05, 1) if args.smoke else (args.t_end, args.repeat)
    rigid = dict(cornering_coefficient=None)  # the wheels fixed on their axles (the model before steer hinges)
    grip = dict(mu_wall=0.5)  # finite grip: the wheels steer (with unlimited grip they are rigid)
    rows = [  # (label, variant, params, python loop, the slide row it is compared with, the rigid-wheel row)
        ("slides, defaults, C loop", "mujoco-ratchet", RobotParams(), False, None, None),
        ("slides, defaults, Python loop", "mujoco-ratchet", RobotParams(), True, None, None),
        ("wheels, defaults", "mujoco-wheels", RobotParams(), False, 0, None),
        ("slides, motor, C loop", "mujoco-ratchet", RobotParams(drive="motor"), False, None, None),
        ("wheels, motor", "mujoco-wheels", RobotParams(drive="motor"), False, 3, None),
        ("wheels, motor, mu_wall 0.5", "mujoco-wheels", RobotParams(drive="motor", **grip), False, 3, 6),
        ("wheels, motor, mu_wall 0.5, rigid", "mujoco-wheels", RobotParams(drive="motor", **grip, **rigid), False,
         3, None),
    ]
    best = [float("inf")] * len(rows)
    for k in range(repeat):
        for i, (label, variant, params, python, _, _) in enumerate(rows):
            print(f"[{k + 1}/{repeat}] {label}", file=sys.stderr, flush=True)
            best[i] = min(best[i], once(variant, params, t_end, python))
    print(f"{'run':36s} {'wall s / sim s':>15s} {'/ slides C (same design)':>26s} {'/ rigid wheels':>15s}")
    for (label, _, _, _, base, fixed), value in zip(rows, best):
        ratio = "" if base is None else f"{value / best[base]:.1f}"
        steer = "" if fixed is None else f"{value / best[fixed]:.2f}"
        print(f"{label:36s} {value:15.3f} {ratio:>26s} {steer:>15s}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
