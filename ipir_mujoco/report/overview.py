"""The report's opening: one picture of what each idealization costs at this design, beside the numerical
error; short verdicts with their detail moved into their sections; the ladder's and the audit's wording.

:func:`idealization_costs` reads the ladder (the first second from rest) and the cruise section (the default
motor at its steady state) of a metrics record; :func:`overview_figure` draws them as bars, one panel per
figure (crank revolutions, travel, cruise speed), beside a band as wide as the worst difference between MuJoCo
and the equations on the same linkage: a bar inside the band is not resolved by the engines.
"""

from __future__ import annotations

import re

from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure
from matplotlib.patches import Patch

from ..labels import SUMMARY
from .document import Heading, Paragraph, pct

FIGURE = "idealization_costs.png"
# (idealization, the rung that has it, the rung that removes it)
COSTS = (("first-order geometry", "paper model", "exact geometry"),
         ("massless rod", "exact geometry", "with rod mass"),
         ("locks that pull (not one-way)", "with rod mass", "one-way clutches"),
         ("slides (not wheels on the wall)", "MuJoCo ratchet", "wheels in contact"))
# the numerical error: the two engines on one linkage, (equations, MuJoCo)
ERRORS = (("with rod mass", "MuJoCo, paper's rule"), ("one-way clutches", "MuJoCo ratchet"))
PANELS = (("revolutions", "crank revolutions, 1 s"), ("travel", "travel, 1 s"), ("cruise", "cruise speed (motor)"))
VERDICT_WORDS = 60  # a verdict paragraph's length at most; the rest goes to its section


def _figures(metrics: dict) -> dict[str, dict[str, float]]:
    """{rung: {revolutions, travel, cruise}} from the ladder and the cruise section (a figure left out where
    the rung does not have it)."""
    out: dict[str, dict[str, float]] = {}
    for rung in metrics.get("ladder", []):
        s = rung["summary"]
        out[rung["name"]] = {"revolutions": s["revolutions"], "travel": 0.5 * (s["x1_final"] + s["x2_final"])}
    cruise = metrics.get("sections", {}).get("cruise") or {}
    for rung in cruise.get("rungs", []):
        if "error" not in rung and rung.get("steady_speed_m_s"):
            out.setdefault(rung["name"], {})["cruise"] = rung["steady_speed_m_s"]
    return out


def idealization_costs(metrics: dict) -> dict:
    """{"costs": [(idealization, {figure: relative change})], "error": {figure: worst relative difference}}:
    each idealization's cost, (with it - without it) / without it, and the engines' disagreement on the same
    linkage (absolute); a figure is missing where a rung lacks it."""
    figures = _figures(metrics)
    costs = []
    for name, with_it, without in COSTS:
        a, b = figures.get(with_it, {}), figures.get(without, {})
        costs.append((name, {k: a[k] / b[k] - 1 for k, _ in PANELS if k in a and k in b and b[k]}))
    error = {}
    for key, _ in PANELS:
        gaps = [abs(figures[m][key] / figures[e][key] - 1) for e, m in ERRORS
                if key in figures.get(e, {}) and key in figures.get(m, {}) and figures[e][key]]
        if gaps:
            error[key] = max(gaps)
    return {"costs": costs, "error": error}


BAND_PX = 3.0  # display pixels: a numerical-error band narrower than this is said in the title, not drawn


