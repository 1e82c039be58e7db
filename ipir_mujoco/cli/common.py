"""What every subcommand shares: the parser class, exit codes, model options, progress lines."""

from __future__ import annotations

import argparse
import re
import sys
from typing import Callable

from ipir_mujoco.core.errors import ParameterError
from ipir_mujoco.core.params import DRIVES, FEEDFORWARDS, RobotParams, load_params

from .. import terminal
from ..terminal import LOG_EVERY_S

EXIT_OK, EXIT_FAILURE, EXIT_BAD_INPUT = 0, 1, 2


# what argparse reads as a negative number (a value, not an option): its own rule knows -1 and -.5 only, so
# that `--dt-out -1e-4` or `--t-end -inf` was "expected one argument" and the value never named
NEGATIVE_NUMBER = re.compile(r"^-(\d+\.?\d*|\.\d+)([eE][-+]?\d+)?$|^-(inf|infinity|nan)$", re.IGNORECASE)


class Parser(argparse.ArgumentParser):
    """argparse with a one-line error message and exit status 2, reading negative numbers in any spelling
    (-1e-4, -inf) as values, which the command then refuses with their range."""

    def __init__(self, *args, **kwargs):
        super().__init__(*args, **kwargs)
        self._negative_number_matcher = NEGATIVE_NUMBER

    def error(self, message: str):  # noqa: D102 (argparse API)
        self.exit(EXIT_BAD_INPUT, f"{self.prog}: error: {message} (see --help)\n")


def add_global_options(parser: argparse.ArgumentParser, top: bool = False) -> None:
    """--debug, accepted before and after the subcommand."""
    parser.add_argument("--debug", action="store_true", default=False if top else argparse.SUPPRESS,
                        help="on a failure, show the Python traceback instead of the one-line message")


def add_model_options(parser: argparse.ArgumentParser) -> None:
    """--set, --config and --drive: the parameter set of the robot."""
    parser.add_argument("--set", dest="overrides", action="append", default=[], metavar="NAME=VALUE",
                        help="set a parameter (SI units; incline in degrees); 'ipir-mujoco params' lists every "
                             "name with its meaning, unit, default and allowed range")
    parser.add_argument("--config", metavar="FILE.toml",
                        help="TOML file of parameters (top level or a [params] table); --set wins over it")
    parser.add_argument("--drive", choices=DRIVES, default=None,
                        help="what turns the crank: torque = the constant M (the paper's case, default); "
                             "motor = a DC gearmotor, M_stall (1 - omega / omega_noload); servo = that motor under "
                             "a speed controller holding omega_target (--set omega_target=RAD_S; docs/control.md); "
                             "wins over --set and the config file; a parameter only another drive uses (M, M_stall, "
                             "omega_noload, the controller's) is refused")
    parser.add_argument("--feedforward", choices=FEEDFORWARDS, default=None,
                        help="--drive servo only: the torque table the speed controller adds to its PI, from "
                             "inverse kinetostatics at omega_target: none (PI alone, default), paper (the paper's "
                             "first-order geometry, L >> r) or exact (the exact slider-crank); wins over --set")


def add_study_options(parser: argparse.ArgumentParser, command: str, set_help: str) -> None:
    """The options every study command (clutch-study, control-study, bend-study) shares: --workers, --out
    (default ./COMMAND), and --set (``set_help`` says what the study sets itself) and --config for the robot."""
    parser.add_argument("--workers", type=int, default=None, help="processes to use (default: all cores)")
    parser.add_argument("--out", metavar="DIR", default=command, help=f"results folder (default ./{command})")
    parser.add_argument("--set", dest="overrides", action="append", default=[], metavar="NAME=VALUE",
                        help=f"a robot parameter (SI units), {set_help}")
    parser.add_argument("--config", metavar="FILE.toml", help="TOML file of robot parameters; --set wins over it")


def model_params(args: argparse.Namespace) -> RobotParams:
    """The parameter set a command's options describe: defaults, --config, --set, then --drive and
    --feedforward (refused in one line with a drive other than servo)."""
    drive = getattr(args, "drive", None)
    # --drive as the last --set, not a replace(): a drive's parameters given with another drive are refused by
    # the run (core.params.refuse_idle_parameters), where replace() would quietly reset them
    params = load_params(args.config, [*args.overrides, *([f"drive={drive}"] if drive is not None else [])])
    feedforward = getattr(args, "feedforward", None)
    if feedforward is not None:
        if params.drive != "servo":
            raise ParameterError(f"--feedforward {feedforward} applies only to --drive servo (the drive here is "
                                 f"{params.drive!r}); allowed: --drive servo, or leave --feedforward out")
        params = params.replace(feedforward=feedforward)
    return params


def check_input_file(option: str, path: str) -> None:
    """A file the user names exists and is a file (not a folder), or a one-line ParameterError."""
    from pathlib import Path

    if not str(path).strip():  # Path('') is '.', the current folder
        raise ParameterError(f"{option} {path!r} names no file; give a file")
    target = Path(path)
    if target.is_dir():
        raise ParameterError(f"{option} {path!r} is a folder; give a file")
    if not target.exists():
        raise ParameterError(f"{option} {path!r} does not exist")
    if not target.is_file():  # /dev/zero, a pipe: read for ever
        raise ParameterError(f"{option} {path!r} is not a regular file (a device or pipe); give a file")


WALL_EVERY_S = LOG_EVERY_S  # s of wall time: the longest a long run's progress stays silent in a log file
FIRST_WALL_S = 2.0  # s of wall time before a run's first progress (work longer than 2 s shows progress)


