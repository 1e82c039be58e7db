"""The report as a list of blocks (heading, paragraph, table, figure), rendered to Markdown and HTML.

A report is built once as blocks and rendered twice, so ``report.md`` and
``index.html`` always say the same. The HTML embeds its figures (PNG, GIF) as
data URIs: one file, readable offline, no scripts. ``**bold**`` in a paragraph
is the only inline markup.
"""

from __future__ import annotations

import base64
import html
import math
import re
from dataclasses import dataclass
from pathlib import Path
from typing import Sequence

from ..labels import significant, signed_percent


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
class Link:
    """A table cell that links to a heading of the report (its text)."""

    text: str
    heading: str


def anchor(text: str) -> str:
    """A heading's anchor, as GitHub makes one for Markdown: lower case, spaces to hyphens, no punctuation."""
    return re.sub(r"[^\w\- ]", "", text.lower()).strip().replace(" ", "-")


def _cell_markdown(cell) -> str:
    if isinstance(cell, Link):
        return f"[{cell.text}](#{anchor(cell.heading)})"
    return str(cell).replace("|", "\\|")


def _cell_html(cell) -> str:
    if isinstance(cell, Link):
        return f'<a href="#{anchor(cell.heading)}">{html.escape(cell.text)}</a>'
    return html.escape(str(cell))


@dataclass
class Image:
    path: str  # relative to the report folder; .png or .gif
    caption: str


def fmt(value, digits: int = 4) -> str:
    """A number to ``digits`` significant digits, trailing zeros kept (:func:`..labels.significant`); 'n/a'
    for None or a non-finite value."""
    if value is None:
        return "n/a"
    if isinstance(value, float) and not math.isfinite(value):
        return "n/a"
    return significant(value, digits)


def pct(value) -> str:
    """A fraction as a signed percentage with two decimals; '' for None."""
    return "" if value is None else signed_percent(value, 2)


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
            out.extend("| " + " | ".join(_cell_markdown(c) for c in row) + " |" for row in block.rows)
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
            body.append(f'<h{block.level} id="{anchor(block.text)}">{html.escape(block.text)}</h{block.level}>')
        elif isinstance(block, Paragraph):
            body.append(f"<p>{_inline(block.text)}</p>")
        elif isinstance(block, Table):
            head = "".join(f"<th>{html.escape(h)}</th>" for h in block.header)
            rows = "".join("<tr>" + "".join(f"<td>{_cell_html(c)}</td>" for c in row) + "</tr>"
                           for row in block.rows)
            body.append(f"<table><tr>{head}</tr>{rows}</table>")
        elif isinstance(block, Image):
            data = base64.b64encode((folder / block.path).read_bytes()).decode("ascii")
            mime = "image/gif" if block.path.endswith(".gif") else "image/png"
            body.append(f'<figure><img src="data:{mime};base64,{data}" alt="{html.escape(block.caption)}">'
                        f"<figcaption>{html.escape(block.caption)}</figcaption></figure>")
    return ("<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">"
            f"<title>ipir-mujoco validation report</title><style>{_CSS}</style></head><body>\n"
            + "\n".join(body) + "\n</body></html>\n")
