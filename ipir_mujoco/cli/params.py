"""``ipir-mujoco params``: every parameter with its meaning, unit, default and allowed range."""

from __future__ import annotations

import argparse
import json
import textwrap

from ipir_mujoco.core.params import describe_parameters

from .common import EXIT_OK


def add_parser(commands) -> None:
    par = commands.add_parser("params", help="list every parameter: meaning, unit, default, allowed range",
                              description="Every parameter of the robot that --set, --config and the Python "
                                          "RobotParams accept, from the one definition all of them read.")
    par.add_argument("--json", action="store_true", help="print a JSON list of {name, meaning, units, default, "
                                                          "allowed} objects")
    par.set_defaults(handler=run)


WIDTH = 100  # columns: the listing reads in a standard terminal and in docs/cli.md


def format_table(rows: list[dict], width: int = WIDTH) -> str:
    """A plain-text table no wider than ``width``: name, unit, default, then the meaning and the
    allowed range wrapped in the last column."""
    header = ("name", "unit", "default")
    cells = [header] + [(r["name"], r["units"], r["default_text"]) for r in rows]
    widths = [max(len(row[i]) for row in cells) for i in range(3)]
    indent = sum(widths) + 2 * len(widths)
    wrap = textwrap.TextWrapper(width=max(30, width - indent), break_on_hyphens=False)

    def left(row) -> str:
        return "  ".join(text.ljust(w) for text, w in zip(row, widths)) + "  "

    lines = [left(header) + "meaning; allowed values", left(["-" * w for w in widths]) + "-" * (width - indent)]
    for row, r in zip(cells[1:], rows):
        text = wrap.wrap(r["meaning"]) + wrap.wrap(f"allowed: {r['allowed']}")
        lines.append(left(row) + text[0])
        lines += [" " * indent + line for line in text[1:]]
    return "\n".join(line.rstrip() for line in lines)


def run(args: argparse.Namespace) -> int:
    rows = describe_parameters()
    if args.json:
        print(json.dumps([{k: r[k] for k in ("name", "meaning", "units", "default", "allowed")} for r in rows]))
    else:
        print(format_table(rows))
        print("\nSet them with --set NAME=VALUE or in a TOML file (--config FILE.toml).\n"
              "Units are SI except incline (degrees).")
    return EXIT_OK
