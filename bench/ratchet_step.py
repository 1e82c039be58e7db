"""Benchmark: cost of the engine's step against a plain mj_step of the same model.

Run on demand (not part of the test suite):

    python bench/ratchet_step.py [--steps N] [--repeats R] [--engine-module MODULE]

All variants step the same compiled model (paper's case, ratchet-limited
slides, timestep 1e-4 s) from the same state, interleaved in one run so
machine load affects them alike; each is timed R times and the best time per
step is kept. Reported as ratios to the plain step:

- plain:            mj_step alone
- ratchet:          the ratchet's bound update (that engine's) + mj_step
- engine, dt_out=dt: everything ``simulate_mujoco`` does per step (ratchet,
                    energy audit, accuracy monitor, a sample every step)
- engine, dt_out=10 dt: the same with a sample every 10 steps

The engine variants time two run lengths and keep the difference, so that
building the model and assembling the result do not count.
``--engine-module`` times another copy of the engine package (for a
before/after comparison); it must export ``simulate_mujoco`` and
``SolverSettings``.
"""

from __future__ import annotations

import argparse
import importlib
import time

import mujoco

from ipir_mujoco.analytic import RobotParams
from ipir_mujoco.engine.clutches import Ratchet
from ipir_mujoco.engine.model import SolverSettings, build_model, drive_control, set_closed_loop_state

DT = 1e-4


def fresh(params):
    model = build_model(params, SolverSettings(timestep=DT), ratchet=True)
    data = mujoco.MjData(model)
    set_closed_loop_state(model, data, params)
    data.ctrl[model.actuator("crank_motor").id] = drive_control(params)
    return model, data


def time_plain(params, steps):
    model, data = fresh(params)
    Ratchet(model, data)  # same limits as the ratcheted run, bounds never raised
    started = time.perf_counter()
    for _ in range(steps):
        mujoco.mj_step(model, data)
    return (time.perf_counter() - started) / steps


def ratchet_timer(ratchet_class):
    def run(params, steps):
        return time_ratchet(params, steps, ratchet_class)
    return run


def time_ratchet(params, steps, ratchet_class=Ratchet):
    model, data = fresh(params)
    ratchet = ratchet_class(model, data)
    started = time.perf_counter()
    for _ in range(steps):
        ratchet.before_step()
        mujoco.mj_step(model, data)
    return (time.perf_counter() - started) / steps


def engine_timer(engine, steps_per_sample):
    def run(params, steps):
        def once(n):
            started = time.perf_counter()
            engine.simulate_mujoco(params, "unilateral", "ratchet", n * DT, dt_out=steps_per_sample * DT,
                                   settings=engine.SolverSettings(timestep=DT))
            return time.perf_counter() - started
        short = steps // 5
        return (once(steps) - once(short)) / (steps - short)
    return run


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--steps", type=int, default=5000, help="steps per timing (default 5000 = 0.5 s simulated)")
    parser.add_argument("--repeats", type=int, default=5, help="timings per variant; the best is kept")
    parser.add_argument("--engine-module", default="ipir_mujoco.engine", help="engine package to time")
    args = parser.parse_args()
    engine = importlib.import_module(args.engine_module)
    params = RobotParams()
    ratchet_class = importlib.import_module(args.engine_module + ".clutches").Ratchet
    variants = {"plain mj_step": time_plain, "ratcheted step": ratchet_timer(ratchet_class),
                "engine, dt_out=dt": engine_timer(engine, 1), "engine, dt_out=10 dt": engine_timer(engine, 10)}
    best = {name: float("inf") for name in variants}
    for _ in range(args.repeats):
        for name, timer in variants.items():  # interleaved, so drifts in machine load hit all alike
            best[name] = min(best[name], timer(params, args.steps))
    plain = best["plain mj_step"]
    print(f"mujoco {mujoco.__version__}, {args.engine_module}, {args.steps} steps x {args.repeats} repeats, "
          "best of each")
    for name, seconds in best.items():
        print(f"  {name:22s} {seconds * 1e6:8.2f} us/step   {seconds / plain:6.2f} x plain")


if __name__ == "__main__":
    main()
