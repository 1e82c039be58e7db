"""The wheeled MuJoCo model (a robot in a round pipe) against the analytic finite-grip model, random designs.

Run on demand from the repository root (about 30-60 min on 2 busy cores; ``--smoke``: 4 designs of 0.3 s at a given 1e-4 s step, seconds):

    python bench/wheels_agreement.py [--designs 100] [--seed 1] [--workers 2] [--wall-budget S] [--skip N]
                                     [--only N,M,...] [--timestep S] [--smoke]

Each design is drawn over the envelope (log-uniform where a range spans decades): m1, m2 0.2-5 kg; r 0.02-0.07 m
(the crank fits the 0.16 m pipe); L / r 1.5-6; J_A 1e-4-1e-2 kg m^2; F_r1, F_r2 0.2-5 N; the drive a constant
torque M 0.05-1 N m or the motor (M_stall 0.1-2 N m, omega_noload 10-60 rad/s); incline -90..90 deg; mu_wall
0.1-1; F_n1, F_n2 5-200 N; phi0 anywhere; 1-2 s. ``analytic-unilateral`` (the one-way equations with finite grip)
and ``mujoco-wheels`` (its automatic settings) run it, and the design lands in one class:

- ``agree``: each module's travel within 1 % of the analytic model's (at least 1 cm) and its skid within 5 % +
  2 mm;
- ``lifted``: a wheel left its wall (``wheel_off_s`` > 0) and the closed-form lift-off check predicted it
  (``lift_predicted``): the constant-press idealization does not hold there, and the run says so;
- ``stopped``: refused (bad input for a model), stopped (a stall) or flagged by MuJoCo's accuracy monitor (its
  figure beyond tolerance, in the run's summary), with its reason;
- ``scrubbed``: a module's rings slid across the pipe (their path across it, from the run's pose columns, at
  least SCRUB_FLOOR: the run summary's ``across1_m``, ``across2_m``, :func:`ipir_mujoco.core.pipe.across_paths`)
  and the closed-form sideways-grip check predicted it
  (:func:`ipir_mujoco.core.pipe.side_grip_check` on the analytic run's linkage forces: a ring's load across the
  pipe beyond its wheels' sideways friction). The analytic model's rails carry those loads without moving; the
  wheels scrub instead (energy lost, and grip along the pipe lost while they slide), which it does not know;
- ``outside``: none of these (each printed with its figures).

Prints one line per design and the counts per class. The table in mjcf/README.md ("The round pipe") is this
script's output.
"""

from __future__ import annotations

import argparse
import math
import sys
import time
from concurrent.futures import ProcessPoolExecutor

import numpy as np

from ipir_mujoco import registry
from ipir_mujoco.analytic.dynamics import OneDofDynamics
from ipir_mujoco.analytic.forces import drive_torque
from ipir_mujoco.analytic.kinetostatics import pin_forces
from ipir_mujoco.core.errors import ParameterError, SimulationError
from ipir_mujoco.core.params import RobotParams
from ipir_mujoco.core.pipe import SCRUB_FLOOR, side_grip_check

TRAVEL_REL, TRAVEL_FLOOR = 0.01, 0.01  # the acceptance: travel within 1 % (at least 1 cm)
SKID_REL, SKID_FLOOR = 0.05, 2e-3  # skid within 5 % + 2 mm


def log_uniform(rng, lo: float, hi: float) -> float:
    return float(math.exp(rng.uniform(math.log(lo), math.log(hi))))


