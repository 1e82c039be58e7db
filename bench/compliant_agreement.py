"""Benchmark: MuJoCo's compliant clutch against the analytic one, same stiffness and backlash.

Run on demand (not part of the test suite):

    python bench/compliant_agreement.py [--stiffness 1e5,1e6] [--backlash 0,1e-3] [--paper-t-end 1.0]
                                        [--cruise-t-end 3.0]
    python bench/compliant_agreement.py --omega-dt 0.4,0.2,0.1,0.05 [--stiffness 1e6,1e7,1e8]
    python bench/compliant_agreement.py --rigid-limit [--stiffness 1e5,1e6,1e7,1e8]

Any of them with ``--smoke``: one stiffness (1e5 N/m), one backlash, runs of 0.02 s (a check that it runs,
not a measurement).

Cases: the paper's start (constant torque 0.25 N m from rest, ``--paper-t-end``
seconds) and the default motor at cruise (``--cruise-t-end`` seconds from rest;
the "peak" is then the last whole revolution's). For every stiffness and
backlash it prints revolutions, travel ((x1 + x2) / 2) and peak clutch force in
both engines, MuJoCo's relative differences, its automatic timestep, and the
wall times. Both engines sample finely enough to catch a peak: MuJoCo every
step, the analytic model every min(1e-5 s, a 500th of the fastest clutch
period), which costs the analytic side some wall time (dense output). Wall
times are of single runs on whatever machine load there is.

With ``--omega-dt`` it measures instead what the timestep rule rests on: for
each stiffness, 1 mm of play, the paper's start and the default motor over
0.4 s from rest (the first impact of each clutch), MuJoCo at the steps
dt = omega_dt / sqrt(k / min(m1, m2)) given (those up to 1e-4 s), sampled every
step, against the analytic model: the relative errors of the peak clutch
force, revolutions and travel, and the accuracy monitor's residual.

With ``--rigid-limit`` (no backlash, the paper's first 0.15 s, every run at
one step of 1e-5 s) it prints each engine's compliant-minus-rigid difference in
revolutions and travel: MuJoCo's compliant clutch against its own rigid
ratchet, the analytic compliant clutch against the analytic rigid one-way
clutch.
"""

from __future__ import annotations

import argparse
import math
import time

from ipir_mujoco import analytic
from ipir_mujoco.analytic import RobotParams
from ipir_mujoco.core.cycles import cycles, travel
from ipir_mujoco.engine import simulate_mujoco
from ipir_mujoco.engine.builders.model import SolverSettings
from ipir_mujoco.engine.modelkinds.timestep import choose_settings, clutch_rate


def figures(run, cruise: bool) -> tuple[float, float, float]:
    """(revolutions, travel [m], peak clutch force [N]: the last whole revolution's at cruise)."""
    peak = cycles(run.series)[-1].peak_clutch_force_n if cruise else run.summary["peak_clutch_force_n"]
    return run.summary["revolutions"], float(travel(run.series)[-1]), peak


def timed(action):
    started = time.perf_counter()
    result = action()
    return result, time.perf_counter() - started


def omega_dt_table(stiffness: list[float], omega_dts: list[float]) -> None:
    """The peak force's error against omega dt (see the module docstring)."""
    print("| k [N/m] | case | omega dt | dt [s] | peak force | revolutions | travel | monitor residual |")
    print("|---|---|---|---|---|---|---|---|")
    for k in stiffness:
        for name, extra in (("paper", {}), ("motor", {"drive": "motor"})):
            params = RobotParams(clutch_stiffness=k, clutch_backlash=1e-3, **extra)
            omega = clutch_rate(params)
            an = analytic.simulate(params, "exact", "unilateral", 0.4, dt_out=min(1e-5, 2 * math.pi / omega / 500))
            for omega_dt in omega_dts:
                h = omega_dt / omega
                if h > 1e-4:
                    continue
                mj = simulate_mujoco(params, "unilateral", "ratchet", 0.4, dt_out=h,
                                     settings=SolverSettings(timestep=h), accuracy="warn")
                errors = [m / a - 1 for a, m in zip(figures(an, False), figures(mj, False))]
                print(f"| {k:.0e} | {name} | {omega_dt:g} | {h:.2g} | {errors[2]:+.1e} | {errors[0]:+.1e} | "
                      f"{errors[1]:+.1e} | {mj.accuracy['residual_ratio']:+.1e} |", flush=True)


