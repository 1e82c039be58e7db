"""Figures of the idealization atlas (:mod:`ipir_mujoco.studies.atlas`), read at a glance.

* ``atlas_safe.png`` (always): each idealization's safe share of the box per metric and threshold, with its
  interval, and which measured it (equations or MuJoCo).
* one varied parameter, ``atlas_1d.png``: |cost| [%] against the parameter, one panel per idealization and
  metric: the equations' designs (dots), MuJoCo's designs (crosses) and its surrogate with its 95 % band, the
  thresholds (dashed) and each crossing with its interval (shaded).
* two, ``atlas_map.png``: |cost| maps (colour, log scale) from each measure's surrogate, the boundary at each
  threshold (solid) with its 95 % uncertainty (dotted: where the side of the threshold becomes known), and the
  MuJoCo runs placed (white dots).
* more, ``atlas_partial.png``: partial dependence of each |cost| on each parameter (the surrogate's mean over
  the other parameters, with the 10-90 % spread over them), the thresholds dashed.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from matplotlib import patheffects
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.colors import LogNorm
from matplotlib.figure import Figure
from matplotlib.patches import Patch
from matplotlib.ticker import FuncFormatter

from ..studies.idealizations.atlas_surrogate import CONFIDENT

COLOURS = ("tab:blue", "tab:red", "tab:green", "tab:purple", "tab:orange")


def _figure(width: float, height: float) -> Figure:
    fig = Figure(figsize=(width, height), layout="constrained")
    FigureCanvasAgg(fig)
    return fig


def _measure(result: dict, name: str) -> tuple[str, dict]:
    """(fidelity, {metric: surrogate}) the atlas reports for ``name``: MuJoCo's where it ran, else the equations'."""
    for fidelity in ("mujoco", "equations"):
        if result["_surrogates"].get((name, fidelity)):
            return fidelity, result["_surrogates"][(name, fidelity)]
    return "", {}


def plot_atlas(result: dict, atlas, out: str | Path) -> list[Path]:
    out = Path(out)
    paths = [plot_safe(result["idealizations"], atlas.axes, out / "atlas_safe.png")]
    d = len(atlas.axes)
    draw = {1: plot_1d, 2: plot_map}.get(d, plot_partial)
    paths.append(draw(result, atlas, out / {1: "atlas_1d.png", 2: "atlas_map.png"}.get(d, "atlas_partial.png")))
    return paths


# the atlas's names in a figure's words
IDEALIZATION_WORDS = {"first-order-kinematics": "first-order kinematics", "massless-rod": "massless rod",
                      "locking-clutches": "locking clutches", "unlimited-grip": "unlimited grip",
                      "constant-press": "constant wall press"}
SHORT_METRICS = {"travel_m": ("travel (mean of the modules)", "m")}


def idealization_words(name: str) -> str:
    return IDEALIZATION_WORDS.get(name, name.replace("-", " "))


def metric_words(metric: str) -> tuple[str, str]:
    """(words, unit) of an atlas metric."""
    from ..studies.idealizations.atlas_space import METRIC_WORDS

    return SHORT_METRICS.get(metric) or METRIC_WORDS.get(metric, (metric.replace("_", " "), "-"))


def axis_label(axis) -> str:
    """'L [m]': a varied parameter with its unit (``axis``: sweep_space.Axis)."""
    from ipir_mujoco.core.params import parameter_units

    unit = parameter_units(axis.name)
    return f"{axis.name} [{unit}]" if unit != "-" else f"{axis.name} [-]"


def plot_safe(idealizations: dict, axes, path: Path, title: str = "Where the paper's model holds") -> Path:
    """Write :func:`safe_figure` to ``path``."""
    safe_figure(idealizations, axes, title).savefig(path, dpi=110)
    return path


def safe_figure(idealizations: dict, axes, title: str = "Where the paper's model holds") -> Figure:
    """Bars: each idealization's safe share per metric and threshold with its interval (``idealizations``:
    atlas.json's; ``axes``: the varied ranges, sweep_space.Axis); each share written right of its interval; the
    legend names only the measures drawn."""
    rows = []
    for name, per in idealizations.items():
        for metric, entry in per.items():
            for k, item in enumerate(entry["by_threshold"]):
                rows.append((f"{idealization_words(name)}, {metric_words(metric)[0]}: error < "
                             f"{100 * item['threshold']:g} %", item, entry["measured_by"]))
                if entry.get("equations"):  # MuJoCo measured it; the equations' answer beside it
                    rows.append(("    the equations", entry["equations"]["by_threshold"][k], "equations"))
    fig = _figure(9.0, 1.5 + 0.32 * len(rows))
    ax = fig.add_subplot()
    colours = {"mujoco": "tab:red", "equations": "tab:blue"}
    notes, drawn = [], set()
    for k, (_label, item, by) in enumerate(rows):
        frac, interval = item["safe_fraction"], item["safe_fraction_interval"]
        if frac is None:
            continue
        ax.barh(k, 100 * frac, color=colours[by], alpha=0.55)
        if frac > 0:  # a bar to see: its colour goes in the legend
            drawn.add(by)
        ax.errorbar(100 * frac, k, xerr=[[100 * max(0.0, frac - interval[0])], [100 * max(0.0, interval[1] - frac)]],
                    color="black", capsize=3, lw=1)
        # right of the interval's end and its cap, past the bar: never over the data
        end = max(100 * interval[1], 100 * frac)
        notes.append(ax.annotate(f"{100 * frac:.1f} %", (end, k), xytext=(6, 0), textcoords="offset points",
                                 va="center", ha="left", fontsize="x-small"))
    ax.set_yticks(range(len(rows)), [label for label, _i, _b in rows], fontsize="small")
    ax.invert_yaxis()
    ranges = [f"{a.name} {a.low:.3g}..{a.high:.3g} {_unit(a.name)}".rstrip() for a in axes]
    ax.set(xlim=(0, 100), xlabel="share of the box where it is safe [%] (line: 95 % interval)",
           title=title + ":\n" + ", ".join(ranges[:3]) + (",\n" + ", ".join(ranges[3:]) if ranges[3:] else ""))
    ax.set_xticks(range(0, 101, 20))
    ax.title.set_fontsize("small")
    words = {"equations": "measured by the equations (dense sample)", "mujoco": "measured by MuJoCo (surrogate)"}
    if drawn:
        fig.legend(handles=[Patch(color=colours[by], alpha=0.55, label=words[by]) for by in ("equations", "mujoco")
                            if by in drawn], fontsize="x-small", loc="outside lower center", ncol=2)
    ax.grid(alpha=0.3, axis="x")
    for _ in range(6):  # room right of 100 % for the shares written there
        fig.canvas.draw()
        frame = ax.get_window_extent()
        over = max((n.get_window_extent().x1 + 2 - frame.x1 for n in notes), default=0.0)
        if over <= 0:
            break
        high = ax.get_xlim()[1]
        ax.set_xlim(0, high * (1 + over / frame.width) * 1.02)
    return fig


def _unit(name: str) -> str:
    from ipir_mujoco.core.params import parameter_units

    unit = parameter_units(name)
    return "" if unit == "-" else unit


def _plain_log_ticks(axis, every_minor: bool = False) -> None:
    """Log-axis labels as plain numbers (0.5, 2, 10), not powers of ten; minor ticks labelled at 2 and 5 (at
    every one with ``every_minor``, for a colour bar spanning less than a decade)."""
    axis.set_major_formatter(FuncFormatter(lambda v, _p: f"{v:g}"))
    axis.set_minor_formatter(FuncFormatter(lambda v, _p: f"{v:g}" if every_minor or _mantissa(v) in (2, 5) else ""))


def _mantissa(v: float) -> int:
    """The leading digit of v > 0 (0.005 -> 5, 20 -> 2): which minor ticks of a log axis carry a label."""
    return int(round(v / 10 ** np.floor(np.log10(v)))) if v > 0 else 0


def _panels(result: dict, atlas):
    return [(name, metric) for name in result["idealizations"] for metric in atlas.metrics]


def plot_1d(result: dict, atlas, path: Path) -> Path:
    figure_1d(result, atlas).savefig(path, dpi=110)
    return path


def figure_1d(result: dict, atlas) -> Figure:
    """|cost| against the one varied parameter, one panel per idealization and metric (module docstring)."""
    axis = atlas.axes[0]
    panels = _panels(result, atlas)
    cols = len(atlas.metrics)
    nrows = max(1, len(panels) // cols)
    fig = _figure(4.6 * cols, 1.1 + 3.0 * nrows)
    u = np.linspace(0, 1, 400)
    x = atlas.values(u[:, None])[:, 0]
    for k, (name, metric) in enumerate(panels):
        ax = fig.add_subplot(nrows, cols, k + 1)
        entry = result["idealizations"][name][metric]
        for fidelity, marker, colour in (("equations", ".", "tab:blue"), ("mujoco", "x", "tab:red")):
            if (name, fidelity) not in result["_measured"]:
                continue
            U, rows = result["_measured"][(name, fidelity)]
            cost = np.array([np.nan if r["cost"].get(metric) is None else abs(r["cost"][metric]) for r in rows])
            ax.plot(atlas.values(U)[:, 0], 100 * np.maximum(cost, 1e-6), marker, color=colour, ms=3 if marker == "." else 5,
                    label=f"{'equations' if fidelity == 'equations' else 'MuJoCo'} "
                          f"({len({tuple(v) for v in np.round(U, 12)})} designs)")
            s = result["_surrogates"].get((name, fidelity), {}).get(metric)
            if fidelity == "mujoco" and s is not None:
                mean, lo, hi = s.cost(u[:, None])
                ax.plot(x, 100 * np.maximum(mean, 1e-6), color=colour, lw=1.2, label="MuJoCo surrogate")
                ax.fill_between(x, 100 * np.maximum(lo, 1e-6), 100 * np.maximum(hi, 1e-6), color=colour, alpha=0.15,
                                label="its 95 % band")
        crossed = False
        for j, item in enumerate(entry["by_threshold"]):
            ax.axhline(100 * item["threshold"], color="grey", ls="--", lw=0.9,
                       label="threshold" + ("s" if len(entry["by_threshold"]) > 1 else "") if j == 0 else None)
            for value, lo, hi in item.get("crossings_interval", {}).get(axis.name, []):
                ax.axvspan(lo, hi, color="gold", alpha=0.5)
                ax.axvline(value, color="darkgoldenrod", lw=1, label=None if crossed else
                           f"crossing ({axis.name} = {value:.4g} {_unit(axis.name)})".replace(" )", ")"))
                crossed = True
        words, unit = metric_words(metric)
        ax.set(yscale="log", xscale="log" if axis.log else "linear", xlabel=axis_label(axis),
               ylabel=f"error in {words} [%]",
               title=f"{idealization_words(name)}: |idealized - real| / |real|\n(measured by {entry['measured_by']})")
        if axis.log:
            _plain_log_ticks(ax.xaxis)
        ax.title.set_fontsize("small")
        _plain_log_ticks(ax.yaxis)
        ax.grid(alpha=0.3, which="both")
        # below the panel: inside, it would cover the designs the panel is about
        ax.legend(fontsize="x-small", loc="upper center", bbox_to_anchor=(0.5, -0.2), ncols=2, frameon=False)
    return fig


def plot_map(result: dict, atlas, path: Path) -> Path:
    figure_map(result, atlas).savefig(path, dpi=110)
    return path


# a boundary's colour per threshold, each drawn with a dark edge so that it shows on the map and in the legend
BOUNDARY_COLOURS = ("white", "orange", "red")
EDGE = [patheffects.withStroke(linewidth=3.2, foreground="black")]


def figure_map(result: dict, atlas) -> Figure:
    """|cost| maps over the two varied parameters with each threshold's boundary (module docstring)."""
    ax_x, ax_y = atlas.axes
    panels = _panels(result, atlas)
    cols = len(atlas.metrics)
    nrows = max(1, len(panels) // cols)
    fig = _figure(5.0 * cols, 1.4 + 3.8 * nrows)
    n = 70
    g = np.linspace(0, 1, n)
    UU = np.array([[a, b] for b in g for a in g])
    XY = atlas.values(UU)
    X, Y = XY[:, 0].reshape(n, n), XY[:, 1].reshape(n, n)
    for k, (name, metric) in enumerate(panels):
        ax = fig.add_subplot(nrows, cols, k + 1)
        fidelity, fitted = _measure(result, name)
        s = fitted.get(metric)
        words, _unit_ = metric_words(metric)
        if s is None:
            ax.set_title(f"{idealization_words(name)}, {words}: no surrogate", fontsize="small")
            ax.set_axis_off()
            continue
        mean = np.maximum(s.cost(UU)[0], 1e-5).reshape(n, n)
        image = ax.pcolormesh(X, Y, 100 * mean, norm=LogNorm(vmin=max(1e-3, 100 * mean.min()), vmax=100 * mean.max()),
                              cmap="viridis", shading="auto")
        bar = fig.colorbar(image, ax=ax, label=f"error in {words} [%]")
        _plain_log_ticks(bar.ax.yaxis, every_minor=mean.max() < 10 * mean.min())
        for j, t in enumerate(atlas.thresholds):
            p = s.p_safe(UU, t).reshape(n, n)
            colour = BOUNDARY_COLOURS[j % len(BOUNDARY_COLOURS)]
            ax.contour(X, Y, p, levels=[0.5], colors=colour, linewidths=1.6).set_path_effects(EDGE)
            ax.contour(X, Y, p, levels=[1 - CONFIDENT, CONFIDENT], colors=colour, linewidths=0.9, linestyles=":")
            ax.plot([], [], color=colour, lw=1.6, path_effects=EDGE,
                    label=f"error = {100 * t:g} % (dotted: its 95 % band)")
        if (name, "mujoco") in result["_measured"]:
            U, rows = result["_measured"][(name, "mujoco")]
            V = atlas.values(U)
            ax.plot(V[:, 0], V[:, 1], "o", ms=3.5, mfc="white", mec="black", mew=0.5, color="black",
                    label=f"MuJoCo designs ({len(U)}, {2 * len(U)} runs)")
        ax.set(xscale="log" if ax_x.log else "linear", yscale="log" if ax_y.log else "linear",
               xlabel=axis_label(ax_x), ylabel=axis_label(ax_y),
               title=f"{idealization_words(name)}: error in {words}\n(surrogate of the "
                     f"{fidelity if fidelity == 'equations' else 'MuJoCo'} cost, |idealized - real| / |real|)")
        for which, axis in ((ax.xaxis, ax_x), (ax.yaxis, ax_y)):
            if axis.log:
                _plain_log_ticks(which)
        ax.title.set_fontsize("small")
        # below the map: inside, it would hide part of the boundary it explains
        ax.legend(fontsize="x-small", loc="upper center", bbox_to_anchor=(0.5, -0.16), ncols=1, frameon=False)
    return fig


def plot_partial(result: dict, atlas, path: Path) -> Path:
    names = list(result["idealizations"])
    d = len(atlas.axes)
    fig = _figure(2.9 * d, 0.8 + 2.5 * len(names))
    C = result["_candidates"]
    bins = np.linspace(0, 1, 13)
    floor = min(atlas.thresholds)  # [%]: costs below 1/100 of the smallest threshold are drawn on the axis's floor
    centres = 0.5 * (bins[1:] + bins[:-1])
    for r, name in enumerate(names):
        fidelity, fitted = _measure(result, name)
        for c, axis in enumerate(atlas.axes):
            ax = fig.add_subplot(len(names), d, r * d + c + 1)
            x = atlas.values(np.column_stack([centres] * d))[:, c]
            for j, metric in enumerate(atlas.metrics):
                s = fitted.get(metric)
                if s is None:
                    continue
                cost = 100 * s.cost(C)[0]
                which = np.digitize(C[:, c], bins[1:-1])
                mean = np.array([cost[which == b].mean() for b in range(len(centres))])
                low = np.array([np.percentile(cost[which == b], 10) for b in range(len(centres))])
                high = np.array([np.percentile(cost[which == b], 90) for b in range(len(centres))])
                colour = COLOURS[j % len(COLOURS)]
                # a cost below the floor everywhere (e.g. an idealization that leaves a metric unchanged) is drawn
                # dotted on the floor, so it does not read as a cost of exactly the floor's value
                below = bool(np.all(high < floor))
                words = metric_words(metric)[0]
                ax.plot(x, np.maximum(mean, floor), color=colour, lw=1.4, ls=":" if below else "-",
                        label=f"{words} (< {floor:g} %)" if below else words)
                ax.fill_between(x, np.maximum(low, floor), np.maximum(high, floor), color=colour, alpha=0.15)
            for t in atlas.thresholds:
                ax.axhline(100 * t, color="grey", ls="--", lw=0.9)
            ax.set(yscale="log", xscale="log" if axis.log else "linear", xlabel=axis_label(axis))
            _plain_log_ticks(ax.yaxis)
            if axis.log:
                _plain_log_ticks(ax.xaxis)
            if c == 0:
                ax.set_ylabel(f"{idealization_words(name)}\nerror [%] ({'MuJoCo' if fidelity == 'mujoco' else 'equations'})",
                              fontsize="small")
            ax.grid(alpha=0.3, which="both")
            if c == 0:  # each row's legend: which metrics sit dotted below the floor differs by idealization
                ax.legend(fontsize="xx-small")
            entry = next(iter(result["idealizations"][name].values()))
            st = entry.get("sensitivity", {}).get(axis.name)
            if isinstance(st, dict) and st.get("ST") is not None:
                ax.set_title(f"ST {st['ST']:.2f} +- {st['ST_conf']:.2f} ({metric_words(atlas.metrics[0])[0]})",
                             fontsize="x-small")
    fig.suptitle("Partial dependence of each idealization's error on each parameter (line: mean over the other "
                 "parameters; band: their 10-90 %; dashed: thresholds;\ndotted: below the axis's floor everywhere)", fontsize="small")
    fig.savefig(path, dpi=100)
    return path
