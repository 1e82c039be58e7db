"""Ctrl-C is an interruption everywhere: exit status 130 and one line, never a result, an error row or a
traceback; ``--resume`` then gives what the uninterrupted run gives.

The signal is sent when a progress line shows on stderr (so it lands in the work that follows, whatever the
machine's load), or, for the moments a line cannot mark (the imports, the end of a command), is made pending
before and let through at a chosen point (an import hook, or after the command returned). Nothing here
asserts on when the signal lands, only on what the command did.
"""

from __future__ import annotations

import csv
import os
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

import pytest

from ipir_mujoco import interrupts, registry
from cli_run import exit_code
from ipir_mujoco.core.params import RobotParams

COMMAND = [sys.executable, "-m", "ipir_mujoco"]


def _default_sigint() -> None:  # the child gets Python's usual Ctrl-C even where the test runs in the background
    signal.signal(signal.SIGINT, signal.SIG_DFL)


def interrupt_after(argv, line: str, cwd: Path, env: dict | None = None, timeout: float = 300.0):
    """Run ``ipir-mujoco ARGV``; send SIGINT once a stderr line containing ``line`` shows. Returns (exit status,
    stderr lines after that line, whether the signal was sent while the command still ran)."""
    process = subprocess.Popen([*COMMAND, *map(str, argv)], cwd=cwd, stdout=subprocess.DEVNULL,
                               stderr=subprocess.PIPE, text=True, preexec_fn=_default_sigint,
                               env={**os.environ, **(env or {})})
    after: list[str] = []
    sent = threading.Event()

    def watch() -> None:
        for text in process.stderr:
            if sent.is_set():
                after.append(text)
            elif line in text:
                sent.set()
                if process.poll() is None:
                    process.send_signal(signal.SIGINT)
    reader = threading.Thread(target=watch, daemon=True)
    reader.start()
    try:
        process.wait(timeout=timeout)
    finally:
        if process.poll() is None:
            process.kill()
    reader.join(timeout=30)
    return process.returncode, after, sent.is_set()


def assert_interrupted(code: int, after: list[str], sent: bool) -> None:
    assert sent, "the progress line never showed"
    # one line, the last on stderr (a progress line may have been under way when the signal came)
    assert code == 130, after
    assert after and "interrupted" in after[-1] and sum("interrupted" in a for a in after) == 1, after
    assert not any("Traceback" in a or "Error" in a for a in after), after


def rows(path: Path) -> list[dict]:
    with path.open(newline="", encoding="utf-8") as fh:
        return list(csv.DictReader(fh))


# ---------------------------------------------------------------------------------------------------------------
# optimize --workers 1: in the Sobol start, in COBYQA's first and a later local step, then --resume

OPTIMIZE = ["optimize", "--vary", "L=0.1:0.3", "--objective", "max:mean_speed_m_s", "--budget", "12",
            "--verify", "none", "--t-end", "0.3", "--workers", "1"]


@pytest.fixture(scope="module")
def optimize_reference(tmp_path_factory):
    out = tmp_path_factory.mktemp("opt") / "reference"
    assert exit_code([*OPTIMIZE, "--out", out]) == 0
    return out


@pytest.mark.slow
@pytest.mark.parametrize("moment", ["optimize 3/12", "optimize 9/12", "optimize 11/12"],
                         ids=["sobol start", "first local step", "later local step"])
def test_optimize_interrupted_then_resumed_gives_the_uninterrupted_evaluations(tmp_path, optimize_reference,
                                                                              moment, capsys):
    """Optimize's designs run in the main process (--workers 1; COBYQA's steps always do): a Ctrl-C there
    stops the study, records no row for the design it cut, and the resumed study's evaluations are the
    uninterrupted run's, byte for byte (COBYQA 9/12 on: the start is 8 designs)."""
    out = tmp_path / "opt"
    code, after, sent = interrupt_after([*OPTIMIZE, "--out", out], moment, tmp_path)
    assert_interrupted(code, after, sent)
    assert "--resume" in after[-1]
    assert all(not r["error"] for r in rows(out / "evaluations.csv"))  # the cut design is no error row
    assert exit_code([*OPTIMIZE, "--out", out, "--resume"]) == 0
    capsys.readouterr()
    assert (out / "evaluations.csv").read_bytes() == (optimize_reference / "evaluations.csv").read_bytes()


