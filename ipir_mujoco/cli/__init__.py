"""Command line: ``ipir-mujoco`` (``python -m ipir_mujoco``); the contract is in docs/cli.md.

Exit status: 0 success, 2 bad input (one line on stderr naming the value and
what is allowed), 1 a failure of the simulation itself (with the reason), 130
interrupted (Ctrl-C). Every failure is one line on stderr; ``--debug`` (before
or after the subcommand) re-raises it with its traceback instead. A study's
subcommand is its declaration's (``ipir_mujoco.studies.contract``: its name,
options, run function and report module), found by
``ipir_mujoco.studies.declared``; every other subcommand (the tools of
:data:`TOOLS`) lives in its own module here with ``add_parser(commands)`` and
``run(args) -> int``.
"""

from __future__ import annotations

from ipir_mujoco import interrupts  # first: its SIGINT handler guards every import below

# Ctrl-C while numpy, scipy, matplotlib or MuJoCo load: nothing is open yet, so leave at once, in one line (a
# KeyboardInterrupt there would print a traceback from inside an import); installed first thing, only from the
# main thread and never over a handler the caller set. Once loaded, the handler raises KeyboardInterrupt as
# Python's own does (and counts: see ipir_mujoco.interrupts).
_loading_guard = interrupts.guard_loading()
try:
    import logging
    import os
    import sys
    from typing import Sequence

    from ipir_mujoco.core.errors import ParameterError, SimulationError, StudyInterrupted

    from .. import __version__
    from ..resources import shipped
    from .. import terminal
    from ..core.older_paths import keep_older_paths
    from ..studies import declared
    from . import compare, kinetostatics, params, render, simulate, validate
    from .common import EXIT_BAD_INPUT, EXIT_FAILURE, EXIT_OK, Parser, add_global_options
finally:
    interrupts.loaded()

EXIT_INTERRUPTED = interrupts.EXIT_INTERRUPTED  # 128 + SIGINT, as shells report it

# a study's command was a module here; it is its study's now (ipir_mujoco.studies), under its older path too
keep_older_paths({f"{__name__}.{older}": f"ipir_mujoco.studies.{now}" for older, now in (
    ("sweep", "sweeps.sweep_command"), ("optimize", "design.optimize_command"),
    ("sensitivity", "design.sensitivity_command"), ("calibrate", "design.calibrate_command"),
    ("uncertainty", "uq.uncertainty_command"), ("atlas", "idealizations.atlas_command"),
    ("climb", "climb.climb_command"), ("clutch_study", "mechanism.clutch_command"),
    ("control_study", "mechanism.control_command"), ("bend_study", "mechanism.bend_command"),
    ("design_check", "design.design_check_command"), ("design_runs", "design_runs"))})

__all__ = ["EXIT_BAD_INPUT", "EXIT_FAILURE", "EXIT_INTERRUPTED", "EXIT_OK", "build_parser", "console", "main"]

# the commands that are not studies: one module each, with add_parser(commands) and run(args) -> int; every
# study with a command of its own adds its own (its declaration: ipir_mujoco.studies.contract)
TOOLS = (simulate, validate, compare, kinetostatics, params, render)


def build_parser(command: str | None = None) -> Parser:
    """The command line's parser: every subcommand, or with ``command`` naming a tool (:data:`TOOLS`) that one
    alone (the studies' declarations are then not read: a tool's start-up does not pay for them)."""
    only = {_tool_name(t): t for t in TOOLS}.get(command)
    parser = Parser(prog="ipir-mujoco",
                    description="Cross-check the analytic model of a two-module inchworm in-pipe robot "
                                "against MuJoCo physics. 'ipir-mujoco params' lists every parameter.",
                    epilog=f"Documentation, installed with the package: {shipped('docs/cli.md')} (every command "
                           f"and option), {shipped('docs/model.md')} (the model and its conventions), "
                           f"{shipped('mjcf/README.md')} (the MuJoCo model and the evidence for its settings).")
    parser.add_argument("--version", action="version", version=f"%(prog)s {__version__}")
    add_global_options(parser, top=True)
    commands = parser.add_subparsers(dest="command", required=True, parser_class=Parser)
    for tool in (only,) if only is not None else TOOLS:
        tool.add_parser(commands)
    for study in () if only is not None else declared():
        if study.command:
            add_study(commands, study)
    for subparser in set(commands.choices.values()):
        add_global_options(subparser)
    return parser


def _tool_name(tool) -> str:
    """A tool's subcommand: its module's name (``cli.simulate``: ``simulate``)."""
    return tool.__name__.rsplit(".", 1)[-1]


def _named_command(argv: Sequence[str] | None) -> str | None:
    """The subcommand ``argv`` names: its first word that is not an option (the only option before it, --debug,
    takes no value), or None."""
    words = sys.argv[1:] if argv is None else argv
    return next((w for w in words if not str(w).startswith("-")), None)


def add_study(commands, study) -> None:
    """The subcommand of a study's declaration (:class:`ipir_mujoco.studies.contract.Declaration`): its parser, its
    options, and a handler that runs it with its report module (each name imported when first read)."""
    parser = commands.add_parser(study.name, help=study.summary, description=study.description)
    study.options(parser)

    def handler(args) -> int:
        study.run(args, _Figures(study.figures) if study.figures is not None else None)
        return EXIT_OK
    parser.set_defaults(handler=handler)


