"""The paper's figures re-drawn from any engine's runs (headless PNG).

Figures are built with :class:`matplotlib.figure.Figure` and saved through the
Agg canvas, so no display and no pyplot state are involved. Each function takes
one or more runs: the first is drawn solid, the others dashed on top, so a
later MuJoCo run can be overlaid on the analytic one. Every figure says which
engine (geometry, clutch rule) drew each curve: in its heading for one run, in
its legend for several.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import TYPE_CHECKING, Sequence

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

if TYPE_CHECKING:  # annotations only: RunResult.plot calls plot_runs here, so nothing here imports core.results
    from ipir_mujoco.core.results import RunResult

REAR, FRONT = "black", "tab:red"  # the paper's colours: module 1 black, module 2 red
STYLES = ("-", "--", ":", "-.")


def run_label(run: RunResult) -> str:
    """Short legend label: engine, geometry, clutch rule."""
    return f"{run.engine}/{run.geometry}/{run.clutch}"


def new_figure(rows: int, height: float = 2.6) -> tuple[Figure, list]:
    fig = Figure(figsize=(8.0, 0.6 + height * rows), layout="constrained")
    FigureCanvasAgg(fig)
    axes = [fig.add_subplot(rows, 1, i + 1) for i in range(rows)]
    return fig, axes


def _engine_heading(fig: Figure, runs: Sequence[RunResult], labels: Sequence[str] | None) -> None:
    """Say which engine drew the figure (one run) or that the legend tells (several)."""
    if len(runs) == 1:
        run = runs[0]
        fig.suptitle(f"drawn from the {run.engine} engine: {run.geometry} geometry, {run.clutch} clutches",
                     fontsize="medium")
    else:
        names = labels if labels else [run_label(r) for r in runs]
        styles = ("solid", "dashed", "dotted", "dash-dot")
        fig.suptitle("line styles: " + ", ".join(f"{name} ({style})" for name, style in zip(names, styles)),
                     fontsize="small")


def _legend_label(runs: Sequence[RunResult], labels: Sequence[str] | None, i: int, what: str) -> str:
    if len(runs) == 1:
        return what
    return f"{what} ({labels[i] if labels else run_label(runs[i])})"


def figure_crank(runs: Sequence[RunResult], labels: Sequence[str] | None = None) -> Figure:
    """Paper's Fig. 2: crank angle in revolutions (a) and cos(phi) (b) against time."""
    fig, (ax_rev, ax_cos) = new_figure(2)
    for i, (style, run) in enumerate(zip(STYLES, runs)):
        t, phi = run.series["t"], run.series["phi"]
        ax_rev.plot(t, phi / (2 * math.pi), style, color=REAR, label=_legend_label(runs, labels, i, "phi"))
        ax_cos.plot(t, np.cos(phi), style, color=REAR, lw=0.8, label=_legend_label(runs, labels, i, "cos phi"))
    ax_rev.set(ylabel="crank angle phi [rev]", title="(a) crank rotation")
    ax_cos.set(xlabel="time t [s]", ylabel="cos phi [-]", title="(b) cos of the crank angle")
    for ax in (ax_rev, ax_cos):
        ax.grid(alpha=0.3)
    if len(runs) > 1:
        ax_rev.legend(fontsize="small")
    _engine_heading(fig, runs, labels)
    return fig


def figure_modules(runs: Sequence[RunResult], labels: Sequence[str] | None = None) -> Figure:
    """Paper's Fig. 3: module displacements (a), velocities (b), accelerations (c); along the route's
    centreline (s) for runs along a route (their x and v columns are, :meth:`ipir_mujoco.engine.kinds.wheels.route_watch.RouteWatch.along_series`)."""
    fig, axes = new_figure(3)
    along = any(run.route is not None for run in runs)
    if along:
        quantities = (("x", "distance along the route s [m]", "(a) distances along the route"),
                      ("v", "speed along the route ds/dt [m/s]", "(b) speeds along the route"),
                      ("a", "rate of ds/dt [m/s^2]", "(c) accelerations along the route"))
    else:
        quantities = (("x", "displacement from start [m]", "(a) displacements"),
                      ("v", "velocity [m/s]", "(b) velocities"),
                      ("a", "acceleration [m/s^2]", "(c) accelerations"))
    for ax, (key, ylabel, title) in zip(axes, quantities):
        for i, (style, run) in enumerate(zip(STYLES, runs)):
            t = run.series["t"]
            name = "s" if along and key == "x" else key
            ax.plot(t, run.series[key + "1"], style, color=REAR, lw=0.9,
                    label=_legend_label(runs, labels, i, f"module 1 (rear) {name}1"))
            ax.plot(t, run.series[key + "2"], style, color=FRONT, lw=0.9,
                    label=_legend_label(runs, labels, i, f"module 2 (front) {name}2"))
        ax.set(ylabel=ylabel, title=title)
        ax.grid(alpha=0.3)
    axes[0].legend(fontsize="small")
    axes[-1].set_xlabel("time t [s]")
    _engine_heading(fig, runs, labels)
    return fig


