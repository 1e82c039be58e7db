"""Convergence of the wheeled MuJoCo model (a robot in a round pipe) in its step, its rows' softness held fixed.

Run on demand from the repository root (about 25 min on 2 busy cores, most of it the bend; ``--cases``: some of
them; ``--smoke``: a few seconds):

    python bench/wheels_convergence.py [--cases cruise,riser,...] [--down-to STEP] [--set NAME=VALUE]...
                                       [--solver-iterations] [--smoke]

The model's contact and limit rows have time constants in seconds (``wheels_model.ROW_TIMES``, 2e-4 s),
properties of the model, so halving the step refines one model rather than stiffening it (the loop's pin, a rigid
joint, follows the step: 2 steps). Four cases: ``cruise``
(the default motor, mu_wall 0.5, F_n 50 N, 1 s); ``riser`` (the default motor up a vertical pipe with mu_wall 0.18,
a grip of 9 N per module against a weight of 9.81 N, 0.5 s: both skid down); ``incline 30`` (mu_wall 0.15 at 30
deg, 0.5 s: both skid back); ``bend`` (a 0.4 m straight, a 30 deg bend of radius 0.8 m (R/D 5) and a straight,
mu_wall 0.8, 1.5 s). Each is run as a user's run is (the automatic step, ``registry.timestep``: 1e-4 s, 5e-5 s
along a route with bends, and where its wheels skid the skid check's halvings, ``engine/run/wheel_skids.py``: the
run kept is at the step the check reached) and at fixed steps 1e-4 s and 1/2, 1/4, 1/8 of it, and down to half the
automatic run's step where that is finer, or to ``--down-to`` (the automatic run is the fixed run at its step: not
repeated). The figures: the crank's revolutions, each module's travel (along the route on a route), the robot's
speed over whole crank revolutions spanning at least the last 0.5 s, each module's skid (where it passes the
check's floor) and the distance along the route. The converged value: from the three finest steps, the finest plus
the rest of the geometric series of their differences where those shrink with one sign at least about as fast as
first order, else the finest (marked: no convergence shown). The acceptance (issue 32): the automatic run within
0.2 % of it on travel and speed, 1 % plus the skid's resolution on skid length (``wheel_skids.skid_resolution``, a
length: how closely soft contacts of time constant tau define a skid's ends, (revolutions + 1) v_max tau). The
table in mjcf/README.md ("The round pipe: convergence") is this script's output.

``--solver-iterations``: the bend at 2.5e-5 and 1.25e-5 s with the model's solver settings and with ten times
the iterations (a minute): whether its drift with the step is the solver's or the discretization's.

``--time-constants``: why 2e-4 s. The robot with the drive off on a riser (mu_wall 0.18: both modules slide down
from rest at a = (G1 + G2) / (m1 + m2 + m_rod) - g, the analytic model's Coulomb answer) for 0.3 s, stepped by hand
at a quarter of each time constant 1e-3, 4e-4, 2e-4, 1e-4 s: the slide's length against the analytic model's.
"""

from __future__ import annotations

import argparse
import math
import sys

import numpy as np

from ipir_mujoco import registry
from ipir_mujoco.core.cycles import cycle_boundaries, travel
from ipir_mujoco.core.params import RobotParams, parse_overrides
from ipir_mujoco.core.route import route_from_tables
from ipir_mujoco.engine.run.wheel_skids import skid_floor, skid_resolution

BEND = [dict(kind="straight", length=0.4), dict(kind="bend", radius=0.8, angle=30.0),
        dict(kind="straight", length=0.3)]
CASES = {
    "cruise": (RobotParams(drive="motor", mu_wall=0.5), 1.0, None),
    "riser": (RobotParams(drive="motor", mu_wall=0.18, incline=90.0), 0.5, None),
    "incline 30": (RobotParams(drive="motor", mu_wall=0.15, incline=30.0), 0.5, None),
    "bend": (RobotParams(drive="motor", mu_wall=0.8), 1.5, BEND),
}
TOLERANCE = {"travel": 2e-3, "speed": 2e-3, "skid": 1e-2, "along": 2e-3}
WINDOW = 0.5  # s: the speed is taken over the whole revolutions that span at least the run's last WINDOW


def revolution_speed(run) -> float:
    """The robot's mean speed [m/s] (the mean of its modules' travel) over whole crank revolutions at the end of
    the run: from the last revolution's end back to the latest revolution end (or the start) at least WINDOW
    before it. Whole revolutions, so the figure holds no part of a stroke (a window of fixed length cuts one
    at a different phase at each step)."""
    series = run.series
    t, phi = series["t"], series["phi"]
    ends, _ = cycle_boundaries(t, phi)
    marks = np.concatenate([[t[0]], ends])
    last = marks[-1]
    first = marks[marks <= last - WINDOW + 1e-12]
    first = first[-1] if first.size else marks[0]
    x = travel(series)
    if last <= first:
        return float("nan")
    return float((np.interp(last, t, x) - np.interp(first, t, x)) / (last - first))


