"""Convergence evidence for the MuJoCo engine: timestep halving, and the envelope of the automatic settings.

Two studies, both kept out of the test suite's fast path:

- :func:`timestep_study`: halve the timestep (constraint time constant two
  steps) and watch the summary figures settle; where the analytic model
  describes the same mechanism, the distance to it.
- :func:`envelope_study`: the *automatic* settings (what a user gets with
  default options) over an envelope of designs and speeds: crank speed (t_end
  up to 5 s at the paper's torque), rod mass (1e-4..0.1 kg), L/r (1.1..20) and
  the module mass ratio (0.1..10), each against the analytic model of the same
  mechanism (one-way clutches for the ratchet, the paper's rule for the locks),
  with the timestep chosen, the accuracy figures and the wall time.

``python -m ipir_mujoco.studies.convergence [--quick]`` prints both tables
(the ones quoted in ``mjcf/README.md``).
"""

from __future__ import annotations

import argparse
import sys
import time
from typing import Callable, Sequence

from ipir_mujoco import registry
from ipir_mujoco.core.cycles import travel
from ipir_mujoco.core.options import progress_text, throttled
from ipir_mujoco.core.errors import SimulationError
from ipir_mujoco.core.params import RobotParams


FIGURES = ("revolutions", "x1_final", "x2_final")
TIMESTEPS = (4e-4, 2e-4, 1e-4, 5e-5, 2.5e-5)
CASES = {
    "paper's case": RobotParams(),
    "short rod, L/r = 1.5": RobotParams(L=0.075),
    "light front, heavy resistance": RobotParams(m2=0.3, F_r1=3.0, F_r2=3.0),
}
CLUTCHES = (("lock", "kinematic"), ("ratchet", "unilateral"))  # MuJoCo's clutch and its rule
# each MuJoCo clutch (ipir_mujoco.registry's variant) and the equations of the same mechanism: the exact geometry
# with the rod, under the paper's rule for the locks and with one-way clutches for the ratchet
PAIRS = {"lock": ("mujoco-lock", "analytic-exact"), "ratchet": ("mujoco-ratchet", "analytic-unilateral")}
TOLERANCE = 1e-3  # the envelope's target: MuJoCo within 0.1 % of the analytic model in revolutions and travel


def timestep_study(cases: dict[str, RobotParams] = CASES, timesteps: Sequence[float] = TIMESTEPS,
                   t_end: float = 1.0, progress: Callable[[str], None] = lambda _m: None) -> list[dict]:
    """One row per (case, clutch, timestep): summary figures, energy residual, distance to the equations.

    ``vs_analytic`` holds (MuJoCo - analytic) / |analytic| for each figure, the
    analytic model being the same mechanism: the exact geometry with rod mass, under
    the paper's rule for the locks and with one-way clutches for the ratchet.
    The runs record the accuracy monitor's figures (``accuracy``) instead of
    stopping on them: coarse steps are the point of the study.
    """
    rows = []
    for case, params in cases.items():
        references = {c: registry.run(PAIRS[c][1], params, t_end).summary for c, _ in CLUTCHES}
        for implementation, rule in CLUTCHES:
            reference = references[implementation]
            for dt in timesteps:
                progress(f"{case}, {implementation}, dt = {dt:g} s")
                started = time.perf_counter()
                run = registry.run(PAIRS[implementation][0], params, t_end, dt_out=4e-4, timestep=dt, accuracy="warn",
                                   progress=throttled(lambda t: progress(f"{case}, {implementation}, dt = {dt:g} s: "
                                                                         f"{t:.2f} / {t_end:g} s simulated")))
                s = run.summary
                row = {"case": case, "clutch": implementation, "rule": rule, "timestep": dt,
                       "wall_s": time.perf_counter() - started,
                       "residual_fraction": s["energy"]["residual_j"] / s["energy"]["motor_work_j"],
                       "accuracy": _figures(run.accuracy), **{key: s[key] for key in FIGURES}}
                row["vs_analytic"] = {k: (s[k] - reference[k]) / abs(reference[k]) for k in FIGURES}
                rows.append(row)
    return rows


def _figures(accuracy: dict) -> dict:
    return {k: accuracy[k] for k in ("residual_ratio", "loop_gap_m", "excursion_m")} | {"ok": accuracy["ok"]}


