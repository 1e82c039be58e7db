"""Convergence of the wheeled MuJoCo model (a robot in a round pipe) in its step, its rows' softness held fixed.

Run on demand from the repository root (about 15 min on 2 busy cores; ``--smoke``: a few seconds):

    python bench/wheels_convergence.py [--cases cruise,riser,...] [--smoke]

The model's contact, limit and loop rows have time constants in seconds (``wheels_model.ROW_TIMES``, 2e-4 s),
properties of the model, so halving the step refines one model rather than stiffening it. Four cases, each at
1e-4 s (half the shortest time constant, MuJoCo's floor: the straight pipe's automatic step) and at 1/2, 1/4,
1/8 of it:
``cruise`` (the default motor, mu_wall 0.5, F_n 50 N, 1 s: each module's travel, and the speed over the last
0.5 s); ``riser`` (the default motor up a vertical pipe with mu_wall 0.18, a grip of 9 N per module against a
weight of 9.81 N, 0.5 s: both skid down); ``incline 30`` (mu_wall 0.15 at 30 deg, 0.5 s: both skid back); ``bend``
(a 0.4 m straight, a 30 deg bend of radius 0.8 m (R/D 5) and a straight, 1.5 s: the distance along the route).
For each figure: its value at each step, the case's automatic step (``registry.timestep``: a quarter of the
shortest time constant along a route with bends) and its difference from the finest (the converged value to
the finest step's own error, which halves at least with each halving here). The acceptance: the default within
0.2 % on travel and speed, 1 % on skid length. The table in mjcf/README.md ("The round pipe: convergence") is
this script's output.

``--time-constants``: why 2e-4 s. The robot with the drive off on a riser (mu_wall 0.18: both modules slide down
from rest at a = (G1 + G2) / (m1 + m2 + m_rod) - g, the analytic model's Coulomb answer) for 0.3 s, stepped by hand
at a quarter of each time constant 1e-3, 4e-4, 2e-4, 1e-4 s: the slide's length against the analytic model's.
"""

from __future__ import annotations

import argparse
import sys

import numpy as np

from ipir_mujoco import registry
from ipir_mujoco.core.params import RobotParams
from ipir_mujoco.core.route import route_from_tables

BEND = [dict(kind="straight", length=0.4), dict(kind="bend", radius=0.8, angle=30.0),
        dict(kind="straight", length=0.3)]
CASES = {
    "cruise": (RobotParams(drive="motor", mu_wall=0.5), 1.0, None),
    "riser": (RobotParams(drive="motor", mu_wall=0.18, incline=90.0), 0.5, None),
    "incline 30": (RobotParams(drive="motor", mu_wall=0.15, incline=30.0), 0.5, None),
    "bend": (RobotParams(drive="motor", mu_wall=0.8), 1.5, BEND),
}
TOLERANCE = {"travel": 2e-3, "speed": 2e-3, "skid": 1e-2, "along": 2e-3}


def figures(run) -> dict[str, tuple[str, float]]:
    """The case's figures: name -> (kind, value)."""
    s, series = run.summary, run.series
    out = {"x1 [m]": ("travel", s["x1_final"]), "x2 [m]": ("travel", s["x2_final"])}
    t = series["t"]
    late = t >= t[-1] - 0.5
    out["speed, last 0.5 s [m/s]"] = ("speed", float(np.polyfit(t[late], series["x1"][late], 1)[0]))
    for k in (1, 2):
        if s[f"slip{k}_m"] > 1e-3:
            out[f"skid {k} [m]"] = ("skid", s[f"slip{k}_m"])
    if "route_s_m" in s:
        out["along the route [m]"] = ("along", s["route_s_m"])
    return out


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
        model = build_wheels_model(params, SolverSettings(timestep=tau / 4), RowTimes(tau, tau, tau))
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


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--smoke", action="store_true", help="one case, 0.05 s, two steps: the script runs")
    parser.add_argument("--time-constants", action="store_true", help="the riser slide at several time constants")
    parser.add_argument("--cases", default=",".join(CASES),
                        help=f"comma-separated cases to run (default all: {','.join(CASES)})")
    args = parser.parse_args(argv)
    if args.time_constants:
        time_constants(args.smoke)
        return 0
    base = registry.timestep("mujoco-wheels", RobotParams(drive="motor", mu_wall=0.5), 1.0, 1e-3)
    factors = (1, 2) if args.smoke else (1, 2, 4, 8)
    chosen = [c.strip() for c in args.cases.split(",")]
    unknown = [c for c in chosen if c not in CASES]
    if unknown:
        parser.error(f"--cases {unknown[0]!r} is unknown; allowed: {', '.join(CASES)}")
    cases = {"cruise": (CASES["cruise"][0], 0.05, None)} if args.smoke else {c: CASES[c] for c in chosen}
    print(f"| case | figure | {' | '.join(f'dt {base / f:.3g} s' for f in factors)} | default dt | default - finest "
          "| within |")
    print("|---|---|" + "---|" * len(factors) + "---|---|---|")
    worst_ok = True
    for name, (params, t_end, tables) in cases.items():
        route = route_from_tables(tables, "bend.toml") if tables else None
        default = registry.timestep("mujoco-wheels", params, t_end, 1e-3, route=route)  # the automatic step
        column = min(range(len(factors)), key=lambda j: abs(base / factors[j] - default))
        rows = []
        for f in factors:
            print(f"{name}: dt {base / f:.3g} s", file=sys.stderr, flush=True)
            rows.append(figures(registry.run("mujoco-wheels", params, t_end, dt_out=1e-3, timestep=base / f,
                                             route=route, accuracy="warn")))
        for key, (kind, value) in rows[0].items():
            values = [r[key][1] if key in r else float("nan") for r in rows]
            diff = (values[column] - values[-1]) / abs(values[-1]) if values[-1] else float("nan")
            ok = abs(diff) <= TOLERANCE[kind]
            worst_ok &= ok
            print(f"| {name} | {key} | {' | '.join(f'{v:.6g}' for v in values)} | {default:.3g} | "
                  f"{100 * diff:+.3f} % | {'yes' if ok else 'NO'} ({100 * TOLERANCE[kind]:g} %) |", flush=True)
    print(f"every figure within its tolerance: {worst_ok}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
