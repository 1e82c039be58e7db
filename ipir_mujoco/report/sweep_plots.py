"""Pictures of a sweep: lines for one varied parameter, heatmaps for two, best designs.

The heatmap colours one metric of the first engine that gives it (a batched
MuJoCo run gives no peak forces) over the first two varied parameters (the
steady speed for a sweep run to steady state, else the mean forward speed;
``--plot-metric`` chooses another) and draws over it the
contours where the second engine diverges from the first by 1 % and 5 % in
that metric (for a metric without a divergence column in revolutions, else in
the steady or mean speed where revolutions are not compared): where
the simpler model can be trusted, and where not. A second panel maps that
divergence itself. Axes carry their units; an axis swept log-spaced (``:log``)
is drawn on a log scale.
"""

from __future__ import annotations

import csv
import textwrap
from pathlib import Path

import numpy as np

from ipir_mujoco.core.errors import ParameterError
from ipir_mujoco.core.params import parameter_units

from ..studies.sweeps.sweep_files import DIVERGENCE
from ..studies.sweeps.sweep_metrics import LEGACY, METRICS, UNITS, described
from ..core.figures import new_figure

# metrics where larger is better; the rest (energy per metre, forces, jumps, time to settle) are better small
LARGER_IS_BETTER = ("mean_speed_m_s", "steady_speed_m_s", "distance_per_rev_m", "efficiency")
NOT_RANKED = ("revolutions", "steady", "stalled", "residual_ratio", "loop_gap_m", "mean_omega_rad_s", *LEGACY)
# a panel whose values all lie within this relative band of their mean is drawn flat across that band: MuJoCo's
# accuracy monitor holds its runs' energy to 1e-3 of what the robot is given (mjcf/README.md), and an engine's
# steady figures lie within 1e-4 to 1e-3 of the periodic limit, so a design-to-design wiggle inside it is
# numerics, not design
RESOLVED = 1e-3
RANKING = (("steady_speed_m_s", "highest first"), ("energy_per_metre_j_m", "lowest first"))
RANKED = 10  # designs listed per ranking


def check_plot_metric(metric: str | None, until_steady: bool) -> str:
    """The heatmap's metric: ``metric`` if it is one (a legacy spelling names its new metric), else the default
    for the kind of sweep."""
    if metric is None:
        return "steady_speed_m_s" if until_steady else "mean_speed_m_s"
    if metric not in METRICS:
        raise ParameterError(f"--plot-metric {metric!r} is unknown; allowed: {', '.join(METRICS)}")
    return LEGACY.get(metric, metric)


def read_results(path: str | Path) -> dict[str, np.ndarray]:
    """results.csv as columns (numbers as float, empty cells as NaN; 'notes' and 'error' as str)."""
    with Path(path).open(newline="", encoding="utf-8") as fh:
        rows = list(csv.DictReader(fh))
    columns = {}
    for name in (rows[0].keys() if rows else []):
        if name in ("error", "notes"):
            columns[name] = np.array([r[name] for r in rows], dtype=object)
        else:
            columns[name] = np.array([float(r[name]) if r[name] != "" else np.nan for r in rows])
    return columns


def _usable(columns: dict[str, np.ndarray], engine: str) -> np.ndarray:
    """Designs where ``engine`` gave a result and the robot did not stall."""
    return np.isfinite(columns[f"{engine}:revolutions"]) & (columns[f"{engine}:stalled"] != 1)


def best_designs(columns: dict[str, np.ndarray], axes: list[str], engines: list[str]) -> list[dict]:
    """The best design per engine and metric (ignoring designs an engine failed on or stalled in)."""
    best = []
    for engine in engines:
        ok = _usable(columns, engine)
        for metric in METRICS:
            if metric in NOT_RANKED:
                continue
            values = np.where(ok, columns[f"{engine}:{metric}"], np.nan)
            if np.all(np.isnan(values)) or np.nanmax(values) - np.nanmin(values) <= RESOLVED * abs(np.nanmean(values)):
                # nothing to rank: equal everywhere (mean speed 0 in every design of runs too short for a
                # revolution), or within what the runs resolve (energy per metre F_r1 + F_r2 at steady state)
                continue
            i = int(np.nanargmax(values) if metric in LARGER_IS_BETTER else np.nanargmin(values))
            best.append({"engine": engine, "metric": metric, "value": float(values[i]),
                         "design_id": int(columns["design_id"][i]), **{a: float(columns[a][i]) for a in axes}})
    return best


