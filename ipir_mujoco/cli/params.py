"""``ipir-mujoco params``: every parameter with its meaning, unit, default and allowed range."""

from __future__ import annotations

import argparse
import json

from ipir_mujoco.analytic.params import describe_parameters

from .common import EXIT_OK


def add_parser(commands) -> None:
    par = commands.add_parser("params", help="list every parameter: meaning, unit, default, allowed range",
                              description="Every parameter of the robot that --set, --config and the Python "
                                          "RobotParams accept, from the one definition all of them read.")
    par.add_argument("--json", action="store_true", help="print a JSON list of {name, meaning, units, default, "
                                                          "allowed} objects")
    par.set_defaults(handler=run)


def format_table(rows: list[dict]) -> str:
    """A plain-text table: name, unit, default, allowed range, meaning."""
    header = ("name", "unit", "default", "allowed", "meaning")
    cells = [header] + [(r["name"], r["units"], r["default_text"], r["allowed"], r["meaning"]) for r in rows]
    widths = [max(len(row[i]) for row in cells) for i in range(4)]
    lines = []
    for row in cells:
        lines.append("  ".join(text.ljust(width) for text, width in zip(row[:4], widths)) + "  " + row[4])
    lines.insert(1, "  ".join("-" * w for w in widths) + "  " + "-" * len(header[4]))
    return "\n".join(lines)


def run(args: argparse.Namespace) -> int:
    rows = describe_parameters()
    if args.json:
        print(json.dumps([{k: r[k] for k in ("name", "meaning", "units", "default", "allowed")} for r in rows]))
    else:
        print(format_table(rows))
        print("\nSet them with --set NAME=VALUE or in a TOML file (--config FILE.toml); "
              "units are SI except incline (degrees).")
    return EXIT_OK
