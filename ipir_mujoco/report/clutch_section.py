"""Real clutches: the engagement-load study's figure, and its section of the validation report.

:func:`study_figure` draws the figure a designer puts in a design review: the
peak clutch force against the clutch stiffness (log-log), one colour per
backlash, the analytic model as lines and MuJoCo as open markers, the rigid
clutches (the limit k -> infinity) marked right of the axis break; one panel
per operating point. :func:`compute`, :func:`render` and :func:`verdict` make
the validation report's section "Real clutches: engagement loads" (registered
in :mod:`ipir_mujoco.report.sections`).
"""

from __future__ import annotations

from pathlib import Path
from typing import Sequence

import matplotlib.ticker
import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure
from matplotlib.lines import Line2D

from ipir_mujoco.core.errors import ParameterError, SimulationError
from ipir_mujoco.core.params import RobotParams

from ..labels import signed_percent
from .document import Heading, Image, Paragraph, Table, fmt

COLOURS = ("tab:blue", "tab:orange", "tab:green", "tab:red", "tab:purple", "tab:brown", "tab:pink", "tab:olive")
RIGID_OFFSET = 0.8  # decades right of the stiffest design where the rigid clutches are drawn
ENGINE_STYLE = {"analytic": {"ls": "-", "lw": 1.6}, "mujoco": {"ls": "none", "marker": "o", "mfc": "none", "ms": 6}}
# [points]: where a marked design's name may go, tried in turn (below right, above right, above left, below
# left, above): the first that covers no data and no other name
LABEL_OFFSETS = (((8, -14), "left"), ((8, 6), "left"), ((-8, 6), "right"), ((-8, -14), "right"), ((0, 10), "center"),
                 ((0, -22), "center"), ((8, -28), "left"), ((8, 18), "left"), ((-8, -28), "right"), ((-8, 18), "right"),
                 ((0, 24), "center"), ((0, -36), "center"))
# beyond those, farther out in 16 directions, joined to their design by a thin line
FAR_OFFSETS = tuple(((round(r * np.cos(a)), round(r * np.sin(a))), "left" if np.cos(a) > 0.3 else
                     "right" if np.cos(a) < -0.3 else "center")
                    for r in (30, 48, 66) for a in np.linspace(0, 2 * np.pi, 16, endpoint=False))
RIGID_STYLE = {"analytic": {"marker": "*", "color": "black", "ms": 13},
               "mujoco": {"marker": "X", "color": "dimgrey", "ms": 9}}


def _ok(metrics: dict, key: str = "peak_clutch_force_n") -> bool:
    return "error" not in metrics and metrics.get(key) is not None and metrics[key] > 0


