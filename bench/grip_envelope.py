"""Benchmark: finite grip over its whole envelope, both engines, at fixed time and to the steady state.

Run on demand (not part of the test suite; CPU-heavy):

    python bench/grip_envelope.py [--designs 200] [--seed 50] [--t-end 1] [--cap 8] [--budget 300] [--workers 1]
    python bench/grip_envelope.py --smoke      # 4 short designs, seconds

Designs (numpy's ``default_rng(seed)``; rigid one-way clutches, the robot from rest):
log-uniform m1, m2 in [0.3, 3] kg, r in [0.02, 0.08] m, J_A in [2e-4, 1e-2] kg m^2, F_r1, F_r2 in [0.2, 5] N;
L / r uniform in [1.5, 6]; phi0 uniform in [0, 2 pi); incline uniform in [-90, 90] deg; half under a constant
torque M (log-uniform [0.05, 1] N m), half under the motor, weak or strong (M_stall log-uniform [0.1, 2] N m,
omega_noload uniform [10, 60] rad/s); mu_wall uniform in [0.05, 1] and each F_ni log-uniform in [1, 300] N
drawn apart (an asymmetric press), so that the grip runs from far below the demand (both modules skid every
stroke, or the robot slides away) to far above it (nothing skids). The rigid limit's constants were measured on
seed 33's designs (mjcf/README.md); the default seed is another.

Each design runs the analytic one-way model (``analytic-unilateral``) and MuJoCo's slide model
(``mujoco-ratchet``) at their default settings, as a user would (the accuracy monitor in its default 'stop'
mode): for ``--t-end`` seconds and, under the motor, to the steady state (``--cap`` the cap). A MuJoCo run whose
modules skid reports each figure as its rigid limit with an error (``figure_errors``; fixed time: revolutions,
x1_final, x2_final; to the steady state: steady_speed_m_s, energy_per_metre_j_m), *accepted* where that error is
within the stated accuracy (1e-3 fixed time, 3e-4 steady; relative to the figure, travel to at least a tenth of
a stroke). Each design and mode is one line whatever its class:

- ``extrapolated``: every figure with MuJoCo's value less the equations' (relative), its error bar, ``acc``
  (accepted) or ``n/a`` (not), ``in`` (the equations inside the bar) or ``OUT``;
- ``no skid``: one run, nothing extrapolated; its largest difference from the equations (the monitor's 1e-3
  and 3e-4 apply);
- ``refused``: MuJoCo stopped the run in one line (its rigid limit not trustworthy, or its monitor): counted
  against the 5 % the issue allows of the designs the equations answer;
- ``up front``: either engine refused the design's parameters (not counted); ``equations failed``: the
  analytic engine could not answer (not counted); ``no steady``: an engine did not reach the steady state by
  the cap (both say so; the fixed figures at the cap are compared where both ran to it).

The totals: refusals over the designs the equations answer; for the accepted figures, how many have the
equations inside their error bar (at least 95 % asked) and within the stated accuracy (all asked); the same for
the figures not accepted; and the cost of a skidding run: its wall time over its first run's (the run the same
design makes where it does not skid), each design's and the largest.
"""

from __future__ import annotations

import argparse
import math
import time

import numpy as np

from ipir_mujoco import registry
from ipir_mujoco.analytic import ParameterError, RobotParams, SimulationError
from ipir_mujoco.engine.kinds.slides_grip.rigid_limit import ACCURACY, FIGURES, figure_scale

TOL = ACCURACY  # {'fixed': 1e-3, 'steady': 3e-4}


def draw(rng: np.random.Generator) -> RobotParams:
    """One design of the envelope (module docstring)."""
    log = lambda lo, hi: float(math.exp(rng.uniform(math.log(lo), math.log(hi))))  # noqa: E731
    r = log(0.02, 0.08)
    values = dict(m1=log(0.3, 3), m2=log(0.3, 3), r=r, L=r * float(rng.uniform(1.5, 6)), J_A=log(2e-4, 1e-2),
                  F_r1=log(0.2, 5), F_r2=log(0.2, 5), phi0=float(rng.uniform(0, 2 * math.pi)),
                  incline=float(rng.uniform(-90, 90)), mu_wall=float(rng.uniform(0.05, 1)), F_n1=log(1, 300),
                  F_n2=log(1, 300))
    if rng.uniform() < 0.5:
        values.update(drive="torque", M=log(0.05, 1))
    else:
        values.update(drive="motor", M_stall=log(0.1, 2), omega_noload=float(rng.uniform(10, 60)))
    return RobotParams(**values)


