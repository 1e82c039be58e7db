"""Benchmark: finite grip over its whole envelope, both engines, at fixed time and to the steady state.

Run on demand (not part of the test suite; CPU-heavy, one design at a time):

    python bench/grip_envelope.py [--designs 200] [--seed 33] [--t-end 1] [--cap 10] [--budget 300]
    python bench/grip_envelope.py --smoke      # 6 short designs, seconds

Designs (numpy's ``default_rng(seed)``; rigid one-way clutches, the robot from rest):
log-uniform m1, m2 in [0.3, 3] kg, r in [0.02, 0.08] m, J_A in [2e-4, 1e-2] kg m^2, F_r1, F_r2 in [0.2, 5] N;
L / r uniform in [1.5, 6]; phi0 uniform in [0, 2 pi); incline uniform in [-90, 90] deg; half under a constant
torque M (log-uniform [0.05, 1] N m), half under the motor, weak or strong (M_stall log-uniform [0.1, 2] N m,
omega_noload uniform [10, 60] rad/s); mu_wall uniform in [0.05, 1] and each F_ni log-uniform in [1, 300] N
drawn apart (an asymmetric press), so that the grip runs from far below the demand (both modules skid every
stroke, or the robot slides away) to far above it (nothing skids).

Each design runs the analytic one-way model (``analytic-unilateral``) and MuJoCo's slide model
(``mujoco-ratchet``) at their default settings, as a user would (MuJoCo's accuracy monitor in its default
'stop' mode, its skid check on): for ``--t-end`` seconds, and, under the motor, to the steady state (``--cap``
the cap). Each pair is judged against the accuracy MuJoCo states:

- fixed time: revolutions (relative to at least 0.1 revolution) and each module's travel (relative to at least
  a tenth of a stroke, as the skid check judges it) within 1e-3;
- to the steady state: the steady speed and the energy per metre within 3e-4;

and sorted into ``within``; ``flagged`` (MuJoCo stopped with its accuracy figure, or finished with a figure
over its tolerance in its accuracy record, e.g. a skid check that did not converge); ``refused`` (either engine
refused the design in one line); ``failed`` (another SimulationError with its one-line reason: the analytic
engine's switch budget, a wall-time budget); ``no steady`` (either engine reports no steady state by the cap:
it says so, no steady figure); ``MISS`` (both finished without a flag and differ by more than the stated
accuracy: the silent miss this benchmark exists to find). Prints each design's class and largest relative
difference, the counts per class and the worst unflagged difference.
"""

from __future__ import annotations

import argparse
import math
import time

import numpy as np

from ipir_mujoco import registry
from ipir_mujoco.analytic import ParameterError, RobotParams, SimulationError
from ipir_mujoco.engine.run.skid_check import TRAVEL_FLOOR

FIXED_TOL, STEADY_TOL = 1e-3, 3e-4


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
    """(status, RunResult or one-line reason, wall [s]): status 'ok', 'refused', 'flagged' (MuJoCo's monitor
    stopped it) or 'failed'."""
    started = time.perf_counter()
    try:
        result = registry.run(variant, params, t_end, dt_out=1e-3, until_steady=until_steady, wall_budget_s=budget)
        return "ok", result, time.perf_counter() - started
    except ParameterError as exc:
        return "refused", str(exc), time.perf_counter() - started
    except SimulationError as exc:
        flagged = "accuracy check failed" in str(exc)
        return ("flagged" if flagged else "failed"), str(exc), time.perf_counter() - started


def differences(a, m, until_steady: bool) -> dict[str, float]:
    """MuJoCo's relative differences from the equations (module docstring's scales)."""
    sa, sm = a.summary, m.summary
    if until_steady:
        return {k: abs(sm[k] - sa[k]) / abs(sa[k]) for k in ("steady_speed_m_s", "energy_per_metre_j_m")
                if sa[k] is not None and sm[k] is not None and sa[k] != 0}
    floor = TRAVEL_FLOOR * 2 * a.params.r
    out = {"revolutions": abs(sm["revolutions"] - sa["revolutions"]) / max(abs(sa["revolutions"]), 0.1)}
    for k in ("x1_final", "x2_final"):
        out[k] = abs(sm[k] - sa[k]) / max(abs(sa[k]), floor)
    return out