def rigid_limit_table(stiffness: list[float]) -> None:
    """Compliant minus rigid, in each engine (see the module docstring)."""
    t_end, settings = 0.15, SolverSettings(timestep=1e-5)
    rigid_mj = simulate_mujoco(RobotParams(), "unilateral", "ratchet", t_end, settings=settings, dt_out=1e-3)
    rigid_an = analytic.simulate(RobotParams(), "exact", "unilateral", t_end)
    print("| k [N/m] | revolutions: mj - mj rigid | an - an rigid | travel [m]: mj - mj rigid | an - an rigid |")
    print("|---|---|---|---|---|")
    for k in stiffness:
        params = RobotParams(clutch_stiffness=k)
        mj = simulate_mujoco(params, "unilateral", "ratchet", t_end, settings=settings, dt_out=1e-3)
        an = analytic.simulate(params, "exact", "unilateral", t_end)
        cells = [f"{run.summary['revolutions'] - rigid.summary['revolutions']:+.4e}"
                 for run, rigid in ((mj, rigid_mj), (an, rigid_an))]
        cells += [f"{travel(run.series)[-1] - travel(rigid.series)[-1]:+.4e}"
                  for run, rigid in ((mj, rigid_mj), (an, rigid_an))]
        print(f"| {k:.0e} | " + " | ".join(cells) + " |", flush=True)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--stiffness", default="1e5,1e6")
    parser.add_argument("--backlash", default="0,1e-3")
    parser.add_argument("--paper-t-end", type=float, default=1.0)
    parser.add_argument("--cruise-t-end", type=float, default=3.0)
    parser.add_argument("--omega-dt", default=None)
    parser.add_argument("--rigid-limit", action="store_true")
    parser.add_argument("--smoke", action="store_true", help="every code path once, in seconds (not a measurement)")
    args = parser.parse_args()
    if args.smoke:
        args.stiffness, args.backlash, args.paper_t_end, args.cruise_t_end = "1e5", "1e-3", 0.02, 0.02
        args.omega_dt = None if args.omega_dt is None else args.omega_dt.split(",")[0]
    if args.rigid_limit:
        rigid_limit_table([float(v) for v in args.stiffness.split(",")])
        return
    if args.omega_dt is not None:
        omega_dt_table([float(v) for v in args.stiffness.split(",")], [float(v) for v in args.omega_dt.split(",")])
        return
    cases = (("paper's start", {}, args.paper_t_end), ("motor cruise", {"drive": "motor"}, args.cruise_t_end))
    print("| k [N/m] | backlash [mm] | case | revolutions an / mj (diff) | travel [m] an / mj (diff) | "
          "peak force [N] an / mj (diff) | mj dt [s] | wall an / mj [s] |")
    print("|---|---|---|---|---|---|---|---|")
    for name, extra, t_end in cases:
        for k in (float(v) for v in args.stiffness.split(",")):
            for backlash in (float(v) for v in args.backlash.split(",")):
                params = RobotParams(clutch_stiffness=k, clutch_backlash=backlash, **extra)
                dt_out = min(1e-5, 2 * math.pi / clutch_rate(params) / 500)
                an, t_an = timed(lambda: analytic.simulate(params, "exact", "unilateral", t_end, dt_out=dt_out))
                h = choose_settings(params, t_end, 1e-4)[0].timestep
                mj, t_mj = timed(lambda: simulate_mujoco(params, "unilateral", "ratchet", t_end, dt_out=h,
                                                         settings=SolverSettings(timestep=h)))
                cruise = "drive" in extra
                cells = [f"{a:.6g} / {m:.6g} ({m / a - 1:+.2e})"
                         for a, m in zip(figures(an, cruise), figures(mj, cruise))]
                print(f"| {k:.0e} | {backlash * 1e3:g} | {name} | " + " | ".join(cells)
                      + f" | {h:.3g} | {t_an:.2f} / {t_mj:.2f} |", flush=True)


if __name__ == "__main__":
    main()
