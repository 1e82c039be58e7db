"""MuJoCo against the equations along random routes: every route's time and motor work in both engines, its class,
and the lift and scrub checks' record against what MuJoCo did.

Run on demand from the repository root (about a minute of wall time per route and worker on 2 busy cores):

    python bench/route_agreement.py [--routes N] [--seed S] [--first K] [--workers N] [--log FILE.jsonl]
                                    [--series DIR] [--recheck] [--set NAME=VALUE]... [--wall-budget SECONDS]
                                    [--smoke]

Route k of seed S (its own random stream, so any route can be rerun alone: ``--first k --routes 1``): a 0.3 m
first straight rising at an incline drawn from -90..90 deg, or exactly 90, -90 or 0 (a quarter each), then 1-3
bends, each of R/D 1.5-50 (log-uniform, the default pipe's D), in a plane 0-360 deg, turning 15-180 deg either way
but at most ARC of arc (so that a gentle bend stays a few seconds long; a bend in a tilted plane makes later
grades, a vertical leg where it turns the pipe up or down), with a straight of 0.05-0.3 m after it three times in
five; a 0.2 m exit. The robot: the motor, mu_wall 0.2-0.8, F_n1 and F_n2 20-100 N, M_stall 0.5-2 N m, every other
parameter at its default (``--set`` changes them for every route).

Each route runs in both engines (:func:`ipir_mujoco.studies.comparison.route_compare.compare_route`, capped at 10 s plus 10 s
per metre): the equations (``analytic-unilateral``, the wheels' scrub in its closed form) and the wheeled MuJoCo
model at its route step with the skid check. One line per route as it finishes, whatever its class: both engines'
time (the robot's centre reaching the route's end) and the motor's work to then net of the kinetic energy the robot
has then, MuJoCo's differences in % (the work's over the energy put through the robot:
:func:`ipir_mujoco.studies.comparison.route_compare.work_difference`), the equations' scrub work [J], the closed
forms' predictions (lift: ``lift_predicted``; scrub: the equations' wheels beyond their friction in a bend) beside
what MuJoCo did (a wheel off its wall for how long; how far its wheels slid sideways), and the class (``agree``:
both within 2 %; ``lift``, ``scrub``: predicted and happened; ``stopped``: an engine did not get through, with its
reason; ``over budget``: a run took more than ``--wall-budget`` of wall time; ``miss``: none of these). Then the
counts per class, the checks' confusion matrices (false alarms and
misses), the largest differences among the routes that agree, and the wall time per route.

``--log FILE.jsonl`` appends each finished route's record (its spec, both engines' records) and, on a later run
with the same file, skips the routes it holds (printing their lines first): a long run can be stopped and resumed.
``--series DIR`` keeps each route's MuJoCo series there (``route_K.npz``); with it and ``--log``, ``--recheck`` runs
nothing and takes the logged routes' lift-off and scrub checks again on their kept series with the checks as they are
now (:func:`ipir_mujoco.core.wall_summary.run_summary`; the series are MuJoCo's, which the checks do not change),
deciding their classes again. ``--smoke``: one short route, one worker (a check that the script runs).
"""

from __future__ import annotations

import argparse
import functools
import json
import math
import sys
import time
from pathlib import Path

import numpy as np

from ipir_mujoco.core.params import RobotParams, load_params, parse_overrides
from ipir_mujoco.core.route import route_from_tables
from ipir_mujoco.studies.pool import map_unordered
from ipir_mujoco.studies.comparison.route_compare import AGREE, compare_route, confusion, judge, percent

D = RobotParams().pipe_diameter  # m: the default pipe, to name the bends' R / D
ARC = 0.6  # m: a bend's longest arc
T_CAP = (10.0, 10.0)  # s, s/m: each run's cap, a constant and per metre of route
WALL_BUDGET_S = 1200.0  # s: each run's wall time at most (a MuJoCo run whose wheels skid in tight bends reruns at
# halved steps down to 6e-6 s: up to 15 times its first run's cost; its skid check keeps the step it reached)


