"""Running the command line inside a test: its exit status, standard output and standard error."""

from __future__ import annotations

import functools
import io
import json
import logging
import os
import re
import runpy
import shlex
import signal
import subprocess
import sys
import tempfile
import time
import traceback
import warnings
from pathlib import Path

from ipir_mujoco.cli import main

# a command as a user types it: the installed ipir-mujoco and this interpreter as python first on PATH, figures
# without a screen, output unbuffered; no screen at all (the viewer must refuse in one line)
SHELL_ENV = {**os.environ, "PATH": f"{Path(sys.executable).parent}{os.pathsep}{os.environ.get('PATH', '')}",
             "MPLBACKEND": "Agg", "PYTHONUNBUFFERED": "1"}
for _name in ("DISPLAY", "WAYLAND_DISPLAY"):
    SHELL_ENV.pop(_name, None)
SHELL_TIMEOUT_S = 900  # per command: a bound on a hung run, far above any documented command's shortened run


def run_shell(text: str, cwd) -> subprocess.CompletedProcess:
    """``text`` run by bash in ``cwd``, output captured."""
    return subprocess.run(text, shell=True, executable="/bin/bash", cwd=cwd, env=SHELL_ENV, capture_output=True,
                          text=True, timeout=SHELL_TIMEOUT_S)


def exit_code(argv) -> int:
    """main()'s exit status, whether it returns it or argparse exits with it."""
    try:
        return main([str(a) for a in argv])
    except SystemExit as exc:
        return exc.code


def run_cli(capsys, *argv):
    """(exit status, stdout, stderr) of ``ipir-mujoco ARGV``, captured by pytest's ``capsys``."""
    code = exit_code(argv)
    out, err = capsys.readouterr()
    return code, out, err


# A documented command that is one program with plain words (no pipe, redirection or other shell syntax) runs in a
# child forked from this test process rather than in a new interpreter: the same entry point with the same
# arguments, folder, environment, standard streams and exit status, without importing numpy, MuJoCo, matplotlib and
# the package again for each of them (about 1-2 s of a new process). The child resets what a test process changed
# and a fresh one has not: warnings shown on stderr with Python's default filters, no logging handlers, Python's
# SIGINT handler. Anything else runs by bash (run_shell).
_SHELL_SYNTAX = re.compile(r"[|&;<>()$`*?{}\[\]~\\]|^\w+=")  # pipes, redirections, expansions, VAR=value
_DEFAULT_WARNINGS = (("ignore", ResourceWarning), ("ignore", ImportWarning), ("ignore", PendingDeprecationWarning),
                     ("ignore", DeprecationWarning))  # a process's filters without -W or -X dev (first one last)


def forked_entry(text: str):
    """``(kind, target, argv)`` for a command :func:`run_command` runs in a forked child, or None: ``ipir-mujoco
    ARGS`` ('console'), ``python FILE.py ARGS`` ('path') and ``python -m MODULE ARGS`` ('module')."""
    if _SHELL_SYNTAX.search(text):
        return None
    words = shlex.split(text)
    if words[0] == "ipir-mujoco":
        return "console", None, words
    if words[0] in ("python", "python3") and len(words) > 1:
        if words[1] == "-m" and len(words) > 2 and words[2].startswith("ipir_mujoco"):
            return "module", words[2], [words[2], *words[3:]]
        if words[1].endswith(".py"):
            return "path", words[1], words[1:]
    return None


@functools.lru_cache(maxsize=1)
def _interpreter_path() -> list[str]:
    """This interpreter's module path as a new process has it, without its first entry (the script's folder), and
    without what pytest and the tests added to this one."""
    done = subprocess.run([sys.executable, "-c", "import json, sys; print(json.dumps(sys.path[1:]))"],
                          capture_output=True, text=True, check=True, env=SHELL_ENV, cwd=tempfile.gettempdir())
    return json.loads(done.stdout)


