"""The wheeled MuJoCo model (a robot in a round pipe) against the analytic finite-grip model, random designs.

Run on demand from the repository root (minutes to an hour for 200 designs, by the machine and its load; each
design's wall time is in its record; ``--smoke``: 4 designs of 0.3 s at a given 1e-4 s step, seconds):

    python bench/wheels_agreement.py [--designs 200] [--seed 1] [--workers 2] [--log FILE.jsonl] [--recheck]
                                     [--series DIR] [--wall-budget S] [--skip N] [--only N,M,...] [--timestep S]
                                     [--smoke]

Each design is drawn over the envelope (log-uniform where a range spans decades): m1, m2 0.2-5 kg; r 0.02-0.07 m
(the crank fits the 0.16 m pipe); L / r 1.5-6; J_A 1e-4-1e-2 kg m^2; F_r1, F_r2 0.2-5 N; the drive a constant
torque M 0.05-1 N m or the motor (M_stall 0.1-2 N m, omega_noload 10-60 rad/s); incline -90..90 deg; mu_wall
0.1-1; F_n1, F_n2 5-200 N; phi0 anywhere; 1-2 s. The wheeled geometry is the parameters' defaults.
``analytic-unilateral`` (the one-way equations with finite grip) and ``mujoco-wheels`` (its automatic settings,
the skid check's halvings included) run it. Per design, whatever its class: each module's travel error (MuJoCo
- equations, and relative) and skid error, the lift-off and scrub checks beside MuJoCo's outcome, and the class:

- ``agree``: each module's travel within 1 % of the equations' (or 1 mm) and its skid within 5 % + 2 mm;
- ``lifted``: a wheel left its wall (``wheel_off_s`` > 0) and the lift-off check predicted it;
- ``scrubbed``: a module's rings slid across the pipe (``scrubbed``: their path across it at least
  :data:`ipir_mujoco.core.side_check.SCRUB_FLOOR`) and the scrub check predicted it;
- ``stopped``: refused (bad input for a model), stopped (a stall) or flagged by MuJoCo's accuracy monitor, with
  its reason;
- ``outside``: none of these.

The checks (:func:`ipir_mujoco.core.wheel_checks.check`) are closed forms of the rings under the linkage's loads.
Two sets of loads feed them: the equations' (the analytic run's pin forces, :func:`.kinetostatics.pin_forces`,
its drive torque, its modules' grip use and rolling: a prediction made without MuJoCo, which decides the class)
and the MuJoCo run's own (its summary's ``lift_predicted``, ``scrub_predicted``: the loop's pin force, its torque
and its wheels' states). The end prints the counts per class and each check's confusion matrix (predicted or not
against happened or not), with its false alarms (predicted, did not happen) as a share of the designs where
nothing happened and of the predictions, and its misses; and, for comparison, the lift check the summary gave
before Dec 7 (quasi-static, springs alone: :func:`ipir_mujoco.core.pipe.lift_check`). Last, on each set of loads,
the lift check's false alarms and misses had it predicted a lift below other shares of the preload than its
LIFT_SHARE (FLOORS): how far moving the floor trades one for the other; and read as a resolution, with the
designs whose least press lies in a band about the floor left undecided (BANDS). With ``--series``, the last line:
how far MuJoCo's modules turned about the pipe's axis where a wheel lifted and where none did.

``--log FILE.jsonl`` appends each design's record as it finishes; a rerun with the same log skips the designs it
holds (reprinting their lines), so a stopped benchmark resumes; with ``--recheck`` it runs nothing on MuJoCo and
takes the logged designs' equations' checks again with the check as it is now (a new analytic run each; MuJoCo's
outcome and the run's own checks as logged), deciding their class again. ``--series DIR`` keeps each design's
MuJoCo series there (``design_K.npz``); with it, ``--recheck`` also takes the run's own checks again on the kept
series (:func:`ipir_mujoco.core.wall_summary.run_summary`: MuJoCo's series, which the checks do not change), so a
change to a check is measured on both sets of loads without running MuJoCo. The tables in mjcf/README.md ("The
round pipe") are this script's output.
"""

