"""Running the command line inside a test: its exit status, standard output and standard error."""

from __future__ import annotations

import os
import subprocess
import sys
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
