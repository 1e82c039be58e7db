"""Render the validation report as Markdown and as self-contained HTML.

The report is built once as a list of blocks (heading, paragraph, table,
figure) and rendered twice, so ``report.md`` and ``index.html`` always say the
same. The HTML embeds its figures as data URIs: one file, readable offline,
no scripts.
"""

from __future__ import annotations

import base64
import html
import math
from dataclasses import dataclass
from pathlib import Path
from typing import Sequence

import numpy as np

from analytic.results import Mode

from .plots import new_figure, write_paper_figures
from .validate import FIGURE_RUNGS, LADDER_FIGURES, Rung


@dataclass
class Heading:
    text: str
    level: int = 2


@dataclass
class Paragraph:
    text: str


@dataclass
class Table:
    header: Sequence[str]
    rows: Sequence[Sequence[str]]


@dataclass
class Image:
    path: str  # relative to the report folder
    caption: str


def _fmt(value, digits: int = 4) -> str:
    if value is None:
        return "n/a"
    if isinstance(value, float) and not math.isfinite(value):
        return "n/a"
    return f"{value:.{digits}g}"


def _pct(value) -> str:
    return "" if value is None else f"{100 * value:+.2f} %"


def figure_clutch_reactions(rung: Rung, path: Path) -> None:
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


def build_blocks(metrics: dict, figures: dict[str, str]) -> list:
    blocks: list = [Heading("ipir-mujoco validation report", 1),
                    Paragraph("The paper's analytic model of the two-module inchworm robot, reproduced and "
                              "taken apart one idealization at a time at the paper's case "
                              f"(simulated {metrics['settings']['t_end_s']:g} s from rest).")]
    blocks.append(Heading("Verdicts"))
    for verdict in metrics["verdicts"]:
        blocks.append(Paragraph(f"**{verdict['question']}** {verdict['answer']}"))

    blocks.append(Heading("The paper's figures, reproduced"))
    blocks.append(Table(
        ["figure", "paper reports", "this model", "accepted interval", "reproduced", "why this interval"],
        [[c["label"], c["reported"], f"{_fmt(c['value'])} {c['units']}", f"[{_fmt(c['low'])}, {_fmt(c['high'])}]",
          "yes" if c["reproduced"] else "NO", c["why"]] for c in metrics["paper_checks"]]))
    for key in ("fig2_crank.png", "fig3_modules.png", "fig4_gap.png"):
        blocks.append(Image(figures[key], {
            "fig2_crank.png": "Paper's Fig. 2: crank angle in revolutions and cos phi; the paper's model (solid), "
                              "MuJoCo with the paper's locks (dashed) and with one-way clutches (dotted).",
            "fig3_modules.png": "Paper's Fig. 3: module displacements (from the start), velocities, accelerations.",
            "fig4_gap.png": "Paper's Fig. 4: gap S in dm and its rate."}[key]))

    blocks.append(Heading("The model ladder"))
    blocks.append(Paragraph("Each rung removes one idealization; the change against the rung before is what "
                            "that idealization costs."))
    header = ["rung", "removes"] + list(LADDER_FIGURES)
    rows = []
    for rung in metrics["ladder"]:
        cells = [rung["name"], rung["isolates"]]
        for key in LADDER_FIGURES:
            change = _pct(rung["change_vs_previous"][key])
            cells.append(_fmt(rung["summary"][key]) + (f" ({change})" if change else ""))
        rows.append(cells)
    blocks.append(Table(header, rows))
    if metrics["not_yet_evaluated"]:
        blocks.append(Paragraph("Not evaluated yet (not built in this version): "
                                + "; ".join(metrics["not_yet_evaluated"]) + "."))

    pull = metrics["clutch_pull"]
    blocks.append(Heading("Clutch forces under the paper's rule"))
    blocks.append(Paragraph(
        f"A locked clutch would have to pull during {100 * pull['fraction_of_time']:.1f} % of the run, with up to "
        f"{-pull['min_reaction_n']:.0f} N. The reaction is the moving module's m a + F_r: it turns negative "
        "whenever that module brakes harder than its resistance alone would brake it."))
    blocks.append(Image(figures["clutch_reactions.png"], "Locked-clutch reactions against crank angle."))

    blocks.append(Heading("Energy audit"))
    blocks.append(Paragraph("For the equations the residual is the integration error; for MuJoCo it is what "
                            "the soft constraints and the time stepping took."))
    blocks.append(Table(["rung", "motor work [J]", "kinetic [J]", "friction [J]", "residual [J]",
                         "residual / motor work"],
                        [[r["name"], _fmt(e["motor_work_j"], 8), _fmt(e["kinetic_j"], 8), _fmt(e["friction_j"], 8),
                          f"{e['residual_j']:.2e}", f"{e['residual_j'] / e['motor_work_j']:.1e}"]
                         for r in metrics["ladder"] for e in [r["summary"]["energy"]]]))

    blocks.append(Heading("Parameters and software"))
    blocks.append(Table(["parameter", "value (SI)"], [[k, _fmt(v, 6)] for k, v in metrics["params"].items()]))
    settings = metrics["settings"]
    blocks.append(Paragraph(f"Analytic solver: DOP853, rtol {settings['rtol']:g}, atol {settings['atol']:g}, "
                            f"output every {settings['dt_out_s']:g} s plus every mode switch"
                            + (" (quick run)." if settings["quick"] else ".")
                            + f" MuJoCo: {settings['mujoco']['integrator']}, timestep {settings['mujoco']['timestep']:g} s, "
                            f"constraint time constant {settings['mujoco']['constraint_time_constant']:g} s, "
                            f"solimp {tuple(settings['mujoco']['solimp'])} (evidence: mjcf/README.md)."))
    blocks.append(Table(["software", "version"], [[k, v] for k, v in metrics["versions"].items()]))
    blocks.append(Paragraph("All numbers above are in metrics.json (schema in ipir_mujoco/validate.py)."))
    return blocks