def spec(seed: int, k: int, overrides: dict) -> dict:
    """Route k's segments and parameters (module docstring), JSON-ready."""
    rng = np.random.default_rng([seed, k])
    incline = float(rng.choice([rng.uniform(-90.0, 90.0), 90.0, -90.0, 0.0]))
    tables = [dict(kind="straight", length=0.35, incline=incline)]
    for _ in range(int(rng.integers(1, 4))):
        ratio = float(math.exp(rng.uniform(math.log(1.5), math.log(50.0))))
        most = min(180.0, math.degrees(ARC / (ratio * D)))
        angle = float(rng.uniform(min(15.0, most), most)) * float(rng.choice([-1.0, 1.0]))
        tables.append(dict(kind="bend", radius=ratio * D, angle=angle, plane=float(rng.uniform(0.0, 360.0)) - 180.0))
        if rng.random() < 0.6:
            tables.append(dict(kind="straight", length=float(rng.uniform(0.05, 0.3))))
    tables.append(dict(kind="straight", length=0.2))
    params = {"drive": "motor", "mu_wall": round(float(rng.uniform(0.2, 0.8)), 3),
              "F_n1": round(float(rng.uniform(20.0, 100.0)), 1), "F_n2": round(float(rng.uniform(20.0, 100.0)), 1),
              "M_stall": round(float(rng.uniform(0.5, 2.0)), 3), **overrides}
    return {"k": k, "segments": tables, "params": params}


def run_route(item: dict, wall_budget_s: float, series_dir: str | None = None) -> dict:
    """One route in a worker: its spec and :func:`ipir_mujoco.studies.comparison.route_compare.compare_route`'s
    record, and the wall time [s]; MuJoCo's series kept in ``series_dir`` (None: not kept)."""
    started = time.perf_counter()
    route = route_from_tables(item["segments"], f"route {item['k']}")
    params = load_params(None, item["params"])
    keep = None if series_dir is None else (
        lambda run: np.savez_compressed(Path(series_dir) / f"route_{item['k']}.npz", **run.series))
    record = compare_route(params, route, T_CAP[0] + T_CAP[1] * route.length, wall_budget_s=wall_budget_s,
                           keep=keep)
    record.update(spec=item, wall_s=time.perf_counter() - started, length_m=route.length,
                  bends=[(round(p.radius / D, 2), round(math.degrees(p.angle), 1), round(math.degrees(p.plane)))
                         for p in route.bends])
    return record


def line(r: dict) -> str:
    """A route's line (module docstring)."""
    e, m, p = r["equations"], r["mujoco"], r["spec"]["params"]
    bends = " ".join(f"{rd:g}/{a:+.0f}/{pl:+.0f}" for rd, a, pl in r["bends"])

    def fig(x, unit, digits=3):
        return "-" if x is None else f"{x:.{digits}f} {unit}"

    off, slid = m.get("route_wheel_off_s"), m.get("slid_m")
    seen = (f"off {off:.3f} s" if off else "no wheel off") + (f", slid {1e3 * slid:.1f} mm" if slid is not None
                                                                else "")
    said = ", ".join(k for k in ("lift", "scrub") if r[k]["predicted"]) or "nothing"
    if m.get("least_press1_n") is not None:  # the lift-off check's least-pressed legs, modules 1 and 2
        said += f" (least press {m['least_press1_n']:.2f} / {m['least_press2_n']:.2f} N)"
    text = (f"{r['spec']['k']:4d} {r['outcome']:19s} incline {r['spec']['segments'][0]['incline']:+6.1f}, bends "
            f"(R/D/deg/plane) {bends}; {r['length_m']:.2f} m; mu {p['mu_wall']:.3f} F_n {p['F_n1']:.0f}/"
            f"{p['F_n2']:.0f} M_stall {p['M_stall']:.2f}: time {fig(e.get('time_s'), 's')} / "
            f"{fig(m.get('time_s'), 's')} ({percent(r['time_diff'])}), net work {fig(e.get('net_work_j'), 'J')} / "
            f"{fig(m.get('net_work_j'), 'J')} ({percent(r['work_diff'])}), scrub {fig(e.get('scrub_j'), 'J')}; "
            f"predicted {said}; MuJoCo {seen}; {r['mujoco'].get('wall_s', 0):.0f}+{r['equations'].get('wall_s', 0):.0f}"
            " s wall")
    if r["outcome"].startswith(("stopped", "over")) or r["outcome"] == "miss":
        for name, rec in (("equations", e), ("MuJoCo", m)):
            if not rec.get("route_done"):
                text += f"\n       {name}: {rec.get('route_stop')}"
    return text