from __future__ import annotations

import argparse
import json
import math
import sys
import time
from concurrent.futures import ProcessPoolExecutor, as_completed
from pathlib import Path

import numpy as np

from ipir_mujoco import registry
from ipir_mujoco.analytic.dynamics import OneDofDynamics
from ipir_mujoco.analytic.forces import drive_torque
from ipir_mujoco.analytic.kinetostatics import pin_forces
from ipir_mujoco.core.errors import ParameterError, SimulationError
from ipir_mujoco.core.params import RobotParams
from ipir_mujoco.core.pipe import lift_check
from ipir_mujoco.core.wheel_checks import check, ring_loads

TRAVEL_REL, TRAVEL_FLOOR = 0.01, 1e-3  # the acceptance: travel within 1 % (or 1 mm)
SKID_REL, SKID_FLOOR = 0.05, 2e-3  # skid within 5 % + 2 mm
CLASSES = ("agree", "lifted", "scrubbed", "stopped", "outside")
EQUATIONS_KEYS = ("least_press1_n", "least_press2_n", "lift_predicted", "slid1_m", "slid2_m", "stuck1", "stuck2",
                  "scrub_predicted")
RUN_KEYS = ("least_press1_n", "least_press2_n", "lift_predicted", "side_use1", "side_use2", "scrub_predicted")
WHOSE = {"equations": "the equations' loads", "run": "the MuJoCo run's own loads",
         "quasi-static": "springs alone, quasi-static (the check before Dec 7)"}
CHECKS = (("lift", "equations"), ("lift", "run"), ("scrub", "equations"), ("scrub", "run"), ("lift", "quasi-static"))


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


def travel_within(a: float, b: float) -> bool:
    return abs(b - a) <= max(TRAVEL_REL * abs(a), TRAVEL_FLOOR)


def skid_within(a: float, b: float) -> bool:
    return abs(b - a) <= SKID_REL * abs(a) + SKID_FLOOR


def equations_checks(analytic, params: RobotParams) -> dict:
    """The lift-off and scrub checks (:func:`ipir_mujoco.core.wheel_checks.check`) on the analytic run's loads:
    the linkage's forces across the pipe (module 1's at A, module 2's at C: :func:`.kinetostatics.pin_forces`),
    its drive's torque, its modules' grip use, rolling and speeds, its samples' interval."""
    s = analytic.series
    _, on_rod_y, _, pin_y = pin_forces(s, OneDofDynamics(params, analytic.geometry))
    loads = ring_loads(params, -pin_y, -on_rod_y, drive_torque(params, s["omega"]))
    return check(params, loads, (s["grip_use1"], s["grip_use2"]), (s["wheels1"] == 1, s["wheels2"] == 1),
                 float(s["t"][1] - s["t"][0]), (s["v1"], s["v2"]))