class _Figures:
    """A study's report module (``ipir_mujoco.report.<name>``), imported when a name of it is first read: after
    the study's checks and its kernels' compile, so that matplotlib's import delays neither."""

    def __init__(self, name: str):
        self._name = f"ipir_mujoco.report.{name}"

    def __getattr__(self, attribute: str):
        import importlib

        return getattr(importlib.import_module(self._name), attribute)


def main(argv: Sequence[str] | None = None) -> int:
    """Run the command line; return the exit status (see the module docstring).

    Ctrl-C anywhere in it is exit status 130 and one line: the first SIGINT raises KeyboardInterrupt, any later
    one is only counted, so that the clean-up runs (:mod:`ipir_mujoco.interrupts`)."""
    swapped = interrupts.begin_command()
    try:
        try:
            return _command(argv)
        except KeyboardInterrupt:  # landed outside the command's own handling (parsing, its last lines)
            print("ipir-mujoco: interrupted", file=sys.stderr)
            return EXIT_INTERRUPTED
    finally:
        interrupts.end_command(swapped)


def console() -> int:
    """The ``ipir-mujoco`` command's entry point (and ``python -m ipir_mujoco``'s): :func:`main` as the process's
    own command, after which a Ctrl-C changes nothing (the result is decided) and is ignored."""
    interrupts.state.process = True
    return main()


def _command(argv: Sequence[str] | None) -> int:
    try:
        args = build_parser(_named_command(argv)).parse_args(argv)
        prefix = f"ipir-mujoco {args.command}"
        notes = _show_notes(prefix)
        try:
            with terminal.command():
                code = args.handler(args)
            # an option's older name used (studies.command.add_variant_option): said once the command succeeded,
            # so that a failure stays one line
            for note in getattr(args, "notes", ()) if code == 0 else ():
                print(f"{prefix}: note: {note}", file=sys.stderr)
            return code
        except BaseException as exc:  # noqa: B902 (every failure becomes one line, or a traceback with --debug)
            if args.debug or isinstance(exc, SystemExit):
                raise
            if isinstance(exc, BrokenPipeError):
                return _reader_gone()
            code, message = _describe_failure(exc)
            print(f"{prefix}: {message}", file=sys.stderr)
            return code
        finally:
            logging.getLogger("ipir_mujoco").removeHandler(notes)
    finally:
        interrupts.state.armed = False  # first, with no call before it: no KeyboardInterrupt from here on


MAX_MESSAGE = 1000  # characters of a one-line failure message shown (a huge value in it is cut)
EXIT_PIPE_CLOSED = 141  # 128 + SIGPIPE, as shells report a writer whose reader left


def _reader_gone() -> int:
    """stdout's reader left (``ipir-mujoco ... | head``): end quietly, as Unix tools do, with no message, and
    point stdout at /dev/null so that the interpreter's last flush does not complain either."""
    try:
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
    except (OSError, ValueError, AttributeError):  # stdout is not a file (tests capture it)
        pass
    return EXIT_PIPE_CLOSED


def _show_notes(prefix: str) -> logging.Handler:
    """What the package says while it works (logger 'ipir_mujoco' at INFO, e.g. that the analytic kernels
    compile once, the first time a machine runs them long enough) goes to stderr as one line each, with the
    command's name; returns the handler, to remove when the command ends."""
    handler = _Notes()
    handler.setFormatter(logging.Formatter(f"{prefix}: %(message)s"))
    logger = logging.getLogger("ipir_mujoco")
    logger.addHandler(handler)
    logger.setLevel(logging.INFO)
    return handler


class _Notes(logging.Handler):
    """The package's notes on stderr, a record marked ``status`` (the compile's "still compiling") as the status
    line (:mod:`ipir_mujoco.terminal`: in place on a terminal, every 5 s in a log)."""

    def emit(self, record: logging.LogRecord) -> None:
        try:
            terminal.say(self.format(record), status=bool(getattr(record, "status", False)))
        except Exception:  # noqa: BLE001 (logging's rule: a note that cannot be written is dropped)
            self.handleError(record)


def _describe_failure(exc: BaseException) -> tuple[int, str]:
    """(exit status, one line) for an exception that reached the command line."""
    def one_line(text: str) -> str:  # a value of 100,000 characters is not repeated whole
        line = " ".join(str(text).split())
        return line if len(line) <= MAX_MESSAGE else f"{line[:MAX_MESSAGE]}... ({len(line)} characters in all)"

    if isinstance(exc, ParameterError):
        return EXIT_BAD_INPUT, f"error: {one_line(exc)}"
    if isinstance(exc, SimulationError):
        return EXIT_FAILURE, f"simulation failed: {one_line(exc)}"
    if isinstance(exc, KeyboardInterrupt):
        return EXIT_INTERRUPTED, "interrupted"
    if isinstance(exc, StudyInterrupted):  # a study's Ctrl-C: where its results so far are
        return EXIT_INTERRUPTED, one_line(exc)
    if isinstance(exc, MemoryError):
        return EXIT_FAILURE, "out of memory (a smaller run: shorter --t-end, larger --dt-out, fewer designs)"
    if isinstance(exc, OSError):
        where = f" {exc.filename!r}" if exc.filename else ""
        return EXIT_FAILURE, f"cannot read or write{where}: {one_line(exc.strerror or exc)}"
    return EXIT_FAILURE, (f"internal error: {type(exc).__name__}: {one_line(exc)} "
                          "(run again with --debug for the traceback, and please report it)")


if __name__ == "__main__":  # pragma: no cover
    sys.exit(console())
