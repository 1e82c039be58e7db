"""A fuzz pass over the whole surface, as a careful user's mistakes go: every command's every option with bad
values (empty, blank, NaN, inf, negative, huge, text, paths that are folders, devices, missing or unwritable),
the issues' own cases, valid extremes (no grip, unlimited grip, a stall), and the public Python API with
arguments of the wrong type.

The contract each case is held to (docs/cli.md, "Entry point and exit status", "Output folders"):

- command line: the exit status the case expects (2 for bad input; 0 or 1 for a valid one); a failure is ONE
  line ``ipir-mujoco CMD: ...`` on stderr (progress lines before it allowed), with no traceback, no
  "internal error" and no library warning anywhere; a failed command leaves nothing in its folder; a
  successful ``--json`` is JSON Python's strict reader takes (no NaN, no Infinity);
- Python API: a wrong type raises ``ParameterTypeError`` (a ValueError and a TypeError), a bad value a
  ``ParameterError``, each with a one-line message; never another exception from deep inside.

Each case ends **clean** (the contract held), **real** (it did not: an internal error, a traceback, a wrong
exit status, a bad input run as if valid, a second line, files left behind, a wrong exception type) or
**expected** (a deviation this file names with its reason: a valid run longer than the case's time limit).
Every case runs in a child forked from this process, which has the package imported (as
tests/command_zygote.py does), in a folder of its own, with a time limit.

    python bench/fuzz_surface.py [--smoke] [--only cli|api] [--explicit] [--match TEXT] [-v]
    python bench/fuzz_surface.py --smoke      # a few cases of each kind

All the cases take ~10 min on 2 busy cores; ``--only api`` runs the Python API's alone (~30 s), ``--explicit``
the issues' named command lines alone, ``-v`` also prints every clean case. It prints one line per case that is
not clean, then ``clean N / real N / expected N`` per part and in all.
"""

from __future__ import annotations

import argparse
import json
import os
import shutil
import signal
import sys
import tempfile
import time
from dataclasses import dataclass, field
from pathlib import Path

ANY = frozenset({0, 1, 2})
BAD = frozenset({2})
OK = frozenset({0, 1})


@dataclass
class Case:
    """A command line (``argv``, ``{f}`` the fixture folder) or a Python call (``call``, run in the child),
    the exit statuses the contract allows, and the time limit [s]."""

    name: str
    argv: list[str] = field(default_factory=list)
    allowed: frozenset = ANY
    call: object = None  # a function of the fixture folder for an API case
    wrong_type: bool = False  # API: the exception must be a ParameterTypeError
    timeout: float = 120.0
    slow_ok: bool = False  # a valid run that may take longer than the limit: a timeout is 'expected'


# ------------------------------------------------------------------------------------------------------------
# the command line