def judge(index: int, params: RobotParams, t_end: float, budget: float | None = None,
          timestep: float | None = None, series_dir: str | None = None) -> dict:
    """Run one design in both engines and classify it (module docstring); ``budget`` [s]: the MuJoCo run's
    wall-time budget (a run past it stops with that reason); ``timestep`` [s]: the MuJoCo run's step (default its
    automatic one); ``series_dir``: where MuJoCo's series is kept (``design_K.npz``; None: not kept). A
    JSON-ready record."""
    row = {"design": index, "params": params.as_dict(), "t_end": t_end}
    started = time.perf_counter()
    try:
        analytic = registry.run("analytic-unilateral", params, t_end, dt_out=1e-3)
        options = {} if budget is None else {"wall_budget_s": budget}
        if timestep is not None:
            options["timestep"] = timestep
        wheels = registry.run("mujoco-wheels", params, t_end, dt_out=1e-3, **options)
    except (ParameterError, SimulationError) as exc:
        return {**row, "class": "stopped", "why": " ".join(str(exc).split()), "wall_s": time.perf_counter() - started}
    row["wall_s"] = time.perf_counter() - started
    if series_dir is not None:
        np.savez_compressed(Path(series_dir) / f"design_{index}.npz", **wheels.series)
    a, w = analytic.summary, wheels.summary
    for k in ("x1_final", "x2_final", "slip1_m", "slip2_m", "revolutions"):
        row[k] = (a[k], w[k])
    row.update({k: (a["energy"].get(k, 0.0), w["energy"].get(k, 0.0)) for k in ("motor_work_j", "skid_j")})
    eq = equations_checks(analytic, params)
    row["checks"] = {"equations": {k: eq[k] for k in EQUATIONS_KEYS}, "run": {k: w[k] for k in RUN_KEYS}}
    row["happened"] = {"lift": w["wheel_off_s"] > 0, "scrub": bool(w["scrubbed"])}
    row.update(wheel_off_s=w["wheel_off_s"], across=(w["across1_m"], w["across2_m"]), press=(w["press1_n"], w["press2_n"]),
               grip=(w["grip1_n"], w["grip2_n"]), unpredicted=w["unpredicted"], timestep=wheels.settings["timestep"])
    violations = wheels.accuracy.get("violations") or []
    stops = [s for s in (analytic.stall, wheels.stall) if s]
    row["agrees"] = all(travel_within(a[f"x{k}_final"], w[f"x{k}_final"])
                        and skid_within(a[f"slip{k}_m"], w[f"slip{k}_m"]) for k in (1, 2))
    row["stop"] = stops[0] if stops else None
    if violations:  # the run warned: the accuracy monitor's figure beyond its tolerance, said in the summary
        v = violations[0]
        row["stop"] = row["stop"] or (f"flagged by the accuracy monitor: {v['figure']} {v['value']:.3g} (tolerance "
                                      f"{v['tolerance']:.3g}) at t = {v['t_s']:.3g} s")
    return classify(row)


def classify(row: dict) -> dict:
    """The record with its class (module docstring) from its travel and skid errors (``agrees``), MuJoCo's
    outcome, the equations' checks and its stop (a stall, or the accuracy monitor's flag)."""
    row = {k: v for k, v in row.items() if k not in ("class", "why")}
    if row["agrees"]:
        return {**row, "class": "agree"}
    for name, kind in (("lift", "lifted"), ("scrub", "scrubbed")):
        if row["happened"][name] and row["checks"]["equations"][f"{name}_predicted"]:
            return {**row, "class": kind}
    if row["stop"]:
        return {**row, "class": "stopped", "why": row["stop"]}
    return {**row, "class": "outside"}


def recheck(row: dict, series_dir: str | None = None) -> dict:
    """A logged record with the equations' checks taken again (the check as it is now, on a new analytic run of
    the design) and its class decided again; MuJoCo's outcome as logged, the run's own checks taken again on its
    series kept in ``series_dir`` (as logged where none was kept)."""
    if "checks" not in row:
        return row
    params = RobotParams(**row["params"])
    eq = equations_checks(registry.run("analytic-unilateral", params, row["t_end"], dt_out=1e-3), params)
    run = row["checks"]["run"]
    kept = None if series_dir is None else Path(series_dir) / f"design_{row['design']}.npz"
    if kept is not None and kept.exists():
        from ipir_mujoco.core.wall_summary import run_summary

        with np.load(kept) as data:
            summary = run_summary(params, {key: data[key] for key in data.files})
        run = {k: summary[k] for k in RUN_KEYS}
    row = {**row, "checks": {**row["checks"], "equations": {k: eq[k] for k in EQUATIONS_KEYS}, "run": run}}
    if "agrees" not in row:  # a record from before Dec 7, 10:00: its class says whether it agreed, or its stop
        row["agrees"] = row["class"] == "agree"
        row["stop"] = row.get("why")
    return classify(row)


def error_text(a: float, w: float) -> str:
    """MuJoCo - equations [mm] and relative to the equations' [%]."""
    rel = "" if a == 0 else f" {100 * (w - a) / abs(a):+.2f} %"
    return f"{1e3 * (w - a):+.2f} mm{rel}"


