"""The climbing-ability figure: speed and clutch reaction against the pipe's incline, every engine.

Top panel: the steady speed (motor; a constant torque has no steady state while it climbs, so there
the mean speed over the last three revolutions of the run), one line per engine (the first engine
solid, the others as open markers over it), the inclines where an engine stalled as crosses at zero
speed, and the limits of :mod:`ipir_mujoco.studies.climbing` as vertical lines: the restart limit
(dashed) and the steady-climb limit (dotted, at the last incline seen to climb; the legend gives the bisection's
bracket, climbs-stalls, as ``climb`` prints it: black where the engines share it, else one line per engine in its
colour). Bottom panel: the peak clutch reaction
(over the steady window, or the whole run; none for MuJoCo's rigid clutches, whose peak is set by its
step) and the mean total clutch reaction over the steady window, with the weight along the pipe,
(m1 + m2 + m_rod) g sin(incline), that the clutches hold on average beside the moving module's
resistance. Lines and markers carry gids (``speed:ENGINE``,
``stalled:ENGINE``, ``peak:ENGINE``, ``stalled-peak:ENGINE``, ``mean:ENGINE``, ``restart``,
``steady-limit:ENGINE``, ``weight``): the data a test can read back.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure
from matplotlib.lines import Line2D

from ipir_mujoco.core.params import RobotParams

from .. import registry

COLOURS = ("tab:blue", "tab:orange", "tab:green", "tab:red", "tab:purple")
FIRST = {"ls": "-", "marker": ".", "lw": 1.6}  # the first engine: the reference the others are drawn over
OTHER = {"ls": "none", "marker": "o", "mfc": "none", "ms": 7}


def _column(rows: list[dict], engine: str, key: str) -> np.ndarray:
    return np.array([np.nan if "error" in (m := r["engines"][engine]) or m.get(key) is None else float(m[key])
                     for r in rows])


def climb_figure(study: dict, params: RobotParams) -> Figure:
    """Speed and clutch reactions against incline (see the module docstring); ``params``: the design."""
    rows = sorted(study["rows"], key=lambda r: r["incline_deg"])
    x = np.array([r["incline_deg"] for r in rows])
    fig = Figure(figsize=(8.0, 7.6), layout="constrained")
    FigureCanvasAgg(fig)
    speed_ax, force_ax = fig.subplots(2, 1, sharex=True)
    motor = study["drive"] == "motor"
    speed_handles, force_handles = [], []
    limits: dict[float, list[str]] = {}
    for j, engine in enumerate(study["engines"]):
        colour, style = COLOURS[j % len(COLOURS)], FIRST if j == 0 else OTHER
        label = registry.variant(engine).label
        stalled = np.array([("error" not in r["engines"][engine]) and bool(r["engines"][engine]["stalled"])
                            for r in rows])
        speed = _column(rows, engine, "steady_speed_m_s" if motor else "mean_speed_m_s")
        speed_ax.plot(x, np.where(stalled, np.nan, speed), color=colour, gid=f"speed:{engine}", **style)
        peak = _column(rows, engine, "peak_clutch_force_n")
        force_ax.plot(x, np.where(stalled, np.nan, peak), color=colour, gid=f"peak:{engine}", **style)
        # dashes offset per engine: engines that agree (their lines on each other) show both colours in turn
        dashes = (3 * j, (3, 3 * len(study["engines"]) - 3))
        force_ax.plot(x, _column(rows, engine, "mean_clutch_force_n"), color=colour, lw=1.0, ls=dashes,
                      gid=f"mean:{engine}")
        if stalled.any():
            cross = {"ls": "none", "marker": "x", "ms": 10 - 3 * j, "mew": 2, "color": colour}
            speed_ax.plot(x[stalled], np.zeros(stalled.sum()), gid=f"stalled:{engine}", **cross)
            force_ax.plot(x[stalled], peak[stalled], gid=f"stalled-peak:{engine}", **cross)
        speed_handles.append(Line2D([], [], color=colour, label=label, **style))
        if np.isfinite(peak).any():  # MuJoCo's rigid clutches give none (module docstring)
            force_handles.append(Line2D([], [], color=colour, label=f"peak, {label}", **style))
        if np.isfinite(_column(rows, engine, "mean_clutch_force_n")).any():  # drawn dashed in the engine's colour
            force_handles.append(Line2D([], [], color=colour, lw=1.0, ls=dashes,
                                        label=f"mean over the steady window, {label}"))
        limit = study["steady_climb"].get(engine, {})
        if limit.get("incline_deg") is not None:
            limits.setdefault(tuple(round(v, 6) for v in limit["bracket"]), []).append((label, colour, engine))
    restart = study["restart"]["incline_deg"]
    if restart is not None:
        speed_ax.axvline(restart, color="grey", ls="--", lw=1.2, gid="restart")
        speed_handles.append(Line2D([], [], color="grey", ls="--",
                                    label=f"restart limit (restarts at every crank angle): {restart:.1f} deg"))
    for (low, high), engines in limits.items():
        # engines with one bracket share one black dotted line; an engine with its own bracket has its colour
        colour = "black" if len(engines) > 1 or len(study["engines"]) == 1 else engines[0][1]
        speed_ax.axvline(low, color=colour, ls=":", lw=1.6, gid="steady-limit:" + ",".join(e for _l, _c, e in engines))
        bracket = f"{high:.2f} deg" if low == high else f"{low:.2f}-{high:.2f} deg"
        speed_handles.append(Line2D([], [], color=colour, ls=":", lw=1.6,
                                    label=f"steady-climb limit from rest: {bracket} "
                                          f"({', '.join(name for name, _c, _e in engines)})"))
    speed_handles.append(Line2D([], [], ls="none", marker="x", mew=2, color="black", label="stalled"))
    fine = np.linspace(min(x.min(), 0.0), x.max(), 200)
    mass = params.m1 + params.m2 + params.rod_mass
    force_ax.plot(fine, mass * params.g * np.sin(np.radians(fine)), color="grey", lw=2.5, alpha=0.5, gid="weight")
    force_handles += [Line2D([], [], color="grey", lw=2.5, alpha=0.5,
                             label="weight along the pipe, (m1 + m2 + rod mass) g sin(incline)"),
                      Line2D([], [], ls="none", marker="x", mew=2, color="black",
                             label="stalled: peak over the run, then held at rest")]
    drive = (f"motor: M_stall {params.M_stall:g} N m, no-load {params.omega_noload:g} rad/s" if motor
             else f"constant torque M = {params.M:g} N m")
    speed_ax.set(ylabel=("steady speed [m/s]" if motor else f"mean speed, last 3 revolutions of {study['t_end_s']:g} s "
                         "[m/s]"), title=f"climbing ability ({drive})")
    top = speed_ax.get_ylim()[1]
    speed_ax.set_ylim(-0.05 * top, top)
    force_ax.set(xlabel="pipe incline above the horizontal [deg]", ylabel="clutch reaction [N]")
    for ax, handles in ((speed_ax, speed_handles), (force_ax, force_handles)):
        ax.grid(alpha=0.3)
        ax.legend(handles=handles, fontsize="x-small", loc="best")
    if x.max() - x.min() >= 30:
        force_ax.set_xticks(np.arange(10 * math.floor(x.min() / 10), x.max() + 1, 10))
    return fig


def write_climb_figure(study: dict, params: RobotParams, path: Path) -> None:
    climb_figure(study, params).savefig(path, dpi=110)