def study_figure(study: dict, highlight: Sequence[dict] = ()) -> Figure:
    """Peak clutch force against stiffness, one panel per operating point (see the module docstring).

    Each curve's line carries the gid ``ENGINE:BACKLASH`` (backlash as ``repr`` of metres), each rigid
    marker ``rigid:ENGINE``, each highlighted design ``pair:NAME``: the data a test can read back.
    ``highlight``: designs to mark, [{name, clutch_stiffness, clutch_backlash}].
    """
    points = list(study["points"])
    fig = Figure(figsize=(5.4 * len(points) + 0.4, 5.2), layout="constrained")
    FigureCanvasAgg(fig)
    axes = fig.subplots(1, len(points), squeeze=False)[0]
    stiffness = np.array(study["stiffness_n_m"])
    rigid_x = stiffness.max() * 10**RIGID_OFFSET
    labels = []  # (panel, text, (k, force)) of the marked designs, placed once the panels are drawn
    drawn = set()  # what the legend may show: ("backlash", j, "curve"|"point"), "analytic", "mujoco", "rigid:ENGINE",
    # "slope"
    for ax, key in zip(axes, points):
        rows = [r for r in study["rows"] if r["point"] == key]
        for j, b in enumerate(study["backlash_m"]):
            chosen = sorted((r for r in rows if r["clutch_backlash_m"] == b), key=lambda r: r["clutch_stiffness_n_m"])
            for engine, style in ENGINE_STYLE.items():
                data = [(r["clutch_stiffness_n_m"], r[engine]["peak_clutch_force_n"]) for r in chosen if _ok(r[engine])]
                if data:
                    x, y = zip(*data)
                    if engine == "analytic" and len(data) == 1:  # a line of one point is not drawn: the marker is
                        continue
                    ax.plot(x, y, color=COLOURS[j % len(COLOURS)], gid=f"{engine}:{b!r}", **style)
                    drawn.add(engine)
                    drawn.add(("backlash", j, "curve" if len(data) > 1 else "point"))
        missing = []
        for engine, style in RIGID_STYLE.items():
            ref = study["rigid"][key][engine]
            if _ok(ref):
                ax.plot([rigid_x], [ref["peak_clutch_force_n"]], ls="none", gid=f"rigid:{engine}", **style)
                drawn.add(f"rigid:{engine}")
            else:
                missing.append(engine)
        if missing:  # say so where the marker would be
            ax.text(0.98, 0.02, "rigid " + " and ".join(missing) + ":\nnot modelled at this point", transform=ax.transAxes,
                    ha="right", va="bottom", fontsize="x-small", color="dimgrey")
        for n, pair in enumerate(highlight):
            row = next((r for r in rows if r["clutch_stiffness_n_m"] == pair["clutch_stiffness"]
                        and r["clutch_backlash_m"] == pair["clutch_backlash"]), None)
            if row is not None and _ok(row["analytic"]):
                force = row["analytic"]["peak_clutch_force_n"]
                ax.plot([pair["clutch_stiffness"]], [force], ls="none", marker="D", ms=10, mfc="none", mec="black",
                        mew=1.5, gid=f"pair:{pair['name']}")
                play = f"{1e3 * pair['clutch_backlash']:g} mm play" if pair["clutch_backlash"] else "no play"
                labels.append((ax, f"{pair['name']} ({play})", (pair["clutch_stiffness"], force)))
        if _slope_guide(ax, rows, study["backlash_m"]):
            drawn.add("slope")
        ax.axvline(stiffness.max() * 10 ** (RIGID_OFFSET / 2), color="grey", lw=0.8, ls=":")
        drawn.add("break")
        decades = 10.0 ** np.arange(np.floor(np.log10(stiffness.min())), np.floor(np.log10(stiffness.max())) + 1)
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xticks(list(decades) + [rigid_x], [f"$10^{{{int(np.log10(d))}}}$" for d in decades] + ["rigid"])
        ax.xaxis.set_minor_locator(matplotlib.ticker.NullLocator())
        low, high = ax.get_ylim()
        # a panel spanning less than a decade gets evenly stepped labels (a log locator would leave one or two)
        ax.yaxis.set_major_locator(matplotlib.ticker.MaxNLocator(nbins=7, steps=[1, 2, 2.5, 5, 10]) if high < 10 * low
                                   else matplotlib.ticker.LogLocator(subs=(1.0, 2.0, 5.0)))
        ax.yaxis.set_major_formatter(matplotlib.ticker.FuncFormatter(lambda v, _: f"{v:g}"))
        ax.yaxis.set_minor_formatter(matplotlib.ticker.NullFormatter())
        ax.set(xlabel="clutch stiffness seen at the module, k [N/m]", ylabel="peak clutch force [N]",
               title=study["points"][key]["label"], xlim=(stiffness.min() / 2, rigid_x * 2))
        ax.title.set_fontsize("medium")
        ax.grid(alpha=0.3, which="major")
    # the legend lists only what is drawn: a colour with a curve, each kind of mark present
    # a backlash with a curve is keyed by a line; one drawn as lone designs only, by its marker
    handles = [Line2D([], [], color=COLOURS[j % len(COLOURS)], lw=3, label=f"backlash {1e3 * b:g} mm")
               if ("backlash", j, "curve") in drawn else
               Line2D([], [], color=COLOURS[j % len(COLOURS)], **ENGINE_STYLE["mujoco"], label=f"backlash {1e3 * b:g} mm")
               for j, b in enumerate(study["backlash_m"])
               if ("backlash", j, "curve") in drawn or ("backlash", j, "point") in drawn]
    kinds = (("analytic", dict(color="black", label="analytic compliant clutch (lines)", **ENGINE_STYLE["analytic"])),
             ("mujoco", dict(color="black", label="MuJoCo compliant ratchet (markers)", **ENGINE_STYLE["mujoco"])),
             ("rigid:analytic", dict(ls="none", label="rigid one-way model (analytic)", **RIGID_STYLE["analytic"])),
             ("rigid:mujoco", dict(ls="none", label="rigid ratchet (MuJoCo)", **RIGID_STYLE["mujoco"])),
             ("slope", dict(color="grey", ls="--", lw=1, label="slope 1/2: an impact, F ~ sqrt(k)")),
             ("break", dict(color="grey", ls=":", lw=0.8, label="axis break: rigid clutches (k -> infinity) right")))
    handles += [Line2D([], [], **style) for kind, style in kinds if kind in drawn]
    if any(a.get_gid() and a.get_gid().startswith("pair:") for ax in axes for a in ax.lines):
        handles.append(Line2D([], [], ls="none", marker="D", mfc="none", mec="black", label="realistic clutches"))
    # as many columns as the figure's width holds: a one-panel figure's legend used to run past its edges
    for ncols in range(min(5, len(handles)), 0, -1):
        legend = fig.legend(handles=handles, loc="outside lower center", fontsize="small", ncols=ncols)
        fig.canvas.draw()
        if legend.get_window_extent().width <= fig.bbox.width or ncols == 1:
            break
        legend.remove()
    _place_labels(fig, labels)
    return fig