def line(row: dict) -> str:
    p = row["params"]
    drive = f"M {p['M']:.3g}" if p["drive"] == "torque" else f"motor {p['M_stall']:.3g} N m/{p['omega_noload']:.3g} rad/s"
    head = (f"#{row['design']:3d} {row['class']:8s} m {p['m1']:.2f}/{p['m2']:.2f} r {p['r']:.3f} L/r "
            f"{p['L'] / p['r']:.2f} inc {p['incline']:+6.1f} mu {p['mu_wall']:.2f} F_n {p['F_n1']:.0f}/{p['F_n2']:.0f} "
            f"{drive} {row['t_end']:.2f} s")
    if "x1_final" not in row:
        return head + f" | {row['why']} | {row['wall_s']:.0f} s"
    errors = " ".join(f"x{k} {row[f'x{k}_final'][0]:+.4f}/{row[f'x{k}_final'][1]:+.4f} m ({error_text(*row[f'x{k}_final'])})"
                      for k in (1, 2))
    skids = " ".join(f"skid{k} {1e3 * row[f'slip{k}_m'][0]:.1f}/{1e3 * row[f'slip{k}_m'][1]:.1f} mm"
                     for k in (1, 2))
    eq, run = row["checks"]["equations"], row["checks"]["run"]
    checks = (f"lift: eq {eq['least_press1_n']:+.2f}/{eq['least_press2_n']:+.2f} N run "
              f"{run['least_press1_n']:+.2f}/{run['least_press2_n']:+.2f} N off {row['wheel_off_s']:.3f} s; "
              f"scrub: eq slid {1e3 * eq['slid1_m']:.2f}/{1e3 * eq['slid2_m']:.2f} mm stuck "
              f"{'/'.join('yes' if eq.get(f'stuck{k}') else 'no' for k in (1, 2))} run "
              f"{'yes' if run['scrub_predicted'] else 'no'} across {1e3 * row['across'][0]:.2f}/"
              f"{1e3 * row['across'][1]:.2f} mm")
    grip = "" if row["grip"][0] is None else (f" | grip {row['grip'][0]:.1f}/{row['grip'][1]:.1f} N against "
                                              f"{p['mu_wall'] * p['F_n1']:.1f}/{p['mu_wall'] * p['F_n2']:.1f} N")
    return (head + f" | {errors} | {skids} | rev {row['revolutions'][0]:.4f}/{row['revolutions'][1]:.4f} | "
            f"drive work {row['motor_work_j'][0]:.3f}/{row['motor_work_j'][1]:.3f} J skid work "
            f"{row['skid_j'][0]:.3f}/{row['skid_j'][1]:.3f} J | {checks}{grip} | step {row['timestep']:.3g} s "
            f"{row['wall_s']:.0f} s" + (f" | {row['why']}" if "why" in row else ""))


def predicted(row: dict, name: str, source: str) -> bool:
    """Whether the check ``name`` ('lift', 'scrub') on ``source``'s loads predicted it for the design: 'equations',
    'run' (the record's), or 'quasi-static' (the lift check before Dec 7, on springs alone and the drive's largest
    torque: :func:`ipir_mujoco.core.pipe.lift_check`, from the design's parameters)."""
    if source == "quasi-static":
        return bool(lift_check(RobotParams(**row["params"]))["lift_predicted"])
    return bool(row["checks"][source][f"{name}_predicted"])


def confusion(rows: list[dict], name: str, source: str) -> str:
    """The check's confusion matrix over the designs that ran: predicted or not against happened or not."""
    cells = {(p, h): [] for p in (True, False) for h in (True, False)}
    for row in rows:
        if "checks" in row:
            cells[(predicted(row, name, source), bool(row["happened"][name]))].append(row["design"])
    tp, fa, miss, tn = (len(cells[k]) for k in ((True, True), (True, False), (False, True), (False, False)))
    share = (lambda a, b: f"{a}/{b} = {100 * a / b:.0f} %" if b else f"{a}/0")
    return (f"{name} check on {WHOSE[source]}: predicted and happened {tp}, predicted but not (false alarms) "
            f"{fa}, happened but not predicted (misses) {miss}, neither {tn}; false alarms {share(fa, fa + tn)} of the "
            f"designs where it did not happen, {share(fa, fa + tp)} of the predictions; misses "
            f"{cells[(False, True)]}; false alarms {cells[(True, False)]}")


