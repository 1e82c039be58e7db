"""Benchmark: do the two engines agree on random designs across the whole envelope, or say why not?

Run on demand (not part of the test suite):

    python bench/agreement_random.py [--designs 60] [--seed 1] [--t-end 1] [--budget 60] [--workers 2]

The package's promise is that every number it prints is right within a stated
tolerance or refused with a reason. This draws random valid designs over every
effect both engines model (constant torque or the motor, inclines from -90 to
90 degrees, rigid or compliant clutches with damping and backlash, the
geometry and masses over wide ranges), runs the analytic one-way model (exact
geometry) and MuJoCo's ratchet (or its compliant clutch) at their default
settings, and sorts each design into:

- ``agree``: both finished and MuJoCo is within 0.1 % of the analytic model
  in revolutions and in travel (revolutions compared against max(|revolutions|,
  1), travel against max(|travel|, 2 r), one revolution's stroke, so a robot
  that barely moves is not judged on a ratio of two small numbers);
- ``agree-1%``: within 1 %, outside 0.1 %;
- ``refused`` / ``failed``: an engine refused the design (ParameterError) or
  stopped with a SimulationError (accuracy monitor, instability, budget),
  each with its one-line reason;
- ``DISAGREE``: both finished without complaint and differ by more than 1 %:
  a silent disagreement, the case this benchmark exists to find.

Designs are drawn with numpy's default_rng(seed): log-uniform m1, m2 in
[0.1, 10] kg, r in [0.005, 0.1] m, L / r in [1.5, 30], J_A in [2e-5, 5e-2]
kg m^2, rod_mass in [1e-3, 0.3] kg; uniform F_r1, F_r2 in [0, 20] N and phi0
in [0, 2 pi) rad; the robot starts at rest; half the designs under a constant
torque M (log-uniform [0.05, 5] N m), half under the motor (M_stall
log-uniform [0.05, 5] N m, omega_noload [3, 100] rad/s); half in a
horizontal pipe, half at an incline uniform in [-90, 90] degrees; a third
with compliant clutches (stiffness log-uniform [1e4, 1e7] N/m, damping 0 or
log-uniform [1, 100] N s/m, backlash 0 or uniform up to 2 % of the stroke).
"""

from __future__ import annotations

import argparse
import math
import time
from concurrent import futures

import numpy as np

from ipir_mujoco import analytic
from ipir_mujoco.analytic import ParameterError, RobotParams, SimulationError
from ipir_mujoco.engine import simulate_mujoco

TIGHT, LOOSE = 1e-3, 1e-2


def draw(rng: np.random.Generator) -> RobotParams:
    log = lambda lo, hi: float(math.exp(rng.uniform(math.log(lo), math.log(hi))))  # noqa: E731
    r = log(0.005, 0.1)
    values = dict(m1=log(0.1, 10), m2=log(0.1, 10), r=r, L=r * log(1.5, 30), J_A=log(2e-5, 5e-2),
                  F_r1=float(rng.uniform(0, 20)), F_r2=float(rng.uniform(0, 20)), rod_mass=log(1e-3, 0.3),
                  phi0=float(rng.uniform(0, 2 * math.pi)), omega0=0.0)
    if rng.uniform() < 0.5:
        values.update(drive="torque", M=log(0.05, 5))
    else:
        values.update(drive="motor", M_stall=log(0.05, 5), omega_noload=log(3, 100))
    if rng.uniform() < 0.5:
        values["incline"] = float(rng.uniform(-90, 90))
    if rng.uniform() < 1 / 3:
        values["clutch_stiffness"] = log(1e4, 1e7)
        if rng.uniform() < 0.5:
            values["clutch_damping"] = log(1, 100)
        if rng.uniform() < 0.5:
            values["clutch_backlash"] = float(rng.uniform(0, 0.02 * 2 * r))
    return RobotParams(**values)