def overview_figure(metrics: dict) -> Figure:
    """Bars of each idealization's cost [%], one panel per figure, the numerical error as a grey band where it is
    wide enough to see (else said in the panel's title only); each value beyond its bar's end, inside the panel."""
    data = idealization_costs(metrics)
    fig = Figure(figsize=(10.0, 3.3), layout="constrained")
    FigureCanvasAgg(fig)
    axes = fig.subplots(1, len(PANELS), sharey=True)
    names = [name for name, _ in data["costs"]]
    notes, bands = [], []  # (panel, annotation) of every value; (panel, error) of every band
    for ax, (key, title) in zip(axes, PANELS):
        values = [costs.get(key) for _, costs in data["costs"]]
        shown = [(i, 100 * v) for i, v in enumerate(values) if v is not None]
        err = 100 * data["error"].get(key, 0.0)
        for i, v in shown:
            ax.barh(i, v, color="tab:red" if v > 0 else "tab:blue", height=0.6, zorder=2)
        reach = max([abs(v) for _, v in shown] + [err, 0.1])
        ax.set_xlim(-1.25 * reach, 1.25 * reach)  # widened below until every value fits
        for i, v in shown:  # the value beyond the bar's end, on the side it points
            notes.append((ax, ax.annotate(f"{v:+.2f} %", (v, i), xytext=(4 if v >= 0 else -4, 0),
                                          textcoords="offset points", ha="left" if v >= 0 else "right",
                                          va="center", fontsize="small")))
        for i in set(range(len(values))) - {i for i, _ in shown}:
            notes.append((ax, ax.annotate("n/a", (0, i), xytext=(4, 0), textcoords="offset points", va="center",
                                          fontsize="small", color="0.4")))
        ax.axvline(0.0, color="black", lw=0.8)
        bands.append((ax, key, title, err))
        ax.set_xlabel("cost: (with it - without it) / without it [%]", fontsize="small")
        ax.grid(axis="x", alpha=0.3)
    axes[0].set_yticks(range(len(names)), names)
    axes[0].invert_yaxis()
    handles = [Patch(color="tab:red", label="the idealization overstates"),
               Patch(color="tab:blue", label="the idealization understates")]
    fig.legend(handles=handles, loc="outside lower center", ncols=3, fontsize="small")
    _fit_notes(fig, notes)
    drawn = False
    for ax, key, title, err in bands:
        scale = ax.get_window_extent().width / (ax.get_xlim()[1] - ax.get_xlim()[0])  # pixels per %
        if err and 2 * err * scale >= BAND_PX:
            # the panel's full height (a background, not a bar: values may be written over it)
            ax.fill_betweenx([0, 1], -err, err, color="0.8", zorder=0, lw=0, transform=ax.get_xaxis_transform())
            drawn = True
        # the band is often thinner than a line: its width is said in the title too
        ax.set_title(title + (f"\nnumerical error \u00b1{err:.2g} %" if err else "\nnumerical error: n/a")
                     + ("" if not err or 2 * err * scale >= BAND_PX else "\n(too narrow to draw)"), fontsize="medium")
    if drawn:
        handles.append(Patch(color="0.8", label="numerical error: MuJoCo against the equations, same linkage"))
        fig.legends[0].remove()
        fig.legend(handles=handles, loc="outside lower center", ncols=3, fontsize="small")
    return fig


def _fit_notes(fig: Figure, notes: list) -> None:
    """Widen each panel's x range (symmetrically, the panels keep their zero in the middle) until every
    annotation lies inside its panel; all panels get the same share of their range for the bars."""
    for _ in range(8):
        fig.canvas.draw()
        renderer = fig.canvas.get_renderer()
        worst = 1.0
        for ax, note in notes:
            frame, box = ax.get_window_extent(renderer), note.get_window_extent(renderer)
            half = frame.width / 2
            centre = frame.x0 + half
            reach = max(box.x1 - centre, centre - box.x0) + 4  # pixels from the zero line, with a margin
            worst = max(worst, reach / half)
        if worst <= 1.0:
            return
        for ax in {id(ax): ax for ax, _ in notes}.values():
            low, high = ax.get_xlim()
            ax.set_xlim(low * worst * 1.02, high * worst * 1.02)


def overview_caption(metrics: dict) -> str:
    data = idealization_costs(metrics)
    worst = max((abs(v), name) for name, costs in data["costs"] for v in costs.values()) if data["costs"] else None
    text = ("What each idealization of the paper's model costs at this design, in the first second from rest and "
            "at the motor's cruise: (the model with it - the model without it) / |the model without it|, the "
            "convention of every cost in this report. Each panel's title gives the numerical error (the engines' "
            "largest disagreement on the same linkage), drawn as a grey band where it is wide enough to see: a bar "
            "inside it is not resolved.")
    if worst:
        text += f" The largest: {worst[1]}, {100 * worst[0]:.1f} %."
    return text


