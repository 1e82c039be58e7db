"""The bend penalty of the wheeled MuJoCo model against R/D: time through a bend over its straightened twin's.

Run on demand from the repository root (tens of minutes on 2 busy cores; ``--workers 2`` halves it):

    python bench/wheels_bend_sweep.py [--ratios 1.5,2,3,5,10,20,50] [--mu 0.3,0.5,0.8] [--arc 1.0] [--right]
                                      [--set NAME=VALUE]... [--workers N] [--json FILE] [--smoke]
    python bench/wheels_bend_sweep.py --closed-form [--ratios ...] [--mu ...] [--set NAME=VALUE]...

Each case is the bend study's route (:mod:`ipir_mujoco.studies.bend_study`: a 0.6 m lead-in, L / 2, the bend,
L / 2, 0.05 m), the default motor, F_n 50 N and every other parameter at its default (``--set`` changes them),
with a horizontal bend of R/D from ``--ratios`` whose angle is 90 degrees or less, so that its arc is at most
``--arc`` metres (at R/D 50 a 90 degree bend of this pipe is 12.6 m long; 1 m keeps each run a few simulated
seconds). Its straightened twin is the same route with the bend replaced by a straight of the bend's arc, the
same marks. Both run as ``mujoco-wheels`` runs with the route do (the automatic step, 5e-5 s with a bend, and the
skid check), and the passage is the bend study's window: the robot's centre from L / 2 before the bend to L / 2
after it, a centreline length L + arc. The penalty is the bend's passage time over its twin's, less one: it
should fall as the bend gentles, to nothing in a straight pipe.

Each route (the bend and its twin) also runs in the equations (``analytic-unilateral`` with the route: the linkage
spanning the bend's chord, the wheels' scrub in its closed form; :func:`ipir_mujoco.studies.bend_study.equations_case`),
over the same window. The bends turn left (``--right``: right, so that the motor's reaction couple on module 1,
which cocks it one way, adds to the bend's cock or takes from it).

Per row: the bend's angle and arc; the passage times, bend / straight twin, and the penalty, MuJoCo's and the
equations'; MuJoCo's time and energy through the bend over the equations' less one; both engines' energies [J]
(the motor's work less the kinetic and potential energy gained over the window), bend / twin; the scrub [J] over
the window, the equations' (their wheels beyond their friction limit) beside MuJoCo's contacts' work in the bend
less in its twin (the wheels' sliding, and the soft contacts' creep under the side forces); how the bend's run
ended where it did not pass (its ``route_stop``); how long some wheel was off its wall in the bend's run and in
its twin's (``route_wheel_off_s``, the whole run); how far MuJoCo's most-slid wheel slid sideways (``slid1``,
``slid2``), bend / twin; each module's cock in the bend, MuJoCo's rolling and standing beside the closed form's
(:func:`cocks`); the summary's lift-off check (``lift_predicted``: on the run's own loads with what the bend adds,
docs/model.md "Along a route") beside the bend's quasi-static closed form's least-pressed leg (the route's fit) and
the step the run kept. The lift check's record over the rows ends the output: predicted and
happened (a wheel off in the bend's run longer than in its twin's), false alarms and misses.

``--closed-form`` runs nothing: per mu_wall and R/D, the rings' slip angle asin(b / R), the module's cock and the
side force its fore ring's legs carry (:func:`ipir_mujoco.core.wheel_legs.scrub_force`, module 1, a horizontal bend),
the rings' whole sideways friction beside it, and the bend's lift-off check (the route's fit: the least-pressed
leg, ``lift_predicted``).
"""

from __future__ import annotations

import argparse
import functools
import json
import math
import sys
import time

import numpy as np

from ipir_mujoco import registry
from ipir_mujoco.analytic.route_geometry import PIECE, pack_route
from ipir_mujoco.analytic.route_model import wheel_constants
from ipir_mujoco.analytic.route_scrub import module_scrub
from ipir_mujoco.core.errors import SimulationError
from ipir_mujoco.core.params import RobotParams, parse_overrides
from ipir_mujoco.core.pipe import bend_cock, bend_slip_angle, ring_side_grip, scrub_force
from ipir_mujoco.core.route import route_from_tables
from ipir_mujoco.studies.bend_study import (DT_OUT, EXIT, LEAD_IN, T_CAP_PER_M, _passage, equations_case,
                                            straight_route)