def rankings(columns: dict[str, np.ndarray], axes: list[str], engines: list[str]) -> dict:
    """Per engine, the RANKED best designs by steady speed (highest first) and energy per metre (lowest)."""
    out: dict = {}
    for engine in engines:
        ok = _usable(columns, engine)
        for metric, order in RANKING:
            values = np.where(ok, columns[f"{engine}:{metric}"], np.nan)
            finite = np.flatnonzero(np.isfinite(values))
            ranked = finite[np.argsort(-values[finite] if metric in LARGER_IS_BETTER else values[finite],
                                       kind="stable")][:RANKED]
            out.setdefault(engine, {})[metric] = {
                "order": order, "units": UNITS[metric],
                "designs": [{"design_id": int(columns["design_id"][i]), "value": float(values[i]),
                             **{a: float(columns[a][i]) for a in axes}} for i in ranked]}
    return out


def _label(name: str) -> str:
    return f"{name} [{parameter_units(name)}]"


def study_caption(study) -> str:
    """What was swept, how, and the base design where it is not the defaults, in one line for a figure."""
    from ipir_mujoco.core.params import RobotParams

    defaults = RobotParams()
    changed = [f"{name}={getattr(study.base, name):g}" if isinstance(getattr(study.base, name), float)
               else f"{name}={getattr(study.base, name)}" for name in study.base.as_dict()
               if getattr(study.base, name) != getattr(defaults, name) and name not in [a.name for a in study.axes]]
    how = f"to the steady state (cap {study.t_end:g} s)" if study.until_steady else f"{study.t_end:g} s each"
    base = "base: the paper's case" + (f" with {', '.join(changed)}" if changed else "")
    return f"sweep of {', '.join(a.name for a in study.axes)}, {len(study.designs())} designs, {how}; {base}"


def plot_sweep(results: str | Path, study, out: str | Path, metric: str = "mean_speed_m_s") -> list[Path]:
    """Write the sweep's figures into ``out``; return their paths."""
    columns = read_results(results)
    axes, engines = list(study.axes), list(study.engines)
    out = Path(out)
    if not len(columns.get("design_id", [])):
        return []
    caption = study_caption(study)
    if len(axes) == 1:
        return [_lines(columns, axes[0], engines, out, caption)]
    return [_heatmap(columns, axes[0], axes[1], engines, LEGACY.get(metric, metric), out, caption)]


def _lines(columns, axis, engines, out: Path, caption: str) -> Path:
    path = out / "sweep_lines.png"
    lines_figure(columns, axis, engines, caption).savefig(path, dpi=110)
    return path


