"""What long work shows on stderr: a status line in place on a terminal, a line every 5 s in a log, and the
kernels' compile said before a long command's work (ipir_mujoco.terminal, cli.common, analytic.accel)."""

from __future__ import annotations

import io
import subprocess
import sys
import threading
import time

import pytest

from ipir_mujoco import terminal


class Tty(io.StringIO):
    def isatty(self) -> bool:
        return True


def test_a_terminal_shows_one_status_line_in_place(monkeypatch):
    """Each status rewrites the line it stands on; an ordinary line takes its place and ends it; ending the
    status leaves a line break after it, once."""
    stream = Tty()
    monkeypatch.setattr(sys, "stderr", stream)
    terminal.say("sweep 1/4 designs", status=True)
    terminal.say("sweep 2/4 designs", status=True)
    terminal.say("a note")
    terminal.say("sweep 3/4 designs", status=True)
    terminal.end_status()
    terminal.end_status()
    assert stream.getvalue() == ("\rsweep 1/4 designs\x1b[K\rsweep 2/4 designs\x1b[K\ra note\x1b[K\n"
                                 "\rsweep 3/4 designs\x1b[K\n")


def test_a_log_gets_a_status_line_every_5_s_and_every_ordinary_line(monkeypatch):
    """On a made-up clock: statuses every second, but a log gets one only once LOG_EVERY_S has passed since its
    last line of any kind; ordinary lines always."""
    stream = io.StringIO()
    monkeypatch.setattr(sys, "stderr", stream)
    clock = [1000.0]
    monkeypatch.setattr(time, "monotonic", lambda: clock[0])
    with terminal.command():  # the log's clock starts with the command
        for second in range(1, 13):
            clock[0] = 1000.0 + second
            terminal.say(f"status {second}", status=True)
            if second == 7:
                terminal.say("a note")
    assert terminal.LOG_EVERY_S == 5.0 and stream.getvalue().splitlines() == ["status 5", "a note", "status 12"]


def test_a_study_says_how_far_it_is_while_a_design_runs_and_stops_with_the_command(monkeypatch):
    """sweep_files.Progress: within a command, its ticker says the designs done, the rate and the time so far
    while no design ends (a design of a wheeled model may take longer than a log's interval); outside a command,
    and once the command has ended, nothing. Waits for the lines (a bound, not a timing)."""
    from ipir_mujoco.studies.sweep_files import Progress

    stream = io.StringIO()
    monkeypatch.setattr(sys, "stderr", stream)
    monkeypatch.setattr(terminal, "LIVE_EVERY_S", 0.01)
    monkeypatch.setattr(terminal, "LOG_EVERY_S", 0.0)
    outside = Progress(4, 0, True, what="sweep")  # the Python API: no ticker
    with terminal.command():
        bar = Progress(4, 0, True, what="sweep")
        for _ in range(6000):
            if stream.getvalue().count("\n") >= 2:
                break
            time.sleep(0.01)
        lines = stream.getvalue().splitlines()
        assert len(lines) >= 2 and all(line.startswith("sweep 0/4 designs, 0.00 designs/s, ") and
                                       line.endswith(" s so far") for line in lines), lines
    time.sleep(0.1)  # a tick in flight lands
    ended = stream.getvalue()
    time.sleep(0.2)
    assert stream.getvalue() == ended  # the command has ended: silent
    assert bar is not outside


def test_a_heartbeat_for_the_command_line_beats_every_second_as_its_status():
    """core.options.heartbeat: to a printer marked live (the command line's) every LIVE_HEARTBEAT_S, each beat a
    Status (shown in place); to any other callable every HEARTBEAT_S, 5 s."""
    from ipir_mujoco.cli.common import study_progress
    from ipir_mujoco.core.options import HEARTBEAT_S, LIVE_HEARTBEAT_S, Status, heartbeat

    assert (HEARTBEAT_S, LIVE_HEARTBEAT_S) == (5.0, 1.0)
    assert heartbeat(study_progress("x"), "step").every_s == 1.0 and heartbeat(print, "step").every_s == 5.0
    lines, first = [], threading.Event()

    def report(message: str) -> None:
        lines.append(message)
        first.set()

    with heartbeat(report, "step", every_s=0.01):
        assert first.wait(60)
    assert isinstance(lines[0], Status)


COMPILE_FIRST = r"""
import sys
from ipir_mujoco.analytic import accel
import ipir_mujoco.analytic as analytic

accel.compilation_pending = lambda: True  # a cold cache, as on a machine's first run


def compile_kernels():  # what the command has loaded, and run, when it compiles
    heavy = sorted(m for m in ("matplotlib", "ipir_mujoco.report.validation",
                               "ipir_mujoco.studies.idealizations.atlas", "ipir_mujoco.studies.sweeps.sweep")
                   if m in sys.modules)
    print("COMPILE", heavy, flush=True)
    raise SystemExit(0)


analytic.compile_kernels = compile_kernels
from ipir_mujoco.cli import main
sys.exit(main(sys.argv[1:]))
"""


@pytest.mark.parametrize("argv", [["validate", "--quick"], ["atlas", "--vary", "L=0.1:0.3", "--budget", "0"],
                                  ["sweep", "--vary", "L=0.1,0.2"]])
def test_a_long_command_compiles_the_kernels_first_on_a_cold_cache(tmp_path, argv):
    """validate, atlas and sweep (their input checked first) compile the analytic kernels before their work, in
    their own process before any pool, validate and atlas before matplotlib and the report load: so the compile's
    note is a cold cache's first line (within a second or two of the start, not after 20 s of imports and runs),
    and the workers load the kernels rather than each compiling them. (sweep's --plot-metric check lives in its
    figure module, with matplotlib.)"""
    done = subprocess.run([sys.executable, "-c", COMPILE_FIRST, *argv, "--out", str(tmp_path / "o")],
                          capture_output=True, text=True, cwd=tmp_path, timeout=300)
    assert done.returncode == 0 and done.stdout.startswith("COMPILE"), (done.stdout, done.stderr)
    loaded = done.stdout.split(" ", 1)[1].strip()
    heavy = {"validate": "[]",  # atlas's checks: its study and the sweep's
             "atlas": "['ipir_mujoco.studies.idealizations.atlas', 'ipir_mujoco.studies.sweeps.sweep']",
             "sweep": "['ipir_mujoco.studies.sweeps.sweep', 'matplotlib']"}
    assert loaded == heavy[argv[0]] and done.stderr == "" and not (tmp_path / "o").exists()