def _place_labels(fig: Figure, labels: list) -> None:
    """Annotate each marked design at the first of LABEL_OFFSETS where its text covers no data (a line, a
    marker) and no label placed before it, inside its panel (where none does, the one covering least)."""
    fig.canvas.draw()  # the layout: the display coordinates the candidates are tested in
    renderer = fig.canvas.get_renderer()
    placed = []
    for ax, text, xy in labels:
        paths = [(line.get_transform().transform_path(line.get_path()), line.get_linestyle() not in ("None", ""))
                 for line in ax.lines if len(line.get_xdata())]
        best = None  # (conflicts, note, box): the candidate covering the least
        for (dx, dy), align in LABEL_OFFSETS + FAR_OFFSETS:
            note = ax.annotate(text, xy, xytext=(dx, dy), ha=align, textcoords="offset points", fontsize="small")
            note.set_in_layout(False)  # else the layout, redone at saving, resizes the panels under the placed names
            box = note.get_window_extent(renderer).expanded(1.02, 1.1)
            inside = ax.get_window_extent(renderer)
            conflicts = (sum(bool(np.any((path.vertices[:, 0] > box.x0) & (path.vertices[:, 0] < box.x1)
                                         & (path.vertices[:, 1] > box.y0) & (path.vertices[:, 1] < box.y1))
                                  or (drawn_line and path.intersects_bbox(box, filled=False)))
                             for path, drawn_line in paths)
                         + 3 * sum(box.overlaps(other) for other in placed)
                         + 3 * (not (inside.x0 <= box.x0 and box.x1 <= inside.x1 and inside.y0 <= box.y0
                                     and box.y1 <= inside.y1)))
            if best is None or conflicts < best[0]:
                if best is not None:
                    best[1].remove()
                best = (conflicts, note, box)
            else:
                note.remove()
            if conflicts == 0:
                break
        conflicts, note, box = best
        dx, dy = note.xyann
        if dx * dx + dy * dy > 30 ** 2:  # far from its design: a thin line to it
            note.remove()
            note = ax.annotate(text, xy, xytext=(dx, dy), ha=note.get_ha(), textcoords="offset points",
                               fontsize="small", arrowprops={"arrowstyle": "-", "color": "0.4", "lw": 0.6,
                                                             "shrinkA": 1, "shrinkB": 6})
            note.set_in_layout(False)
        placed.append(box)


