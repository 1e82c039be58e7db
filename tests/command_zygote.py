"""A process that has the package and its libraries imported and forks a child for each command the tests run as a
user types it (tests/cli_run.py's run_command): the child becomes that command's process (its folder, environment,
standard streams, arguments, the ``ipir-mujoco`` script's or a ``python`` script's first path entry) and exits
the way the interpreter does, while a new interpreter would first spend 1-2 s importing numpy, SciPy, MuJoCo,
matplotlib and the package.

It is a fresh interpreter of its own, not the test process: a test process has pytest's warnings, logging and
capture in place and, once a test has rendered, MuJoCo's OpenGL driver with threads of its own, which a forked
child does not have (a render there waits on them for ever). Here nothing runs but imports (no thread, no OpenGL
context), and a child is forked only from this one thread.

Protocol, one JSON line each way per command: the request (kind, target, argv, cwd, env and the two files that
take standard output and error); the answer ``{"pid": N}`` once forked (the test kills N on its timeout), then
``{"status": S}`` (subprocess's returncode: the exit status, or minus the signal). End of input ends it.

    python tests/command_zygote.py    # then one request per line on standard input
"""

from __future__ import annotations

import atexit
import importlib
import io
import json
import os
import runpy
import signal
import sys
import traceback
from pathlib import Path


def preload() -> None:
    """Import what the commands import: the package's modules and with them numpy, SciPy, MuJoCo, matplotlib."""
    import matplotlib.pyplot  # noqa: F401 (MPLBACKEND from the environment, as in the commands)

    import ipir_mujoco

    root = Path(ipir_mujoco.__file__).parent
    for path in sorted(root.rglob("*.py")):
        parts = path.relative_to(root.parent).with_suffix("").parts
        if parts[-1] == "__main__":
            continue
        try:
            importlib.import_module(".".join(parts[:-1] if parts[-1] == "__init__" else parts))
        except Exception:  # noqa: BLE001 (an optional extra not installed: the command imports it, or says so)
            pass


def become(request: dict) -> int | None:
    """In the forked child: set up the command's process and run it; its exit status."""
    os.chdir(request["cwd"])
    os.environ.clear()
    os.environ.update(request["env"])
    streams = [os.open(os.devnull, os.O_RDONLY), *(os.open(request[name], os.O_WRONLY | os.O_TRUNC)
                                                   for name in ("stdout", "stderr"))]
    for fd, target in enumerate(streams):
        os.dup2(target, fd)
        os.close(target)
    # as the interpreter opens them with PYTHONUNBUFFERED (the tests' environment): text written through
    sys.stdin = sys.__stdin__ = io.TextIOWrapper(io.FileIO(0, "r", closefd=False))
    sys.stdout = sys.__stdout__ = io.TextIOWrapper(io.FileIO(1, "w", closefd=False), write_through=True)
    sys.stderr = sys.__stderr__ = io.TextIOWrapper(io.FileIO(2, "w", closefd=False), write_through=True,
                                                   errors="backslashreplace")
    sys.argv = list(request["argv"])
    kind, target = request["kind"], request["target"]
    if kind == "console":  # the installed script: its folder first on the path
        sys.path[0] = str(Path(sys.executable).parent)
        from ipir_mujoco.cli import console

        return console()
    if kind == "module":  # python -m MODULE: the current folder first, the module run afresh as __main__
        sys.path[0] = os.getcwd()
        sys.modules.pop(target, None)
        runpy.run_module(target, run_name="__main__", alter_sys=True)
        return 0
    script = Path(target).resolve()  # python FILE.py: the script's folder first, its name absolute
    sys.path[0] = str(script.parent)
    runpy.run_path(str(script), run_name="__main__")
    return 0


def finish(request: dict) -> None:
    """In the forked child: the command, then the end an interpreter gives it: an uncaught exception's traceback
    (exit 1; Ctrl-C's, then death by SIGINT), SystemExit's status or message, the exit functions and the streams
    flushed. The modules are not torn down (a new process's exit does that to no effect on what it printed, in
    about 0.3 s with these libraries loaded)."""
    try:
        code = become(request)
    except SystemExit as exc:
        code = exc.code
    except KeyboardInterrupt:
        traceback.print_exc()
        code = -signal.SIGINT
    except BaseException:  # noqa: B902 (as the interpreter does)
        traceback.print_exc()
        code = 1
    if code is not None and not isinstance(code, int):
        print(code, file=sys.stderr)
        code = 1
    atexit._run_exitfuncs()
    for stream in (sys.stdout, sys.stderr):
        try:
            stream.flush()
        except (OSError, ValueError):  # a closed stream or a reader gone: nothing more to say
            pass
    if code == -signal.SIGINT:
        signal.signal(signal.SIGINT, signal.SIG_DFL)
        os.kill(os.getpid(), signal.SIGINT)
    os._exit((code or 0) & 0xFF)


def serve() -> None:
    """Answer requests until standard input ends (a forked child never returns: :func:`finish`)."""
    answers = os.dup(1)
    preload()
    while True:
        line = sys.stdin.readline()
        if not line:
            return
        request = json.loads(line)
        sys.stdout.flush()
        sys.stderr.flush()
        pid = os.fork()
        if pid == 0:
            os.close(answers)
            finish(request)
        os.write(answers, (json.dumps({"pid": pid}) + "\n").encode())
        _, status = os.waitpid(pid, 0)
        os.write(answers, (json.dumps({"status": os.waitstatus_to_exitcode(status)}) + "\n").encode())


if __name__ == "__main__":
    serve()
