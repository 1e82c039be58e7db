"""Benchmark: cost of a ratcheted step against a plain mj_step of the same model.

Run on demand (not part of the test suite):

    python bench/ratchet_step.py [--steps N] [--repeats R]

All variants step the same compiled model (paper's case, ratchet-limited
slides) from the same state, interleaved in one run so machine load affects
them alike; each is timed R times and the best time per step is kept. Reported
as ratios to the plain step:

- plain:       mj_step alone
- ratchet:     the ratchet's bound update (running maximum -> jnt_range) + mj_step
- engine loop: everything ipir_mujoco.engine does per step (bound update,
               energy bookkeeping from constraint rows, sampling every dt_out)
"""

from __future__ import annotations

import argparse
import time

import mujoco

from ipir_mujoco.analytic import RobotParams
from ipir_mujoco.engine.clutches import Ratchet
from ipir_mujoco.engine import simulate_mujoco
from ipir_mujoco.engine.model import SolverSettings, build_model, set_closed_loop_state


def fresh(params):
    model = build_model(params, SolverSettings(), ratchet=True)
    data = mujoco.MjData(model)
    set_closed_loop_state(model, data, params)
    data.ctrl[model.actuator("crank_motor").id] = params.M
    return model, data


def time_plain(params, steps):
    model, data = fresh(params)
    Ratchet(model, data)  # same limits as the ratcheted run, bounds never raised
    started = time.perf_counter()
    for _ in range(steps):
        mujoco.mj_step(model, data)
    return (time.perf_counter() - started) / steps


def time_ratchet(params, steps):
    model, data = fresh(params)
    ratchet = Ratchet(model, data)
    started = time.perf_counter()
    for _ in range(steps):
        ratchet.before_step()
        mujoco.mj_step(model, data)
    return (time.perf_counter() - started) / steps


def time_engine(params, steps):
    dt = SolverSettings().timestep
    started = time.perf_counter()
    simulate_mujoco(params, "unilateral", "ratchet", steps * dt, dt_out=dt)
    return (time.perf_counter() - started) / steps


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--steps", type=int, default=5000, help="steps per timing (default 5000 = 0.5 s simulated)")
    parser.add_argument("--repeats", type=int, default=5, help="timings per variant; the best is kept")
    args = parser.parse_args()
    params = RobotParams()
    variants = {"plain mj_step": time_plain, "ratcheted step": time_ratchet, "engine loop step": time_engine}
    best = {name: float("inf") for name in variants}
    for _ in range(args.repeats):
        for name, timer in variants.items():  # interleaved, so drifts in machine load hit all alike
            best[name] = min(best[name], timer(params, args.steps))
    plain = best["plain mj_step"]
    print(f"mujoco {mujoco.__version__}, {args.steps} steps x {args.repeats} repeats, best of each")
    for name, seconds in best.items():
        print(f"  {name:18s} {seconds * 1e6:8.2f} us/step   {seconds / plain:6.2f} x plain")


if __name__ == "__main__":
    main()