def envelope_cases(quick: bool = False) -> list[tuple[str, RobotParams, float]]:
    """(label, parameters, t_end [s]) over the envelope; ``quick``: its corners only."""
    base = RobotParams()
    speeds = (1.0, 3.0) if quick else (1.0, 2.0, 3.0, 5.0)
    rods = (1e-4, 0.1) if quick else (1e-4, 1e-3, 0.01, 0.1)
    ratios = (1.1, 20.0) if quick else (1.1, 1.5, 4.0, 10.0, 20.0)
    masses = ((1.0, 0.1), (0.1, 1.0)) if quick else ((1.0, 0.1), (1.0, 10.0), (0.1, 1.0), (10.0, 1.0))
    cases = [(f"speed: t_end = {t:g} s", base, t) for t in speeds]
    cases += [(f"rod mass {m:g} kg", base.replace(rod_mass=m), 1.0) for m in rods]
    cases += [(f"L/r = {q:g}", base.replace(L=q * base.r), 1.0) for q in ratios]
    cases += [(f"m1 = {m1:g} kg, m2 = {m2:g} kg", base.replace(m1=m1, m2=m2), 1.0) for m1, m2 in masses]
    return cases


def envelope_study(quick: bool = False, progress: Callable[[str], None] = lambda _m: None,
                   clutches: Sequence[tuple[str, str]] = (("ratchet", "unilateral"), ("lock", "kinematic")),
                   cases: Sequence[tuple[str, RobotParams, float]] | None = None) -> dict:
    """MuJoCo with default (automatic) settings against the analytic model over the envelope.

    Returns ``{"rows": [...], "worst_error": float, "worst_case": str,
    "mujoco_wall_s": float, "analytic_wall_s": float, "tolerance": 1e-3}``;
    each row: case, clutch, rule, t_end, the timestep chosen and how often it
    was halved, ``error`` {revolutions, travel, x1_final, x2_final} (relative,
    signed), the accuracy figures, and both wall times; or, for a run the
    accuracy monitor stopped, ``stopped`` (its message). The runs use the
    default options (accuracy 'stop', automatic timestep). ``quick`` runs the
    corners only. ``cases`` replaces the envelope by other (label, parameters,
    t_end [s]) triples.
    """
    rows = []
    for label, params, t_end in (envelope_cases(quick) if cases is None else cases):
        for implementation, rule in clutches:
            progress(f"{label}, {implementation}")
            started = time.perf_counter()
            reference = registry.run(PAIRS[implementation][1], params, t_end, dt_out=1e-3)
            analytic_wall = time.perf_counter() - started
            beat = throttled(lambda t, label=label, implementation=implementation, t_end=t_end: progress(
                f"{label}, {implementation}: " + progress_text(t, t_end)))
            try:
                run = registry.run(PAIRS[implementation][0], params, t_end, dt_out=1e-3, progress=beat)
            except SimulationError as exc:  # default options: a run the monitor stops is a finding, not a crash
                rows.append({"case": label, "clutch": implementation, "rule": rule, "t_end": t_end,
                             "stopped": str(exc), "analytic_wall_s": analytic_wall})
                continue
            error = {k: (run.summary[k] - reference.summary[k]) / abs(reference.summary[k]) for k in FIGURES}
            moved = travel(run.series)[-1] - travel(run.series)[0]
            moved_ref = travel(reference.series)[-1] - travel(reference.series)[0]
            error["travel"] = (moved - moved_ref) / abs(moved_ref)
            rows.append({"case": label, "clutch": implementation, "rule": rule, "t_end": t_end,
                         "timestep": run.settings["timestep"], "refinements": len(run.settings["refinements"]),
                         "error": error, "accuracy": _figures(run.accuracy), "wall_s": run.wall_time_s,
                         "analytic_wall_s": analytic_wall})
    finished = [r for r in rows if "error" in r]
    worst = max(finished, key=lambda r: max(abs(r["error"]["revolutions"]), abs(r["error"]["travel"])))
    return {"rows": rows, "tolerance": TOLERANCE, "stopped": len(rows) - len(finished),
            "worst_error": max(abs(worst["error"]["revolutions"]), abs(worst["error"]["travel"])),
            "worst_case": f"{worst['case']}, {worst['clutch']}",
            "mujoco_wall_s": sum(r.get("wall_s", 0.0) for r in rows),
            "analytic_wall_s": sum(r["analytic_wall_s"] for r in rows)}


def markdown_table(rows: list[dict]) -> str:
    lines = ["| case | clutch | dt [s] | revolutions | x1 [m] | x2 [m] | vs equations (rev, x1, x2) "
             "| energy residual / motor work | wall [s] |", "|---|---|---|---|---|---|---|---|---|"]
    for row in rows:
        versus = row.get("vs_analytic")
        versus_text = ", ".join(f"{100 * versus[k]:+.3f} %" for k in FIGURES) if versus else ""
        lines.append(f"| {row['case']} | {row['clutch']} ({row['rule']}) | {row['timestep']:g} "
                     f"| {row['revolutions']:.5f} | {row['x1_final']:.5f} | {row['x2_final']:.5f} | {versus_text} "
                     f"| {row['residual_fraction']:+.1e} | {row['wall_s']:.1f} |")
    return "\n".join(lines)


