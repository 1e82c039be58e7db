"""Benchmark: every speed target of the package in one run, with its ratio, and the README's table.

Run on demand (not part of the test suite), from the repository root:

    python bench/targets.py [--repeats 3] [--before REV|none] [--skip-sweep] [--smoke]

Targets (ratios measured in this one run; absolute times printed too):

- the paper's model (approx, kinematic), 1 s: at most 0.1 of the analytic
  package at ``--before`` (default 5590109, the last one on solve_ivp);
- the one-way model (exact, unilateral), 1 s: at most 30 ms;
- 10 s against 1 s: at most 11x, with the crank revolutions beside it (an
  event-driven solver's work grows with the revolutions; under a constant
  torque they grow like t^2, under the motor like t);
- a serial MuJoCo ratchet run, 5 s, dt_out 1 ms: at most 1.5x a plain
  ``mj_step`` over the same steps of the same compiled model (in a C loop);
- a 20 x 20 sweep of L and m2 (MuJoCo ratchet + analytic one-way, 1 s each,
  the sweep's defaults): at most 1.5x the MuJoCo floor, the designs' steps x a
  plain ``mj_step`` / the cores;
- the command's start-up (``bench/startup.py``, best of at least 5): ``--help``
  and ``params`` at most 1.5x, ``simulate`` at most 2.5x the interpreter
  loading numpy, in CPU time.

The first target compares with an old revision of the package: where its
git history is missing (an installed package) or ``--before none``, the bench
says so and gives that row without the ratio. ``--smoke`` runs every row once
in seconds (runs cut to 0.05 s, a 2 x 2 sweep): a check that it runs, not a
measurement.

The single-component benchmarks give more detail: ``bench/analytic_speed.py``
(every analytic case, first-call and fallback costs), ``bench/ratchet_step.py``
(every MuJoCo clutch, before and after), ``bench/sweep_throughput.py``.
"""

from __future__ import annotations

import argparse
import math
import os
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

import analytic_speed  # noqa: E402  (bench/ siblings)
import ratchet_step  # noqa: E402
import startup  # noqa: E402

from ipir_mujoco.engine.modelkinds.timestep import choose_settings  # noqa: E402
from ipir_mujoco.studies.sweep import run_sweep  # noqa: E402
from ipir_mujoco.studies.sweep_space import Study, parse_vary  # noqa: E402


def analytic_rows(before_rev: str, repeats: int, smoke: bool = False) -> list[tuple]:
    with tempfile.TemporaryDirectory() as folder:
        before = analytic_speed.load_before(before_rev, Path(folder))
        from ipir_mujoco import analytic

        cases = analytic_speed.CASES
        if smoke:  # every case 20 times shorter: the code paths, not the times
            cases = {name: (p, g, c, t_end / 20, o) for name, (p, g, c, t_end, o) in cases.items()}
        timed = {}
        names = ["paper model (approx, kinematic), 1 s", "one-way model (exact, unilateral), 1 s"]
        names += [name for pair in analytic_speed.PAIRS for name in pair if name not in names]
        for name in names:
            timed[name] = analytic_speed.best(analytic, cases[name],
                                              1 if name in analytic_speed.LONG else repeats)
        paper_before, _ = analytic_speed.best(before, cases["paper model (approx, kinematic), 1 s"], repeats)
    paper, one_way = timed["paper model (approx, kinematic), 1 s"], timed["one-way model (exact, unilateral), 1 s"]
    rows = [("paper model, 1 s", f"{paper[0] * 1e3:.1f} ms (before {paper_before * 1e3:.0f} ms)"
             if paper_before else f"{paper[0] * 1e3:.1f} ms (no before here)",
             paper[0] / paper_before if paper_before else math.nan, "<= 0.1 of before"),
            ("one-way model, 1 s", f"{one_way[0] * 1e3:.1f} ms", one_way[0] / 0.030, "<= 30 ms (ratio to 30 ms)")]
    for short, long_ in analytic_speed.PAIRS:
        (t1, run1), (t10, run10) = timed[short], timed[long_]
        revs = run10.summary["revolutions"] / run1.summary["revolutions"]
        times = run10.t_end / run1.t_end
        rows.append((f"{long_} / {run1.t_end:g} s", f"{t10:.3f} s against {t1 * 1e3:.1f} ms; revolutions x{revs:.1f}",
                     t10 / t1, f"<= {1.1 * times:g} (cost per revolution: x{t10 / t1 / revs:.2f})"))
    return rows


