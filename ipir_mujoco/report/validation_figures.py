"""The validation report's own figures, drawn from a run or from metrics.json: the locked clutches' reactions
against crank angle, the first-order model's divergence against L/r, the share of each stroke a lock would pull.

:func:`.validation.write_report` draws them into the report's figures/ folder (the paper's Fig. 2-4 are
:func:`ipir_mujoco.core.figures.write_paper_figures`'; the overview, :mod:`.overview`).
"""

from __future__ import annotations

import math
from pathlib import Path

import matplotlib.ticker
import numpy as np

from ipir_mujoco.core.results import Mode

from ..core.figures import new_figure
from ..studies.validation.validate import LadderRun


def figure_clutch_reactions(rung: LadderRun, path: Path) -> None:
    """Reaction of each locked clutch against crank angle, negative (pulling) intervals shaded."""
    s = rung.run.series
    fig, (ax,) = new_figure(1, height=3.4)
    angle = np.degrees(np.mod(s["phi"], 2 * math.pi))
    for mode, column, colour, label in ((Mode.EXPANSION, "lambda1", "black", "rear clutch (module 1) locked"),
                                        (Mode.CONTRACTION, "lambda2", "tab:red", "front clutch (module 2) locked")):
        held = s["mode"] == mode
        ax.plot(angle[held], s[column][held], ".", ms=1.5, color=colour, label=label)
    ax.axhspan(min(ax.get_ylim()[0], -1.0), 0.0, color="tab:blue", alpha=0.12, label="reaction < 0: lock would pull")
    ax.axhline(0.0, color="grey", lw=0.8)
    ax.set(xlabel="crank angle phi mod 360 [deg]", ylabel="clutch reaction [N]", xlim=(0, 360),
           title=f"clutch reactions under the paper's rule ({rung.name}, whole run)")
    ax.set_yscale("symlog", linthresh=10.0)
    ax.grid(alpha=0.3)
    ax.legend(fontsize="small", loc="lower left", markerscale=6)
    fig.savefig(path, dpi=120)


LR_CURVES = (("revolutions", "crank revolutions"), ("x1_final", "module 1 travel"), ("v2_max", "peak speed, module 2"),
             ("first_contraction_end_s", "end of first contraction"), ("S_at_angle", "gap S at same crank angle"),
             ("S_dot_at_angle", "gap rate dS/dt at same crank angle"))


def figure_lr_study(study: dict, path: Path) -> None:
    """|divergence| of the first-order model against L/r, log-log, with the 1 % and 5 % lines."""
    fig, (ax,) = new_figure(1, height=4.2)
    ratios = np.array(study["ratios"])
    for key, label in LR_CURVES:
        values = np.array([abs(row["divergence"][key]) if row["divergence"][key] is not None else np.nan
                           for row in study["rows"]])
        ax.plot(ratios, 100 * np.maximum(values, 1e-4), "o-", ms=3, lw=1.2, label=label)
    physics = np.array([abs(row["mujoco_vs_exact"]["revolutions"]) for row in study["rows"]])
    ax.plot(ratios, 100 * physics, "k:", lw=1.0, label="MuJoCo vs the exact equations of its linkage (with its "
                                                        "rod), revolutions")
    for level in (1, 5):  # labelled at the left edge, clear of the curves (which fall to the right)
        ax.axhline(level, color="grey", lw=0.8, ls="--")
        ax.text(0.005, level * 1.08, f"{level} %", transform=ax.get_yaxis_transform(), ha="left", va="bottom",
                fontsize="small", color="dimgrey", bbox={"facecolor": "white", "edgecolor": "none", "pad": 1})
    ax.set(xscale="log", yscale="log", xlabel="L / r [-]", ylabel="|first order - exact| / |exact| [%]",
           title="where L >> r breaks down: divergence of the paper's first-order model")
    ticks = [x for x in (1.05, 1.5, 2, 3, 4, 6, 10, 15, 20) if ratios[0] <= x <= ratios[-1]]
    ax.set_xticks(ticks, [f"{x:g}" for x in ticks])
    ax.xaxis.set_minor_formatter(matplotlib.ticker.NullFormatter())
    ax.grid(alpha=0.3, which="both")
    fig.legend(*ax.get_legend_handles_labels(), loc="outside lower center", ncol=2, fontsize="x-small")
    fig.savefig(path, dpi=120)


def figure_pull_per_stroke(per_stroke: list[dict], path: Path) -> None:
    """Pull fraction of each complete stroke (the last one, cut short by the end of the run, is left out)."""
    fig, (ax,) = new_figure(1, height=3.0)
    for mode, colour in (("contraction", "tab:red"), ("expansion", "black")):
        rows = [s for s in per_stroke if s["mode"] == mode and s.get("complete", True)]
        ax.plot([s["mean_crank_speed"] for s in rows], [100 * s["pull_fraction"] for s in rows], "o-", color=colour,
                label=f"{mode} strokes ({'front' if mode == 'contraction' else 'rear'} clutch locked)")
    ax.set(xlabel="mean crank speed of the stroke [rad/s]", ylabel="time the lock pulls [% of stroke]",
           title="how much of each stroke the paper's lock would have to pull", ylim=(0, None))
    ax.grid(alpha=0.3)
    ax.legend(fontsize="small")
    fig.savefig(path, dpi=120)