def figures(run) -> dict[str, tuple[str, float, float]]:
    """The case's figures: name -> (kind, value, floor [the figure's own unit]): each module's travel, the speed
    over whole revolutions, each module's skid (its floor: how closely the model defines a skid,
    :func:`~ipir_mujoco.engine.run.wheel_skids.skid_resolution`), the distance along a route."""
    s = run.summary
    out = {"revolutions": ("travel", s["revolutions"], 0.0),
           "x1 [m]": ("travel", s["x1_final"], 0.0), "x2 [m]": ("travel", s["x2_final"], 0.0),
           "speed, whole revolutions [m/s]": ("speed", revolution_speed(run), 0.0)}
    for k in (1, 2):  # each run's skid, shown where the automatic run's passes the floor
        out[f"skid {k} [m]"] = ("skid", s[f"slip{k}_m"], skid_resolution(run, k))
    if "route_s_m" in s:
        out["along the route [m]"] = ("along", s["route_s_m"], 0.0)
    return out


CONVERGING = 0.55  # the largest ratio of successive differences taken as convergence (first order: 1/2)


def converged(values: list[float]) -> tuple[float, bool]:
    """(the converged value, whether the values show convergence) from the three finest steps' values (coarse
    to fine): where their two differences have one sign and shrink at least about as fast as first order (ratio
    q <= CONVERGING), the finest plus the differences still to come, d q / (1 - q) (a geometric series); else the
    finest, not shown converged (a slower ratio extrapolates into noise: q = 0.99 multiplies the last difference
    by 99)."""
    if len(values) < 3 or not all(np.isfinite(values[-3:])):
        return values[-1], False
    d1, d2 = values[-2] - values[-3], values[-1] - values[-2]
    if d2 == 0.0:
        return values[-1], True
    if d1 * d2 > 0 and abs(d2) <= CONVERGING * abs(d1):
        q = abs(d2) / abs(d1)
        return values[-1] + d2 * q / (1 - q), True
    return values[-1], False


def time_constants(smoke: bool) -> None:
    """The riser slide at several row time constants (module docstring, ``--time-constants``)."""
    import mujoco

    from ipir_mujoco.engine.builders.model import MOTOR, SolverSettings, drive_control, qpos_address
    from ipir_mujoco.engine.controllers.wheels import WheelRatchet
    from ipir_mujoco.engine.builders.wheels_model import RowTimes, build_wheels_model, set_wheels_state

    params, t_end = RobotParams(M=0.0, mu_wall=0.18, incline=90.0), (0.02 if smoke else 0.3)
    analytic = registry.run("analytic-unilateral", params, t_end, dt_out=1e-3).summary["x1_final"]
    print("| row time constant [s] | step [s] | slide of module 1 [m] | analytic [m] | difference |")
    print("|---|---|---|---|---|")
    for tau in ((2e-4,) if smoke else (1e-3, 4e-4, 2e-4, 1e-4)):
        model = build_wheels_model(params, SolverSettings(timestep=tau / 4), RowTimes(tau, tau))
        data = mujoco.MjData(model)
        set_wheels_state(model, data, params)
        data.ctrl[model.actuator(MOTOR).id] = drive_control(params)
        mujoco.mj_forward(model, data)
        ratchet = WheelRatchet(model, data, params)
        for _ in range(round(t_end / model.opt.timestep)):
            ratchet.before_step()
            mujoco.mj_step(model, data)
        x1 = float(data.qpos[qpos_address(model, "rear_slide")])
        print(f"| {tau:g} | {tau / 4:g} | {x1:.6f} | {analytic:.6f} | {100 * (x1 / analytic - 1):+.2f} % |",
              flush=True)