def design(rng) -> tuple[RobotParams, float]:
    """One random design over the envelope (module docstring) and its run length [s]."""
    r = rng.uniform(0.02, 0.07)
    values = dict(m1=log_uniform(rng, 0.2, 5.0), m2=log_uniform(rng, 0.2, 5.0), r=r, L=r * rng.uniform(1.5, 6.0),
                  J_A=log_uniform(rng, 1e-4, 1e-2), F_r1=log_uniform(rng, 0.2, 5.0), F_r2=log_uniform(rng, 0.2, 5.0),
                  incline=rng.uniform(-90.0, 90.0), mu_wall=rng.uniform(0.1, 1.0), F_n1=log_uniform(rng, 5.0, 200.0),
                  F_n2=log_uniform(rng, 5.0, 200.0), phi0=rng.uniform(0.0, 2 * math.pi))
    if rng.random() < 0.5:
        values.update(drive="torque", M=log_uniform(rng, 0.05, 1.0))
    else:
        values.update(drive="motor", M_stall=log_uniform(rng, 0.1, 2.0), omega_noload=rng.uniform(10.0, 60.0))
    return RobotParams(**values), float(rng.uniform(1.0, 2.0))


def within(a: float, b: float, rel: float, floor: float) -> bool:
    return abs(b - a) <= max(rel * abs(a), floor) if floor == TRAVEL_FLOOR else abs(b - a) <= rel * abs(a) + floor


def side_check(analytic, params: RobotParams) -> dict:
    """The closed-form sideways-grip check (:func:`ipir_mujoco.core.pipe.side_grip_check`) on the analytic run's
    linkage forces across the pipe (module 1's at A, module 2's at C: :func:`.kinetostatics.pin_forces`), its
    drive's torque and its modules' grip use."""
    series = analytic.series
    _, on_rod_y, _, pin_y = pin_forces(series, OneDofDynamics(params, analytic.geometry))
    return side_grip_check(params, pin_y, on_rod_y, drive_torque(params, series["omega"]),
                           (series["grip_use1"], series["grip_use2"]))


def judge(index: int, params: RobotParams, t_end: float, budget: float | None = None,
          timestep: float | None = None) -> dict:
    """Run one design in both engines and classify it (module docstring); ``budget`` [s]: the MuJoCo run's
    wall-time budget (a run past it stops with that reason); ``timestep`` [s]: the MuJoCo run's step (default its
    automatic one)."""
    row = {"design": index, "params": params, "t_end": t_end}
    try:
        analytic = registry.run("analytic-unilateral", params, t_end, dt_out=1e-3)
        started = time.perf_counter()
        options = {} if budget is None else {"wall_budget_s": budget}
        if timestep is not None:
            options["timestep"] = timestep
        wheels = registry.run("mujoco-wheels", params, t_end, dt_out=1e-3, **options)
        row["wall_s"] = time.perf_counter() - started
    except (ParameterError, SimulationError) as exc:
        return {**row, "class": "stopped", "why": " ".join(str(exc).split())}
    a, w = analytic.summary, wheels.summary
    row.update({k: (a[k], w[k]) for k in ("x1_final", "x2_final", "slip1_m", "slip2_m", "revolutions")})
    row.update({k: (a["energy"].get(k, 0.0), w["energy"].get(k, 0.0)) for k in ("motor_work_j", "skid_j")})
    row.update(wheel_off_s=w["wheel_off_s"], lift_predicted=w["lift_predicted"], press=(w["press1_n"], w["press2_n"]))
    side = side_check(analytic, params)
    row.update(side_use=(side["side_use1"], side["side_use2"]), scrub_predicted=side["scrub_predicted"],
               across=(w["across1_m"], w["across2_m"]))
    stops = [s for s in (analytic.stall, wheels.stall) if s]
    agree = all(within(a[f"x{k}_final"], w[f"x{k}_final"], TRAVEL_REL, TRAVEL_FLOOR)
                and abs(w[f"slip{k}_m"] - a[f"slip{k}_m"]) <= SKID_REL * a[f"slip{k}_m"] + SKID_FLOOR for k in (1, 2))
    if agree:
        return {**row, "class": "agree"}
    if w["wheel_off_s"] > 0 and w["lift_predicted"]:
        return {**row, "class": "lifted"}
    if stops:
        return {**row, "class": "stopped", "why": stops[0]}
    violations = wheels.accuracy.get("violations") or []
    if violations:  # the run warned: the accuracy monitor's figure beyond its tolerance, said in the summary
        v = violations[0]
        return {**row, "class": "stopped", "why": f"flagged by the accuracy monitor: {v['figure']} {v['value']:.3g} "
                                                  f"(tolerance {v['tolerance']:.3g}) at t = {v['t_s']:.3g} s"}
    if row["scrub_predicted"] and max(row["across"]) >= SCRUB_FLOOR:
        return {**row, "class": "scrubbed"}
    return {**row, "class": "outside"}