def describe(p: RobotParams) -> str:
    drive = (f"M={p.M:.3g}" if p.drive == "torque"
             else f"motor M_stall={p.M_stall:.3g} omega_noload={p.omega_noload:.3g}")
    return (f"m1={p.m1:.3g} m2={p.m2:.3g} r={p.r:.3g} L={p.L:.3g} J_A={p.J_A:.3g} F_r={p.F_r1:.3g}/{p.F_r2:.3g} "
            f"phi0={p.phi0:.3g} incline={p.incline:.3g} mu_wall={p.mu_wall:.3g} F_n={p.F_n1:.3g}/{p.F_n2:.3g} {drive}")


def run(variant: str, params: RobotParams, t_end: float, until_steady: bool, budget: float):
    """(status, RunResult or one-line reason, wall [s]): 'ok', 'up front' (ParameterError) or 'failed'."""
    started = time.perf_counter()
    try:
        result = registry.run(variant, params, t_end, dt_out=1e-3, until_steady=until_steady, wall_budget_s=budget)
        return "ok", result, time.perf_counter() - started
    except ParameterError as exc:
        return "up front", str(exc), time.perf_counter() - started
    except SimulationError as exc:
        return "failed", str(exc), time.perf_counter() - started


def judge(params: RobotParams, t_end: float, until_steady: bool, budget: float) -> dict:
    """One design and mode: {'class', 'detail', 'figures': [(figure, rel. difference, rel. error or None,
    accepted, covered)], 'cost': wall over the first run's or None}."""
    (sa, a, _), (sm, m, wall) = (run(v, params, t_end, until_steady, budget)
                                 for v in ("analytic-unilateral", "mujoco-ratchet"))
    out = {"figures": [], "cost": None, "cost_steps": None, "wall": wall}
    if "up front" in (sa, sm):
        return {**out, "class": "up front", "detail": a if sa == "up front" else m}
    if sa == "failed":
        return {**out, "class": "equations failed", "detail": a}
    if sm == "failed":
        return {**out, "class": "refused", "detail": m}
    kind = "steady" if until_steady and a.summary["steady"] and m.summary["steady"] else "fixed"
    if until_steady and (a.summary["steady"] or m.summary["steady"]) and kind == "fixed":
        who = [name for name, r in (("analytic", a), ("mujoco", m)) if not r.summary["steady"]]
        return {**out, "class": "no steady", "detail": f"no steady state by {t_end:g} s: {', '.join(who)}"}
    sa_, sm_ = a.summary, m.summary
    errors = sm_.get("figure_errors") or {}
    accepted = m.accuracy.get("figures_accepted") or {}
    for key in FIGURES[kind]:
        if sa_[key] is None or sm_[key] is None:
            continue
        scale = figure_scale(key, [sa_[key], sm_[key]], params)
        diff = (sm_[key] - sa_[key]) / scale
        if key in errors:
            bar = errors[key] / scale
            out["figures"].append((key, diff, bar, bool(accepted.get(key)), abs(diff) <= bar, kind))
        else:
            out["figures"].append((key, diff, None, abs(diff) <= TOL[kind], None, kind))
    extrapolation = m.settings.get("extrapolation")
    if extrapolation and extrapolation.get("runs"):
        runs = extrapolation["runs"]
        first = next(r for r in runs if r["ratio"] == 1.0)
        out["cost"] = wall / first["wall_s"] if first.get("wall_s") else None
        out["cost_steps"] = sum(r.get("steps", 0) for r in runs) / first["steps"]
        plan = extrapolation["plan"]
        detail = f"{plan}; steps {', '.join(f'{s:.3g}' for s in extrapolation['used'])} s"
        return {**out, "class": "extrapolated", "detail": detail}
    label = "no steady" if until_steady and not a.summary["steady"] else "no skid"
    return {**out, "class": label, "detail": f"timestep {m.settings['timestep']:.3g} s"}


def _line(i: int, mode: str, verdict: dict) -> str:
    figures = "  ".join(
        f"{key} {diff:+.2e}" + ("" if bar is None else f" +-{bar:.1e} {'acc' if accepted else 'n/a'} "
                                                      f"{'in' if covered else 'OUT'}")
        for key, diff, bar, accepted, covered, _ in verdict["figures"])
    cost = ("" if verdict["cost"] is None
            else f", cost {verdict['cost']:.2f} first runs ({verdict['cost_steps']:.2f} in steps)")
    return (f"[{i:3d}] {mode:6s} {verdict['class']:16s} {figures}  ({verdict['detail']}; MuJoCo "
            f"{verdict['wall']:.1f} s{cost})")