FLOORS = (-0.5, 0.0, 0.05, 0.1, 0.2, 0.3, 0.4, 0.5)  # least presses over the preload the trade-off is printed at
BANDS = ((-0.5, 0.3), (-0.5, 0.4))  # least presses over the preload left undecided (mjcf/README.md, "Four seeds")
TURNED_DEG = (2.0, 10.0)  # a module's turn about the pipe's axis counted as begun, and as large


def least_share(row: dict, source: str) -> float:
    """The lift check's least press on ``source``'s loads over its leg's preload F_ni / (2 n), the lower of the
    two modules' (the check predicts a lift below LIFT_SHARE, 0.05)."""
    p, checks = row["params"], row["checks"][source]
    return min(checks[f"least_press{k}_n"] / (p[f"F_n{k}"] / (2 * p["wheel_legs"])) for k in (1, 2))


def shares_lifted(rows: list[dict], source: str) -> list[tuple[float, bool]]:
    """Per design that ran: its :func:`least_share` on ``source``'s loads and whether a wheel lifted in MuJoCo."""
    return [(least_share(r, source), bool(r["happened"]["lift"])) for r in rows if "checks" in r]


def trade_off(rows: list[dict], source: str) -> str:
    """The lift check's false alarms and misses had it predicted a lift below each of FLOORS of the preload
    instead of LIFT_SHARE: how far a floor trades one for the other (designs that ran)."""
    shares = shares_lifted(rows, source)
    quiet = sum(not lifted for _, lifted in shares)
    cells = []
    for floor in FLOORS:
        alarms = sum(share < floor and not lifted for share, lifted in shares)
        misses = sum(share >= floor and lifted for share, lifted in shares)
        cells.append(f"{floor:g}: {alarms} ({100 * alarms / max(quiet, 1):.0f} %) / {misses}")
    return f"lift check on {WHOSE[source]}, false alarms / misses with a lift below each share of the preload: " + \
        ", ".join(cells)


def undecided(rows: list[dict], source: str) -> str:
    """The lift check read as a resolution: a lift predicted below the lower end of each of BANDS, none from its
    upper end, the designs between undecided; its false alarms and misses among the rest."""
    shares = shares_lifted(rows, source)
    cells = []
    for lo, hi in BANDS:
        alarms = sum(share < lo and not lifted for share, lifted in shares)
        misses = sum(share >= hi and lifted for share, lifted in shares)
        cells.append(f"{lo:g} to {hi:g}: {sum(lo <= share < hi for share, _ in shares)} undecided, {alarms} false "
                     f"alarms, {misses} misses")
    return f"lift check on {WHOSE[source]} with an undecided band: " + "; ".join(cells)