def run_one(index: int, params: RobotParams, t_end: float, budget: float) -> dict:
    row = {"design": index, "params": params}
    for name, call in (("analytic", lambda: analytic.simulate(params, "exact", "unilateral", t_end, dt_out=1e-3,
                                                              wall_budget_s=budget)),
                       ("mujoco", lambda: simulate_mujoco(params, "unilateral", "ratchet", t_end, dt_out=1e-3,
                                                          wall_budget_s=budget))):
        started = time.perf_counter()
        try:
            run = call()
        except ParameterError as exc:
            row[name] = ("refused", str(exc))
        except SimulationError as exc:
            row[name] = ("failed", str(exc))
        else:
            s = run.summary
            row[name] = ("ok", (s["revolutions"], 0.5 * (s["x1_final"] + s["x2_final"])))
        row[name + "_wall"] = time.perf_counter() - started
    return row


def judge(row: dict) -> tuple[str, str]:
    (sa, va), (sm, vm) = row["analytic"], row["mujoco"]
    if sa != "ok" or sm != "ok":
        why = "; ".join(f"{n}: {v}" for n, (s, v) in (("analytic", row["analytic"]), ("mujoco", row["mujoco"]))
                        if s != "ok")
        return ("refused" if "refused" in (sa, sm) else "failed"), why
    (rev_a, travel_a), (rev_m, travel_m) = va, vm
    stroke = 2 * row["params"].r
    d_rev = abs(rev_m - rev_a) / max(abs(rev_a), 1.0)
    d_travel = abs(travel_m - travel_a) / max(abs(travel_a), stroke)
    worst = max(d_rev, d_travel)
    detail = (f"revolutions {rev_a:.5g} / {rev_m:.5g} ({d_rev:.2e}), travel {travel_a:.5g} / {travel_m:.5g} m "
              f"({d_travel:.2e})")
    return ("agree" if worst <= TIGHT else "agree-1%" if worst <= LOOSE else "DISAGREE"), detail


def describe(p: RobotParams) -> str:
    drive = f"M={p.M:.3g}" if p.drive == "torque" else f"motor M_stall={p.M_stall:.3g} omega_noload={p.omega_noload:.3g}"
    clutch = "rigid" if p.clutch_stiffness is None else (
        f"k={p.clutch_stiffness:.3g} c={p.clutch_damping:.3g} backlash={p.clutch_backlash:.3g}")
    return (f"m1={p.m1:.3g} m2={p.m2:.3g} r={p.r:.3g} L={p.L:.3g} J_A={p.J_A:.3g} rod_mass={p.rod_mass:.3g} "
            f"F_r1={p.F_r1:.3g} F_r2={p.F_r2:.3g} phi0={p.phi0:.3g} {drive} incline={p.incline:.3g} {clutch}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--designs", type=int, default=60)
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--t-end", type=float, default=1.0, help="simulated time per design [s]")
    parser.add_argument("--budget", type=float, default=60.0, help="wall-time budget per engine and design [s]")
    parser.add_argument("--workers", type=int, default=2)
    args = parser.parse_args()
    rng = np.random.default_rng(args.seed)
    designs = [draw(rng) for _ in range(args.designs)]
    counts: dict[str, int] = {}
    started = time.perf_counter()
    with futures.ProcessPoolExecutor(args.workers) as pool:
        jobs = [pool.submit(run_one, i, p, args.t_end, args.budget) for i, p in enumerate(designs)]
        for job in futures.as_completed(jobs):
            row = job.result()
            verdict, detail = judge(row)
            counts[verdict] = counts.get(verdict, 0) + 1
            print(f"[{row['design']:3d}] {verdict:9s} {detail}  (wall {row['analytic_wall']:.2f} / "
                  f"{row['mujoco_wall']:.2f} s)", flush=True)
            if verdict not in ("agree",):
                print(f"      {describe(row['params'])}", flush=True)
    print(f"\n{args.designs} designs, {time.perf_counter() - started:.0f} s wall: "
          + ", ".join(f"{k} {v}" for k, v in sorted(counts.items())))


if __name__ == "__main__":
    main()
