"""Benchmark: the MuJoCo ratchet over random valid designs (backward excursion, unstable runs).

Run on demand (not part of the test suite):

    python bench/ratchet_random.py [--designs 100] [--seed 0] [--engine-module MODULE] [--budget 60] [--smoke]

Designs are drawn with numpy's default_rng(seed), each parameter independently:
log-uniform m1, m2 in [0.1, 10] kg, r in [0.005, 0.1] m, L / r in [1.1, 30],
J_A in [2e-5, 5e-2] kg m^2, M in [0.05, 5] N m, rod_mass in [1e-3, 0.3] kg;
uniform F_r1, F_r2 in [0, 20] N, phi0 in [0, 2 pi) rad, omega0 in [-50, 50]
rad/s; t_end 1 s, constant torque, one-way clutches (the ratchet), output
every 1e-4 s. Each design runs with the engine's default settings (for an
engine that chooses its timestep, its own choice) and a wall-time budget.

Reported: how each run ended (finished, MuJoCo unstable, stopped by the
accuracy monitor, refused as needing too small a step, over the budget), the
worst backward excursion of a module below its running maximum in the samples
(and, where the engine reports it, the per-step figure of its accuracy
monitor), and how many designs exceed 1e-6 m.
"""

from __future__ import annotations

import argparse
import importlib
import inspect
import math
import time

import mujoco
import numpy as np

from ipir_mujoco.analytic import ParameterError, RobotParams, SimulationError
from ipir_mujoco.engine.builders.model import build_model, set_closed_loop_state


def draw(rng: np.random.Generator) -> RobotParams:
    log = lambda lo, hi: float(math.exp(rng.uniform(math.log(lo), math.log(hi))))  # noqa: E731
    r = log(0.005, 0.1)
    return RobotParams(m1=log(0.1, 10), m2=log(0.1, 10), r=r, L=r * log(1.1, 30), J_A=log(2e-5, 5e-2),
                       F_r1=float(rng.uniform(0, 20)), F_r2=float(rng.uniform(0, 20)), M=log(0.05, 5),
                       rod_mass=log(1e-3, 0.3), phi0=float(rng.uniform(0, 2 * math.pi)),
                       omega0=float(rng.uniform(-50, 50)))


def initial_kinetic(params: RobotParams) -> float:
    """Kinetic energy of the start state [J] (the same for every engine: the loop-consistent start)."""
    model = build_model(params)
    data = mujoco.MjData(model)
    set_closed_loop_state(model, data, params)
    return float(data.energy[1])


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--designs", type=int, default=100)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--engine-module", default="ipir_mujoco.engine", help="engine package to run")
    parser.add_argument("--budget", type=float, default=60.0, help="wall-time budget per design [s]")
    parser.add_argument("--smoke", action="store_true", help="every code path once, in seconds (not a measurement)")
    args = parser.parse_args()
    if args.smoke:
        args.designs = 2
    engine = importlib.import_module(args.engine_module)
    budgeted = "wall_budget_s" in inspect.signature(engine.simulate_mujoco).parameters
    rng = np.random.default_rng(args.seed)
    counts: dict[str, int] = {}
    worst, worst_step, above, started = 0.0, 0.0, 0, time.perf_counter()
    for i in range(args.designs):
        params = draw(rng)
        extra = {"wall_budget_s": args.budget} if budgeted else {}
        try:
            run = engine.simulate_mujoco(params, "unilateral", "ratchet", 1.0, dt_out=1e-4, **extra)
        except ParameterError as exc:
            outcome = "refused (needs too small a step)" if "timestep" in str(exc) else f"bad input: {exc}"
        except SimulationError as exc:
            text = str(exc)
            outcome = ("unstable" if "unstable" in text or "non-finite" in text else
                       "stopped by the accuracy monitor" if "accuracy" in text else
                       "over the wall budget" if "budget" in text else text)
        else:
            outcome = "finished"
            s = run.series
            back = max(float(np.max(np.maximum.accumulate(s[c]) - s[c])) for c in ("x1", "x2"))
            worst = max(worst, back)
            step = (run.accuracy or {}).get("excursion_m", back)
            worst_step = max(worst_step, step)
            above += max(back, step) > 1e-6
            energy = run.energy
            scale = max(abs(energy["motor_work_j"]), energy["friction_j"], initial_kinetic(params),
                        2 * math.pi * abs(params.M))
            if abs(energy["residual_j"]) > 1e-3 * scale:
                outcome = "finished, residual > 1e-3 of the energy"
        counts[outcome] = counts.get(outcome, 0) + 1
        print(f"design {i}: {outcome}", flush=True)
    print(f"{args.engine_module}: {args.designs} designs (seed {args.seed}) in {time.perf_counter() - started:.0f} s")
    for outcome, count in sorted(counts.items()):
        print(f"  {outcome:35s} {count}")
    print(f"  worst backward excursion (samples)  {worst:.3g} m")
    print(f"  worst backward excursion (per step) {worst_step:.3g} m")
    print(f"  finished designs with more than 1e-6 m: {above}")


if __name__ == "__main__":
    main()
