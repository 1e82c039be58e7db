"""Pictures of a sweep: lines for one varied parameter, heatmaps for two, best designs.

The heatmap shows the first engine's mean forward speed over the two varied
parameters, with the contours where the second engine diverges from it by 1 %
and 5 % (in crank revolutions) drawn over it: where the simpler model can be
trusted, and where not.
"""

from __future__ import annotations

import csv
from pathlib import Path

import numpy as np

from .plots import new_figure
from ..studies.sweep_metrics import METRICS

# metrics where larger is better; the rest (forces, jumps) are better small
LARGER_IS_BETTER = ("mean_speed_mps", "distance_per_rev_m", "efficiency")
UNITS = {"revolutions": "rev", "mean_speed_mps": "m/s", "distance_per_rev_m": "m", "efficiency": "-",
         "peak_clutch_reaction_n": "N", "peak_rod_force_n": "N", "accel_jump_mps2": "m/s^2", "stalled": "0/1"}


def read_results(path: str | Path) -> dict[str, np.ndarray]:
    """results.csv as columns (numbers as float, empty cells as NaN; 'error' as str)."""
    with Path(path).open(newline="") as fh:
        rows = list(csv.DictReader(fh))
    columns = {}
    for name in (rows[0].keys() if rows else []):
        if name == "error":
            columns[name] = np.array([r[name] for r in rows], dtype=object)
        else:
            columns[name] = np.array([float(r[name]) if r[name] != "" else np.nan for r in rows])
    return columns


def best_designs(columns: dict[str, np.ndarray], axes: list[str], engines: list[str]) -> list[dict]:
    """The best design per engine and metric (ignoring failed and stalled designs)."""
    best = []
    for engine in engines:
        ok = np.array([not e for e in columns["error"]]) & (columns[f"{engine}:stalled"] == 0)
        for metric in METRICS:
            if metric in ("stalled", "revolutions"):
                continue
            values = np.where(ok, columns[f"{engine}:{metric}"], np.nan)
            if np.all(np.isnan(values)):
                continue
            i = int(np.nanargmax(values) if metric in LARGER_IS_BETTER else np.nanargmin(values))
            best.append({"engine": engine, "metric": metric, "value": float(values[i]),
                         "design_id": int(columns["design_id"][i]), **{a: float(columns[a][i]) for a in axes}})
    return best


def plot_sweep(results: str | Path, axes: list[str], engines: list[str], out: str | Path) -> list[Path]:
    """Write the sweep's figures into ``out``; return their paths."""
    columns = read_results(results)
    out = Path(out)
    written = []
    if len(axes) == 1:
        x = columns[axes[0]]
        order = np.argsort(x)
        shown = ("mean_speed_mps", "efficiency", "distance_per_rev_m", "peak_clutch_reaction_n", "peak_rod_force_n",
                 "accel_jump_mps2")
        fig, panels = new_figure(len(shown), height=2.2)
        for ax, metric in zip(panels, shown):
            for engine in engines:
                ax.plot(x[order], columns[f"{engine}:{metric}"][order], "o-", ms=3, label=engine)
            ax.set(ylabel=f"{metric} [{UNITS[metric]}]")
            ax.grid(alpha=0.3)
        panels[0].legend(fontsize="small")
        panels[-1].set_xlabel(axes[0])
        path = out / "sweep_lines.png"
        fig.savefig(path, dpi=110)
        written.append(path)
    elif len(axes) >= 2:
        x, y = columns[axes[0]], columns[axes[1]]
        speed = columns[f"{engines[0]}:mean_speed_mps"]
        fig, (ax,) = new_figure(1, height=5.0)
        grid = _as_grid(x, y, speed)
        if grid is not None:
            xs, ys, zs = grid
            mesh = ax.pcolormesh(xs, ys, zs, shading="nearest", cmap="viridis")
        else:
            mesh = ax.tricontourf(x, y, speed, levels=20, cmap="viridis")
        fig.colorbar(mesh, ax=ax, label=f"{engines[0]} mean forward speed [m/s]")
        if len(engines) > 1:
            divergence = np.abs(columns[f"divergence:{engines[1]}:revolutions"]) * 100
            finite = divergence[np.isfinite(divergence)]
            low, high = (finite.min(), finite.max()) if finite.size else (np.nan, np.nan)
            levels = [level for level in (1, 5) if low < level < high]
            if levels:
                drawn = _as_grid(x, y, divergence)
                draw = ax.contour if drawn is not None else ax.tricontour
                contours = draw(*(drawn if drawn is not None else (x, y, divergence)), levels=levels,
                                colors=["white", "red"][:len(levels)], linewidths=1.5)
                ax.clabel(contours, fmt=lambda v: f"{v:g} %", fontsize="small")
                title = (f"contours: {engines[1]} differs from {engines[0]} by "
                         f"{' / '.join(f'{v} %' for v in levels)} in revolutions")
            else:
                title = (f"{engines[1]} differs from {engines[0]} by {low:.2g} to {high:.2g} % in revolutions "
                         "everywhere: no 1 % / 5 % contour inside the map")
        else:
            title = "mean forward speed"
        failed = np.array([bool(e) for e in columns["error"]])
        if failed.any():
            ax.plot(x[failed], y[failed], "kx", ms=5, label="failed design")
            ax.legend(fontsize="small", loc="upper right")
        ax.set(xlabel=axes[0], ylabel=axes[1], title=title)
        path = out / "sweep_heatmap.png"
        fig.savefig(path, dpi=110)
        written.append(path)
    return written


def _as_grid(x, y, z):
    """(X, Y, Z) 2-D arrays if the points form a full grid, else None."""
    xs, ys = np.unique(x), np.unique(y)
    if xs.size * ys.size != x.size:
        return None
    Z = np.full((ys.size, xs.size), np.nan)
    Z[np.searchsorted(ys, y), np.searchsorted(xs, x)] = z
    return xs, ys, Z