def _slope_guide(ax, rows: list[dict], backlash: list[float]) -> bool:
    """A dashed slope-1/2 line ending at the largest backlash's stiffest analytic point; whether drawn."""
    if not backlash or max(backlash) == 0:
        return False
    ends = sorted((r["clutch_stiffness_n_m"], r["analytic"]["peak_clutch_force_n"]) for r in rows
                  if r["clutch_backlash_m"] == max(backlash) and _ok(r["analytic"]))
    if len(ends) >= 2:
        (k0, _), (k1, f1) = ends[0], ends[-1]
        ax.plot([k0, k1], [f1 * (k0 / k1) ** 0.5 * 1.6, f1 * 1.6], color="grey", ls="--", lw=1, gid="slope")
        return True
    return False


def write_study_figure(study: dict, path: Path, highlight: Sequence[dict] = ()) -> None:
    study_figure(study, highlight).savefig(path, dpi=110)


# --- the validation report's section --------------------------------------------------------------------------------

# Realistic clutches as the module sees them: a clutch of torsional stiffness k_t [N m/rad] in a wheel
# hub of radius R_w acts at the wheel's contact as k = k_t / R_w^2, and lost motion theta at the hub as
# backlash R_w theta. Small wheels: R_w = 15 mm.
REALISTIC = (
    {"name": "sprag", "clutch_stiffness": 1e6, "clutch_backlash": 0.0,
     "why": "a small sprag clutch (rated ~3 N m) twists by 1-3 deg at its rating (vendors state under 3 deg): "
            "k_t ~ 60-170 N m/rad, k ~ 3e5-8e5 N/m per clutched wheel of 15 mm radius, about 1e6 N/m with two "
            "such wheels in parallel; its sprags are spring-loaded against both races, so there is no play"},
    {"name": "roller", "clutch_stiffness": 3e5, "clutch_backlash": 3e-4,
     "why": "a drawn-cup roller clutch: its rollers roll up their ramps before they wedge (~1 deg of lost "
            "motion: 0.26 mm at a 15 mm wheel) and its thin drawn cup is softer than a sprag's races"},
    {"name": "worn roller + tyre", "clutch_stiffness": 1e5, "clutch_backlash": 1e-3,
     "why": "the roller clutch worn (~4 deg of lost motion: 1 mm) behind a polyurethane tyre, whose shear "
            "compliance in series sets the stiffness"},
)
GRID = {"stiffness": (1e4, 1e5, 1e6, 1e7), "backlash": (0.0, 1e-3)}  # the curves behind the realistic clutches


def compute(params: RobotParams, quick: bool, progress) -> dict:
    """The realistic clutches (and, unless ``quick``, a grid for the curves) at both operating points."""
    from .. import registry
    from ..studies.mechanism.clutch_study import run_study

    designs = [(p["clutch_stiffness"], p["clutch_backlash"]) for p in REALISTIC]
    if not quick:
        designs += [(k, b) for k in GRID["stiffness"] for b in GRID["backlash"]]
    base = params.replace(clutch_stiffness=None, clutch_backlash=0.0)
    study = run_study(base, designs=designs, progress=progress)
    # the ideal clutch's spikes: the paper's own model (first order, massless rod, ideal locks) at start-up
    try:
        paper = registry.run("analytic-approx", base.replace(drive="torque", rod_mass=0.0, rod_inertia=0.0), 1.0,
                             dt_out=1e-4)
    except (ParameterError, SimulationError) as exc:  # a design the paper's model does not cover: said, not fatal
        ideal = {"error": " ".join(str(exc).split())}
    else:
        s = paper.series
        ideal = {"peak_acceleration_m_s2": float(np.maximum(np.abs(s["a1"]), np.abs(s["a2"])).max()),
                 "peak_clutch_force_n": paper.summary["peak_clutch_force_n"]}
    return {"realistic": [dict(p) for p in REALISTIC], "quick": quick, "study": study, "paper_model": ideal}


def _row(study: dict, point: str, pair: dict) -> dict | None:
    return next((r for r in study["rows"] if r["point"] == point and r["clutch_stiffness_n_m"] == pair["clutch_stiffness"]
                 and r["clutch_backlash_m"] == pair["clutch_backlash"]), None)