def _task(item):
    i, params, mode, t_end, until_steady, budget = item
    return i, mode, params, judge(params, t_end, until_steady, budget)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--designs", type=int, default=200)
    parser.add_argument("--seed", type=int, default=50)
    parser.add_argument("--first", type=int, default=0, help="skip the designs before this one")
    parser.add_argument("--t-end", type=float, default=1.0, help="fixed-time runs' simulated time [s]")
    parser.add_argument("--cap", type=float, default=8.0, help="runs to the steady state: the cap [s]")
    parser.add_argument("--budget", type=float, default=300.0, help="wall-time budget per run [s]")
    parser.add_argument("--workers", type=int, default=1)
    parser.add_argument("--smoke", action="store_true", help="4 designs, 0.2 s, steady cap 1 s")
    args = parser.parse_args()
    if args.smoke:
        args.designs, args.t_end, args.cap = 4, 0.2, 1.0
    rng = np.random.default_rng(args.seed)
    designs = [draw(rng) for _ in range(args.designs)]
    items = [(i, p, mode, t_end, steady, args.budget) for i, p in enumerate(designs) if i >= args.first
             for mode, t_end, steady in [("fixed", args.t_end, False)]
             + ([("steady", args.cap, True)] if p.drive == "motor" else [])]
    started = time.perf_counter()
    verdicts = []
    if args.workers > 1:
        import multiprocessing

        with multiprocessing.get_context("spawn").Pool(args.workers) as pool:
            results = pool.imap(_task, items)
            for i, mode, params, verdict in results:
                verdicts.append((mode, verdict))
                print(_line(i, mode, verdict) + ("" if verdict["class"] in ("extrapolated", "no skid")
                                                 else f"\n      {describe(params)}"), flush=True)
    else:
        for item in items:
            i, mode, params, verdict = _task(item)
            verdicts.append((mode, verdict))
            print(_line(i, mode, verdict) + ("" if verdict["class"] in ("extrapolated", "no skid")
                                             else f"\n      {describe(params)}"), flush=True)
    summarize(verdicts, args, time.perf_counter() - started)


def summarize(verdicts: list, args, wall: float) -> None:
    """The totals (module docstring)."""
    print(f"\n{args.designs} designs, seed {args.seed}, {len(verdicts)} runs (fixed time and to the steady "
          f"state), {wall:.0f} s wall")
    classes = {}
    for mode, v in verdicts:
        classes[(mode, v["class"])] = classes.get((mode, v["class"]), 0) + 1
    for mode in ("fixed", "steady"):
        print(f"{mode:6s}: " + ", ".join(f"{c} {n}" for (m, c), n in sorted(classes.items()) if m == mode))
    answered = [v for _, v in verdicts if v["class"] not in ("up front", "equations failed")]
    refused = [v for v in answered if v["class"] == "refused"]
    print(f"refused: {len(refused)} of the {len(answered)} runs the equations answer "
          f"({100 * len(refused) / max(len(answered), 1):.1f} %; at most 5 % asked)")
    figures = [f for _, v in verdicts if v["class"] == "extrapolated" for f in v["figures"] if f[2] is not None]
    for label, chosen in (("accepted", True), ("not accepted", False)):
        group = [f for f in figures if f[3] == chosen]
        covered = sum(f[4] for f in group)
        within = sum(abs(f[1]) <= TOL[f[5]] for f in group)
        worst = max((abs(f[1]) / TOL[f[5]] for f in group), default=0.0)
        print(f"{label} figures: {len(group)}; the equations inside the error bar in {covered} "
              f"({100 * covered / max(len(group), 1):.1f} %), within the stated accuracy in {within} (worst "
              f"{worst:.2f} of it)")
    plain = [f for _, v in verdicts if v["class"] == "no skid" for f in v["figures"]]
    within = sum(abs(f[1]) <= TOL[f[5]] for f in plain)
    print(f"no-skid figures (one run): {len(plain)}, within the stated accuracy {within}")
    for label, key in (("wall time", "cost"), ("steps", "cost_steps")):
        costs = [v[key] for _, v in verdicts if v[key] is not None]
        if costs:
            print(f"cost of a skidding run in first runs (the same design's run where it does not skid), by {label}: "
                  f"mean {np.mean(costs):.2f}, median {np.median(costs):.2f}, largest {max(costs):.2f}; above 3: "
                  f"{sum(c > 3 for c in costs)} of {len(costs)}")


if __name__ == "__main__":
    main()
