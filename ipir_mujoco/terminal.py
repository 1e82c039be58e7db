"""What a command shows on stderr while its work goes on: lines, and one status line.

A *status* (how far a run or a study has got, "still running", a rate and the time left) is shown as a terminal
user expects it: on a terminal, one line rewritten in place (at least every LIVE_EVERY_S while work goes on), which
the next ordinary line replaces; in a log (stderr not a terminal), at most one status line every LOG_EVERY_S, so
that a log gets a line at least that often and is not flooded. An ordinary line (a result, a note) is printed as it
comes, in both. Everything is written to ``sys.stderr`` as it is when written (tests capture it).

The command line marks the time its command runs (:func:`command`): a :func:`ticker` (the studies' progress,
whose designs may each take longer than a log's interval) says its status only while that command runs, so that
nothing is printed after it has ended; outside a command (the Python API), a ticker is silent.
"""

from __future__ import annotations

import sys
import threading
import time
import weakref
from contextlib import contextmanager
from typing import Callable

LIVE_EVERY_S = 1.0  # s of wall time: how often a terminal's status line is rewritten while work goes on
LOG_EVERY_S = 5.0  # s of wall time: how often a log gets a status line while work goes on (at most and at least)


class _Stderr:
    """The state of stderr's status line (one per process, behind a lock: tickers write from their threads)."""

    def __init__(self) -> None:
        self.lock = threading.Lock()
        self.open = False  # a status line stands on the terminal, not ended
        self.last = time.monotonic()  # wall time of the last line written to a log
        self.generation = 0  # counts the commands run: a ticker speaks only within its own
        self.running = False  # a command of the command line runs


_state = _Stderr()


def say(text: str, status: bool = False) -> None:
    """Write ``text`` on stderr: an ordinary line, or (``status``) the status line (module docstring)."""
    stream = sys.stderr
    tty = _isatty(stream)
    with _state.lock:
        if tty:
            if status:
                stream.write("\r" + text + "\x1b[K")
            else:
                stream.write(("\r" + text + "\x1b[K\n") if _state.open else text + "\n")
            _state.open = status
        else:
            now = time.monotonic()
            if status and now - _state.last < LOG_EVERY_S:
                return
            stream.write(text + "\n")
            _state.last = now
        stream.flush()


def end_status() -> None:
    """End a status line standing on the terminal (a newline after it), so that what follows starts a line."""
    with _state.lock:
        if _state.open:
            sys.stderr.write("\n")
            sys.stderr.flush()
            _state.open = False


def on_terminal() -> bool:
    """Whether stderr is a terminal (its status line is rewritten in place) rather than a log."""
    return _isatty(sys.stderr)


def _isatty(stream) -> bool:
    try:
        return stream.isatty()
    except (AttributeError, ValueError):  # closed, or not a file
        return False


@contextmanager
def command():
    """The command line's command runs within this: tickers may speak; on leaving, a status line standing on
    the terminal is ended and every ticker falls silent."""
    _state.generation += 1
    _state.running = True
    _state.last = time.monotonic()
    try:
        yield
    finally:
        _state.running = False
        _state.generation += 1
        end_status()


def ticker(owner, status: Callable[[object], str | None]) -> None:
    """While the command line's command that is running now runs, and ``owner`` lives, say ``status(owner)`` as
    the status line every LIVE_EVERY_S on a terminal, every LOG_EVERY_S in a log (None: nothing to say; the
    ticker stops once ``owner.finished`` is true). Outside a command, nothing. A daemon thread holding ``owner``
    weakly: it never holds up the process's exit or keeps the owner alive."""
    if not _state.running:
        return
    generation, ref = _state.generation, weakref.ref(owner)

    def tick() -> None:
        while True:
            time.sleep(LIVE_EVERY_S)
            target = ref()
            if target is None or getattr(target, "finished", False) or _state.generation != generation:
                return
            text = status(target)
            del target
            if text is not None:
                say(text, status=True)

    threading.Thread(target=tick, name="ipir-status", daemon=True).start()