def mujoco_row(repeats: int, t_end: float = 5.0) -> tuple:
    case = ratchet_step.CASES["ratchet"]
    params, rule, implementation = case[:3]
    dt_out = 1e-3
    timestep = choose_settings(params, t_end, dt_out, None, implementation)[0].timestep
    smoke = t_end < 1.0  # --smoke: the timer and call costs measured briefly too
    overhead = ratchet_step.timer_cost(2000 if smoke else 200_000)
    plain = engine = math.inf
    for _ in range(repeats):
        plain = min(plain, ratchet_step.plain_step(case, t_end, timestep, overhead))
        engine = min(engine, ratchet_step.engine_step(ratchet_step.simulate_mujoco, ratchet_step.SolverSettings, case,
                                                      t_end, dt_out, timestep, given=False))
    floor = plain - ratchet_step.call_overhead(case, timestep, *((200, 1) if smoke else ()))
    steps = int(t_end / timestep * (1 + 1e-12))
    return (f"MuJoCo ratchet, {t_end:g} s, dt_out 1 ms", f"{engine * steps:.2f} s for {steps} steps; plain mj_step "
            f"{floor * 1e6:.2f} us", engine / floor, "<= 1.5 x plain mj_step")


def sweep_row(plain_step_s: float, repeats: int, n: int = 20, t_end: float = 1.0) -> tuple:
    study = Study((parse_vary(f"L=0.06:0.5:{n}"), parse_vary(f"m2=0.2:3:{n}")), t_end=t_end)
    steps = 0
    for design in study.designs():
        params = study.base.replace(**design)
        settings, _ = choose_settings(params, study.t_end, 1e-3, None, "ratchet")
        steps += int(study.t_end / settings.timestep * (1 + 1e-12))
    cores = os.cpu_count() or 1
    floor = steps * plain_step_s / cores
    wall = math.inf
    for _ in range(repeats):
        with tempfile.TemporaryDirectory() as folder:
            started = time.perf_counter()
            run_sweep(study, Path(folder) / "s", progress=False)
            wall = min(wall, time.perf_counter() - started)
    from ipir_mujoco.engine.loop.stepper import compiled_status

    how = "serial MuJoCo, compiled loop" if compiled_status()[0] else "mujoco.batch (no compiled loop here)"
    return (f"{n} x {n} sweep (MuJoCo ratchet + analytic one-way, {t_end:g} s; {how})",
            f"{wall:.1f} s ({n * n / wall:.1f} designs/s); floor {floor:.1f} s ({steps} steps x {plain_step_s * 1e6:.2f}"
            f" us / {cores} cores)", wall / floor, "<= 1.5 x floor")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=3, help="timings per case; the best is kept (default 3)")
    parser.add_argument("--before", default=analytic_speed.BEFORE,
                        help="git revision of the 'before' analytic code ('none': leave it out)")
    parser.add_argument("--smoke", action="store_true", help="every row once, in seconds (not a measurement)")
    parser.add_argument("--skip-sweep", action="store_true",
                        help="leave out the 20 x 20 sweep (about 12 s a repeat on 2 cores)")
    args = parser.parse_args()
    if args.smoke:
        args.repeats = 1
    load = os.getloadavg()
    print(f"load average {load[0]:.2f} {load[1]:.2f} {load[2]:.2f} on {os.cpu_count()} cores; best of {args.repeats}",
          flush=True)
    rows = analytic_rows(args.before, args.repeats, args.smoke)
    t_run = 0.05 if args.smoke else 1.0
    rows.append(mujoco_row(args.repeats, 0.25 if args.smoke else 5.0))
    if not args.skip_sweep:
        case = ratchet_step.CASES["ratchet"]
        timestep = choose_settings(case[0], t_run, 1e-3, None, "ratchet")[0].timestep
        costs = ((2000,), (200, 1)) if args.smoke else ((), ())
        plain = min(ratchet_step.plain_step(case, t_run, timestep, ratchet_step.timer_cost(*costs[0]))
                    - ratchet_step.call_overhead(case, timestep, *costs[1])
                    for _ in range(1 if args.smoke else max(args.repeats, 3)))
        rows.append(sweep_row(plain, args.repeats, 2 if args.smoke else 20, t_run))
    floor, started = startup.measure(max(args.repeats, 5) if not args.smoke else 1)
    for name, (wall, cpu), wanted in started:
        rows.append((f"start-up: {name}", f"{wall * 1e3:.0f} ms wall, {cpu * 1e3:.0f} ms CPU; python -c 'import numpy' "
                     f"{floor[0] * 1e3:.0f} / {floor[1] * 1e3:.0f} ms", cpu / floor[1], f"<= {wanted:g} x the floor (CPU)"))
    print("\n| target | measured | ratio | wanted |\n|---|---|---|---|")
    for name, measured, ratio, wanted in rows:
        print(f"| {name} | {measured} | {ratio:.3g} | {wanted} |")


if __name__ == "__main__":
    main()