def figure_gap(runs: Sequence[RunResult], labels: Sequence[str] | None = None) -> Figure:
    """Paper's Fig. 4: gap S in dm (left axis) and its rate S_dot in m/s (right axis)."""
    fig, (ax,) = new_figure(1, height=3.4)
    ax_rate = ax.twinx()
    for i, (style, run) in enumerate(zip(STYLES, runs)):
        t = run.series["t"]
        ax.plot(t, run.series["S"] * 10.0, style, color=REAR, label=_legend_label(runs, labels, i, "S"))
        ax_rate.plot(t, run.series["S_dot"], style, color=FRONT, lw=0.8, label=_legend_label(runs, labels, i, "S_dot"))
    ax.set(xlabel="time t [s]", ylabel="gap S = x2 - x1 [dm]", title="gap between the modules and its rate")
    ax_rate.set_ylabel("gap rate S_dot [m/s]", color=FRONT)
    ax.grid(alpha=0.3)
    lines = ax.get_lines() + ax_rate.get_lines()
    # below the axes: inside, any corner hides part of S or S_dot (lower left: the first minimum of S)
    fig.legend(lines, [line.get_label() for line in lines], fontsize="small", loc="outside lower center",
               ncol=min(len(lines), 3))
    _engine_heading(fig, runs, labels)
    return fig


PAPER_FIGURES = {
    "fig2_crank.png": figure_crank,
    "fig3_modules.png": figure_modules,
    "fig4_gap.png": figure_gap,
}


def plot_runs(runs: Sequence[RunResult], path: str | Path | None = None) -> list[Figure]:
    """The paper's figures (crank, modules, gap against time) of ``runs``, the first solid, the others dashed
    over it.

    Parameters
    ----------
    runs : sequence of RunResult
    path : str or Path or None
        A folder to write them in as fig2-4 PNG (made if missing); None: not written.

    Returns
    -------
    list of matplotlib.figure.Figure
        The three figures.
    """
    runs = list(runs)
    if path is not None:
        Path(path).mkdir(parents=True, exist_ok=True)
        write_paper_figures(runs, path)
    return [figure_crank(runs), figure_modules(runs), figure_gap(runs)]


def write_paper_figures(runs: Sequence[RunResult], directory: str | Path, labels: Sequence[str] | None = None,
                        dpi: int = 120) -> list[Path]:
    """Save the paper's Fig. 2-4 for ``runs`` (legend ``labels``) as PNG files in ``directory``."""
    directory = Path(directory)
    written = []
    for name, build in PAPER_FIGURES.items():
        path = directory / name
        build(runs, labels).savefig(path, dpi=dpi)
        written.append(path)
    return written


def figure_kinetostatics(run: RunResult) -> Figure:
    """Torque, clutch reactions and rod force against crank angle for a prescribed crank motion."""
    fig, (ax_torque, ax_clutch, ax_rod) = new_figure(3)
    s = run.series
    angle = np.degrees(s["phi"] - s["phi"][0])
    ax_torque.plot(angle, s["motor_torque"], color="tab:blue", lw=1.0)
    ax_torque.set(ylabel="motor torque [N m]", title=f"what the motion needs ({run.settings.get('motion', '')}, "
                                                     f"{run.clutch} clutches, {run.geometry} geometry)")
    ax_clutch.plot(angle, s["lambda1"], color=REAR, lw=1.0, label="rear clutch lambda1")
    ax_clutch.plot(angle, s["lambda2"], color=FRONT, lw=1.0, label="front clutch lambda2")
    ax_clutch.axhline(0.0, color="grey", lw=0.8)
    ax_clutch.set(ylabel="clutch reaction [N]")
    ax_clutch.legend(fontsize="small")
    ax_rod.plot(angle, s["rod_force"], color="tab:green", lw=1.0)
    ax_rod.axhline(0.0, color="grey", lw=0.8)
    ax_rod.set(xlabel="crank angle from start [deg]", ylabel="rod force [N] (tension > 0)")
    for ax in (ax_torque, ax_clutch, ax_rod):
        ax.grid(alpha=0.3)
    return fig
