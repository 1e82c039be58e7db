"""The equations along a route: what a route costs against its straightened twin, and what of that is the chord
geometry, the per-module gravity and the modules' yaw.

Run on demand from the repository root (a few seconds once the kernels are compiled):

    python bench/route_equations.py [--clutch unilateral|kinematic] [--set NAME=VALUE]... [--random N] [--seed S]
                                    [--smoke]

The analytic route model (``analytic-unilateral`` by default, the motor, mu_wall 0.8 as the bend study's default)
along each route below and along its straightened twin (one straight of the same length and first incline, which
is today's straight-pipe model to the solver's tolerance). Per route it prints the route time [s] (module 1's A
reaching the route's end), the time the robot's centre (midway between A and C along the route) took from the
first bend's start to the last one's end, and the motor's work [J] to the route's end, of both, their differences in
% of the twin's, and the route time's and the work's differences split in

- chord: the route less its twin with g = 0 (the linkage spanning the bend's chord, the modules' points inside
  the centreline, the inertia terms, and the wheels' scrub in the bends, whose work the scrub column gives);
- gravity: the rest, the per-module gravity of the route's grades;
- yaw: the route with the modules' transverse inertias set to 0 (their yaw through a bend then stores nothing),
  against the full model: what the modules' yaw kinetic energy changes, with its closed-form share of a module's
  translational kinetic energy in the bend, I_t / (m R^2) = (3 rho^2 + ring_spacing^2) / (12 R^2).

With ``--random N`` it runs N random routes instead (``--seed S``; 1-3 bends of R/D 1.5-50 in planes -180..180 deg,
turning -180..180 deg, straights between them or not, a first incline of -90..90 deg, mu_wall 0.2-0.8, F_n 20-100 N,
M_stall 0.5-2 N m, to the route's end or 30 s) and prints each route's outcome and its energy audit's residual
against the energy put through, then the outcomes' counts and the largest residual. The scrub column: the wheels'
scrub work along the route [J] (analytic/route_scrub.py; zero with unlimited grip, the paper's rule's default).

docs/model.md, "The equations along a route", quotes this script's tables.
"""

from __future__ import annotations

import argparse
import math
import sys

import numpy as np

from ipir_mujoco import registry
from ipir_mujoco.analytic import route_model
from ipir_mujoco.core.params import RobotParams, load_params
from ipir_mujoco.core.route import read_route, route_from_tables

D = RobotParams().pipe_diameter  # m: the default pipe, to name the bends' R / D


def _bend(ratio: float, angle: float, plane: float = 0.0, exit_length: float = 0.3, exit_incline=None):
    tables = [dict(kind="straight", length=0.4), dict(kind="bend", radius=ratio * D, angle=angle, plane=plane),
              dict(kind="straight", length=exit_length)]
    return route_from_tables(tables)


ROUTES = {
    "mjcf/bend90.toml (R/D 5, 90 deg)": lambda: read_route("mjcf/bend90.toml"),
    "R/D 50, 15 deg": lambda: _bend(50.0, 15.0),
    "R/D 20, 15 deg": lambda: _bend(20.0, 15.0),
    "R/D 20, 90 deg": lambda: _bend(20.0, 90.0),
    "R/D 2, 90 deg": lambda: _bend(2.0, 90.0),
    "R/D 5, 90 deg up into a riser (plane 90)": lambda: _bend(5.0, 90.0, 90.0, 0.5),
}


def twin(route):
    """The route unrolled straight: one straight of its length, rising at its first incline."""
    return route_from_tables([dict(kind="straight", length=route.length, incline=route.incline)])


def measure(variant: str, params: RobotParams, route, window: tuple[float, float]) -> tuple[float, float, float, dict]:
    """(route time [s], motor work [J], the time [s] the robot's centre took through ``window`` (from, to) [m] along
    the route, summary) of a run to the route's end (refused if it does not get there)."""
    run = registry.run(variant, params, 120.0, route=route, dt_out=1e-4)
    s = run.summary
    if not s["route_done"]:
        raise SystemExit(f"the run did not reach the route's end: {s['route_stop']}")
    centre = np.maximum.accumulate(0.5 * (run.series["x1"] + run.series["x2"] + run.series["S"][0]))
    through = np.interp(window[1], centre, run.series["t"]) - np.interp(window[0], centre, run.series["t"])
    return s["route_time_s"], s["energy"]["motor_work_j"], through, s


