"""What every subcommand shares: the parser class, exit codes, model options, progress lines."""

from __future__ import annotations

import argparse
import re
import sys
from typing import Callable

from ipir_mujoco.core.errors import ParameterError
from ipir_mujoco.core.options import progress_text
from ipir_mujoco.core.params import DRIVES, FEEDFORWARDS, RobotParams, load_params

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
                             "wins over --set and the config file")
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
    params = load_params(args.config, args.overrides)
    if getattr(args, "drive", None) is not None:
        params = params.replace(drive=args.drive)
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


WALL_EVERY_S = 10.0  # s of wall time: how long a long run's progress stays silent in a log file, to its next report
FIRST_WALL_S = 2.0  # s of wall time before a long run's first such line (work longer than 2 s shows progress)


def tenths_printer(total: float, text: Callable[[float], str], final_within: float = 0.0,
                   every_s: float | None = None) -> Callable[[float], None]:
    """Progress on stderr, ``report(done)`` for ``done`` of ``total`` (any unit): on a terminal one line
    (``text(done)``) rewritten in place, ended once ``done`` is within ``final_within`` of ``total``; in a log
    file one line per tenth of the total and, with ``every_s`` [s], one at the first report at least ``every_s``
    seconds of wall time after the last line (a run capped far beyond where it ends, as a route's, would otherwise
    print nothing for minutes), the first of them after FIRST_WALL_S."""
    import time

    if sys.stderr.isatty():
        def report(done: float) -> None:  # a repeat's own time (RepeatProgress.t) decides where its line ends
            own = getattr(done, "t", done)
            print("\r" + text(done), end="\n" if own >= total - final_within else "", file=sys.stderr, flush=True)
        return report
    shown, last = [0], [time.monotonic() - (every_s or 0.0) + FIRST_WALL_S]

    def report_lines(done: float) -> None:
        tenth = min(int(10 * done / total + 1e-9), 10)
        now = time.monotonic()
        if tenth > shown[0] or (every_s is not None and now - last[0] >= every_s):
            shown[0], last[0] = max(shown[0], tenth), now
            print(text(done), file=sys.stderr, flush=True)
    return report_lines


def progress_printer(t_end: float):
    """Progress of a run on stderr (:func:`tenths_printer` of the simulated time [s], the callable's argument):
    per tenth of the simulated time for runs long enough to wait for (simulated time > 2 s), and in a log file at
    least every WALL_EVERY_S of wall time whatever the length, the first after FIRST_WALL_S (a wheeled run steps
    seconds of wall time per simulated second; a run done within FIRST_WALL_S prints nothing). A run repeated at a
    finer step (the accuracy checks) says so in its lines (:func:`ipir_mujoco.core.options.progress_text`)."""
    import time

    def text(t: float) -> str:
        return progress_text(t, t_end)
    if t_end > 2.0:
        return tenths_printer(t_end, text, final_within=0.05, every_s=WALL_EVERY_S)
    if sys.stderr.isatty():
        return None
    last = [time.monotonic() - WALL_EVERY_S + FIRST_WALL_S]

    def wall_only(t: float) -> None:  # a short run: the wall clock's lines only
        now = time.monotonic()
        if now - last[0] >= WALL_EVERY_S:
            last[0] = now
            print(text(t), file=sys.stderr, flush=True)
    return wall_only


def wall_progress(total: float, text: Callable[[float], str], after_s: float = 2.0) -> Callable[[float], None]:
    """:func:`tenths_printer` of ``total`` that prints nothing during the first ``after_s`` seconds of wall
    time (a short job stays quiet, a long one says where it is; the first line it prints says how far the
    work went before)."""
    import time

    started, report = time.monotonic(), tenths_printer(total, text)

    def maybe(done: float) -> None:
        if time.monotonic() - started >= after_s:
            report(done)
    return maybe


def study_progress(command: str) -> Callable[[str], None]:
    """A study's progress on stderr, one line per message, prefixed with the command's name."""
    def progress(message: str) -> None:
        print(f"{command}: {message}", file=sys.stderr, flush=True)
    return progress


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