def tenths_printer(total: float, text: Callable[[float], str], final_within: float = 0.0,
                   every_s: float | None = None, after_s: float = 0.0) -> Callable[[float], None]:
    """Progress on stderr, ``report(done)`` for ``done`` of ``total`` (any unit): on a terminal the status line
    (``text(done)``, :mod:`ipir_mujoco.terminal`: rewritten in place at each report), ended as a line once
    ``done`` is within ``final_within`` of ``total``; in a log file one line per tenth of the total and, with
    ``every_s`` [s], one at the first report at least ``every_s`` seconds of wall time after the last line (a
    run capped far beyond where it ends, as a route's, would otherwise print nothing for minutes), the first of
    them after FIRST_WALL_S. Nothing during the first ``after_s`` seconds (a short job stays quiet)."""
    import time

    started = time.monotonic()
    if sys.stderr.isatty():
        def report(done: float) -> None:  # a repeat's own time (RepeatProgress.t) decides where its line ends
            if time.monotonic() - started < after_s:
                return
            own = getattr(done, "t", done)
            terminal.say(text(done), status=own < total - final_within)
        return report
    shown, last = [0], [started - (every_s or 0.0) + max(FIRST_WALL_S, after_s)]

    def report_lines(done: float) -> None:
        now = time.monotonic()
        if now - started < after_s:
            return
        tenth = min(int(10 * done / total + 1e-9), 10)
        if tenth > shown[0] or (every_s is not None and now - last[0] >= every_s):
            shown[0], last[0] = max(shown[0], tenth), now
            terminal.say(text(done))
    return report_lines


def progress_printer(t_end: float) -> Callable[[float], None]:
    """Progress of a run on stderr (:func:`tenths_printer` of the simulated time [s], the callable's argument):
    on a terminal a status line rewritten at each report (the engines report every 0.1 s of simulated time and
    at least every half second of wall time), from the start for runs long enough to wait for (simulated time
    > 2 s), after FIRST_WALL_S of wall time for shorter ones (a run done sooner prints nothing); in a log file
    per tenth of the simulated time for the long ones, and at least every WALL_EVERY_S of wall time whatever
    the length, the first after FIRST_WALL_S. A run repeated at a finer step (the accuracy checks) says so in
    its lines (:func:`ipir_mujoco.core.options.progress_text`)."""
    from ipir_mujoco.core.options import progress_text

    def text(t: float) -> str:
        return progress_text(t, t_end)
    if t_end > 2.0:
        return tenths_printer(t_end, text, final_within=0.05, every_s=WALL_EVERY_S)
    return tenths_printer(float("inf") if not sys.stderr.isatty() else t_end, text, final_within=0.05,
                          every_s=WALL_EVERY_S, after_s=FIRST_WALL_S)


def wall_progress(total: float, text: Callable[[float], str], after_s: float = 2.0) -> Callable[[float], None]:
    """:func:`tenths_printer` of ``total`` that prints nothing during the first ``after_s`` seconds of wall
    time (a short job stays quiet, a long one says where it is; the first line it prints says how far the
    work went before)."""
    return tenths_printer(total, text, after_s=after_s)


def compile_first(engines=None) -> None:
    """Before a long command's work: the analytic kernels compiled now, in this process, where numba's cache
    does not hold them yet (once per machine: 12-40 s, said at once on stderr and every second while it lasts,
    :mod:`ipir_mujoco.analytic.accel`), so that the command says so within a second or two of its start rather
    than after its imports and first runs, and a pool's workers load them rather than each compiling them.
    ``engines``: the variants the command runs (None: the analytic engines among them); nothing without one."""
    from ipir_mujoco import registry

    if engines is not None and all(registry.variant(e).is_mujoco for e in engines):
        return
    from ipir_mujoco.analytic import accel, compile_kernels

    if accel.compilation_pending():
        compile_kernels()


def study_progress(command: str) -> Callable[[str], None]:
    """A study's progress on stderr, one line per message, prefixed with the command's name; a message that is
    a status (:class:`ipir_mujoco.core.options.Status`: "still running") as the status line (in place on a
    terminal, every 5 s in a log). ``live``: the study's heartbeats may beat every second."""
    from ipir_mujoco.core.options import Status

    def progress(message: str) -> None:
        terminal.say(f"{command}: {message}", status=isinstance(message, Status))
    progress.live = True
    return progress


def files_line(out, *names) -> str:
    """'OUT/a.csv, OUT/b.json, ...': every file a command wrote with its folder (``names`` relative to ``out``;
    a path already holding its folder, a figure's as the study returned it, as it is)."""
    from pathlib import Path

    return ", ".join(str(n) if Path(n).parent != Path(".") else str(Path(out) / n) for n in names)


def write_study_files(out, files: tuple[str, str, str], study: dict, write_csv, write_figure, table: str,
                      counted: str) -> None:
    """A study command's ending: ``files`` (CSV, JSON, figure) written into ``out`` all or nothing
    (``write_csv(path, study)``, the study as JSON, ``write_figure(path)``), then the ``table`` and one line
    '``counted`` in S s; results: ...' on stdout."""
    from pathlib import Path

    from ipir_mujoco.core.results import write_json

    from ..output import staged_output

    with staged_output(out) as staging:
        write_csv(staging / files[0], study)
        write_json(staging / files[1], study)
        write_figure(staging / files[2])
    print(table)
    print(f"{counted} in {study['wall_s']:.1f} s; results: " + ", ".join(str(Path(out) / f) for f in files))
