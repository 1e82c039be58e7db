"""Ctrl-C (SIGINT) is an interruption, wherever it lands: never a result, an error row or a SystemError.

Python's own handler raises KeyboardInterrupt at the next bytecode the main thread runs. Where that is
inside code that calls back into Python (numba's compiled dispatchers, a C extension, a library's
``except Exception``), the KeyboardInterrupt can come out as another exception (``SystemError: ...
returned a result with an exception set``) or be swallowed. So the package counts the signals itself
(:func:`handler`) and asks after the work whether one arrived (:func:`raise_if_interrupted`):
:func:`ipir_mujoco.registry.run` does, so that a run interrupted anywhere raises KeyboardInterrupt, and
the studies (which record a run's *failure* as a row) never record an interruption as one.

The command line installs :func:`handler` as its first statement (:func:`guard_loading`: while the
numerics load, a Ctrl-C ends the process at once in one line, as nothing is open yet) and keeps it while the
command runs; its first signal raises KeyboardInterrupt, later ones are only counted, so that the
command's clean-up (killing a pool's workers, sorting a results file) is not cut short by a second Ctrl-C.
From Python, :func:`watching` installs it for the length of a run where Python's default handler is in
place, and leaves any handler of the caller's alone.

One place a command's KeyboardInterrupt is never raised: inside code run from a string (``exec``/``eval``
of source text, which namedtuple, dataclasses, numba's generated code and MuJoCo's bindings all do while
the work goes on). CPython marks a KeyboardInterrupt that leaves such code as unhandled even when the
program catches it later, and a process started as ``python -m ipir_mujoco`` then kills itself by SIGINT
when it exits (status -2, after its one "interrupted" line; seen with Python 3.11 to 3.13). There the handler lets
the signal through again a moment later (:func:`_pass_on`) and raises at the first check outside.

Imports nothing but the interpreter's own modules (signal, _thread, os, threading, time): it is loaded
before numpy.
"""

from __future__ import annotations

import _thread
import os
import threading
import time
from contextlib import contextmanager

try:  # the interpreter's own module, loaded at start-up: no import time in which a Ctrl-C could land
    import _signal as _sig
except ImportError:  # pragma: no cover (another Python implementation)
    import signal as _sig

EXIT_INTERRUPTED = 130  # 128 + SIGINT, as shells report it
LOADING_LINE = b"ipir-mujoco: interrupted\n"



class _State:
    """What :func:`handler` does with the next SIGINT. A plain attribute store (``state.armed = False``) runs
    no Python call, so no signal handler can run between the statement before it and the store itself."""

    armed = True  # the next SIGINT raises KeyboardInterrupt (False: counted only)
    command = False  # a command line's command runs: its first SIGINT disarms the handler (outside: none does)
    loading = False  # the command line is still importing: a SIGINT ends the process at once
    process = False  # the command line runs as the process (its console entry): ignore SIGINT once it is done
    count = 0  # SIGINTs received while handler() was installed, ever
    passed_on = False  # the next call is a SIGINT handler() let through again (already counted)


state = _State()


def handler(signum, frame):  # noqa: ARG001 (signal handler signature)
    """The package's SIGINT handler: count the signal; while loading, leave in one line (exit 130); else raise
    KeyboardInterrupt, as Python's default handler does, except that in a command only the first signal
    raises (later ones are only counted, so that the command's clean-up is not cut short)."""
    if state.passed_on:
        state.passed_on = False
    else:
        state.count += 1
    if state.loading:
        os.write(2, LOADING_LINE)
        os._exit(EXIT_INTERRUPTED)
    if state.armed:
        if state.process and _in_code_from_a_string(frame):  # see the module's docstring
            state.passed_on = True
            _thread.start_new_thread(_pass_on, ())  # not threading's: the main thread may hold its locks
            return
        state.armed = not state.command
        raise KeyboardInterrupt


PASS_ON_S = 0.005  # s before a signal held back is let through again (a string's code runs for microseconds)