def judge(params: RobotParams, t_end: float, until_steady: bool, budget: float) -> tuple[str, str, float, float]:
    """(class, detail, largest relative difference or nan, MuJoCo's wall time [s]) of one design and mode."""
    (sa, a, wa), (sm, m, wm) = (run(v, params, t_end, until_steady, budget)
                                for v in ("analytic-unilateral", "mujoco-ratchet"))
    if "refused" in (sa, sm):
        return "refused", a if sa == "refused" else m, math.nan, wm
    if sm == "flagged":
        return "flagged", m, math.nan, wm
    if "failed" in (sa, sm):
        return "failed", a if sa == "failed" else m, math.nan, wm
    if until_steady and not (a.summary["steady"] and m.summary["steady"]):
        who = [name for name, r in (("analytic", a), ("mujoco", m)) if not r.summary["steady"]]
        return "no steady", f"no steady state by {t_end:g} s: {', '.join(who)}", math.nan, wm
    diff = differences(a, m, until_steady)
    worst_key = max(diff, key=diff.get) if diff else None
    worst = diff[worst_key] if diff else math.nan
    tol = STEADY_TOL if until_steady else FIXED_TOL
    slips = f"slips {m.summary['slip1_m']:.3g}/{m.summary['slip2_m']:.3g} m"
    check = m.accuracy.get("skid_check")
    detail = f"{worst_key} {worst:.2e}, {slips}, skid check {check}, dt {m.settings['timestep']:.3g} s"
    if not m.accuracy.get("ok", True):
        return "flagged", detail + f"; {m.accuracy['violations'][0]['figure']}", worst, wm
    return ("within" if worst <= tol else "MISS"), detail, worst, wm


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--designs", type=int, default=200)
    parser.add_argument("--seed", type=int, default=33)
    parser.add_argument("--t-end", type=float, default=1.0, help="fixed-time runs' simulated time [s]")
    parser.add_argument("--cap", type=float, default=10.0, help="runs to the steady state: the cap [s]")
    parser.add_argument("--budget", type=float, default=300.0, help="wall-time budget per run [s]")
    parser.add_argument("--smoke", action="store_true", help="6 designs, 0.3 s, steady cap 1 s")
    args = parser.parse_args()
    if args.smoke:
        args.designs, args.t_end, args.cap = 6, 0.3, 1.0
    rng = np.random.default_rng(args.seed)
    designs = [draw(rng) for _ in range(args.designs)]
    counts: dict[tuple[str, str], int] = {}
    worst_unflagged: dict[str, tuple[float, int]] = {"fixed": (0.0, -1), "steady": (0.0, -1)}
    started = time.perf_counter()
    for i, p in enumerate(designs):
        modes = [("fixed", args.t_end, False)] + ([("steady", args.cap, True)] if p.drive == "motor" else [])
        for mode, t_end, until_steady in modes:
            verdict, detail, worst, wall = judge(p, t_end, until_steady, args.budget)
            counts[(mode, verdict)] = counts.get((mode, verdict), 0) + 1
            if verdict in ("within", "MISS") and worst > worst_unflagged[mode][0]:
                worst_unflagged[mode] = (worst, i)
            print(f"[{i:3d}] {mode:6s} {verdict:9s} {detail}  (MuJoCo {wall:.1f} s)", flush=True)
            if verdict != "within":
                print(f"      {describe(p)}", flush=True)
        if (i + 1) % 10 == 0:  # running counts, so that a run cut short still tells
            print(f"  after {i + 1} designs ({time.perf_counter() - started:.0f} s): "
                  + ", ".join(f"{m} {v} {n}" for (m, v), n in sorted(counts.items())), flush=True)
    print(f"\n{args.designs} designs, seed {args.seed}, {time.perf_counter() - started:.0f} s wall")
    for mode in ("fixed", "steady"):
        row = {v: n for (m, v), n in counts.items() if m == mode}
        print(f"{mode:6s}: " + ", ".join(f"{v} {n}" for v, n in sorted(row.items())))
        value, design = worst_unflagged[mode]
        print(f"        worst unflagged difference {value:.2e} (design {design}; stated "
              f"{STEADY_TOL if mode == 'steady' else FIXED_TOL:.0e})")


if __name__ == "__main__":
    main()
