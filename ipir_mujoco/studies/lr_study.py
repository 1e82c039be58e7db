"""Where L >> r breaks down: the first-order model against the real linkage over L/r.

At fixed r and every other parameter as given, L/r is swept on a log grid. For
each ratio four runs under the paper's clutch rule: the first-order equations
(the paper's), the exact slider-crank equations with the same massless rod
(so the difference is the L >> r assumption alone), and MuJoCo's real linkage
beside the exact equations of that same linkage (the parameter set's rod: MuJoCo
needs a rod with mass, and comparing it with the massless equations would
measure the rod, not the engine).
The divergence of each summary figure is (first order - exact) / |exact|
(``divergence``), MuJoCo's (MuJoCo - exact with the rod) / |exact with the rod|
(``mujoco_vs_exact``); at matching crank angle the gap S and its rate S_dot are
compared too (largest error over the run, as a fraction of the stroke 2r and of
the largest |S_dot|).

A threshold "off by more than 1 % below L/r = X" is bracketed by the sweep: X
lies between the largest ratio where the divergence exceeds the level and the
next ratio of the grid, so the grid spacing is the threshold's resolution.
"""

from __future__ import annotations

import time
from typing import Callable, Sequence

import numpy as np

from ipir_mujoco import registry
from ipir_mujoco.core.params import RobotParams

from .compare import compare_runs, relative_change

FIGURES = ("revolutions", "x1_final", "x2_final", "v1_max", "v2_max", "first_contraction_end_s")
ANGLE_FIGURES = ("S_at_angle", "S_dot_at_angle")
LEVELS = (0.01, 0.05)
RATIOS_FULL = tuple(float(x) for x in np.geomspace(1.05, 20.0, 14))
RATIOS_QUICK = tuple(float(x) for x in np.geomspace(1.05, 20.0, 5))


def lr_study(params: RobotParams, ratios: Sequence[float] = RATIOS_FULL, t_end: float = 1.0, dt_out: float = 1e-4,
             progress: Callable[[str], None] = lambda _m: None) -> dict:
    """Run the sweep; returns {ratios, rows, thresholds} (see the module docstring)."""
    massless = params.replace(rod_mass=0.0, rod_inertia=0.0)
    rows = []
    for i, ratio in enumerate(ratios, start=1):
        started = time.perf_counter()
        L = ratio * params.r
        first = registry.run("analytic-approx", massless.replace(L=L), t_end, dt_out=dt_out)
        exact = registry.run("analytic-exact", massless.replace(L=L), t_end, dt_out=dt_out)
        with_rod = registry.run("analytic-exact", params.replace(L=L), t_end, dt_out=dt_out)
        physics = registry.run("mujoco-lock", params.replace(L=L), t_end, dt_out=dt_out)
        angle = compare_runs(exact, first)["angle_grid"]
        row = {"ratio": ratio, "L": L,
               "first_order": {k: first.summary[k] for k in FIGURES},
               "exact": {k: exact.summary[k] for k in FIGURES},
               "exact_with_rod": {k: with_rod.summary[k] for k in FIGURES},
               "mujoco": {k: physics.summary[k] for k in FIGURES},
               "divergence": {k: relative_change(first.summary[k], exact.summary[k]) for k in FIGURES},
               "mujoco_vs_exact": {k: relative_change(physics.summary[k], with_rod.summary[k]) for k in FIGURES}}
        row["divergence"]["S_at_angle"] = angle["S"]["max"] / (2 * params.r)
        row["divergence"]["S_dot_at_angle"] = angle["S_dot"]["max"] / angle["S_dot"]["scale"]
        rows.append(row)
        progress(f"L/r {i}/{len(ratios)}: L/r = {ratio:.3g}, first order off by "
                 f"{100 * row['divergence']['revolutions']:+.2f} % in revolutions "
                 f"({time.perf_counter() - started:.1f} s)")
    return {"ratios": list(ratios), "rows": rows, "thresholds": thresholds(rows)}


def thresholds(rows: list[dict]) -> dict:
    """For each figure and level: the L/r below which |divergence| exceeds the level, bracketed by the grid.

    ``{figure: {"1%": {"between": [lo, hi]} | {"below_sweep": True} | {"whole_sweep": True}}}``:
    lo is the largest ratio where |divergence| > level, hi the next ratio of the
    grid (where it is within the level). ``below_sweep``: never off by that much
    in the sweep; ``whole_sweep``: off by more even at the largest ratio.
    """
    ratios = [row["ratio"] for row in rows]
    result = {}
    for figure in FIGURES + ANGLE_FIGURES:
        values = [row["divergence"][figure] for row in rows]
        per_level = {}
        for level in LEVELS:
            over = [i for i, v in enumerate(values) if v is not None and abs(v) > level]
            key = f"{100 * level:g}%"
            if not over:
                per_level[key] = {"below_sweep": True, "smallest_ratio": ratios[0]}
            elif over[-1] == len(ratios) - 1:
                per_level[key] = {"whole_sweep": True, "largest_ratio": ratios[-1]}
            else:
                per_level[key] = {"between": [ratios[over[-1]], ratios[over[-1] + 1]]}
        result[figure] = per_level
    return result


def describe_threshold(entry: dict) -> str:
    """'L/r < 2.4 (between 1.9 and 2.9)' style text for one threshold entry."""
    if "between" in entry:
        lo, hi = entry["between"]
        return f"below L/r ~ {np.sqrt(lo * hi):.2g} (between {lo:.3g} and {hi:.3g})"
    if entry.get("below_sweep"):
        return f"never in the sweep (L/r >= {entry['smallest_ratio']:.3g})"
    return f"at every L/r of the sweep (up to {entry['largest_ratio']:.3g})"