# a short, valid run of each command, to which one bad option is added (the option given twice: argparse takes
# the last, and an append option gets one more item)
BASE = {
    "simulate": ["simulate", "--t-end", "0.02"],
    "validate": ["validate", "--quick"],
    "compare": ["compare", "{f}/run", "{f}/run2"],
    "sweep": ["sweep", "--vary", "L=0.1,0.2", "--variants", "analytic-approx", "--t-end", "0.02", "--workers", "1"],
    "optimize": ["optimize", "--vary", "L=0.1:0.3", "--objective", "max:revolutions", "--budget", "2", "--verify",
                 "none", "--t-end", "0.02", "--workers", "1"],
    "sensitivity": ["sensitivity", "--vary", "L=0.1:0.3", "--metric", "revolutions", "--samples", "2", "--t-end",
                    "0.02", "--workers", "1"],
    "kinetostatics": ["kinetostatics", "--omega", "10", "--revolutions", "1"],
    "params": ["params"],
    "render": ["render", "--t-end", "0.02", "--fps", "5"],
    "clutch-study": ["clutch-study", "--stiffness", "1e4", "--backlash", "0", "--points", "startup", "--workers",
                     "1"],
    "climb": ["climb", "--inclines", "0", "--variants", "analytic-unilateral", "--t-end", "0.05"],
    "control-study": ["control-study", "--quick", "--workers", "1"],
    "bend-study": ["bend-study", "--quick", "--workers", "1"],
    "atlas": ["atlas", "--vary", "L=0.1:0.3", "--idealization", "first-order-kinematics", "--metric", "revolutions",
              "--samples", "2", "--budget", "0", "--t-end", "0.05", "--workers", "1"],
    "uncertainty": ["uncertainty", "--dist", "L=uniform:0.1:0.3", "--metric", "revolutions", "--samples", "4",
                    "--t-end", "0.05", "--workers", "1"],
    "calibrate": ["calibrate", "--data", "{f}/measured.csv", "--fit", "L=0.15:0.25"],
}
# commands whose valid run takes minutes: only what they refuse is judged
LONG = {"validate", "control-study", "bend-study"}
# options whose values are numbers but where a word or a sign is meaningful
INF_OK = {"--wall-budget"}
SIGNED = {"--omega"}  # kinetostatics turns the crank backwards at a negative --omega
# studies that stream their rows into --out as designs finish: a failure after some ran keeps them for --resume
STREAMING = {"sweep", "optimize", "sensitivity", "atlas"}
SKIP = {"--debug", "--help"}

NUMBER_VALUES = {"": BAD, " ": BAD, "abc": BAD, "nan": BAD, "-nan": BAD, "inf": BAD, "-inf": BAD, "-1": BAD,
                 "0": ANY, "1e300": ANY, "1e-300": ANY, "1" * 5000: ANY}
TEXT_VALUES = {"": BAD, " ": BAD, "nan": ANY, ",": BAD, ":": BAD, "=": BAD, "\x01": BAD, "x" * 5000: ANY}
FILE_VALUES = {"": BAD, "{f}/missing.toml": BAD, "{f}/folder": BAD, "/dev/zero": BAD, "{f}/binary.bin": BAD,
               "{f}/empty.txt": BAD}
EMPTY_OK = {"--config", "--study", "--dist-file"}  # an empty TOML file is a valid one (nothing set)
OUT_VALUES = {"": BAD, "{f}/afile": BAD, "{f}/afile/sub": BAD, "/proc/ipir-fuzz/x": BAD}
SET_VALUES = {"": BAD, "=": BAD, "m1": BAD, "m1=": BAD, "m1=abc": BAD, "m1=nan": BAD, "m1=inf": BAD, "m1=-1": BAD,
              "m1=1e300": BAD, "nope=1": BAD, "=1": BAD, "L=0.01": BAD, "drive=servo": ANY, "mu_wall=0": ANY,
              "mu_wall=-0": ANY, "wheel_legs=3.5": BAD, "omega_target=1e-9": ANY, "rod_inertia=uniform": ANY}
# what a value of each option is, where its metavar or name does not say
KIND = {"--set": "set", "--config": "file", "--route": "file", "--mjcf": "file", "--study": "file", "--data": "file",
        "--dist-file": "file", "--save-mjcf": "outfile", "--out": "out", "--samples": None}


def option_kind(command: str, action) -> str | None:
    name = action.option_strings[-1]
    if name in SKIP or action.nargs == 0:
        return None
    if name == "--samples":  # kinetostatics reads a file, the studies a count
        return "file" if command == "kinetostatics" else "number"
    if name == "--out" and command == "render":
        return "outfile"
    if name in KIND:
        return KIND[name]
    if action.choices:
        return "choice"
    if action.type in (int, float):
        return "number"
    return "text"


