"""Timestep-convergence study of the MuJoCo engine.

Halve the timestep (with the constraint time constant kept at two steps) and
watch the summary figures settle; where the analytic model describes the same
mechanism (locks with the paper's rule against the exact geometry with rod
mass), also show the distance to it. Run ``python -m ipir_mujoco.convergence``
for the table quoted in ``mjcf/README.md``.
"""

from __future__ import annotations

import sys
import time
from typing import Callable, Sequence

from ipir_mujoco import analytic
from ipir_mujoco.analytic.params import RobotParams

from ..engine import simulate_mujoco
from ..engine.model import SolverSettings

FIGURES = ("revolutions", "x1_final", "x2_final")
TIMESTEPS = (4e-4, 2e-4, 1e-4, 5e-5, 2.5e-5)
CASES = {
    "paper's case": RobotParams(),
    "short rod, L/r = 1.5": RobotParams(L=0.075),
    "light front, heavy resistance": RobotParams(m2=0.3, F_r1=3.0, F_r2=3.0),
}
CLUTCHES = (("lock", "kinematic"), ("ratchet", "unilateral"))


def timestep_study(cases: dict[str, RobotParams] = CASES, timesteps: Sequence[float] = TIMESTEPS,
                   t_end: float = 1.0, progress: Callable[[str], None] = lambda _m: None) -> list[dict]:
    """One row per (case, clutch, timestep): summary figures, energy residual, distance to the equations.

    ``vs_analytic`` (lock + paper's rule only) holds (MuJoCo - analytic) / |analytic|
    for each figure, the analytic model being the exact geometry with rod mass.
    """
    rows = []
    for case, params in cases.items():
        reference = analytic.simulate(params, "exact", "kinematic", t_end).summary
        for implementation, rule in CLUTCHES:
            for dt in timesteps:
                progress(f"{case}, {implementation}, dt = {dt:g} s")
                started = time.perf_counter()
                run = simulate_mujoco(params, rule, implementation, t_end, dt_out=4e-4,
                                      settings=SolverSettings(timestep=dt))
                s = run.summary
                row = {"case": case, "clutch": implementation, "rule": rule, "timestep": dt,
                       "wall_s": time.perf_counter() - started,
                       "residual_fraction": s["energy"]["residual_j"] / s["energy"]["motor_work_j"],
                       **{key: s[key] for key in FIGURES}}
                if implementation == "lock":
                    row["vs_analytic"] = {k: (s[k] - reference[k]) / abs(reference[k]) for k in FIGURES}
                rows.append(row)
    return rows


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


if __name__ == "__main__":  # pragma: no cover
    table = markdown_table(timestep_study(progress=lambda m: print(m, file=sys.stderr, flush=True)))
    print(table)