# ---------------------------------------------------------------------------------------------------------------
# sweep (a pool, and --workers 1 in MuJoCo's compiled and Python loops) and sensitivity

SWEEP = ["sweep", "--vary", "L=0.1:0.3:10", "--t-end", "0.3"]


@pytest.mark.slow
@pytest.mark.parametrize("extra,env", [
    (["--variants", "analytic-unilateral", "--workers", "2"], {}),
    (["--variants", "mujoco-ratchet", "--no-batch", "--workers", "1"], {}),
    (["--variants", "mujoco-ratchet", "--no-batch", "--workers", "1"], {"IPIR_MUJOCO_STEPPER": "python"}),
], ids=["analytic pool", "mujoco compiled loop", "mujoco python loop"])
def test_sweep_interrupted_then_resumed_gives_the_uninterrupted_rows(tmp_path, extra, env, capsys, monkeypatch):
    out, reference = tmp_path / "sweep", tmp_path / "reference"
    code, after, sent = interrupt_after([*SWEEP, *extra, "--out", out], "sweep 3/10", tmp_path, env)
    assert_interrupted(code, after, sent)
    assert all(not r["error"] for r in rows(out / "results.csv"))
    for name, value in env.items():
        monkeypatch.setenv(name, value)
    assert exit_code([*SWEEP, *extra, "--out", out, "--resume"]) == 0
    assert exit_code([*SWEEP, *extra, "--out", reference]) == 0
    capsys.readouterr()
    assert (out / "results.csv").read_bytes() == (reference / "results.csv").read_bytes()


@pytest.mark.slow
def test_sensitivity_interrupted_then_resumed_gives_the_uninterrupted_indices(tmp_path, capsys):
    argv = ["sensitivity", "--vary", "L=0.1:0.3", "--vary", "m2=0.5:1.5", "--metric", "mean_speed_m_s",
            "--samples", "4", "--t-end", "0.3", "--workers", "1"]
    out, reference = tmp_path / "sen", tmp_path / "reference"
    code, after, sent = interrupt_after([*argv, "--out", out], "sensitivity 4/16", tmp_path)
    assert_interrupted(code, after, sent)
    assert not (out / "indices.csv").exists()
    assert exit_code([*argv, "--out", out, "--resume"]) == 0
    assert exit_code([*argv, "--out", reference]) == 0
    capsys.readouterr()
    for name in ("evaluations.csv", "indices.csv"):
        assert (out / name).read_bytes() == (reference / name).read_bytes()


# ---------------------------------------------------------------------------------------------------------------
# the other study commands: 130, one line, no results folder

@pytest.mark.slow
@pytest.mark.parametrize("argv,line", [
    (["clutch-study", "--quick", "--workers", "1"], "[1/28]"),
    (["control-study", "--quick", "--workers", "1"], "open loop"),
    (["validate", "--quick"], "[1/7] paper model:"),
    (["climb", "--inclines", "0,10,20", "--t-end", "2"], "0 deg, analytic"),
    (["bend-study", "--quick", "--workers", "1"], "bend-study:"),
    (["simulate", "--engine", "mujoco", "--t-end", "6"], "simulated"),
    (["simulate", "--t-end", "6"], "simulated"),
], ids=["clutch-study", "control-study", "validate", "climb", "bend-study", "simulate mujoco", "simulate analytic"])
def test_a_study_interrupted_exits_130_in_one_line_and_writes_no_results(tmp_path, argv, line):
    code, after, sent = interrupt_after([*argv, "--out", tmp_path / "out"], line, tmp_path)
    assert_interrupted(code, after, sent)
    assert not (tmp_path / "out").exists()