def solver_iterations(smoke: bool) -> None:
    """The bend at two fixed steps with the model's solver settings (iterations 100, line-search 50, tolerance
    1e-12) and with ten and four times the iterations (``--solver-iterations``): whether the bend's drift with
    the step is MuJoCo's solver stopping short of convergence (the figures would move with the iterations) or
    the discretization itself (they would not)."""
    from ipir_mujoco.engine.kinds.wheels import model as wheels_model

    params, t_end, tables = CASES["bend"]
    route = route_from_tables(tables, "bend.toml")
    t_end, steps = (0.05, (1e-4,)) if smoke else (t_end, (2.5e-5, 1.25e-5))
    build = wheels_model.build_wheels_model
    print("| step [s] | iterations / line search | revolutions | x1 [m] | x2 [m] | along the route [m] |")
    print("|---|---|---|---|---|---|")
    try:
        for dt in steps:
            for iterations, line in ((None, None), (1000, 200)):
                def more(spec, decorate=None):
                    if decorate is not None:
                        decorate(spec)
                    if iterations is not None:
                        spec.option.iterations, spec.option.ls_iterations = iterations, line

                def built(params, settings, *, mjcf=None, route=None, decorate=None):
                    return build(params, settings, mjcf=mjcf, route=route,
                                 decorate=lambda spec: more(spec, decorate))
                wheels_model.build_wheels_model = built  # the one place the wheeled kind compiles its model
                s = registry.run("mujoco-wheels", params, t_end, dt_out=1e-3, timestep=dt, route=route).summary
                shown = "the model's (100 / 50)" if iterations is None else f"{iterations} / {line}"
                print(f"| {dt:g} | {shown} | {s['revolutions']:.6g} | {s['x1_final']:.6g} | {s['x2_final']:.6g} | "
                      f"{s['route_s_m']:.6g} |", flush=True)
    finally:
        wheels_model.build_wheels_model = build


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--smoke", action="store_true", help="one case, 0.05 s, two steps: the script runs")
    parser.add_argument("--time-constants", action="store_true", help="the riser slide at several time constants")
    parser.add_argument("--solver-iterations", action="store_true",
                        help="the bend at 2.5e-5 and 1.25e-5 s with 100 and 1000 solver iterations")
    parser.add_argument("--down-to", type=float, default=None, metavar="STEP",
                        help="fixed steps down to this [s] too (default: down to half the automatic run's step)")
    parser.add_argument("--cases", default=",".join(CASES),
                        help=f"comma-separated cases to run (default all: {','.join(CASES)})")
    parser.add_argument("--set", action="append", default=[], metavar="NAME=VALUE",
                        help="change every case's parameters (e.g. cornering_coefficient=rigid)")
    args = parser.parse_args(argv)
    overrides = parse_overrides(args.set)
    if args.time_constants:
        time_constants(args.smoke)
        return 0
    if args.solver_iterations:
        solver_iterations(args.smoke)
        return 0
    base = registry.timestep("mujoco-wheels", RobotParams(drive="motor", mu_wall=0.5), 1.0, 1e-3)
    factors = (1, 2) if args.smoke else (1, 2, 4, 8)
    chosen = [c.strip() for c in args.cases.split(",")]
    unknown = [c for c in chosen if c not in CASES]
    if unknown:
        parser.error(f"--cases {unknown[0]!r} is unknown; allowed: {', '.join(CASES)}")
    cases = {"cruise": (CASES["cruise"][0], 0.05, None)} if args.smoke else {c: CASES[c] for c in chosen}
    print("| case | figure | step [s]: value | automatic run: step [s], skid check | converged | automatic - "
          "converged | within |")
    print("|---|---|---|---|---|---|---|")
    worst_ok = True
    for name, (params, t_end, tables) in cases.items():
        params = params.replace(**overrides)
        route = route_from_tables(tables, "bend.toml") if tables else None
        print(f"{name}: the automatic run", file=sys.stderr, flush=True)
        auto = registry.run("mujoco-wheels", params, t_end, dt_out=1e-3, route=route)  # the step it chooses
        kept = auto.settings["timestep"]
        steps = [base / f for f in factors]
        finest = kept if args.smoke else min(kept / 2, args.down_to or kept)
        while steps[-1] > finest * (1 + 1e-9) or steps[-1] >= kept * (1 + 1e-9):
            steps.append(steps[-1] / 2)  # down to half the automatic run's step (a reference finer than it)
        rows = []
        for dt in steps:
            if math.isclose(dt, kept, rel_tol=1e-9):
                rows.append(figures(auto))  # the same run (deterministic): not repeated
                continue
            print(f"{name}: dt {dt:.3g} s", file=sys.stderr, flush=True)
            rows.append(figures(registry.run("mujoco-wheels", params, t_end, dt_out=1e-3, timestep=dt,
                                             route=route, accuracy="warn")))
        mine = figures(auto)
        check = auto.accuracy.get("skid_check", "no skid")
        for h in auto.settings.get("skid_check", []):  # what decided each halving of the automatic run
            print(f"{name}: skid check {h['timestep']:.3g} -> {h['half']:.3g} s: differences "
                  f"{ {k: round(v, 6) for k, v in h['differences'].items() if v is not None} }, largest estimate "
                  f"{h['figure']} {h['difference']}", file=sys.stderr, flush=True)
        for key, (kind, value, _) in mine.items():
            if kind == "skid" and value <= skid_floor(auto, int(key.split()[1])):
                continue
            values = [r[key][1] if key in r else float("nan") for r in rows]
            floor = rows[-1][key][2] if key in rows[-1] else 0.0
            limit, trend = converged(values)
            diff = (value - limit) / abs(limit) if limit else float("nan")
            ok = abs(value - limit) <= TOLERANCE[kind] * abs(limit) + floor  # a skid: 1 % + its resolution
            worst_ok &= ok
            scale = f" + {floor * 1e3:.2g} mm" if floor else ""
            cells = ", ".join(f"{dt:.3g}: {v:.6g}" for dt, v in zip(steps, values))
            print(f"| {name} | {key} | {cells} | {kept:.3g}, {check} | {limit:.6g}{'' if trend else ' (finest)'} | "
                  f"{100 * diff:+.3f} % | "
                  f"{'yes' if ok else 'NO'} ({100 * TOLERANCE[kind]:g} %{scale}) |", flush=True)
    print(f"every figure within its tolerance: {worst_ok}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