def random_routes(count: int, seed: int, clutch: str) -> int:
    """``count`` random routes (module docstring): each one's outcome and residual, then the counts."""
    from ipir_mujoco.core.errors import SimulationError

    rng = np.random.default_rng(seed)
    counts, worst = {}, 0.0
    for k in range(count):
        tables = [dict(kind="straight", length=0.45, incline=float(rng.choice([rng.uniform(-90, 90), 90, -90, 0])))]
        for _ in range(rng.integers(1, 4)):
            tables.append(dict(kind="bend", radius=float(math.exp(rng.uniform(math.log(1.5), math.log(50))) * D),
                               angle=float(rng.uniform(-180, 180)), plane=float(rng.uniform(-180, 180))))
            if rng.random() < 0.6:
                tables.append(dict(kind="straight", length=float(rng.uniform(0.05, 0.5))))
        tables.append(dict(kind="straight", length=0.3))
        route = route_from_tables(tables)
        given = ["drive=motor", f"mu_wall={rng.uniform(0.2, 0.8):.3f}", f"F_n1={rng.uniform(20, 100):.1f}",
                 f"F_n2={rng.uniform(20, 100):.1f}", f"M_stall={rng.uniform(0.5, 2.0):.3f}"]
        params = load_params(None, given if clutch == "unilateral" else [given[0], given[-1]])
        variant = "analytic-unilateral" if clutch == "unilateral" else "analytic-exact"
        try:
            s = registry.run(variant, params, 30.0, route=route, dt_out=1e-3).summary
        except SimulationError as exc:
            kind, line = "failed", f"failed: {exc}"
        else:
            residual = abs(s["accuracy"]["residual_ratio"])
            worst = max(worst, residual)
            kind = "done" if s["route_done"] else s["route_stop"].split(":")[0].split(" reached")[0]
            line = f"{kind:8s} t = {s['route_time_s'] or 0.0:7.3f} s, residual {residual:.1e}: {s['route_stop']}"
        counts[kind] = counts.get(kind, 0) + 1
        print(f"{k:4d} {len(route.bends)} bends, {route.length:6.2f} m, incline {route.incline:+6.1f}, "
              f"{' '.join(given[1:])}: {line}")
    print(f"{count} routes: {', '.join(f'{n} {kind}' for kind, n in counts.items())}; largest residual {worst:.1e} of "
          "the energy put through")
    return 0


def main(argv: list[str]) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--clutch", choices=("unilateral", "kinematic"), default="unilateral")
    parser.add_argument("--set", action="append", default=[], metavar="NAME=VALUE")
    parser.add_argument("--random", type=int, default=0, metavar="N", help="N random routes (module docstring)")
    parser.add_argument("--seed", type=int, default=1, metavar="S")
    parser.add_argument("--smoke", action="store_true", help="two routes only (a check that it runs)")
    args = parser.parse_args(argv)
    if args.random:
        return random_routes(2 if args.smoke else args.random, args.seed, args.clutch)
    given = ["drive=motor", *(["mu_wall=0.8"] if args.clutch == "unilateral" else []), *args.set]
    params = load_params(None, given)
    variant = "analytic-unilateral" if args.clutch == "unilateral" else "analytic-exact"
    rho = 0.5 * params.pipe_diameter - 2 * params.wheel_radius
    print(f"{variant}, {', '.join(given)}; times [s], work [J], differences in % of "
          "the straightened twin")
    print(f"{'route':44s} {'time':>8s} {'twin':>8s} {'d time':>7s} {'bends':>7s} {'twin':>7s} {'d bends':>7s} "
          f"{'work':>8s} {'twin':>8s} {'d work':>7s} {'chord t/W':>13s} {'gravity t/W':>15s} {'yaw t/W':>15s} "
          f"{'yaw KE':>7s} {'scrub':>7s} {'residual':>9s}")
    for name, build in list(ROUTES.items())[:2 if args.smoke else None]:
        route = build()
        bends = route.bends
        window = (bends[0].s0, bends[-1].s0 + bends[-1].length)  # the bends, from the first's start to the last's end
        time_, work, bend, s = measure(variant, params, route, window)
        time0, work0, bend0, _ = measure(variant, params, twin(route), window)
        flat = params.replace(g=0.0)
        time_g0, work_g0, _, _ = measure(variant, flat, route, window)
        time0_g0, work0_g0, _, _ = measure(variant, flat, twin(route), window)
        inertia = route_model.transverse_inertia
        route_model.transverse_inertia = lambda p, m: 0.0
        try:
            time_i0, work_i0, _, _ = measure(variant, params, route, window)
        finally:
            route_model.transverse_inertia = inertia

        def pct(a, b):
            return 100.0 * (a / b - 1.0)

        chord = (pct(time_g0, time0_g0), pct(work_g0, work0_g0))
        total = (pct(time_, time0), pct(work, work0))
        gravity = (total[0] - chord[0], total[1] - chord[1])
        yaw = (pct(time_, time_i0), pct(work, work_i0))
        R = min(b.radius for b in bends)
        share = (3 * rho**2 + params.ring_spacing**2) / (12 * R**2)
        residual = s["energy"]["residual_j"] / work
        print(f"{name:44s} {time_:8.4f} {time0:8.4f} {total[0]:+7.2f} {bend:7.4f} {bend0:7.4f} "
              f"{pct(bend, bend0):+7.2f} "
              f"{work:8.4f} {work0:8.4f} {total[1]:+7.2f} {chord[0]:+6.2f}/{chord[1]:+6.2f} "
              f"{gravity[0]:+7.2f}/{gravity[1]:+7.2f} {yaw[0]:+7.3f}/{yaw[1]:+7.3f} {100 * share:6.2f}% "
              f"{s['energy']['scrub_j']:7.4f} {residual:9.1e}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