def _both(an: dict, mj: dict, key: str, scale: float = 1.0, digits: int = 3) -> str:
    cells = ["n/a" if "error" in m or m.get(key) is None else fmt(m[key] * scale, digits) for m in (an, mj)]
    return " / ".join(cells)


TABLE = (("peak_clutch_force_n", "peak clutch force [N]", 1.0),
         ("peak_acceleration_m_s2", "peak module acceleration [m/s^2]", 1.0),
         ("lost_per_stroke_m", "travel lost per stroke [mm]", 1e3),
         ("steady_speed_m_s", "steady speed [m/s]", 1.0),
         ("energy_per_metre_j_m", "energy per metre [J/m]", 1.0))
CRUISE_ONLY = ("steady_speed_m_s", "energy_per_metre_j_m")


def render(metrics: dict, figures_dir: Path) -> list:
    study, paper = metrics["study"], metrics["paper_model"]
    write_study_figure(study, figures_dir / "clutch_engagement.png", metrics["realistic"])
    blocks: list = [Heading("Real clutches: engagement loads"), Paragraph(
        "The paper blames its acceleration spikes on the ideal clutch, which engages in no time, and leaves real "
        "clutches to future work. Here each one-way clutch is a spring of stiffness k behind a free play "
        "(backlash), never pulling, in both engines (the analytic compliant clutch, exact geometry; MuJoCo's "
        "ratchet with a spring in its pawl), at the paper's start-up (constant torque, 1 s from rest) and at "
        "cruise (the default motor at its periodic steady state; its last revolutions). k is the stiffness seen "
        "at the module: a clutch of torsional stiffness k_t in a wheel of radius R_w gives k = k_t / R_w^2. "
        "Three clutches, assumed (any others: ipir-mujoco clutch-study --stiffness LIST --backlash LIST):")]
    for pair in metrics["realistic"]:
        blocks.append(Paragraph(f"**{pair['name']}** (k = {pair['clutch_stiffness']:.3g} N/m, backlash "
                                f"{1e3 * pair['clutch_backlash']:g} mm): {pair['why']}."))
    header = ["operating point", "clutch"] + [f"{label}, analytic / MuJoCo" for _, label, _ in TABLE]
    rows = []
    for key, point in study["points"].items():
        def cells(an: dict, mj: dict) -> list[str]:
            return ["" if name in CRUISE_ONLY and not point["until_steady"] else _both(an, mj, name, scale)
                    for name, _, scale in TABLE]

        for pair in metrics["realistic"]:
            row = _row(study, key, pair)
            rows.append([key, pair["name"]] + cells(row["analytic"], row["mujoco"]))
        ref = study["rigid"][key]
        rows.append([key, "rigid (k -> infinity)"] + cells(ref["analytic"], ref["mujoco"]))
        if not point["until_steady"] and "error" not in paper:
            rows.append([key, "the paper's ideal lock (paper's model, analytic only)",
                         fmt(paper["peak_clutch_force_n"], 4), fmt(paper["peak_acceleration_m_s2"], 4), "", "", ""])
    blocks.append(Table(header, rows))
    blocks.append(Image("figures/clutch_engagement.png", _caption(metrics)))
    blocks.append(Paragraph(_physics(study)))
    return blocks


def _caption(metrics: dict) -> str:
    return ("Peak clutch force against the clutch stiffness seen at the module (log-log), one colour per backlash: "
            "analytic compliant clutch (lines), MuJoCo's compliant ratchet (open circles), the rigid clutches right "
            "of the dotted break (star: analytic one-way model; cross: MuJoCo's ratchet), the realistic clutches "
            "(diamonds" + ("; quick run: no grid behind them)" if metrics["quick"] else ")")
            + ". Left: cruise; right: the paper's start-up.")


def _slopes(study: dict, point: str, with_play: bool) -> str | None:
    names = {"analytic": "analytic", "mujoco": "MuJoCo"}
    found = [s for s in study["scaling"] if s["point"] == point and s["slope_stiff"] is not None
             and (s["clutch_backlash_m"] > 0) == with_play]
    return ", ".join(f"{names[s['engine']]} {s['slope_stiff']:.2f}" for s in found) or None


