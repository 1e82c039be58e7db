"""The bend study's figure: time and energy to pass a 90-degree bend against R/D.

Top panel: the time to pass the bend (:mod:`ipir_mujoco.studies.bend_study`: from the front module entering the bend
to the rear module leaving it) over the analytic finite-grip model's straight-pipe prediction for the same length
(the line at 1: length / steady speed): the wheeled MuJoCo model in the bend (markers joined, one line per bend
plane; a red cross at 1 where it did not pass) and in the same length of straight pipe (open squares). Bottom panel:
the energy the robot used over the same window (the motor's work less the kinetic and potential energy gained) over
the analytic prediction (energy per metre x length), the same. Crosses: the equations along the same route (the
analytic route model through the same bend, its wheels' scrub in closed form), in the bend plane's colour. A shaded band marks the R/D where the closed form says the wheels need more spread
than their springs reach. Log R/D axis. Lines and markers carry gids (``bend:time``, ``straight:time``,
``analytic:time``, ``equations:time``, ``failed:time``, ``wall-lost:time`` and the same ``:energy``): the data a test can read.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure


def _values(rows: list[dict], which: str, key: str) -> np.ndarray:
    return np.array([np.nan if (v := (r.get(which) or {}).get(key)) is None else float(v) for r in rows])


PLANE_STYLES = (("o-", "tab:blue"), ("D--", "tab:green"), ("^:", "tab:purple"), ("v-.", "tab:brown"))


def bend_figure(study: dict) -> Figure:
    """The figure (module docstring) of a study as :func:`ipir_mujoco.studies.bend_study.run_study` gives it; one
    bend line per plane (gid ``bend:...`` for the first, ``bend@PLANE:...`` for the others)."""
    every = sorted(study["rows"], key=lambda r: r["R_over_D"])
    planes = list(dict.fromkeys(r.get("plane_deg", 0.0) for r in every))
    by_plane = {p: [r for r in every if r.get("plane_deg", 0.0) == p] for p in planes}
    rows = by_plane[planes[0]]  # the straight twins and the analytic line: one per R/D
    x = np.array([r["R_over_D"] for r in rows])
    fig = Figure(figsize=(8.0, 7.0), layout="constrained")
    FigureCanvasAgg(fig)
    axes = fig.subplots(2, 1, sharex=True)
    ref = study["reference"]
    lost = [r["R_over_D"] for r in every if not r["bend"].get("wheels_keep_wall", True)]
    for ax, key, gid, label in ((axes[0], "time_s", "time", "time to pass / analytic prediction [-]"),
                                (axes[1], "energy_j", "energy", "energy to pass / analytic prediction [-]")):
        analytic = _values(rows, "analytic", key)
        ax.axhline(1.0, color="0.3", lw=1.4, gid=f"analytic:{gid}",
                   label=("analytic finite-grip model, straight pipe, same length: "
                          + (f"length / {ref['steady_speed_m_s']:.4g} m/s" if gid == "time" else
                             f"{ref['energy_per_metre_j_m']:.4g} J/m x length")))
        ax.plot(x, _values(rows, "straight", key) / analytic, "s", mfc="none", color="tab:orange", ms=8,
                gid=f"straight:{gid}", label="MuJoCo wheels, straight pipe (same length)")
        for k, plane in enumerate(planes):
            mine = by_plane[plane]
            style, colour = PLANE_STYLES[k % len(PLANE_STYLES)]
            across = ("across gravity" if abs(plane) % 180 == 0 else
                      "in the plane of gravity" if abs(plane) == 90 else "")
            ax.plot([r["R_over_D"] for r in mine], _values(mine, "bend", key) / _values(mine, "analytic", key), style,
                    color=colour, ms=6, gid=f"bend:{gid}" if k == 0 else f"bend@{plane:g}:{gid}",
                    label=f"MuJoCo wheels, 90-degree bend, plane {plane:g} deg" + (f" ({across})" if across else ""))
            ax.plot([r["R_over_D"] for r in mine], _values(mine, "equations", key) / _values(mine, "analytic", key),
                    "x", color=colour, ms=8, mew=1.6, gid=f"equations:{gid}" if k == 0 else f"equations@{plane:g}:{gid}",
                    label=f"equations along the same route, plane {plane:g} deg")
        failed = [r["R_over_D"] for r in every if not r["bend"].get("passed")]
        if failed:
            ax.plot(failed, [1.0] * len(failed), "x", color="tab:red", ms=10, mew=2, gid=f"failed:{gid}",
                    label="did not pass (see the table)")
        if lost:
            ax.axvspan(min(x) / 1.1, max(lost) * 1.1, color="tab:red", alpha=0.08, gid=f"wall-lost:{gid}",
                       label="closed form: the wheels need more spread than their springs reach")
        ax.set_ylabel(label)
        ax.set_xscale("log")
        ax.grid(True, which="both", alpha=0.3)
    handles, labels = axes[0].get_legend_handles_labels()  # below the axes: inside, it would hide points
    fig.legend(handles, labels, fontsize=7.5, loc="outside lower center", ncol=1)
    axes[1].set_xlabel("bend radius over pipe diameter, R/D [-]")
    params = study["settings"]["params"]
    fig.suptitle(f"Passing a 90-degree bend (window: L + pi R / 2 of centreline): D = {params['pipe_diameter']:g} m, "
                 f"mu_wall = {params['mu_wall']:g}, F_n = {params['F_n1']:g} / {params['F_n2']:g} N, default motor",
                 fontsize=9)
    axes[1].set_xticks(list(x), [f"{v:g}" for v in x])
    axes[1].minorticks_off()
    return fig


def write_bend_figure(study: dict, path: str | Path) -> None:
    bend_figure(study).savefig(path, dpi=120)