def lines_figure(columns, axis, engines, caption: str | None = None):
    """One panel per metric any engine gives, against the one varied parameter; lines carry gids
    ``ENGINE:METRIC`` (stalled designs left out) and ``stalled:ENGINE:METRIC`` (their crosses). A panel
    whose values lie within :data:`RESOLVED` of their mean is drawn across that band and says so (gid
    ``flat:METRIC`` on its note)."""
    x = columns[axis.name]
    order = np.argsort(x)
    shown = ("mean_speed_m_s", "steady_speed_m_s", "energy_per_metre_j_m", "efficiency", "distance_per_rev_m",
             "peak_clutch_force_n", "peak_rod_force_n", "accel_jump_m_s2")
    shown = [m for m in shown if any(np.isfinite(columns[f"{e}:{m}"]).any() for e in engines)]
    fig, panels = new_figure(len(shown), height=2.0)
    if caption:
        fig.suptitle("\n".join(textwrap.wrap(caption, 90)), fontsize="medium")
    for ax, metric in zip(panels, shown):
        for j, engine in enumerate(engines):
            values = columns[f"{engine}:{metric}"][order]
            # a stalled design's figures are those of a robot at rest (no speed, a partial revolution): a
            # cross, not a point of the curve
            stalled = columns[f"{engine}:stalled"][order] == 1
            line, = ax.plot(x[order], np.where(stalled, np.nan, values), "o-", ms=3, label=engine,
                            gid=f"{engine}:{metric}")
            if stalled.any():
                ax.plot(x[order][stalled], values[stalled], "x", ms=6, color=line.get_color(),
                        label=f"{engine}: stalled" if metric == shown[0] else None, gid=f"stalled:{engine}:{metric}")
        notes = []  # said above the panel (a note inside it lay on a curve)
        absent = [e for e in engines if not np.isfinite(columns[f"{e}:{metric}"]).any()]
        if absent:  # e.g. MuJoCo's rigid clutches' peak forces, which would measure its step (docs/cli.md)
            notes.append(f"not given by {', '.join(absent)}")
        ax.set_ylabel("\n".join(textwrap.wrap(described(metric), 22)), fontsize="small")
        ax.ticklabel_format(axis="y", useOffset=False)
        flat = _flatten(ax, metric, [columns[f"{e}:{metric}"] for e in engines])
        if flat:
            notes.append(flat)
        if notes:
            ax.set_title("; ".join(notes), fontsize="x-small", color="0.3", loc="right", gid=f"note:{metric}")
        ax.grid(alpha=0.3)
        if axis.log:
            ax.set_xscale("log")
    fig.legend(*panels[0].get_legend_handles_labels(), loc="outside lower center", ncols=2, fontsize="small")
    panels[-1].set_xlabel(_label(axis.name))
    return fig


def _flatten(ax, metric: str, values: list[np.ndarray]) -> str | None:
    """Draw a panel whose finite values all lie within RESOLVED of their mean across that band; the note that
    says so (None if the values vary more)."""
    finite = np.concatenate([v[np.isfinite(v)] for v in values])
    if finite.size < 2:
        return None
    mean = float(finite.mean())
    half = RESOLVED * abs(mean)
    if half > 0 and float(finite.max() - finite.min()) <= 2 * half:
        ax.set_ylim(mean - 1.5 * half, mean + 1.5 * half)
        return f"flat: within {100 * RESOLVED:g} % of {mean:.5g} everywhere (below what the runs resolve)"
    return None


def _words(metric: str) -> str:
    """A metric in words, without its unit."""
    return described(metric).rsplit(" [", 1)[0]


def coloured_engine(columns: dict[str, np.ndarray], engines: list[str], metric: str) -> tuple[str | None, str]:
    """The engine whose ``metric`` the heatmap colours: the first that gives it for some design (a batched
    MuJoCo run gives no peak forces, for one), and the title's words for it; (None, words) if none does."""
    for engine in engines:
        if np.isfinite(columns[f"{engine}:{metric}"]).any():
            skipped = engines[:engines.index(engine)]
            return engine, f"{_words(metric)} of {engine}" + (
                f" ({', '.join(skipped)} gives no {_words(metric)})" if skipped else "")
    return None, f"no engine gives {metric} for these designs"


def compared_metric(columns: dict[str, np.ndarray], engines: list[str], metric: str) -> str:
    """The metric whose divergence the heatmap draws: ``metric`` if it has a divergence column, else the
    revolutions, else (not compared between runs stopped at their steady state) the steady or mean speed."""
    if metric in DIVERGENCE:
        return metric
    given = [m for m in ("revolutions", "steady_speed_m_s", "mean_speed_m_s")
             if np.isfinite(columns[f"divergence:{engines[1]}:{m}"]).any()]
    return (given or ["revolutions"])[0]