def cli_cases() -> list[Case]:
    import argparse as ap

    from ipir_mujoco.cli import build_parser

    parser = build_parser()
    sub = next(a for a in parser._actions if isinstance(a, ap._SubParsersAction))
    cases = []
    for command, sp in sub.choices.items():
        base = BASE.get(command)
        if base is None:
            continue
        for action in sp._actions:
            if not action.option_strings:
                continue
            kind = option_kind(command, action)
            if kind is None:
                continue
            option = action.option_strings[-1]
            values = {"number": NUMBER_VALUES, "text": TEXT_VALUES, "file": FILE_VALUES, "out": OUT_VALUES,
                      "outfile": {"": BAD, "{f}/folder": BAD, "{f}/afile/x.gif": BAD, "/proc/ipir-fuzz/x.xml": BAD},
                      "set": SET_VALUES, "choice": {"": BAD, "abc": BAD}}[kind]
            for value, allowed in values.items():
                if option in INF_OK and value == "inf" or option in SIGNED and value == "-1":
                    allowed = ANY
                if option in EMPTY_OK and value == "{f}/empty.txt":
                    allowed = ANY
                if command in LONG and allowed != BAD:
                    continue  # a valid run of minutes: its refusals are what this pass judges
                shown = value if len(value) < 20 else f"{value[:8]}...({len(value)})"
                cases.append(Case(f"{command} {option} {shown!r}", base + [option, value], allowed,
                                  slow_ok=allowed != BAD))
    return cases


def explicit_cli_cases() -> list[Case]:
    """The hardening issues' cases and valid extremes, each with what the contract asks."""
    wheels = ["simulate", "--engine", "mujoco", "--mujoco-model", "wheels", "--t-end", "0.05"]
    opt = ["optimize", "--objective", "max:revolutions", "--budget", "2", "--verify", "none", "--t-end", "0.02",
           "--workers", "1"]
    sen = ["sensitivity", "--metric", "revolutions", "--samples", "2", "--t-end", "0.02", "--workers", "1"]
    return [
        # issue 53
        Case("wheels mu_wall=0 --json", wheels + ["--set", "mu_wall=0", "--json"], frozenset({0})),
        Case("wheels mu_wall=0 --out", wheels + ["--set", "mu_wall=0", "--out", "o"], frozenset({0})),
        Case("slides mu_wall=0 --json", ["simulate", "--engine", "mujoco", "--clutch", "unilateral", "--accuracy",
                                         "warn", "--t-end", "0.05", "--set", "mu_wall=0", "--json"], OK),
        Case("analytic mu_wall=0 --json", ["simulate", "--geometry", "exact", "--clutch", "unilateral", "--t-end",
                                           "0.05", "--set", "mu_wall=0", "--json"], OK),
        Case("stall --json", ["simulate", "--drive", "motor", "--set", "M_stall=0.01", "--t-end", "1", "--json"],
             frozenset({0})),
        Case("optimize --vary drive=0:1", opt + ["--vary", "drive=0:1"], BAD),
        Case("optimize --vary L=0.01:0.04", opt + ["--vary", "L=0.01:0.04"], BAD),
        Case("optimize --vary m1=-1:1", opt + ["--vary", "m1=-1:1"], BAD),
        Case("optimize --vary m1=0:1", opt + ["--vary", "m1=0:1"], BAD),
        Case("optimize --vary wheel_legs=3:8", opt + ["--vary", "wheel_legs=3:8"], BAD),
        Case("optimize --verify ''", opt[:-6] + ["--vary", "L=0.1:0.3", "--t-end", "0.02", "--workers", "1",
                                                 "--verify", ""], BAD),
        Case("sensitivity --vary drive=0:1", sen + ["--vary", "drive=0:1"], BAD),
        Case("sensitivity --vary m1=-1:1", sen + ["--vary", "m1=-1:1"], BAD),
        Case("sweep --vary m1=-1,1", ["sweep", "--vary", "m1=-1,1", "--variants", "analytic-approx", "--t-end", "0.02",
                                      "--workers", "1"], BAD),
        Case("sweep --vary drive=1,2", ["sweep", "--vary", "drive=1,2", "--variants", "analytic-approx", "--t-end",
                                        "0.02", "--workers", "1"], BAD),
        Case("clutch-study --set omega_target=5", BASE["clutch-study"] + ["--set", "omega_target=5"], BAD),
        Case("clutch-study --set speed_dip=0.1", BASE["clutch-study"] + ["--set", "speed_dip=0.1"], BAD),
        Case("climb --set omega_target=5", BASE["climb"] + ["--set", "omega_target=5"], BAD),
        Case("servo omega_target=1e-9 exact", ["simulate", "--drive", "servo", "--feedforward", "exact", "--set",
                                               "omega_target=1e-9", "--t-end", "0.05"], BAD),
        Case("render t_end=1e9", ["render", "--t-end", "1e9"], BAD),
        Case("render wheels pipe too small", ["render", "--mujoco-model", "wheels", "--set", "pipe_diameter=0.05"],
             BAD),
        Case("route first straight 0.31", wheels[:-2] + ["--route", "{f}/short.toml", "--set", "mu_wall=0.5"], BAD),
        Case("optimize --resume binary evaluations", opt + ["--vary", "L=0.1:0.3", "--resume", "--out",
                                                            "{f}/opt_binary"], BAD),
        Case("sweep all designs fail", ["sweep", "--vary", "L=0.1,0.2", "--variants", "analytic-approx", "--t-end",
                                        "0.5", "--timeout-per-design", "1e-6", "--workers", "1"], frozenset({1})),
        Case("simulate --out ''", ["simulate", "--t-end", "0.02", "--out", ""], BAD),
        Case("simulate --wall-budget 1e-6 wheels", wheels + ["--set", "mu_wall=0.5", "--wall-budget", "1e-6"],
             frozenset({1})),
    ]