def _pass_on() -> None:
    """From another thread: :func:`handler` again in the main thread at its next check (a thread, as the
    main thread would otherwise run it at once, inside the same code)."""
    time.sleep(PASS_ON_S)
    _thread.interrupt_main(_sig.SIGINT)  # does nothing once the command ended (SIGINT ignored)


def _in_code_from_a_string(frame) -> bool:
    """Whether ``frame`` runs inside code that ``exec`` or ``eval`` runs from source text (CPython compiles it
    as ``<module>`` of ``<string>``); the outermost frame (``python -c``'s own code) does not count."""
    while frame is not None and frame.f_back is not None:
        code = frame.f_code
        if code.co_name == "<module>" and code.co_filename == "<string>":
            return True
        frame = frame.f_back
    return False


def count() -> int:
    """How many SIGINTs :func:`handler` has received in this process."""
    return state.count


def interrupted_since(since: int) -> bool:
    """Whether a SIGINT arrived after :func:`count` was ``since``."""
    return state.count != since


def _main_thread() -> bool:
    return threading.current_thread() is threading.main_thread()


def guard_loading() -> bool:
    """Install :func:`handler` in loading mode if Python's default handler is in place (never over a
    handler the caller set; main thread only), or put it back in loading mode where it is installed; True if
    so. End it with :func:`loaded`."""
    try:
        current = _sig.getsignal(_sig.SIGINT)
        if current is handler:  # installed already (the package's __init__ as the command starts): loading again
            state.loading = True
            return True
        if current is not _sig.default_int_handler:
            return False
        state.loading = True
        _sig.signal(_sig.SIGINT, handler)
        return True
    except (ValueError, AttributeError):  # not the main thread, or no signals here
        state.loading = False
        return False


def loaded() -> None:
    """The command line's imports are done: a SIGINT now raises KeyboardInterrupt (as Python's default handler
    does, so that the handler may stay installed in a process that only imported the command line)."""
    state.loading = False


def _install() -> bool:
    """Install :func:`handler` if Python's default SIGINT handler is in place (main thread only); True if it did."""
    if not _main_thread():
        return False
    try:
        if _sig.getsignal(_sig.SIGINT) is _sig.default_int_handler:
            _sig.signal(_sig.SIGINT, handler)
            return True
    except (ValueError, AttributeError):  # pragma: no cover
        pass
    return False


@contextmanager
def watching():
    """Count SIGINTs during the block, with :func:`handler` installed if Python's default handler is in place
    (main thread only); yields the count at the start, for :func:`interrupted_since`."""
    swapped = _install()
    try:
        yield state.count
    finally:
        if swapped:
            _sig.signal(_sig.SIGINT, _sig.default_int_handler)


@contextmanager
def as_keyboard_interrupt():
    """A block in which a Ctrl-C ends as KeyboardInterrupt, whatever the code it landed in made of it (an error,
    an error row, or nothing): the run's own outcome is dropped when a SIGINT arrived during the block."""
    with watching() as since:
        try:
            yield
        except BaseException:
            if interrupted_since(since):
                raise KeyboardInterrupt from None
            raise
        if interrupted_since(since):
            raise KeyboardInterrupt


def begin_command() -> bool:
    """A command starts: :func:`handler` installed (if Python's default handler is in place; True then) and
    armed. End it with :func:`end_command`."""
    swapped = _install()
    state.armed = state.command = True
    return swapped


def end_command(swapped: bool) -> None:
    """A command has ended (after ``state.armed = False``, its last statement): as the process's own command
    (:data:`state.process`) a SIGINT from here to the process's end changes nothing and is ignored (Python's
    shutdown would otherwise restore the default action, and the process would die by the signal with no
    line); called from Python, the handler raises again, and the caller's is put back where it was swapped."""
    if not _main_thread():
        return
    try:
        if state.process:
            _sig.signal(_sig.SIGINT, _sig.SIG_IGN)
            return
        state.command = False
        state.armed = True
        if swapped:
            _sig.signal(_sig.SIGINT, _sig.default_int_handler)
    except (ValueError, AttributeError):  # pragma: no cover
        pass