def _heatmap(columns, ax_x, ax_y, engines, metric, out: Path, caption: str = "") -> Path:
    x, y = columns[ax_x.name], columns[ax_y.name]
    shown, heading = coloured_engine(columns, engines, metric)
    panels_count = 2 if len(engines) > 1 else 1
    fig, panels = new_figure(panels_count, height=4.2)
    ax = panels[0]
    if shown is None:
        ax.text(0.5, 0.5, heading, transform=ax.transAxes, ha="center", va="center")
        ax.set(xlim=(np.nanmin(x), np.nanmax(x)), ylim=(np.nanmin(y), np.nanmax(y)))
    else:
        _colour_map(fig, ax, x, y, columns[f"{shown}:{metric}"], f"{shown}: {described(metric)}")
    if len(engines) > 1:
        compared = compared_metric(columns, engines, metric)
        divergence = np.abs(columns[f"divergence:{engines[1]}:{compared}"]) * 100
        finite = divergence[np.isfinite(divergence)]
        low, high = (finite.min(), finite.max()) if finite.size else (np.nan, np.nan)
        levels = [level for level in (1, 5) if low < level < high]
        if levels:
            grid = _as_grid(x, y, divergence)
            draw = ax.contour if grid is not None else ax.tricontour
            contours = draw(*(grid if grid is not None else (x, y, divergence)), levels=levels,
                            colors=["white", "red"][:len(levels)], linewidths=1.5)
            ax.clabel(contours, fmt=lambda v: f"{v:g} %", fontsize="small")
            title = (f"{heading}; contours: {engines[1]} differs from {engines[0]} by "
                     f"{' / '.join(f'{v} %' for v in levels)} in {_words(compared)}")
        elif finite.size:
            title = (f"{heading}; {engines[1]} differs from {engines[0]} by {low:.2g} to {high:.2g} % in "
                     f"{_words(compared)} everywhere (no 1 % / 5 % contour inside the map)")
        else:
            title = f"{heading}; no design where both engines give {_words(compared)}"
        _colour_map(fig, panels[1], x, y, divergence, f"|{engines[1]} - {engines[0]}| / |{engines[0]}| "
                                                         f"in {_words(compared)} [%]")
        panels[1].set_title(f"divergence of {engines[1]} from {engines[0]} in {_words(compared)}",
                            fontsize="medium")
    else:
        title = heading
    failed = np.array([bool(e) for e in columns["error"]])
    stalled = np.zeros(len(x), dtype=bool)
    for engine in engines:
        stalled |= columns[f"{engine}:stalled"] == 1
    for mask, marker, label in ((failed, "kx", "failed design"), (stalled & ~failed, "w+", "stalled design")):
        if mask.any():
            ax.plot(x[mask], y[mask], marker, ms=5, label=label)
    if (failed | stalled).any():
        ax.legend(fontsize="small", loc="upper right")
    ax.set_title("\n".join(textwrap.wrap(title, 80)), fontsize="medium")
    if caption:
        fig.suptitle("\n".join(textwrap.wrap(caption, 90)), fontsize="medium")
    for panel in panels:
        panel.set(xlabel=_label(ax_x.name), ylabel=_label(ax_y.name))
        if ax_x.log:
            panel.set_xscale("log")
        if ax_y.log:
            panel.set_yscale("log")
    path = out / "sweep_heatmap.png"
    fig.savefig(path, dpi=110)
    return path


def _colour_map(fig, ax, x, y, z, label: str) -> None:
    grid = _as_grid(x, y, z)
    if grid is not None:
        mesh = ax.pcolormesh(*grid, shading="nearest", cmap="viridis")
    elif np.isfinite(z).sum() >= 3:
        keep = np.isfinite(z)
        mesh = ax.tricontourf(x[keep], y[keep], z[keep], levels=20, cmap="viridis")
    else:
        mesh = ax.scatter(x, y, c=z, cmap="viridis")
    fig.colorbar(mesh, ax=ax, label="\n".join(textwrap.wrap(label, 40)))


def _as_grid(x, y, z):
    """(X, Y, Z) 2-D arrays if the points form a full grid, else None."""
    xs, ys = np.unique(x), np.unique(y)
    if xs.size * ys.size != x.size:
        return None
    Z = np.full((ys.size, xs.size), np.nan)
    Z[np.searchsorted(ys, y), np.searchsorted(xs, x)] = z
    return xs, ys, Z