# ------------------------------------------------------------------------------------------------------------
# the Python API

# ------------------------------------------------------------------------------------------------------------
# the fixtures and the forked children


def make_fixtures(root: Path) -> None:
    from ipir_mujoco.cli import main

    quiet = open(os.devnull, "w")
    saved = sys.stdout, sys.stderr
    sys.stdout = sys.stderr = quiet
    try:
        assert main(["simulate", "--t-end", "0.05", "--dt-out", "1e-3", "--out", str(root / "run")]) == 0
        assert main(["simulate", "--geometry", "exact", "--t-end", "0.05", "--dt-out", "1e-3", "--out",
                     str(root / "run2")]) == 0
        assert main(["sweep", "--vary", "L=0.1,0.2", "--variants", "analytic-approx", "--t-end", "0.02", "--workers",
                     "1", "--out", str(root / "swp")]) == 0
        assert main(["optimize", "--vary", "L=0.1:0.3", "--objective", "max:revolutions", "--budget", "2",
                     "--verify", "none", "--t-end", "0.02", "--workers", "1", "--out", str(root / "opt_binary")]) == 0
    finally:
        sys.stdout, sys.stderr = saved
    with (root / "opt_binary" / "evaluations.csv").open("ab") as fh:
        fh.write(b"\xff\xfe\x00\n")
    lines = (root / "run" / "timeseries.csv").read_text().splitlines()
    header = lines[0].split(",")
    t, x1 = header.index("t"), header.index("x1")
    (root / "measured.csv").write_text("t,x1\n" + "\n".join(f"{ln.split(',')[t]},{ln.split(',')[x1]}"
                                                             for ln in lines[1:]) + "\n")
    (root / "folder").mkdir()
    (root / "afile").write_text("x")
    (root / "empty.txt").write_text("")
    (root / "binary.bin").write_bytes(b"\xff\xfe\x00\x01" * 10)
    (root / "short.toml").write_text('[[segment]]\nkind = "straight"\nlength = 0.31\n[[segment]]\nkind = "bend"\n'
                                     'radius = 0.8\nangle = 90\n')
    (root / "route.toml").write_text('[[segment]]\nkind = "straight"\nlength = 0.4\n')
    (root / "config.toml").write_text("m1 = 2\n")