def _child(kind: str, target, argv: list[str], cwd, out: int, err: int) -> int:
    """In the forked child: the command as a new process runs it; its exit status."""
    os.chdir(cwd)
    os.environ.clear()
    os.environ.update(SHELL_ENV)
    null = os.open(os.devnull, os.O_RDONLY)
    os.dup2(null, 0)
    os.dup2(out, 1)
    os.dup2(err, 2)
    sys.stdin = sys.__stdin__ = io.TextIOWrapper(io.FileIO(0, "r", closefd=False))
    sys.stdout = sys.__stdout__ = io.TextIOWrapper(io.FileIO(1, "w", closefd=False), write_through=True)
    sys.stderr = sys.__stderr__ = io.TextIOWrapper(io.FileIO(2, "w", closefd=False), write_through=True,
                                                   errors="backslashreplace")
    signal.signal(signal.SIGINT, signal.default_int_handler)
    warnings.resetwarnings()
    for action, category in _DEFAULT_WARNINGS:
        warnings.filterwarnings(action, category=category)
    warnings.filterwarnings("default", category=DeprecationWarning, module="__main__")
    warnings.showwarning = warnings._showwarning_orig  # pytest records warnings: a process prints them
    warnings._showwarnmsg_impl = lambda message: sys.stderr.write(warnings._formatwarnmsg(message))
    logging.root.handlers.clear()
    logging.root.setLevel(logging.WARNING)
    sys.argv = list(argv)
    try:
        if kind == "console":  # the installed script's own lines (its folder first on the path)
            sys.path[:] = [str(Path(sys.executable).parent), *_interpreter_path()]
            from ipir_mujoco.cli import console

            return console()
        if kind == "module":
            sys.path[:] = [str(cwd), *_interpreter_path()]
            runpy.run_module(target, run_name="__main__", alter_sys=True)
        else:
            script = Path(cwd, target).resolve()  # as Python 3.9+ names a script run by path: absolute
            sys.path[:] = [str(script.parent), *_interpreter_path()]
            runpy.run_path(str(script), run_name="__main__")
        return 0
    except SystemExit as exc:
        if exc.code is None or isinstance(exc.code, int):
            return exc.code or 0
        print(exc.code, file=sys.stderr)
        return 1
    except BaseException:  # noqa: B902 (as the interpreter does: the traceback, exit status 1)
        traceback.print_exc()
        return 1


def run_command(text: str, cwd, timeout: float = SHELL_TIMEOUT_S) -> subprocess.CompletedProcess:
    """``text`` run as a user types it in ``cwd``, output captured: in a child forked from this process where
    :func:`forked_entry` says it can, else by bash (:func:`run_shell`). Raises subprocess.TimeoutExpired after
    ``timeout`` s (the child killed)."""
    entry = forked_entry(text)
    if entry is None:
        return run_shell(text, cwd)
    with tempfile.TemporaryFile() as out, tempfile.TemporaryFile() as err:
        sys.stdout.flush()
        sys.stderr.flush()
        pid = os.fork()
        if pid == 0:  # the child: never returns into pytest
            code = 1
            try:
                code = _child(*entry, cwd, out.fileno(), err.fileno())
            finally:
                for stream in (sys.stdout, sys.stderr):
                    try:
                        stream.flush()
                    except BaseException:  # noqa: B902 (a closed stream: nothing more to say)
                        pass
                os._exit(code if isinstance(code, int) and 0 <= code < 256 else 1)
        deadline = time.monotonic() + timeout
        while True:
            done, status = os.waitpid(pid, os.WNOHANG)
            if done:
                break
            if time.monotonic() > deadline:
                os.kill(pid, signal.SIGKILL)
                os.waitpid(pid, 0)
                out.seek(0)
                raise subprocess.TimeoutExpired(text, timeout, output=out.read().decode(errors="replace"))
            time.sleep(0.01)
        texts = []
        for stream in (out, err):
            stream.seek(0)
            texts.append(stream.read().decode(errors="replace"))
    return subprocess.CompletedProcess(text, os.waitstatus_to_exitcode(status), *texts)
