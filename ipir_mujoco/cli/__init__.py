"""Command line: ``ipir-mujoco`` (``python -m ipir_mujoco``); the contract is in docs/cli.md.

Exit status: 0 success, 2 bad input (one line on stderr naming the value and
what is allowed), 1 a failure of the simulation itself (with the reason).
Each subcommand lives in its own module with ``add_parser(commands)`` and
``run(args) -> int``.
"""

from __future__ import annotations

import sys
from typing import Sequence

from ipir_mujoco.analytic.errors import ParameterError, SimulationError

from .. import __version__
from . import compare, kinetostatics, params, render, simulate, sweep, validate
from .common import EXIT_BAD_INPUT, EXIT_FAILURE, EXIT_OK, Parser

__all__ = ["EXIT_BAD_INPUT", "EXIT_FAILURE", "EXIT_OK", "build_parser", "main"]

COMMANDS = (simulate, validate, compare, sweep, kinetostatics, params, render)


def build_parser() -> Parser:
    parser = Parser(prog="ipir-mujoco",
                    description="Cross-check the analytic model of a two-module inchworm in-pipe robot "
                                "against MuJoCo physics. 'ipir-mujoco params' lists every parameter.")
    parser.add_argument("--version", action="version", version=f"%(prog)s {__version__}")
    commands = parser.add_subparsers(dest="command", required=True, parser_class=Parser)
    for command in COMMANDS:
        command.add_parser(commands)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    try:
        return args.handler(args)
    except ParameterError as exc:
        print(f"ipir-mujoco {args.command}: error: {exc}", file=sys.stderr)
        return EXIT_BAD_INPUT
    except SimulationError as exc:
        print(f"ipir-mujoco {args.command}: simulation failed: {exc}", file=sys.stderr)
        return EXIT_FAILURE


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