def to_markdown(blocks: list) -> str:
    out = []
    for block in blocks:
        if isinstance(block, Heading):
            out.append("#" * block.level + " " + block.text)
        elif isinstance(block, Paragraph):
            out.append(block.text)
        elif isinstance(block, Table):
            out.append("| " + " | ".join(block.header) + " |")
            out.append("|" + "---|" * len(block.header))
            out.extend("| " + " | ".join(str(c).replace("|", "\\|") for c in row) + " |" for row in block.rows)
        elif isinstance(block, Image):
            out.append(f"![{block.caption}]({block.path})\n\n*{block.caption}*")
        out.append("")
    return "\n".join(out)


_CSS = """body{font-family:sans-serif;max-width:1100px;margin:2em auto;padding:0 1em;color:#222;line-height:1.45}
table{border-collapse:collapse;margin:1em 0;font-size:0.9em}th,td{border:1px solid #bbb;padding:4px 8px;
vertical-align:top}th{background:#eee}img{max-width:100%}figure{margin:1.5em 0}figcaption{color:#555}"""


def _inline(text: str) -> str:
    escaped = html.escape(text)
    parts = escaped.split("**")
    return "".join(f"<strong>{p}</strong>" if i % 2 else p for i, p in enumerate(parts))


def to_html(blocks: list, folder: Path) -> str:
    body = []
    for block in blocks:
        if isinstance(block, Heading):
            body.append(f"<h{block.level}>{html.escape(block.text)}</h{block.level}>")
        elif isinstance(block, Paragraph):
            body.append(f"<p>{_inline(block.text)}</p>")
        elif isinstance(block, Table):
            head = "".join(f"<th>{html.escape(h)}</th>" for h in block.header)
            rows = "".join("<tr>" + "".join(f"<td>{html.escape(str(c))}</td>" for c in row) + "</tr>"
                           for row in block.rows)
            body.append(f"<table><tr>{head}</tr>{rows}</table>")
        elif isinstance(block, Image):
            data = base64.b64encode((folder / block.path).read_bytes()).decode("ascii")
            body.append(f'<figure><img src="data:image/png;base64,{data}" alt="{html.escape(block.caption)}">'
                        f"<figcaption>{html.escape(block.caption)}</figcaption></figure>")
    return ("<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">"
            f"<title>ipir-mujoco validation report</title><style>{_CSS}</style></head><body>\n"
            + "\n".join(body) + "\n</body></html>\n")


def write_report(folder: Path, metrics: dict, rungs: list[Rung]) -> None:
    """Write figures/, report.md and index.html into ``folder`` (metrics.json is the caller's)."""
    figures_dir = folder / "figures"
    figures_dir.mkdir(parents=True, exist_ok=True)
    drawn = [r for r in rungs if r.name in FIGURE_RUNGS]
    write_paper_figures([r.run for r in drawn], figures_dir, labels=[r.name for r in drawn])
    figure_clutch_reactions(rungs[0], figures_dir / "clutch_reactions.png")
    figures = {p.name: f"figures/{p.name}" for p in figures_dir.iterdir()}
    blocks = build_blocks(metrics, figures)
    (folder / "report.md").write_text(to_markdown(blocks))
    (folder / "index.html").write_text(to_html(blocks, folder))