from ipir_mujoco.studies.pool import map_unordered
from ipir_mujoco.studies.comparison.route_compare import percent

RATIOS = (1.5, 2.0, 3.0, 5.0, 10.0, 20.0, 50.0)
MUS = (0.3, 0.5, 0.8)
ARC = 1.0  # m: the longest bend's arc
LIFT_SLACK_S = 0.01  # s: a wheel off its wall this much longer in the bend's run than in its twin's lifted there


def bend_angle(ratio: float, params: RobotParams, arc: float) -> float:
    """The bend's angle [deg]: 90, or less so that its arc is at most ``arc`` [m]."""
    return min(90.0, math.degrees(arc / (ratio * params.pipe_diameter)))


def bend_route(params: RobotParams, ratio: float, angle: float):
    half = dict(kind="straight", length=params.L / 2)
    return route_from_tables([dict(kind="straight", length=LEAD_IN), half,
                              dict(kind="bend", radius=ratio * params.pipe_diameter, angle=angle, plane=0.0), half,
                              dict(kind="straight", length=EXIT)], "bend sweep")


def cocks(run, route, params: RobotParams) -> dict:
    """Each module's cock in the bend [rad], nose out: MuJoCo's yaw off the centreline's heading at its point, the
    mean over the samples with both its rings in the bend (0.1 m clear of its ends) while it rolls (faster than
    0.05 m/s) and while it stands; beside the closed form's psi in the bend's middle
    (:func:`ipir_mujoco.analytic.route_scrub.module_scrub`)."""
    bend = route.bends[0]
    inside = (bend.s0 + 0.1, bend.s0 + bend.length - 0.1)
    series, sign = run.series, math.copysign(1.0, bend.angle)
    q, (mu, corner, n, p1, p2, travel, rho) = pack_route(route), wheel_constants(params)
    middle = bend.s0 + 0.5 * bend.length
    out = {}
    for k, stations in ((1, series["x1"]), (2, series["x2"] + series["S"][0])):
        where = (stations > inside[0]) & (stations < inside[1])
        if not where.any():
            continue
        heading = np.array([route.at(float(x))[2] for x in stations[where]])
        cock = -sign * (series[f"yaw{k}"][where] - heading)
        rolling = np.abs(series[f"v{k}"][where]) > 0.05
        out[k] = {"rolling": float(cock[rolling].mean()) if rolling.any() else None,
                  "standing": float(cock[~rolling].mean()) if (~rolling).any() else None,
                  "closed_form": float(module_scrub(q, 0, q.size // PIECE, middle, 0.5 * params.ring_spacing, mu,
                                                    corner, int(n), (p1, p2)[k - 1], travel, rho)[1])}
    return out


def run_case(item: tuple, overrides: dict, turn: float = 1.0) -> dict:
    """One case in a worker: item = (mu_wall, 'bend' | 'straight', R/D or the arc [m], angle [deg]), the bend
    turning left (``turn`` 1) or right (-1); MuJoCo's run
    and, under ``equations``, the equations' along the same route
    (:func:`ipir_mujoco.studies.bend_study.equations_case`)."""
    mu, kind, ratio, angle = item
    params = RobotParams(**{"drive": "motor", **overrides, "mu_wall": mu})
    arc = math.radians(angle) * ratio * params.pipe_diameter if kind == "bend" else ratio
    route = bend_route(params, ratio, turn * angle) if kind == "bend" else straight_route(params, arc)
    equations = equations_case(params, route)
    started = time.perf_counter()
    try:
        run = registry.run("mujoco-wheels", params, T_CAP_PER_M * route.length, dt_out=DT_OUT, route=route,
                           accuracy="warn")
    except SimulationError as exc:
        return {"error": str(exc), "passed": False, "time_s": None, "wall_s": time.perf_counter() - started,
                "equations": equations}
    out = _passage(run, route, 1, 4)
    fit = run.summary["route_fit"]["bends"]
    out.update(wall_s=time.perf_counter() - started, lift_predicted=run.summary["lift_predicted"],
               least_press_n=min(run.summary["least_press1_n"], run.summary["least_press2_n"]),
               bend_least_press_n=(min(min(b["least_press1_n"], b["least_press2_n"]) for b in fit) if fit else None),
               equations=equations, slid_m=max(float(run.series["slid1"][-1]), float(run.series["slid2"][-1])),
               cocks=cocks(run, route, params) if kind == "bend" else {})
    return out