def envelope_table(study: dict) -> str:
    lines = ["| case | clutch (vs analytic) | t_end [s] | auto dt [s] | revolutions | travel | worst residual "
             "| worst loop gap [m] | MuJoCo wall [s] |", "|---|---|---|---|---|---|---|---|---|"]
    for r in study["rows"]:
        if "stopped" in r:
            lines.append(f"| {r['case']} | {r['clutch']} ({r['rule']}) | {r['t_end']:g} | stopped: {r['stopped']} "
                         "| | | | | |")
            continue
        a = r["accuracy"]
        dt = f"{r['timestep']:.3g}" + (f" ({r['refinements']} halvings)" if r["refinements"] else "")
        lines.append(f"| {r['case']} | {r['clutch']} ({r['rule']}) | {r['t_end']:g} | {dt} "
                     f"| {100 * r['error']['revolutions']:+.4f} % | {100 * r['error']['travel']:+.4f} % "
                     f"| {a['residual_ratio']:+.1e} | {a['loop_gap_m']:.1e} | {r['wall_s']:.1f} |")
    lines.append("")
    lines.append(f"Worst error over the envelope: {100 * study['worst_error']:.4f} % ({study['worst_case']}); "
                 f"runs stopped by the accuracy monitor: {study['stopped']}; "
                 f"MuJoCo wall time {study['mujoco_wall_s']:.0f} s in all (analytic {study['analytic_wall_s']:.0f} s).")
    return "\n".join(lines)


# the envelope corners validate --quick still runs: the lightest rod and the shortest L/r
SMOKE_CASES = ("rod mass 0.0001 kg", "L/r = 1.1")

def convergence_evidence(params: RobotParams, quick: bool, progress: Callable[[str], None]) -> dict:
    """MuJoCo's figures against its timestep, the equations' against their tolerance (paper's case)."""
    from .paper_reference import differences_from_paper

    # the step the engine chooses by itself for each clutch at this design (the ladder's 1 s runs), and half of it
    auto = {implementation: registry.timestep(PAIRS[implementation][0], params, 1.0, 1e-4)
            for implementation, _ in CLUTCHES}
    timesteps = (1e-4, 5e-5, 2.5e-5) if quick else (4e-4, 2e-4, 1e-4, 5e-5, 2.5e-5)
    timesteps = tuple(sorted(set(timesteps) | {h / 2 for h in auto.values()}, reverse=True))
    label = "paper's case" if not differences_from_paper(params) else "this design"
    rows = timestep_study({label: params}, timesteps, progress=progress)
    equations = []
    for rtol in ((1e-10, 1e-12) if quick else (1e-6, 1e-8, 1e-10, 1e-12)):
        run = registry.run("analytic-unilateral", params, 1.0, rtol=rtol, atol=rtol * 1e-2, dt_out=1e-3)
        energy = run.summary["energy"]
        equations.append({"rtol": rtol, **{k: run.summary[k] for k in ("revolutions", "x1_final", "x2_final")},
                          "residual_fraction": energy["residual_j"] / energy["motor_work_j"]})
    def spread(items, key_filter):
        chosen = [r for r in items if key_filter(r)]
        return max(abs(a[k] - b[k]) / abs(b[k]) for a in chosen for b in chosen
                   for k in ("revolutions", "x1_final", "x2_final"))

    # numerical error of the defaults: the largest change among each clutch's own automatic step and the finer
    # ones tried (half of it at least)
    mj_error = max(spread(rows, lambda r, c=c: r["clutch"] == c and r["timestep"] <= auto[c] * (1 + 1e-9))
                   for c in auto)
    eq_error = spread(equations, lambda r: r["rtol"] <= 1e-10)
    # the automatic settings over the envelope of designs and speeds (the corners; the whole envelope is in
    # the package's mjcf/README.md); --quick checks two of the corners with the ratchet only
    corners = envelope_cases(quick=True)
    envelope = (envelope_study(cases=[c for c in corners if c[0] in SMOKE_CASES], progress=progress,
                               clutches=(("ratchet", "unilateral"),))
                if quick else envelope_study(quick=True, progress=progress))
    return {"mujoco": rows, "equations": equations, "mujoco_default_error": mj_error, "mujoco_auto_timestep": auto,
            "equations_default_error": eq_error, "envelope": envelope}


def main(argv: list[str] | None = None) -> int:  # pragma: no cover - a study run on demand
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="the envelope's corners only")
    parser.add_argument("--envelope-only", action="store_true", help="skip the timestep-halving table")
    args = parser.parse_args(argv)
    say = lambda m: print(m, file=sys.stderr, flush=True)  # noqa: E731
    if not args.envelope_only:
        print(markdown_table(timestep_study(progress=say)))
        print()
    print(envelope_table(envelope_study(args.quick, progress=say)))
    return 0


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