# ---------------------------------------------------------------------------------------------------------------
# the moments no progress line marks: the signal is pending, let through at a chosen point

CHILD = r"""
import os, signal, sys
signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT})
os.kill(os.getpid(), signal.SIGINT)  # pending until let through
target = sys.argv[1]
class Hook:
    def find_spec(self, name, path=None, target_=None):
        if name == target:
            open("reached", "w").close()
            signal.pthread_sigmask(signal.SIG_UNBLOCK, {signal.SIGINT})
        return None
sys.meta_path.insert(0, Hook())
sys.argv = ["ipir-mujoco", *sys.argv[2:]]
from ipir_mujoco.cli import console
code = console()
if target == "after":
    open("reached", "w").close()
    signal.pthread_sigmask(signal.SIG_UNBLOCK, {signal.SIGINT})
sys.exit(code)
"""


@pytest.mark.parametrize("target", ["numpy", "matplotlib", "ipir_mujoco.analytic.unilateral_model",
                                    "ipir_mujoco.core.figures",
                                    "after"])
def test_ctrl_c_at_any_moment_is_at_most_one_line(tmp_path, target):
    """While the command line loads (numpy, scipy, matplotlib), inside the run (a module the run imports), and
    after the command returned (its result decided: the signal is ignored, the status is the command's)."""
    argv = ["simulate", "--geometry", "exact", "--clutch", "unilateral", "--t-end", "0.05", "--out", "out"]
    done = subprocess.run([sys.executable, "-c", CHILD, target, *argv], cwd=tmp_path, capture_output=True,
                          text=True, timeout=300, preexec_fn=_default_sigint)
    assert (tmp_path / "reached").exists(), f"{target} was never imported"
    # a run lasting over 2 s of wall time (a loaded machine) says how far it got: progress, not a message
    said = [line for line in done.stderr.splitlines() if not line.startswith("simulated ")]
    assert "Traceback" not in done.stderr and len(said) <= 1, done.stderr
    if target == "after":
        assert done.returncode == 0 and said == [] and (tmp_path / "out" / "summary.json").is_file()
    else:
        assert done.returncode == 130 and done.stderr.strip().endswith("interrupted"), done.stderr
        assert not (tmp_path / "out").exists()


MODULE_CHILD = r"""
import os, runpy, signal, sys
signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT})
os.kill(os.getpid(), signal.SIGINT)  # pending until let through
class Hook:
    def find_spec(self, name, path=None, target=None):
        if name == "ipir_mujoco.core.figures":  # imported by the run, the command's handler armed
            open("reached", "w").close()
            # let through inside code run from a string (as namedtuple, dataclasses, numba's generated code and
            # MuJoCo's bindings run it while the work goes on)
            exec("signal.pthread_sigmask(signal.SIG_UNBLOCK, {signal.SIGINT}); [n for n in range(9)]")
        return None
sys.meta_path.insert(0, Hook())
sys.argv = ["-m", *sys.argv[1:]]
runpy.run_module("ipir_mujoco", run_name="__main__", alter_sys=True)
"""


