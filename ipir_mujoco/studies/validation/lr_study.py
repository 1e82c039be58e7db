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
next ratio of the grid, so the grid spacing is the threshold's resolution. For
crank revolutions (:data:`REFINED`), the report's headline, the bracket is then
narrowed on the equations themselves to :data:`CROSSING_TOL` in L/r by the
atlas's own root-finding (:func:`.atlas_adaptive.refine_crossings`, on the same
pair of runs as the atlas's ``first-order-kinematics``), so that the report and
``ipir-mujoco atlas --vary L=...`` state one crossing.
"""

from __future__ import annotations

import time
from typing import Callable, Sequence

import numpy as np

from ipir_mujoco import registry
from ipir_mujoco.core.params import RobotParams

from ..comparison.compare import compare_runs, relative_change

FIGURES = ("revolutions", "x1_final", "x2_final", "v1_max", "v2_max", "first_contraction_end_s")
ANGLE_FIGURES = ("S_at_angle", "S_dot_at_angle")
LEVELS = (0.01, 0.05)
REFINED = ("revolutions",)  # figures whose thresholds are narrowed past the grid's bracket
CROSSING_TOL = 2e-3  # L/r: the narrowed bracket's width (3 significant digits of a crossing near 5)
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
    found = thresholds(rows)
    for figure in REFINED:
        for key, entry in found[figure].items():
            if "between" in entry:
                started = time.perf_counter()
                entry.update(refine_threshold(massless, figure, float(key.rstrip("%")) / 100, entry["between"],
                                              t_end, dt_out))
                progress(f"L/r: first order off by {key} in {figure} below L/r = {entry['crossing']:.4g} "
                         f"({time.perf_counter() - started:.1f} s)")
    return {"ratios": list(ratios), "rows": rows, "thresholds": found}


def divergence(params: RobotParams, ratio: float, figure: str, t_end: float, dt_out: float) -> float:
    """(first order - exact) / |exact| of a summary figure at L = ratio r (``params``: the massless rod's)."""
    L = ratio * params.r
    first = registry.run("analytic-approx", params.replace(L=L), t_end, dt_out=dt_out).summary[figure]
    exact = registry.run("analytic-exact", params.replace(L=L), t_end, dt_out=dt_out).summary[figure]
    return relative_change(first, exact)


def refine_threshold(params: RobotParams, figure: str, level: float, between: Sequence[float], t_end: float,
                     dt_out: float, tol: float = CROSSING_TOL) -> dict:
    """The crossing |divergence| = ``level`` inside the grid's bracket ``between`` [L/r], narrowed to ``tol`` by
    :func:`.atlas_adaptive.refine_crossings` (the atlas's k-section): {"crossing": L/r, "crossing_interval": [lo,
    hi], "crossing_L_m": L at the crossing}. ``params``: the massless rod's design."""
    from ..idealizations.atlas_adaptive import refine_crossings

    lo, hi = map(float, between)
    ends = np.array([divergence(params, x, figure, t_end, dt_out) for x in (lo, hi)])

    def evaluate(U: np.ndarray) -> list:
        return [divergence(params, float(x), figure, t_end, dt_out) for x in U[:, 0]]

    found = refine_crossings(np.array([lo, hi]), ends, level, evaluate, workers=1, tol=tol)
    if not found:  # the grid's bracket does not cross on a second look (cannot happen for a smooth divergence)
        return {}
    x, a, b = found[-1]
    return {"crossing": x, "crossing_interval": [a, b], "crossing_L_m": x * params.r}


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
    """'below L/r = 5.09 (L = 0.254 m)' for a narrowed threshold, 'below an L/r between 6.44 and 8.08' for one
    the grid brackets only (no midpoint: the bracket is all the grid knows)."""
    if "crossing" in entry:
        return f"below L/r = {entry['crossing']:.3g} (L = {entry['crossing_L_m']:.3g} m)"
    if "between" in entry:
        lo, hi = entry["between"]
        return f"below an L/r between {lo:.3g} and {hi:.3g}"
    if entry.get("below_sweep"):
        return f"never in the sweep (L/r >= {entry['smallest_ratio']:.3g})"
    return f"at every L/r of the sweep (up to {entry['largest_ratio']:.3g})"