def recheck(record: dict, series_dir: str) -> dict:
    """A logged route's record with MuJoCo's lift-off and scrub checks taken again on its kept series (module
    docstring), its class decided again; as logged where no series was kept (a run that failed)."""
    from ipir_mujoco.core.wall_summary import run_summary
    from ipir_mujoco.engine.kinds.wheels.route_watch import check_route, pipe_fit

    path = Path(series_dir) / f"route_{record['spec']['k']}.npz"
    if not path.is_file():
        return record
    with np.load(path) as kept:
        series = {key: kept[key] for key in kept.files}
    route = route_from_tables(record["spec"]["segments"], f"route {record['spec']['k']}")
    params = check_route(route, "wheels", load_params(None, record["spec"]["params"]), False)
    checks = run_summary(params, series, pipe_fit(route, params), straight=False)
    mujoco = {**record["mujoco"], **{key: checks[key] for key in ("lift_predicted", "least_press1_n",
                                                                  "least_press2_n", "scrub_predicted")}}
    return {**record, **judge(record["equations"], mujoco)}


def report(records: list[dict]) -> None:
    """The closing lines (module docstring)."""
    counts: dict[str, int] = {}
    for r in records:
        counts[r["outcome"]] = counts.get(r["outcome"], 0) + 1
    print(f"{len(records)} routes: " + ", ".join(f"{n} {c}" for c, n in sorted(counts.items())))
    for key in ("lift", "scrub"):
        c = confusion(records, key)
        print(f"{key} check against MuJoCo: " + ", ".join(f"{n} {what}" for what, n in c.items()))
    agree = [r for r in records if r["outcome"] == "agree"]
    if agree:
        for key in ("time_diff", "work_diff"):
            worst = max(agree, key=lambda r: abs(r[key]))
            print(f"largest {key.split('_')[0]} difference among the {len(agree)} that agree: "
                  f"{percent(worst[key])} (route {worst['spec']['k']})")
    print(f"misses (beyond {100 * AGREE:g} % with no prediction that came true): {counts.get('miss', 0)}")
    walls = [r["wall_s"] for r in records]
    if walls:
        print(f"wall time per route: median {np.median(walls):.0f} s, most {max(walls):.0f} s, "
              f"{sum(walls) / 60:.0f} min in all")


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--routes", type=int, default=100)
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--first", type=int, default=0, help="the first route's number")
    parser.add_argument("--workers", type=int, default=1)
    parser.add_argument("--log", default=None, metavar="FILE.jsonl", help="append records here; skip those it holds")
    parser.add_argument("--set", action="append", default=[], metavar="NAME=VALUE")
    parser.add_argument("--wall-budget", type=float, default=WALL_BUDGET_S, metavar="SECONDS",
                        help="each run's wall-time budget (default %(default)g s)")
    parser.add_argument("--series", default=None, metavar="DIR", help="keep each route's MuJoCo series here")
    parser.add_argument("--recheck", action="store_true",
                        help="with --log and --series: the logged routes' checks taken again on their kept series")
    parser.add_argument("--smoke", action="store_true", help="one short route (a check that the script runs)")
    args = parser.parse_args(argv)
    overrides = parse_overrides(args.set)
    load_params(None, overrides)  # bad input: one line, before any run
    if args.recheck and not (args.log and args.series):
        parser.error("--recheck takes the routes of --log and their series in --series: give both")
    if args.series:
        Path(args.series).mkdir(parents=True, exist_ok=True)
    if args.smoke:  # one short level route, one gentle bend
        items = [spec(args.seed, 0, overrides)]
        items[0]["segments"] = [dict(kind="straight", length=0.35, incline=0.0),
                                dict(kind="bend", radius=30 * D, angle=4.0, plane=0.0),
                                dict(kind="straight", length=0.05)]
        args.workers = 1
    else:
        items = [spec(args.seed, k, overrides) for k in range(args.first, args.first + args.routes)]
    records: list[dict] = []
    held = {}
    if args.log and Path(args.log).is_file():
        for text in Path(args.log).read_text().splitlines():
            r = json.loads(text)
            if r["spec"] in items:
                held[r["spec"]["k"]] = r
    for k in sorted(held):
        records.append(recheck(held[k], args.series) if args.recheck else held[k])
        print(line(records[-1]), flush=True)
    todo = [] if args.recheck else [item for item in items if item["k"] not in held]
    print(f"{len(held)} routes from {args.log}, {len(todo)} to run on {args.workers} workers", file=sys.stderr,
          flush=True)

    def done(item, record) -> None:
        records.append(record)
        print(line(record), flush=True)
        if args.log:
            with open(args.log, "a") as handle:
                handle.write(json.dumps(record) + "\n")

    map_unordered(functools.partial(run_route, wall_budget_s=args.wall_budget, series_dir=args.series), todo,
                  args.workers, done)
    report(records)
    return 0


if __name__ == "__main__":
    sys.exit(main())
