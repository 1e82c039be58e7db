"""The control study's design-review figure (:mod:`ipir_mujoco.studies.control_study`).

Four panels: (a) the crank speed's deviation from its target over one steady revolution at the fastest study
speed, one curve per servo controller (MuJoCo; the open loop's tens of percent said in words); (b) the speed
ripple per controller and variant at each speed (log scale); (c) the peak clutch force per controller and
variant (the equations'; MuJoCo's rigid ratchet's n/a); (d) the dead-centre profile: peak clutch force and the
electrical energy per metre against the speed target's dip. Each data line or bar group
carries a gid (``trace:CONTROLLER``, ``ripple:VARIANT``, ``force:VARIANT``, ``profile-force:VARIANT``,
``profile-energy:VARIANT``) so that a test can read the figure back.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

CONTROLLER_COLOURS = {"open-loop": "tab:grey", "pi": "tab:blue", "pi+paper": "tab:orange", "pi+exact": "tab:green"}
# the controllers in words (their code names are the study's and the servo's --feedforward choices)
CONTROLLER_WORDS = {"open-loop": "open loop", "pi": "PI alone", "pi+paper": "PI + paper's feedforward",
                    "pi+exact": "PI + exact feedforward"}
VARIANT_STYLE = {"analytic-approx-unilateral": {"hatch": "//", "label": "paper's geometry (its promise)"},
                 "analytic-unilateral": {"hatch": "", "label": "exact equations"},
                 "mujoco-ratchet": {"hatch": "..", "label": "MuJoCo"}}
LINE_STYLE = {"analytic-unilateral": {"ls": "-", "marker": "o"}, "mujoco-ratchet": {"ls": "--", "marker": "s",
                                                                                  "mfc": "none"}}


def _value(row: dict, key: str) -> float:
    value = None if "error" in row else row.get(key)
    return math.nan if value is None else float(value)


def study_figure(study: dict) -> Figure:
    """The figure (see the module docstring)."""
    fig = Figure(figsize=(12.5, 9.0), layout="constrained")
    FigureCanvasAgg(fig)
    (ax_trace, ax_ripple), (ax_force, ax_profile) = fig.subplots(2, 2)
    rows, speeds = study["rows"], study["speeds_rad_s"]
    controllers, variants = study["controllers"], study["variants"]

    if speeds:
        fastest = max(speeds)
        off_scale = []
        for c in controllers:
            row = next((r for r in rows if r["controller"] == c and r["speed_rad_s"] == fastest
                        and r["variant"] == "mujoco-ratchet" and "error" not in r), None)
            if row is None or not row["trace"]["phi_rad"]:
                continue
            phi = np.degrees(np.mod(row["trace"]["phi_rad"], 2 * math.pi))
            order = np.argsort(phi)
            deviation = 100 * (np.asarray(row["trace"]["omega_rad_s"])[order] / fastest - 1)
            if c == "open-loop":  # tens of percent: off the servo's scale, said in words
                off_scale.append(f"open loop: {deviation.min():+.0f} % .. {deviation.max():+.0f} % (off scale)")
                continue
            ax_trace.plot(phi[order], deviation, color=CONTROLLER_COLOURS[c], lw=1.4, label=CONTROLLER_WORDS.get(c, c),
                          gid=f"trace:{c}")
        ax_trace.axhline(0.0, color="black", ls=":", lw=1.0, label="target")
        for dc in (0, 180, 360):
            ax_trace.axvline(dc, color="lightgrey", lw=0.8, zorder=0, label="dead centres" if dc == 0 else None)
        ax_trace.set_xlim(0, 360)
        ax_trace.set_xticks(range(0, 361, 45))
        ax_trace.set_title(f"(a) crank speed over a steady revolution, {fastest:g} rad/s target (MuJoCo)")
        ax_trace.set_xlabel("crank angle phi [deg] (dead centres at 0 and 180)")
        ax_trace.set_ylabel("crank speed - target [% of target]")
        # legends of line panels sit below them, off the curves
        # (the open loop's swing, off this scale, is said in the legend's title: a note in the panel lay on a curve)
        ax_trace.legend(fontsize=8, loc="upper center", bbox_to_anchor=(0.5, -0.14), ncols=4,
                        title=off_scale[0] if off_scale else None, title_fontsize=8)

    groups = [(w, c) for w in speeds for c in controllers]
    x = np.arange(len(groups))
    for ax, key, title, unit, log in ((ax_ripple, "speed_ripple", "(b) speed ripple (peak-to-peak / mean)", "-", True),
                                      (ax_force, "peak_clutch_force_n", "(c) peak clutch force", "N", False)):
        table = {v: [_value(next((r for r in rows if r["speed_rad_s"] == w and r["controller"] == c
                                  and r["variant"] == v), {"error": ""}), key) for w, c in groups] for v in variants}
        shown = [v for v in variants if not all(math.isnan(value) for value in table[v])]
        missing = [VARIANT_STYLE[v]["label"] for v in variants if v not in shown]
        width = 0.8 / max(1, len(shown))
        for j, v in enumerate(shown):
            values = table[v]
            bars = ax.bar(x + (j - (len(shown) - 1) / 2) * width, values, width,
                          color=[CONTROLLER_COLOURS[c] for _, c in groups], edgecolor="black", lw=0.6,
                          hatch=VARIANT_STYLE[v]["hatch"], label=VARIANT_STYLE[v]["label"])
            for bar in bars:
                bar.set_gid(f"{'ripple' if key == 'speed_ripple' else 'force'}:{v}")
        ax.set_xticks(x, [f"{CONTROLLER_WORDS.get(c, c)}\n{w:g} rad/s" for w, c in groups], fontsize=8)
        if log:
            ax.set_yscale("log")
        ax.set_title(title)
        ax.set_ylabel(f"{title.split(') ')[1].split(' (')[0]} [{unit}]")
        ax.set_xlabel("controller and mean crank speed")
        # headroom above the tallest bar for the legend (a decade on the log axis, 45 % on the linear one)
        tallest = max((value for v in shown for value in table[v] if not math.isnan(value)), default=None)
        if tallest:
            bottom = ax.get_ylim()[0]
            ax.set_ylim(bottom, tallest * (12.0 if log else 1.45))
        ax.legend(fontsize=8, title="bars: hatch = model", title_fontsize=8, loc="upper center", ncols=len(shown))
        if missing:  # MuJoCo's rigid ratchet: its peaks measure its timestep (studies/mechanism/control_study.py)
            ax.set_xlabel(f"controller and mean crank speed\n({', '.join(missing)}: n/a, a rigid ratchet's sampled "
                          "peak measures its timestep)")

    profile = study["profile"]
    prows = profile["rows"]
    if prows:
        energy_ax = ax_profile.twinx()
        for v in profile["variants"]:
            chosen = sorted((r for r in prows if r["variant"] == v), key=lambda r: r["speed_dip"])
            dips = [r["speed_dip"] for r in chosen]
            style = LINE_STYLE.get(v, {})
            force = [_value(r, "peak_clutch_force_n") for r in chosen]
            if not all(math.isnan(f) for f in force):  # MuJoCo's: n/a (see panel c)
                ax_profile.plot(dips, force, color="tab:red", **style,
                                label=f"peak clutch force, {VARIANT_STYLE[v]['label']}", gid=f"profile-force:{v}")
            energy_ax.plot(dips, [_value(r, "electrical_energy_per_metre_j_m") for r in chosen], color="tab:purple",
                           **style, label=f"electrical energy, {VARIANT_STYLE[v]['label']}",
                           gid=f"profile-energy:{v}")
        ax_profile.set_title(f"(d) dead-centre profile, {profile['speed_rad_s']:g} rad/s mean, PI + exact feedforward")
        ax_profile.set_xlabel("speed target's dip at the dead centres, speed_dip [-] (0: constant speed)")
        ax_profile.set_ylabel("peak clutch force [N]", color="tab:red")
        energy_ax.set_ylabel("electrical energy per metre [J/m]", color="tab:purple")
        lines = ax_profile.get_lines() + energy_ax.get_lines()
        ax_profile.legend(lines, [ln.get_label() for ln in lines], fontsize=8, loc="upper center",
                          bbox_to_anchor=(0.5, -0.14), ncols=2)
    fig.suptitle("Speed control of the inchworm robot's crank: controllers and a dead-centre profile")
    return fig


def write_study_figure(study: dict, path: Path) -> None:
    study_figure(study).savefig(path, dpi=110)