def test_ctrl_c_inside_code_run_from_a_string_exits_130_under_python_m(tmp_path):
    """CPython marks a KeyboardInterrupt that left code run by exec or eval from a string as unhandled, even once
    caught, and a process started with -m (pymain_run_module) then killed itself by SIGINT as it exited: status
    -2 after the one "interrupted" line (clutch-study under load, the signal in a namedtuple's or numba's
    generated code). The package's handler raises outside such code."""
    (tmp_path / "ctrl_c_child.py").write_text(MODULE_CHILD)
    argv = ["simulate", "--geometry", "exact", "--clutch", "unilateral", "--t-end", "0.05", "--out", "out"]
    done = subprocess.run([sys.executable, "-m", "ctrl_c_child", *argv], cwd=tmp_path, capture_output=True,
                          text=True, timeout=300, preexec_fn=_default_sigint)
    assert (tmp_path / "reached").exists()
    said = [line for line in done.stderr.splitlines() if not line.startswith("simulated ")]
    # interrupted, or (had the command ended before the signal was let through again) its result decided
    assert done.returncode in (130, 0) and "Traceback" not in done.stderr, (done.returncode, done.stderr)
    if done.returncode == 130:
        assert len(said) == 1 and said[0].endswith("interrupted") and not (tmp_path / "out").exists(), said
    else:
        assert said == [] and (tmp_path / "out" / "summary.json").is_file(), said


# ---------------------------------------------------------------------------------------------------------------
# the Python API

def _interrupt_soon(seconds: float) -> threading.Timer:
    timer = threading.Timer(seconds, lambda: os.kill(os.getpid(), signal.SIGINT))
    timer.start()
    return timer


@pytest.mark.parametrize("variant", ["analytic-unilateral", "mujoco-ratchet"])
def test_registry_run_raises_keyboard_interrupt_wherever_the_signal_lands(variant):
    """The signal at several moments of runs (compiled kernels included): each run either ends normally, before
    the signal, or raises KeyboardInterrupt, never another exception (SystemError from a compiled dispatcher)."""
    registry.run(variant, RobotParams(), 0.02)  # loaded and compiled before the signals
    outcomes = set()
    for k in range(6):
        timer = _interrupt_soon(0.02 + 0.04 * k)
        try:
            try:
                registry.run(variant, RobotParams(), 2.0)
                outcomes.add("finished")
            finally:
                # the signal lands here if the run ended first: wait for it whatever the load (a timer on a busy
                # machine fires late), inside this try, so that none is left to land outside it or in a later test
                timer.join()
            time.sleep(0)  # Python runs the handler at the next instruction
        except KeyboardInterrupt:
            outcomes.add("interrupted")
    assert "interrupted" in outcomes
    # Python's handler back, or the package's (installed by importing the command line), raising as Python's does
    assert signal.getsignal(signal.SIGINT) in (signal.default_int_handler, interrupts.handler)
    assert interrupts.state.armed


def test_an_interruption_a_library_swallowed_is_still_raised(monkeypatch):
    """A SIGINT whose KeyboardInterrupt became another exception, or was swallowed, inside a run: the run
    raises KeyboardInterrupt all the same."""
    from ipir_mujoco import analytic

    real = analytic.simulate

    def swallowing(*args, **kwargs):
        try:
            os.kill(os.getpid(), signal.SIGINT)
            time.sleep(0.5)
        except KeyboardInterrupt:
            pass  # what numba's dispatcher or a broad except did
        return real(*args, **kwargs)

    def mangling(*args, **kwargs):
        try:
            os.kill(os.getpid(), signal.SIGINT)
            time.sleep(0.5)
        except KeyboardInterrupt:
            raise SystemError("returned a result with an exception set") from None
        return real(*args, **kwargs)

    for fake in (swallowing, mangling):
        monkeypatch.setattr(analytic, "simulate", fake)
        with pytest.raises(KeyboardInterrupt):
            registry.run("analytic-approx", RobotParams(), 0.01)
    assert interrupts.state.armed


def test_the_command_line_catches_ctrl_c_from_its_first_statement(tmp_path):
    """The guard is installed before the heavy imports start, and once loaded raises KeyboardInterrupt as
    Python's own handler does."""
    code = ("import signal, sys; import ipir_mujoco.cli as c; from ipir_mujoco import interrupts; "
            "print(signal.getsignal(signal.SIGINT) is interrupts.handler, c._loading_guard)")
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True,
                          preexec_fn=_default_sigint, cwd=tmp_path)
    assert done.stdout.split() == ["True", "True"]