def _missing(study: dict) -> str:
    """Which rigid references could not run, and why (one engine refuses what it does not model)."""
    gone = [f"{key}, {engine}: {ref['error']}" for key, refs in study["rigid"].items()
            for engine in ("analytic", "mujoco") if "error" in (ref := refs[engine])]
    return (" Rigid references that could not run (n/a above): " + "; ".join(gone) + ".") if gone else ""


def _physics(study: dict) -> str:
    parts = [f"{key}: with play {play}; without {_slopes(study, key, False) or 'n/a'}"
             for key in study["points"] if (play := _slopes(study, key, True))]
    slopes = (" Slopes of the peak force over the stiffest decade computed: " + "; ".join(parts) + ".") if parts else \
        " (The quick run skips the grid these slopes come from.)"
    return ("Why the curves look so. With play the module crosses it and hits its clutch at a speed v0 that k "
            "does not change: a mass m pressed by a load Q onto a spring at v0 peaks at F = Q + sqrt(Q^2 + k m v0^2), "
            "which grows as sqrt(k) (log-log slope 1/2). Without play the module meets its clutch at zero speed "
            "and the spring takes a suddenly applied load: it overshoots towards twice the static load, a finite "
            "limit it approaches with a shortfall ~ k^-1/2." + slopes + " The rigid clutches are not that limit: "
            "the rigid one-way model reports the static reaction (it applies the load in no time, with no spring "
            "to overshoot), and MuJoCo's rigid ratchet is a constraint with a time constant of two steps, whose "
            "overshoot depends on the step." + _missing(study) + " An ideal clutch's engagement force is therefore a property of the numerics; a real one's is set by "
            "its stiffness and its play. Without damping the spring gives back what it took: a module bounces "
            "off its clutch, so travel per stroke can be gained (a negative loss) rather than lost; "
            "clutch_damping takes part of it.")


def verdict(metrics: dict) -> dict:
    """The report's opening answer: each realistic clutch's peak force and acceleration at both points."""
    study, paper = metrics["study"], metrics["paper_model"]
    answers, key_figure = [], None
    for key, point in study["points"].items():
        cells = []
        head = "at cruise" if point["until_steady"] else "at the paper's start-up"
        for pair in metrics["realistic"]:
            row = _row(study, key, pair)
            if row is None or "error" in row["analytic"]:
                cells.append(f"{pair['name']} n/a")
                continue
            an, div = row["analytic"], row["divergence"]["peak_clutch_force_n"]
            cells.append(f"{pair['name']} {an['peak_clutch_force_n']:.3g} N, {an['peak_acceleration_m_s2']:.3g} m/s^2"
                         + ("" if div is None else f" (MuJoCo {signed_percent(div, 2)})"))
            if key_figure is None:
                key_figure = f"{an['peak_clutch_force_n']:.3g} N peak ({pair['name']}, {head})"
        rigid = [f"{name} {ref['peak_clutch_force_n']:.3g} N, {ref['peak_acceleration_m_s2']:.3g} m/s^2"
                 for name, ref in (("analytic", study["rigid"][key]["analytic"]),
                                   ("MuJoCo", study["rigid"][key]["mujoco"])) if "error" not in ref]
        answers.append(f"{head}: " + "; ".join(cells) + (" (rigid clutches: " + "; ".join(rigid) + ")"
                                                          if rigid else ""))
    ideal = "" if "error" in paper else (
        f". The paper's ideal lock instead carries up to {paper['peak_clutch_force_n']:.4g} N and jolts a module by "
        f"{paper['peak_acceleration_m_s2']:.4g} m/s^2 at start-up: its spikes come from the lock rule, not from real "
        "engagement")
    answer = ("Peak clutch force and peak module acceleration, " + ". And ".join(answers) + ideal
              + ". With real one-way clutches the accelerations stay those of the "
                "linkage unless the play makes a stiff clutch an impact (F ~ sqrt(k)); the force is set by the "
                "clutch's stiffness and play.")
    return {"question": "What engagement loads does a real one-way clutch give, instead of the ideal clutch's "
                        "spikes?", "answer": answer, "evidence": "sections.clutch_engagement",
            "short": "set by the clutch's stiffness and play", "key": key_figure or ""}