def line(row: dict) -> str:
    p = row["params"]
    drive = f"M {p.M:.3g}" if p.drive == "torque" else f"motor {p.M_stall:.3g} N m/{p.omega_noload:.3g} rad/s"
    head = (f"#{row['design']:3d} {row['class']:8s} m {p.m1:.2f}/{p.m2:.2f} r {p.r:.3f} L/r {p.L / p.r:.2f} "
            f"inc {p.incline:+6.1f} mu {p.mu_wall:.2f} F_n {p.F_n1:.0f}/{p.F_n2:.0f} {drive} {row['t_end']:.2f} s")
    if row["class"] == "stopped" and "x1_final" not in row:
        return head + f" | {row['why']}"
    figures = " ".join(f"{k} {a:+.4f}/{w:+.4f}" for k, (a, w) in
                       ((k, row[k]) for k in ("revolutions", "x1_final", "x2_final", "slip1_m", "slip2_m")))
    figures += " | drive work {:.3f}/{:.3f} J skid work {:.3f}/{:.3f} J".format(*row["motor_work_j"], *row["skid_j"])
    return head + (f" | {figures} | off {row['wheel_off_s']:.3f} s lift predicted {row['lift_predicted']} "
                   f"press {row['press'][0]:.1f}/{row['press'][1]:.1f} N | side grip use {row['side_use'][0]:.2f}/"
                   f"{row['side_use'][1]:.2f} across {1e3 * row['across'][0]:.2f}/{1e3 * row['across'][1]:.2f} mm | "
                   f"{row['wall_s']:.0f} s"
                   + (f" | {row['why']}" if "why" in row else ""))


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--designs", type=int, default=100)
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--skip", type=int, default=0, help="draw and skip the first N designs (resume a run)")
    parser.add_argument("--wall-budget", type=float, default=None,
                        help="each MuJoCo run's wall-time budget [s]: a run past it is stopped with that reason")
    parser.add_argument("--only", default=None, metavar="N,M,...",
                        help="run only these designs (their numbers as printed; with --skip, these and those after it)")
    parser.add_argument("--timestep", type=float, default=None, help="the MuJoCo runs' step [s] (default: automatic)")
    parser.add_argument("--smoke", action="store_true", help="4 designs of 0.3 s at the 1e-4 s step unless "
                        "--timestep gives one (no skid check's reruns): the script runs")
    args = parser.parse_args(argv)
    only = None if args.only is None else {int(k) for k in args.only.split(",")}
    rng = np.random.default_rng(args.seed)
    count = 4 if args.smoke else args.designs
    if args.smoke and args.timestep is None:  # a given step is not checked (the skid check reruns up to 15x)
        args.timestep = 1e-4
    jobs = []
    for k in range(count):
        params, t_end = design(rng)
        if (k >= args.skip and only is None) or (only is not None and (k in only or (args.skip and k >= args.skip))):
            jobs.append((k, params, 0.3 if args.smoke else t_end, args.wall_budget, args.timestep))
    counts = {"agree": 0, "lifted": 0, "stopped": 0, "scrubbed": 0, "outside": 0}
    with ProcessPoolExecutor(max_workers=max(1, args.workers)) as pool:
        futures = [pool.submit(judge, *job) for job in jobs]
        for done, future in enumerate(futures, start=1):
            row = future.result()
            counts[row["class"]] += 1
            print(line(row), flush=True)
            print(f"[{done}/{len(jobs)}] {counts}", file=sys.stderr, flush=True)
    print(" ".join(f"{k}: {v}" for k, v in counts.items()))
    return 0


if __name__ == "__main__":
    sys.exit(main())
