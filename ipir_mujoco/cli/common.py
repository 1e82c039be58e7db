"""What every subcommand shares: the parser class, exit codes, progress lines; and, from
:mod:`ipir_mujoco.studies.command` (below the studies, which read them too), the model options, the parameter
set they describe, a study's progress and the files a command writes."""

from __future__ import annotations

import argparse
import re
import sys
from typing import Callable

from .. import terminal
from ..studies.command import (add_model_options, add_study_options, check_input_file, compile_first,  # noqa: F401
                               files_line, model_params, study_progress, write_study_files)
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