def turns(rows: list[dict], series_dir: str) -> str:
    """How far MuJoCo's modules turned about the pipe's axis (the kept series' roll1, roll2) in the designs that
    lifted a wheel and in those that did not, and whether the turn began (TURNED_DEG[0]) before or after the
    first wheel left its wall (the series' wheels_off)."""
    begun, large = (math.radians(a) for a in TURNED_DEG)
    counts = {True: [0, 0], False: [0, 0]}  # lifted: [designs, turned by more than TURNED_DEG[1]]
    before, delays = 0, []
    for row in rows:
        path = Path(series_dir) / f"design_{row['design']}.npz"
        if "checks" not in row or not path.is_file():
            continue
        with np.load(path) as kept:
            t, off = kept["t"], kept["wheels_off"] > 0
            turn = np.maximum(np.abs(kept["roll1"]), np.abs(kept["roll2"]))
        lifted = bool(row["happened"]["lift"])
        counts[lifted][0] += 1
        counts[lifted][1] += bool(turn.max() > large)
        if lifted and (turn > begun).any():
            delay = float(t[np.argmax(turn > begun)] - t[np.argmax(off)])
            before += delay < 0
            delays.append(delay)
    after = f"{np.median(delays):.3g}" if delays else "-"
    return (f"modules turned about the pipe by more than {TURNED_DEG[1]:g} deg: {counts[True][1]} of {counts[True][0]} "
            f"designs that lifted a wheel, {counts[False][1]} of {counts[False][0]} that did not; of the "
            f"{len(delays)} lifted that turned by {TURNED_DEG[0]:g} deg, {len(delays) - before} after their first "
            f"wheel left its wall (median {after} s after), {before} before")


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--designs", type=int, default=100)
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--log", default=None, metavar="FILE.jsonl",
                        help="append each design's record; designs already in it are not run again (resume)")
    parser.add_argument("--skip", type=int, default=0, help="draw and skip the first N designs")
    parser.add_argument("--wall-budget", type=float, default=None,
                        help="each MuJoCo run's wall-time budget [s]: a run past it is stopped with that reason")
    parser.add_argument("--only", default=None, metavar="N,M,...",
                        help="run only these designs (their numbers as printed; with --skip, these and those after it)")
    parser.add_argument("--timestep", type=float, default=None, help="the MuJoCo runs' step [s] (default: automatic)")
    parser.add_argument("--recheck", action="store_true",
                        help="with --log: the logged designs' equations' checks taken again with the check as it is "
                             "now (a new analytic run each; MuJoCo's outcome as logged; the run's own checks as "
                             "logged, or taken again on the series kept in --series)")
    parser.add_argument("--series", default=None, metavar="DIR",
                        help="keep each design's MuJoCo series here; with --recheck, the run's own checks taken again "
                             "on them")
    parser.add_argument("--smoke", action="store_true", help="4 designs of 0.3 s at the 1e-4 s step unless "
                        "--timestep gives one (no skid check's reruns): the script runs")
    args = parser.parse_args(argv)
    only = None if args.only is None else {int(k) for k in args.only.split(",")}
    rng = np.random.default_rng(args.seed)
    count = 4 if args.smoke else args.designs
    if args.smoke and args.timestep is None:  # a given step is not checked (the skid check reruns up to 15x)
        args.timestep = 1e-4
    if args.series:
        Path(args.series).mkdir(parents=True, exist_ok=True)
    done: dict[int, dict] = {}
    if args.log and Path(args.log).exists():
        for text in Path(args.log).read_text(encoding="utf-8").splitlines():
            if text.strip():
                record = json.loads(text)
                done[record["design"]] = record
    jobs, rows = [], []
    for k in range(count):
        params, t_end = design(rng)
        if (k >= args.skip and only is None) or (only is not None and (k in only or (args.skip and k >= args.skip))):
            if k in done:
                rows.append(recheck(done[k], args.series) if args.recheck else done[k])
                print(line(rows[-1]), flush=True)
            elif not args.recheck:
                jobs.append((k, params, 0.3 if args.smoke else t_end, args.wall_budget, args.timestep, args.series))
    with ProcessPoolExecutor(max_workers=max(1, args.workers)) as pool:
        futures = [pool.submit(judge, *job) for job in jobs]
        for finished, future in enumerate(as_completed(futures), start=1):
            row = future.result()
            rows.append(row)
            print(line(row), flush=True)
            if args.log:
                with open(args.log, "a", encoding="utf-8") as handle:
                    handle.write(json.dumps(row) + "\n")
            print(f"[{finished}/{len(jobs)}]", file=sys.stderr, flush=True)
    rows.sort(key=lambda r: r["design"])
    print(" ".join(f"{c}: {sum(r['class'] == c for r in rows)}" for c in CLASSES))
    for name, source in CHECKS:
        print(confusion(rows, name, source))
    for source in ("equations", "run"):
        print(trade_off(rows, source))
        print(undecided(rows, source))
    if args.series:
        print(turns(rows, args.series))
    unsaid = [r["design"] for r in rows if r.get("unpredicted")]
    print(f"runs whose summary says 'unpredicted': {unsaid}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
