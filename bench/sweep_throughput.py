"""Benchmark: sweep throughput on 1 and 2 cores, and batched vs serial MuJoCo steps.

Run on demand (not part of the test suite):

    python bench/sweep_throughput.py [--designs N] [--t-end SECONDS] [--smoke]

Reports, measured in one run on this machine:
- designs per second of the analytic one-way-clutch model through the process
  pool with 1 and 2 workers;
- designs per second of MuJoCo's ratchet through mujoco.batch with 1 and 2 threads,
  in two one-thread processes of half the designs each (how the sweep runs its
  batch chunks; process start included), and through the serial engine (one
  design after another; it steps in C where its compiled loop is built);
- the cost of one batched ratcheted step per design as a ratio to one step of the
  serial engine (ipir_mujoco.engine), both on one thread.
"""

from __future__ import annotations

import argparse
import functools
import tempfile
import time
from concurrent import futures

from ipir_mujoco.analytic import RobotParams
from ipir_mujoco.engine import simulate_mujoco
from ipir_mujoco.engine.builders.model import SolverSettings
from ipir_mujoco.studies.sweep import run_sweep
from ipir_mujoco.engine.run.batch import run_ratchet_batch
from ipir_mujoco.studies.sweep_space import Study, parse_vary


def timed(action) -> float:
    started = time.perf_counter()
    action()
    return time.perf_counter() - started


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--designs", type=int, default=32)
    parser.add_argument("--t-end", type=float, default=0.5)
    parser.add_argument("--smoke", action="store_true", help="every code path once, in seconds (not a measurement)")
    args = parser.parse_args()
    if args.smoke:
        args.designs, args.t_end = 2, 0.02
    n, t_end = args.designs, args.t_end
    study = Study((parse_vary(f"L=0.06:0.5:{n}"),), engines=("analytic-unilateral",), t_end=t_end)
    designs = [RobotParams(L=d["L"]) for d in study.designs()]
    steps = round(t_end / SolverSettings().timestep)
    print(f"{n} designs, {t_end:g} s simulated each ({steps} MuJoCo steps)")
    for workers in (1, 2):
        with tempfile.TemporaryDirectory() as folder:
            seconds = timed(lambda: run_sweep(study, folder, workers=workers, progress=False))
        print(f"  analytic one-way clutches, process pool, {workers} worker(s): {n / seconds:7.2f} designs/s")
    batched = {}
    for threads in (1, 2):
        batched[threads] = timed(lambda: run_ratchet_batch(designs, t_end, 1e-3, nthread=threads))
        print(f"  MuJoCo ratchet, mujoco.batch, {threads} thread(s):          {n / batched[threads]:7.2f} designs/s")

    def two_processes():
        chunk = functools.partial(run_ratchet_batch, t_end=t_end, dt_out=1e-3, nthread=1)
        with futures.ProcessPoolExecutor(2) as pool:
            list(pool.map(chunk, [designs[:n // 2], designs[n // 2:]]))
    processes = timed(two_processes)
    print(f"  MuJoCo ratchet, mujoco.batch, 2 processes of 1 thread:   {n / processes:7.2f} designs/s")
    serial = timed(lambda: [simulate_mujoco(p, "unilateral", "ratchet", t_end, dt_out=1e-3) for p in designs])
    print(f"  MuJoCo ratchet, serial engine (Python loop):             {n / serial:7.2f} designs/s")
    per_step_batch = batched[1] / (n * steps)
    per_step_serial = serial / (n * steps)
    print(f"  one batched step per design: {per_step_batch * 1e6:.2f} us; serial loop step: "
          f"{per_step_serial * 1e6:.2f} us; ratio batched/serial = {per_step_batch / per_step_serial:.3f}")


if __name__ == "__main__":
    main()
