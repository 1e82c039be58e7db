"""The wheeled MuJoCo model's cost per simulated second against the slide model's, as ratios measured in one run.

Run on demand from the repository root (about a minute; ``--smoke``: seconds):

    python bench/wheels_cost.py [--t-end SECONDS] [--repeat N] [--smoke] [--profile]

Each at its defaults for ``--t-end`` simulated seconds, each run ``--repeat`` times, the best kept, the runs
interleaved so that a busy machine slows both alike:

- the slide model (``mujoco-ratchet``) on the default design (the paper's constant torque, unlimited grip) and
  with the default motor, stepped in C (its default) and in Python (``IPIR_MUJOCO_STEPPER=python``);
- the wheeled model (``mujoco-wheels``: the robot in a round pipe, 51 degrees of freedom, 12 sprung wheels on
  hub ratchets and steer hinges, stepped in C as the slide model) on the same designs, and with the default motor
  on a finite grip (mu_wall 0.5); each also with rigid wheels (``cornering_coefficient=rigid``: no steer hinges,
  39 degrees of freedom).

Prints wall seconds per simulated second, each wheeled run's ratio to the slide model's C loop on the same
design (the issue's target: at most 10 at the defaults) and to the same run with rigid wheels.

``--profile`` prints instead where a wheeled step's time goes, with the default motor on unlimited grip: the
compiled loop's cost per step against a bare ``mj_step`` on a copy of the same state (the loop's own share: the
hub ratchets, the bookkeeping, the samples), and MuJoCo's own timers of those bare steps per stage.
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


def profile(params: RobotParams, nstep: int = 2000) -> None:
    """Print the wheeled loop's cost per step [us] against a bare mj_step's, and MuJoCo's timers per stage."""
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
    loop = (time.perf_counter() - started) / nstep
    step = data.timer[int(mujoco.mjtTimer.mjTIMER_STEP)].duration / nstep
    print(f"timestep {model.opt.timestep:g} s, nv {model.nv}, {data.ncon} contacts, {data.nefc} constraint rows; "
          f"{'compiled' if steps.compiled else 'Python'} loop")
    print(f"{'the loop, per step':34s} {loop * 1e6:8.1f} us")
    print(f"{'  of which mj_step (its timer)':34s} {step * 1e6:8.1f} us")
    for i, timer in enumerate(data.timer):
        if timer.number and i != int(mujoco.mjtTimer.mjTIMER_STEP):
            print(f"    {mujoco.mjtTimer(i).name[8:].lower():30s} {timer.duration / nstep * 1e6:8.1f} us")


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--t-end", type=float, default=1.0)
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--smoke", action="store_true", help="0.05 s, once: the script runs")
    parser.add_argument("--profile", action="store_true", help="where a wheeled step's time goes (module docstring)")
    args = parser.parse_args(argv)
    if args.profile:
        profile(RobotParams(drive="motor"), nstep=200 if args.smoke else 2000)
        return 0
    t_end, repeat = (0.05, 1) if args.smoke else (args.t_end, args.repeat)
    rigid = dict(cornering_coefficient=None)  # the wheels fixed on their axles (the model before steer hinges)
    rows = [  # (label, variant, params, python loop, the slide row it is compared with, the rigid-wheel row)
        ("slides, defaults, C loop", "mujoco-ratchet", RobotParams(), False, None, None),
        ("slides, defaults, Python loop", "mujoco-ratchet", RobotParams(), True, None, None),
        ("wheels, defaults", "mujoco-wheels", RobotParams(), False, 0, 3),
        ("wheels, defaults, rigid wheels", "mujoco-wheels", RobotParams(**rigid), False, 0, None),
        ("slides, motor, C loop", "mujoco-ratchet", RobotParams(drive="motor"), False, None, None),
        ("wheels, motor", "mujoco-wheels", RobotParams(drive="motor"), False, 4, 6),
        ("wheels, motor, rigid wheels", "mujoco-wheels", RobotParams(drive="motor", **rigid), False, 4, None),
        ("wheels, motor, mu_wall 0.5", "mujoco-wheels", RobotParams(drive="motor", mu_wall=0.5), False, 4, 8),
        ("wheels, motor, mu_wall 0.5, rigid", "mujoco-wheels", RobotParams(drive="motor", mu_wall=0.5, **rigid), False,
         4, None),
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