def child_cli(case: Case, root: Path, folder: Path) -> int:
    from ipir_mujoco.cli import main

    argv = [a.format(f=root) for a in case.argv]
    return main(argv)


def child_api(case: Case, root: Path, folder: Path) -> int:
    from ipir_mujoco.core.errors import ParameterError, ParameterTypeError

    call = case.call
    try:
        if isinstance(call, tuple):
            target, makers, position, bad = call
            args = [make(str(root)) for make in makers]
            args[position] = bad
            target(*args)
        else:
            call(str(root))
        outcome = {"raised": None}
    except BaseException as exc:  # noqa: BLE001 (what was raised is the finding)
        outcome = {"raised": type(exc).__name__, "parameter": isinstance(exc, ParameterError),
                   "type": isinstance(exc, ParameterTypeError), "message": str(exc)[:300],
                   "lines": str(exc).count("\n") + 1}
    print(json.dumps(outcome))
    return 0


def run_case(case: Case, root: Path, work: Path, index: int) -> tuple[str, str]:
    """('clean' | 'real' | 'expected', why) of one case, run in a forked child."""
    folder = work / f"case{index}"
    folder.mkdir()
    out, err = folder.parent / f"out{index}.txt", folder.parent / f"err{index}.txt"
    pid = os.fork()
    if pid == 0:  # the child
        code = 1
        try:
            os.chdir(folder)
            os.setpgid(0, 0)
            for fd, path in ((1, out), (2, err)):
                handle = os.open(path, os.O_WRONLY | os.O_CREAT | os.O_TRUNC)
                os.dup2(handle, fd)
                os.close(handle)
            sys.stdout = os.fdopen(1, "w", buffering=1)
            sys.stderr = os.fdopen(2, "w", buffering=1)
            code = (child_api if case.call is not None else child_cli)(case, root, folder)
        except SystemExit as exc:
            code = exc.code if isinstance(exc.code, int) else 2
        except BaseException as exc:  # noqa: BLE001
            print(f"FUZZ: uncaught {type(exc).__name__}: {exc}", file=sys.stderr)
            code = 99
        finally:
            try:
                sys.stdout.flush()
                sys.stderr.flush()
            finally:
                os._exit(code if isinstance(code, int) else 1)
    deadline = time.monotonic() + case.timeout
    status = None
    while time.monotonic() < deadline:
        done, status = os.waitpid(pid, os.WNOHANG)
        if done:
            break
        time.sleep(0.02)
    else:
        try:
            os.killpg(pid, signal.SIGKILL)
        except ProcessLookupError:
            pass
        os.waitpid(pid, 0)
        shutil.rmtree(folder, ignore_errors=True)
        if case.slow_ok:
            return "expected", f"a valid run longer than the case's {case.timeout:g} s"
        return "real", f"ran past {case.timeout:g} s (a bad input that runs?)"
    code = os.waitstatus_to_exitcode(status)
    stdout, stderr = out.read_text(errors="replace"), err.read_text(errors="replace")
    left = sorted(p.name for p in folder.iterdir())
    shutil.rmtree(folder, ignore_errors=True)
    return (judge_api(case, code, stdout, stderr) if case.call is not None
            else judge_cli(case, code, stdout, stderr, left))


def judge_cli(case: Case, code: int, stdout: str, stderr: str, left: list[str]) -> tuple[str, str]:
    lines = [ln for ln in stderr.splitlines() if ln.strip()]
    last = lines[-1] if lines else ""
    if code == 99 or "Traceback" in stderr or "internal error" in stderr:
        return "real", f"exit {code}: {last[:200]}"
    if "Warning" in stderr:
        return "real", f"a library warning: {next(ln for ln in lines if 'Warning' in ln)[:200]}"
    if code not in case.allowed:
        return "real", f"exit {code}, expected {sorted(case.allowed)}: {last[:200] or stdout[-200:]}"
    if code != 0:
        said = [ln for ln in lines if ln.startswith("ipir-mujoco ") and ": " in ln]
        if len(said) != 1 or not last.startswith("ipir-mujoco"):
            return "real", f"exit {code} with {len(said)} message lines: {last[:200]}"
        if left and code == 1 and case.argv[0] in STREAMING:
            return "expected", f"exit 1 kept the finished designs' rows for --resume (docs/cli.md): {last[:160]}"
        if left:
            return "real", f"exit {code} left {left[:5]} behind: {last[:160]}"
    elif "--json" in case.argv:
        try:
            json.loads(stdout, parse_constant=lambda name: (_ for _ in ()).throw(ValueError(name)))
        except ValueError as exc:
            return "real", f"--json printed what a strict reader refuses: {exc}"
    return "clean", f"exit {code}: {last[:160]}"