def cock_text(cock: dict | None) -> str:
    """The cocks' cell: per module MuJoCo's rolling / standing mean, the closed form's."""
    if not cock:
        return "-"
    return "; ".join(" / ".join("-" if c[key] is None else f"{c[key]:.4f}" for key in ("rolling", "standing"))
                     + f", {c['closed_form']:.4f}" for c in (cock.get(k, cock.get(str(k))) for k in (1, 2)) if c)


def mm(metres: float | None) -> float | None:
    return None if metres is None else 1e3 * metres


def closed_form(overrides: dict, ratios, mus, arc: float) -> int:
    """The ``--closed-form`` table (module docstring)."""
    from ipir_mujoco.engine.builders.route_walls import fit_prediction

    print("| mu_wall | R/D | ring slip angle [rad] | cock [rad] | fore ring's side force [N] | rings' sideways "
          "friction [N] | bend's least press [N] | lift predicted |")
    print("|---|---|---|---|---|---|---|---|")
    for mu in mus:
        p = RobotParams(**{"drive": "motor", **overrides, "mu_wall": mu})
        for r in sorted(ratios):
            radius = r * p.pipe_diameter
            a, side = bend_slip_angle(p, radius), scrub_force(p, 0, (1.0, 0.0), radius)
            cock = bend_cock(p, 0, (1.0, 0.0), radius)
            fit = fit_prediction(bend_route(p, r, bend_angle(r, p, arc)), p, 0.5 * p.ring_spacing,
                                 p.suspension_travel)["bends"][0]
            least = min(fit["least_press1_n"], fit["least_press2_n"])
            print(f"| {mu:g} | {r:g} | {a:.4f} | {cock:.4f} | {side:.2f} | "
                  f"{ring_side_grip(p, 0, (1.0, 0.0)):.2f} | {least:.2f} | {least < 0} |")
    return 0


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--ratios", default=",".join(f"{r:g}" for r in RATIOS))
    parser.add_argument("--mu", default=",".join(f"{m:g}" for m in MUS))
    parser.add_argument("--arc", type=float, default=ARC, help="the longest bend's arc [m]")
    parser.add_argument("--set", action="append", default=[], metavar="NAME=VALUE")
    parser.add_argument("--workers", type=int, default=1)
    parser.add_argument("--json", default=None, help="write every run's record here")
    parser.add_argument("--smoke", action="store_true", help="R/D 50 at mu_wall 0.5, 0.6 m of arc: the script runs")
    parser.add_argument("--closed-form", action="store_true", help="the closed forms only, no runs")
    parser.add_argument("--right", action="store_true", help="the bends turn right (default: left)")
    args = parser.parse_args(argv)
    overrides = parse_overrides(args.set)
    ratios = [float(r) for r in args.ratios.split(",")]
    mus = [float(m) for m in args.mu.split(",")]
    if args.closed_form:
        return closed_form(overrides, ratios, mus, args.arc)
    if args.smoke:
        ratios, mus, args.arc = [50.0], [0.5], 0.2
    base = RobotParams(**{"drive": "motor", **overrides})
    items = []
    for mu in mus:
        arcs = set()
        for r in sorted(ratios, reverse=True):
            angle = bend_angle(r, base, args.arc)
            items.append((mu, "bend", r, angle))
            arcs.add(round(math.radians(angle) * r * base.pipe_diameter, 12))
        items += [(mu, "straight", arc, 0.0) for arc in sorted(arcs, reverse=True)]
    results = {}
    started = time.perf_counter()

    def done(item, result):
        results[item] = result
        print(f"[{len(results)}/{len(items)}] mu_wall {item[0]:g} {item[1]} {item[2]:g}: "
              f"{'passage %.4f s' % result['time_s'] if result.get('time_s') else result.get('route_stop', result.get('error'))}"
              f" ({result['wall_s']:.0f} s wall)", file=sys.stderr, flush=True)

    map_unordered(functools.partial(run_case, overrides=overrides, turn=-1.0 if args.right else 1.0), items,
                  args.workers, done)
    print(f"wheeled MuJoCo model, the motor, F_n {base.F_n1:g}/{base.F_n2:g} N, cornering_coefficient "
          f"{'rigid' if base.cornering_coefficient is None else f'{base.cornering_coefficient:g} /rad'}"
          f"{' (' + ', '.join(args.set) + ')' if args.set else ''}; bends horizontal, at most 90 deg and "
          f"{args.arc:g} m of arc; {time.perf_counter() - started:.0f} s wall")
    print("| mu_wall | R/D | angle [deg] | arc [m] | MuJoCo bend / straight [s] | MuJoCo penalty | equations bend / "
          "straight [s] | equations penalty | MuJoCo - equations in the bend: time / energy | energy bend / straight "
          "[J]: MuJoCo; equations | scrub [J]: equations / MuJoCo's skid, bend less straight | outcome | wheel off "
          "bend / straight [s] | slid bend / straight [mm] | cock [rad] module 1; 2: MuJoCo rolling / standing, closed "
          "form | lift predicted (the fit's least press [N]) | step [s] |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|")
    record = {"predicted and lifted": 0, "predicted, no lift (false alarm)": 0, "lifted, not predicted (miss)": 0,
              "neither": 0}
    rows = []
    for mu in mus:
        for r in sorted(ratios):
            angle = bend_angle(r, base, args.arc)
            arc = math.radians(angle) * r * base.pipe_diameter
            bend = results[(mu, "bend", r, angle)]
            twin = results[(mu, "straight", round(arc, 12), 0.0)]
            eb, es = bend["equations"], twin["equations"]

            def pair(a, b, digits=4):
                return " / ".join("-" if x is None else f"{x:.{digits}f}" for x in (a, b))

            def penalty(a, b):
                return percent(a / b - 1) if a and b else "-"

            outcome = "passed" if bend.get("passed") else bend.get("route_stop", bend.get("error"))
            off_b, off_s = bend.get("route_wheel_off_s"), twin.get("route_wheel_off_s")
            off = f"{off_b:.3f} / {off_s:.3f}" if off_b is not None and off_s is not None else "-"
            predicted = bend.get("lift_predicted")
            lifted = off_b is not None and off_s is not None and off_b > off_s + LIFT_SLACK_S
            if predicted is not None:
                key = ("predicted and lifted" if predicted and lifted else "predicted, no lift (false alarm)"
                       if predicted else "lifted, not predicted (miss)" if lifted else "neither")
                record[key] += 1
            press = bend.get("bend_least_press_n")
            lift = f"{predicted} ({press:.2f})" if press is not None else "-"
            skid = (bend["scrub_j"] - twin["scrub_j"] if bend.get("scrub_j") is not None and
                    twin.get("scrub_j") is not None else None)
            print(f"| {mu:g} | {r:g} | {angle:.1f} | {arc:.3f} | {pair(bend.get('time_s'), twin.get('time_s'))} | "
                  f"{penalty(bend.get('time_s'), twin.get('time_s'))} | {pair(eb['time_s'], es['time_s'])} | "
                  f"{penalty(eb['time_s'], es['time_s'])} | {penalty(bend.get('time_s'), eb['time_s'])} / "
                  f"{penalty(bend.get('energy_j'), eb['energy_j'])} | "
                  f"{pair(bend.get('energy_j'), twin.get('energy_j'), 3)}; {pair(eb['energy_j'], es['energy_j'], 3)} | "
                  f"{pair(eb['scrub_j'], skid, 3)} | {outcome} | {off} | "
                  f"{pair(mm(bend.get('slid_m')), mm(twin.get('slid_m')), 1)} | {cock_text(bend.get('cocks'))} | "
                  f"{lift} | {bend.get('timestep_s', '-')} |")
            rows.append({"mu_wall": mu, "R_over_D": r, "angle_deg": angle, "arc_m": arc, "bend": bend,
                         "straight": twin})
    print("lift check over the rows: " + ", ".join(f"{k} {v}" for k, v in record.items()))
    if args.json:
        with open(args.json, "w") as f:
            json.dump({"rows": rows, "lift_record": record, "overrides": overrides}, f, indent=1)
    return 0


if __name__ == "__main__":
    sys.exit(main())
