"""Running the command line inside a test: its exit status, standard output and standard error."""

from __future__ import annotations

import atexit
import json
import math
import os
import re
import select
import shlex
import signal
import subprocess
import sys
import tempfile
import threading
import time
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



# A command of plain words (no pipe, redirection or other shell syntax) runs in a child forked by a process that has
# the libraries imported (tests/command_zygote.py), one per thread of the tests; anything else runs by bash.
_SHELL_SYNTAX = re.compile(r"[|&;<>()$`*?{}\[\]~\\]|^\w+=")  # pipes, redirections, expansions, VAR=value
ZYGOTE = Path(__file__).with_name("command_zygote.py")


def forked_entry(text: str):
    """``(kind, target, argv)`` for a command :func:`run_command` runs in a forked child, or None: ``ipir-mujoco
    ARGS`` ('console'), ``python FILE.py ARGS`` ('path') and ``python -m ipir_mujoco...`` ('module')."""
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


class _Zygote:
    """tests/command_zygote.py as a process, started at this thread's first command, ended with this process."""

    def __init__(self):
        self.errors = tempfile.TemporaryFile()  # its own failure, if it fails: the test says why
        self.process = subprocess.Popen([sys.executable, str(ZYGOTE)], stdin=subprocess.PIPE,
                                        stdout=subprocess.PIPE, stderr=self.errors, env=SHELL_ENV,
                                        cwd=tempfile.gettempdir())
        self.pending = b""
        atexit.register(self.process.stdin.close)  # its end of input: it ends

    def answer(self, deadline: float) -> dict | None:
        """The next answer line, or None at ``deadline`` (time.monotonic())."""
        fd = self.process.stdout.fileno()
        while b"\n" not in self.pending:
            wait = None if deadline == math.inf else max(0.0, deadline - time.monotonic())
            ready, _, _ = select.select([fd], [], [], wait)
            if not ready:
                return None
            chunk = os.read(fd, 4096)
            if not chunk:
                self.errors.seek(0)
                raise RuntimeError(f"the command process {ZYGOTE.name} ended (exit {self.process.wait()}):\n"
                                   + self.errors.read().decode(errors="replace")[-2000:])
            self.pending += chunk
        line, self.pending = self.pending.split(b"\n", 1)
        return json.loads(line)

    def run(self, entry, text: str, cwd, timeout: float) -> subprocess.CompletedProcess:
        kind, target, argv = entry
        with tempfile.NamedTemporaryFile() as out, tempfile.NamedTemporaryFile() as err:
            request = dict(kind=kind, target=target, argv=argv, cwd=str(Path(cwd).resolve()), env=SHELL_ENV,
                           stdout=out.name, stderr=err.name)
            self.process.stdin.write((json.dumps(request) + "\n").encode())
            self.process.stdin.flush()
            deadline = time.monotonic() + timeout
            pid = self.answer(math.inf)["pid"]
            done = self.answer(deadline)
            if done is None:
                os.kill(pid, signal.SIGKILL)
                self.answer(math.inf)
                raise subprocess.TimeoutExpired(text, timeout, output=Path(out.name).read_text(errors="replace"))
            texts = [Path(f.name).read_text(errors="replace") for f in (out, err)]
        return subprocess.CompletedProcess(text, done["status"], *texts)


_zygotes = threading.local()


def run_command(text: str, cwd, timeout: float = SHELL_TIMEOUT_S) -> subprocess.CompletedProcess:
    """``text`` run as a user types it in ``cwd``, output captured: a command :func:`forked_entry` accepts in a
    child of tests/command_zygote.py (the same entry point, arguments, folder, environment and streams, without a
    new interpreter's imports), anything else by bash (:func:`run_shell`). Raises subprocess.TimeoutExpired after
    ``timeout`` s (the command killed)."""
    entry = forked_entry(text)
    if entry is None:
        return run_shell(text, cwd)
    if getattr(_zygotes, "zygote", None) is None:
        _zygotes.zygote = _Zygote()
    return _zygotes.zygote.run(entry, text, cwd, timeout)