def judge_api(case: Case, code: int, stdout: str, stderr: str) -> tuple[str, str]:
    try:
        outcome = json.loads(stdout.strip().splitlines()[-1])
    except (ValueError, IndexError):
        return "real", f"the child printed no outcome (exit {code}): {stderr.strip()[-200:]}"
    if outcome["raised"] is None:
        return "real", "accepted a wrong type"
    if not outcome["parameter"]:
        return "real", f"{outcome['raised']}: {outcome['message'][:160]}"
    if case.wrong_type and not outcome["type"]:
        return "real", f"a ParameterError, not a ParameterTypeError: {outcome['message'][:160]}"
    if outcome["lines"] != 1:
        return "real", f"a message of {outcome['lines']} lines"
    return "clean", outcome["message"][:160]


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--smoke", action="store_true", help="a few cases of each kind")
    parser.add_argument("--only", choices=("cli", "api"), default=None)
    parser.add_argument("--match", default=None, help="only the cases whose name contains this")
    parser.add_argument("--explicit", action="store_true", help="the command line's named cases only (the issues')")
    parser.add_argument("-v", "--verbose", action="store_true")
    args = parser.parse_args(argv)
    os.environ.setdefault("MPLBACKEND", "Agg")
    import matplotlib.pyplot  # noqa: F401 (imported before the forks, as the commands import it)

    import ipir_mujoco.cli  # noqa: F401
    from ipir_mujoco import registry
    from ipir_mujoco.core.params import RobotParams

    registry.run("analytic-unilateral", RobotParams(), 0.01)  # the compiled kernels, once, before the forks
    parts = {}
    if args.only in (None, "cli"):
        parts["cli"] = explicit_cli_cases() + ([] if args.explicit else cli_cases())
    if args.only in (None, "api"):
        from fuzz_api import api_cases  # the Python API's cases (bench/fuzz_api.py)

        parts["api"] = api_cases()
    if args.match:
        parts = {k: [c for c in v if args.match in c.name] for k, v in parts.items()}
    if args.smoke:
        parts = {k: v[:: max(1, len(v) // 25)] for k, v in parts.items()}
    root = Path(tempfile.mkdtemp(prefix="ipir-fuzz-"))
    totals = {}
    try:
        make_fixtures(root / "f")
        started = time.monotonic()
        index = 0
        for part, cases in parts.items():
            counts = {"clean": 0, "real": 0, "expected": 0}
            for case in cases:
                index += 1
                verdict, why = run_case(case, root / "f", root, index)
                counts[verdict] += 1
                if verdict != "clean" or args.verbose:
                    print(f"{verdict:8s} {part}: {case.name}: {why}", flush=True)
            totals[part] = counts
            print(f"{part}: {len(cases)} cases: clean {counts['clean']} / real {counts['real']} / expected "
                  f"{counts['expected']}", flush=True)
        all_counts = {k: sum(c[k] for c in totals.values()) for k in ("clean", "real", "expected")}
        print(f"all: {sum(all_counts.values())} cases in {time.monotonic() - started:.0f} s: clean "
              f"{all_counts['clean']} / real {all_counts['real']} / expected {all_counts['expected']}")
    finally:
        shutil.rmtree(root, ignore_errors=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