def short_verdict(answer: str, words: int = VERDICT_WORDS) -> tuple[str, bool]:
    """(the answer's first sentences, at most ``words`` words (at least the first sentence), whether any were
    left out)."""
    sentences = re.split(r"(?<=[.!?])\s+(?=[A-Z(])", answer.strip())
    kept, count = [], 0
    for sentence in sentences:
        n = len(sentence.split())
        if kept and count + n > words:
            break
        kept.append(sentence)
        count += n
    head = kept[0].split(": ", 1)[0]
    if count > words + 10 and ": " in kept[0] and len(head.split()) >= 5:
        # one long sentence ("about" 60 words: up to 70 kept): its head, before the colon that details it
        return head.rstrip(",;") + ".", True
    return " ".join(kept), len(kept) < len(sentences)


def verdict_blocks(verdicts: list[dict]) -> tuple[list, dict[str, list]]:
    """The verdicts section (each answer cut to :data:`VERDICT_WORDS`, pointing to its section), and the full
    answers to put at the top of their sections: {section title: [Paragraph]}."""
    blocks: list = [Heading("Verdicts")]
    moved: dict[str, list] = {}
    for v in verdicts:
        text, cut = short_verdict(v["answer"])
        section = v.get("section")
        if cut and section:
            blocks.append(Paragraph(f"**{v['question']}** {text} (More in \"{section}\".)"))
            moved.setdefault(section, []).append(Paragraph(f"**{v['question']}** {v['answer']}"))
        else:
            blocks.append(Paragraph(f"**{v['question']}** {v['answer']}"))
    return blocks, moved


def place_moved(blocks: list, moved: dict[str, list]) -> list:
    """``blocks`` with each section's moved verdicts right under its heading (left at the end, under a heading
    of their own, where no heading has the title)."""
    out, left = [], dict(moved)
    for block in blocks:
        out.append(block)
        if isinstance(block, Heading) and block.text in left:
            out += left.pop(block.text)
    if left:
        out.append(Heading("Verdicts in full"))
        out += [p for paragraphs in left.values() for p in paragraphs]
    return out


def monitor_verdict(accuracy: dict | None) -> str:
    """The energy-audit table's cell for a rung's accuracy record: '' for the equations (no monitor),
    'within' or 'ABOVE (figure)' against MuJoCo's tolerances."""
    if not accuracy or "tolerances" not in accuracy:
        return ""
    if accuracy.get("ok", True) and not accuracy.get("violations"):
        return "within its tolerances"
    return "ABOVE: " + ", ".join(sorted({v["figure"] for v in accuracy.get("violations", [])})) + " (see below)"


def accuracy_flag(name: str, accuracy: dict | None) -> str:
    """A sentence for a MuJoCo rung whose run went beyond the accuracy monitor's tolerances (a rung run with
    accuracy='warn' finishes and is reported, and its figures carry that error), or ''."""
    if not accuracy or "tolerances" not in accuracy or (accuracy.get("ok", True) and not accuracy.get("violations")):
        return ""
    parts = []
    for figure, tolerance in accuracy["tolerances"].items():
        worst = accuracy.get(figure)
        first = next((v for v in accuracy.get("violations", []) if v["figure"] == figure), None)
        if first is not None and worst is not None:
            parts.append(f"{figure} {abs(worst):.1e} against the tolerance {tolerance:g} (first above it at "
                         f"t = {first['t_s']:.3g} s)")
    return (f"{name}: " + "; ".join(parts) + ". The monitor warned instead of stopping this rung (accuracy="
            f"'{accuracy.get('mode', 'warn')}'), so its figures carry that error; compare its changes with it "
            "before drawing conclusions.")


def ladder_change(value, before, relative, key: str) -> str:
    """``value`` against ``before``: the signed percentage ``relative``, or, where the figure reaches zero or
    changes sign (a clutch reaction from -1371 N, a pull, to 0: '+100 %' would read as a doubling), the
    difference in the figure's unit ('+1371 N'); '' where either is missing (the first rung). The ladder's table
    gives each idealization's cost: ``value`` the rung before (with it), ``before`` the rung (without it)."""
    if before is None or value is None:
        return ""
    if (value == 0) != (before == 0) or (value * before < 0):
        unit = SUMMARY.get(key, (key, ""))[1]
        return f"{value - before:+.4g}" + (f" {unit}" if unit and unit != "-" else "")
    return "" if relative is None else pct(relative)

