"""Bad input from every side: the command line, study and config files, run folders, the Python API.

Each case must end as exit 2 (the user's input) or 1 (the simulation) with ONE line on stderr
that names the offending value, create nothing, and print no library warning. The table holds
every case the hardening issue found (and their neighbours); hypothesis adds random text for the
parsers. ``IPIR_FUZZ=long`` runs the property tests with many more examples (the CI profile is
derandomized and short: see conftest.py).
"""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
import warnings
from decimal import Decimal
from fractions import Fraction
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from ipir_mujoco import analytic, registry
from ipir_mujoco.analytic import ParameterError, RobotParams, load_params
from ipir_mujoco.cli import main
from ipir_mujoco.core.options import (DEFAULT_WALL_BUDGET_S, MAX_SAMPLES, RunOptions, check_run_options,
                                      check_step_count)
from ipir_mujoco.studies.sweep import run_sweep
from ipir_mujoco.studies.sweep_space import MAX_DESIGNS, Study, parse_vary

LONG = os.environ.get("IPIR_FUZZ") == "long"
EXAMPLES = 2000 if LONG else 60


def run_cli(capsys, argv):
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            code = main([str(a) for a in argv])
        except SystemExit as exc:  # argparse's own errors
            code = exc.code
    out, err = capsys.readouterr()
    return code, out, err, [str(w.message) for w in caught]


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    """Bad files of every kind, and one good run folder to break (shared: no case may write into it)."""
    f = tmp_path_factory.mktemp("fuzz")
    (f / "latin1.toml").write_bytes(b"L = 0.3 # \xff\xfe\n")
    (f / "latin1_study.toml").write_bytes(b'[sweep]\nvary = ["L=0.1,0.2"] # \xff\n')
    for name, text in {"t_end_abc": '[sweep]\nvary=["L=0.1,0.2"]\nt_end="abc"\n',
                       "sample_x": '[sweep]\nvary=["L=0.1:0.2"]\nsample="x"\n',
                       "vary_numbers": "[sweep]\nvary=[1,2]\n",
                       "vary_string": '[sweep]\nvary="L=0.1,0.2"\n',
                       "engines_string": '[sweep]\nvary=["L=0.1,0.2"]\nengines="analytic-approx"\n',
                       "sweep_not_table": 'sweep = 3\n',
                       "params_bad": '[sweep]\nvary=["L=0.1,0.2"]\n[params]\nm1 = "heavy"\n'}.items():
        (f / f"{name}.toml").write_text(text)
    (f / "folder").mkdir()
    (f / "afile").write_text("x")
    run = f / "run"
    assert main(["simulate", "--t-end", "0.05", "--dt-out", "1e-3", "--out", str(run)]) == 0
    header = (run / "timeseries.csv").read_text().splitlines()[0]
    for name, text in {"empty": "", "header_only": header + "\n", "torn": header + "\n0,0,0"}.items():
        shutil.copytree(run, f / name)
        (f / name / "timeseries.csv").write_text(text)
    shutil.copytree(run, f / "nan")
    lines = (f / "nan" / "timeseries.csv").read_text().splitlines()
    cells = lines[5].split(",")
    cells[4] = "nan"
    lines[5] = ",".join(cells)
    (f / "nan" / "timeseries.csv").write_text("\n".join(lines) + "\n")
    (f / "big_int.toml").write_text("L = " + "1" * 100_000 + "\n")  # past Python's 4300-digit limit
    (f / "deep.toml").write_text("L = " + "[" * 5000 + "]" * 5000 + "\n")
    (f / "deep_study.toml").write_text("[sweep]\nvary = " + "[" * 5000 + "]" * 5000 + "\n")
    (f / "k_header_only.csv").write_text("t,phi\n")
    (f / "clash").mkdir()
    (f / "clash" / "summary.json").mkdir()  # a folder where simulate writes a file
    sweep = f / "swp"
    assert main(["sweep", "--vary", "L=0.1,0.2", "--variants", "analytic-approx", "--t-end", "0.05",
                 "--out", str(sweep)]) == 0
    for name, tail in {"garbage": b"hello world\n", "binary": b"\xff\xfe\x00\x01\n", "nul": b"5,\x00\n",
                       "extra": (sweep / "results.csv").read_bytes().splitlines()[1] + b",1,2\n"}.items():
        shutil.copytree(sweep, f / f"swp_{name}")
        with (f / f"swp_{name}" / "results.csv").open("ab") as fh:
            fh.write(tail)
    (f / "k_empty.csv").write_text("")
    (f / "k_semicolon.csv").write_text("t;phi\n0;0\n0.1;0.2\n0.2;0.5\n0.3;0.9\n")
    (f / "k_ragged.csv").write_text("t,phi\n0,0\n0.1\n0.2,0.5\n0.3,0.9\n")
    return f


# (argv with {f} for the fixture folder, exit status, a fragment of the one line)
CASES = [
    (["simulate", "--set", "omega0=1e300"], 2, "omega0=1e+300 is out of range"),
    (["simulate", "--geometry", "exact", "--set", "L=1e300"], 2, "L=1e+300 is out of range"),
    (["simulate", "--set", "M=1e300"], 2, "M=1e+300 is out of range"),
    (["simulate", "--config", "{f}/latin1.toml"], 2, "not UTF-8"),
    (["simulate", "--config", "{f}/folder"], 2, "is a folder"),
    (["simulate", "--t-end", "1e9"], 2, "t_end=1e+09 is out of range"),
    (["simulate", "--t-end", "100", "--dt-out", "1e-12"], 2, "would keep 1e+14 samples"),
    (["simulate", "--dt-out", "0"], 2, "dt_out=0.0 is out of range"),
    (["simulate", "--engine", "mujoco", "--t-end", "0.1", "--dt-out", "0.2"], 2, "dt_out <= t_end"),
    (["simulate", "--engine", "mujoco", "--mjcf", "{f}/folder"], 2, "is a folder"),
    (["simulate", "--engine", "mujoco", "--max-switches", "10"], 2, "--max-switches 10 applies only"),
    (["simulate", "--max-switches", "0"], 2, "--max-switches=0 is out of range"),
    # a constant torque has no periodic steady state: refused before any run, not run to the cap
    (["simulate", "--until-steady"], 2, "until_steady with drive=torque"),
    (["simulate", "--engine", "mujoco", "--until-steady", "--set", "drive=torque"], 2, "--drive motor"),
    (["sweep", "--vary", "L=0.1,0.2", "--until-steady", "--out", "{f}/steady"], 2, "until_steady with drive=torque"),
    (["simulate", "--t-end", "0.1", "--out", "{f}/afile/sub"], 2, "is a file, not a folder"),
    (["simulate", "--t-end", "0.1", "--out", "{f}/afile"], 2, "is not a folder"),
    (["compare", "{f}/run", "{f}/empty"], 2, "is empty"),
    (["compare", "{f}/run", "{f}/header_only"], 2, "0 sample row(s)"),
    (["compare", "{f}/run", "{f}/torn"], 2, "1 sample row(s)"),
    (["compare", "--json", "{f}/run", "{f}/nan"], 2, "x1=nan is not a finite number"),
    (["compare", "{f}/run", "{f}/afile"], 2, "has no column 't' in its header row"),
    (["compare", "{f}/run", "{f}/run", "--tolerance", "nan"], 2, "tolerance=nan"),
    (["kinetostatics", "--samples", "{f}/k_empty.csv", "--out", "{f}/k"], 2, "is empty"),
    (["kinetostatics", "--samples", "{f}/k_semicolon.csv", "--out", "{f}/k"], 2, "not ';'"),
    (["kinetostatics", "--samples", "{f}/k_ragged.csv", "--out", "{f}/k"], 2, "line 3 has 1 values"),
    (["kinetostatics", "--samples", "{f}/folder", "--out", "{f}/k"], 2, "is a folder"),
    (["kinetostatics", "--omega", "1e12", "--out", "{f}/k"], 2, "omega=1e+12 rad/s is out of range"),
    (["kinetostatics", "--omega", "nan", "--out", "{f}/k"], 2, "omega=nan"),
    (["sweep", "--study", "{f}/latin1_study.toml", "--out", "{f}/s"], 2, "not UTF-8"),
    (["sweep", "--study", "{f}/folder", "--out", "{f}/s"], 2, "is a folder"),
    (["sweep", "--study", "{f}/t_end_abc.toml", "--out", "{f}/s"], 2, "t_end='abc' is not a number"),
    (["sweep", "--study", "{f}/sample_x.toml", "--out", "{f}/s"], 2, "sample='x' is not a whole number"),
    (["sweep", "--study", "{f}/vary_numbers.toml", "--out", "{f}/s"], 2, "vary[0]=1 is not a string"),
    (["sweep", "--study", "{f}/vary_string.toml", "--out", "{f}/s"], 2, "vary='L=0.1,0.2' is not a list"),
    (["sweep", "--study", "{f}/engines_string.toml", "--out", "{f}/s"], 2,
     "engines='analytic-approx' is not a list"),
    (["sweep", "--study", "{f}/sweep_not_table.toml", "--out", "{f}/s"], 2, "must be a table"),
    (["sweep", "--study", "{f}/params_bad.toml", "--out", "{f}/s"], 2, "m1='heavy' is not a number"),
    (["sweep", "--vary", "L=0.1,0.2", "--variants", ",", "--out", "{f}/s"], 2, "--variants ',' names no variant"),
    (["sweep", "--vary", "L=0.08:0.3:1e12", "--out", "{f}/s"], 2, "allowed: N <= 100000"),
    (["sweep", "--vary", "L=0.08:0.3:400", "--vary", "m2=0.1:1:400", "--out", "{f}/s"], 2, "400 x 400"),
    (["sweep", "--vary", "L=0.1,nan", "--out", "{f}/s"], 2, "every value must be a finite number"),
    (["sweep", "--vary", "L=0.1:0.2", "--sample", "2", "--seed", "-1", "--out", "{f}/s"], 2, "seed=-1"),
    (["sweep", "--vary", "L=0.1:0.2", "--sample", "0", "--out", "{f}/s"], 2, "sample=0"),
    (["sweep", "--vary", "L=0.1,0.2", "--t-end", "inf", "--out", "{f}/s"], 2, "t_end=inf"),
    (["sweep", "--vary", "L=0.1,0.2", "--timeout-per-design", "-1", "--out", "{f}/s"], 2, "timeout_per_design"),
    (["sweep", "--vary", "L=0.1,0.2", "--workers", "0", "--out", "{f}/s"], 2, "workers=0"),
    (["sweep", "--vary", "L=0.1,0.2", "--plot-metric", "beauty", "--out", "{f}/s"], 2, "'beauty' is unknown"),
    (["sweep", "--vary", "L=0.1,0.2", "--resume", "--out", "{f}/run"], 2, "holds no sweep"),
    (["sweep", "--vary", "L=0.1,0.2", "--out", "{f}/afile/sub"], 2, "is a file, not a folder"),
    # issue 26, round 2: unbounded runs
    (["simulate", "--engine", "mujoco", "--clutch", "unilateral", "--timestep", "1e-12", "--t-end", "1"], 2,
     "would take 1e+12 MuJoCo steps"),
    (["simulate", "--engine", "mujoco", "--timestep", "1e-9", "--t-end", "3600", "--dt-out", "1"], 2,
     "allowed: at most 1e+08 steps"),
    (["simulate", "--wall-budget", "0"], 2, "--wall-budget 0 is out of range"),
    (["simulate", "--wall-budget", "nan"], 2, "--wall-budget nan is out of range"),
    (["simulate", "--wall-budget", "-5"], 2, "--wall-budget -5 is out of range"),
    (["simulate", "--t-end", "0.5", "--wall-budget", "1e-6"], 1, "--wall-budget 1e-06 s; raise it"),
    # sweeps
    (["sweep", "--vary", "L=0.01,0.02", "--variants", "analytic-approx", "--t-end", "0.1", "--out", "{f}/s"], 2,
     "every one of the 2 designs is invalid; the first (L=0.01)"),
    (["sweep", "--vary", "L=0.1,0.2", "--variants", "analytic-approx", "--t-end", "0.05", "--resume",
      "--out", "{f}/swp_garbage"], 2, "results.csv' line 4 has 1 cells"),
    (["sweep", "--vary", "L=0.1,0.2", "--variants", "analytic-approx", "--t-end", "0.05", "--resume",
      "--out", "{f}/swp_extra"], 2, "results.csv' line 4 has"),
    (["sweep", "--vary", "L=0.1,0.2", "--variants", "analytic-approx", "--t-end", "0.05", "--resume",
      "--out", "{f}/swp_binary"], 2, "results.csv' line 4 is not UTF-8"),
    (["sweep", "--vary", "L=0.1,0.2", "--variants", "analytic-approx", "--t-end", "0.05", "--resume",
      "--out", "{f}/swp_nul"], 2, "results.csv' line 4"),
    # configuration files
    (["simulate", "--config", "{f}/big_int.toml"], 2, "an integer of more than 4300 digits"),
    (["simulate", "--config", "{f}/deep.toml"], 2, "nests arrays or tables too deep"),
    (["sweep", "--study", "{f}/deep_study.toml", "--out", "{f}/s"], 2, "nests arrays or tables too deep"),
    (["sweep", "--study", "{f}/big_int.toml", "--out", "{f}/s"], 2, "an integer of more than 4300 digits"),
    # Dask addresses
    (["sweep", "--vary", "L=0.1,0.2", "--scheduler", "garbage", "--out", "{f}/s"], 2,
     "--scheduler 'garbage' is not a scheduler address"),
    (["sweep", "--vary", "L=0.1,0.2", "--scheduler", "tcp://127.0.0.1:1", "--out", "{f}/s"], 2,
     "--scheduler 'tcp://127.0.0.1:1' cannot be reached"),
    (["sweep", "--vary", "L=0.1,0.2", "--scheduler", "inproc://x", "--out", "{f}/s"], 2,
     "'inproc://x' did not answer as a Dask scheduler"),
    (["sweep", "--vary", "L=0.1,0.2", "--scheduler", "udp://h:1", "--out", "{f}/s"], 2, "SCHEME://HOST:PORT"),
    (["sweep", "--vary", "L=0.1,0.2", "--scheduler", "", "--out", "{f}/s"], 2, "is not a scheduler address"),
    # messages that name the option the value came from
    (["simulate", "--engine", "mujoco", "--timestep", "inf"], 2, "--timestep=inf is out of range"),
    (["simulate", "--engine", "mujoco", "--timestep", "nan"], 2, "--timestep=nan is out of range"),
    (["kinetostatics", "--omega", "1e-9", "--out", "{f}/k"], 2, "--omega 1e-09 rad/s with --revolutions 2"),
    (["kinetostatics", "--omega", "-1e-3", "--out", "{f}/k"], 2, "0.003491 <= |omega|"),
    (["simulate", "--dt-out", "-1e-4"], 2, "dt_out=-0.0001 is out of range"),
    (["simulate", "--t-end", "-inf"], 2, "t_end=-inf is out of range"),
    (["simulate", "--t-end", "-1E+2"], 2, "t_end=-100.0 is out of range"),
    (["sweep", "--vary", "L=0.1,0.2", "--t-end", "-1e-3", "--out", "{f}/s"], 2, "t_end=-0.001 is out of range"),
    (["kinetostatics", "--samples", "{f}/k_header_only.csv", "--out", "{f}/k"], 2,
     "k_header_only.csv' has 0 sample row(s)"),
    (["clutch-study", "--stiffness", "", "--out", "{f}/c"], 2, "--stiffness '' gives 0 values"),
    (["clutch-study", "--backlash", " ", "--out", "{f}/c"], 2, "--backlash ' ' gives 0 values"),
    # devices read for ever: refused, never read into memory (the wider pass of round 2)
    (["simulate", "--config", "/dev/zero"], 2, "is not a regular file"),
    (["sweep", "--study", "/dev/zero", "--out", "{f}/s"], 2, "is not a regular file"),
    (["kinetostatics", "--samples", "/dev/zero", "--out", "{f}/k"], 2, "is not a regular file"),
    (["simulate", "--engine", "mujoco", "--mjcf", "/dev/zero"], 2, "is not a regular file"),
    # output folders: a name the command writes, taken by another kind of entry
    (["simulate", "--t-end", "0.01", "--out", "{f}/clash"], 2, "clash/summary.json' is a folder, where"),
    # round 3: the studies check every option before the first design
    (["sweep", "--vary", "L=log", "--out", "{f}/s"], 2, "--vary 'L=log' is malformed"),
    (["sweep", "--vary", "L=0.1:0.2:3:4", "--out", "{f}/s"], 2, "--vary 'L=0.1:0.2:3:4' is malformed"),
    (["optimize", "--vary", "L=log", "--objective", "max:mean_speed_m_s", "--out", "{f}/o"], 2, "is malformed"),
    (["sensitivity", "--vary", "L=log", "--metric", "mean_speed_m_s", "--out", "{f}/o"], 2, "is malformed"),
    (["optimize", "--vary", "L=0.1:0.3", "--objective", "max:drive", "--out", "{f}/o"], 2,
     "'drive' is not a number"),
    (["optimize", "--vary", "L=0.1:0.3", "--objective", "max:mean_speed_m_s", "--constraint", "L<0.2",
      "--out", "{f}/o"], 2, "--constraint 'L<0.2' does not parse"),
    (["optimize", "--vary", "L=0.1:0.3", "--objective", "max:mean_speed_m_s", "--workers", "0", "--out", "{f}/o"],
     2, "--workers 0"),
    (["sensitivity", "--vary", "L=0.1:0.3", "--metric", "feedforward", "--out", "{f}/o"], 2,
     "'feedforward' is not a number"),
    (["sweep", "--vary", "L=0.1,0.2", "--resume", "--out", "{f}/swp_garbage/results.csv"], 2, "is not a folder"),
    (["render", "--t-end", "0.1", "--out", "/sys/ipir-mujoco-test/x.gif"], 2, "cannot write in"),
    # round 4 (issue 53): every option and range checked before the first run, the value the user gave named
    (["optimize", "--vary", "drive=0:1", "--objective", "max:revolutions", "--out", "{f}/o"], 2,
     "--vary 'drive=0:1': drive is not a number"),
    (["optimize", "--vary", "L=0.01:0.04", "--objective", "max:revolutions", "--out", "{f}/o"], 2,
     "no design of the study can have L=0.01"),
    (["optimize", "--vary", "m1=-1:1", "--objective", "max:revolutions", "--out", "{f}/o"], 2,
     "m1=-1.0 is out of range"),
    (["optimize", "--vary", "L=0.1:0.3", "--objective", "max:revolutions", "--verify", "", "--out", "{f}/o"], 2,
     "--verify '' names no model"),
    (["sensitivity", "--vary", "L=0.1:0.3", "--metric", "revolutions", "--variant", "", "--out", "{f}/o"], 2,
     "variant '' is unknown"),
    (["sweep", "--vary", "L=0.1,0.2", "--set", "omega_target=5", "--out", "{f}/s"], 2, "only drive=servo"),
    (["clutch-study", "--points", "startup", "--set", "omega_target=5", "--out", "{f}/c"], 2,
     "the startup point runs drive=torque (the study sets it): omega_target=5.0"),
    (["climb", "--inclines", "0", "--set", "omega_target=5", "--out", "{f}/c"], 2, "only drive=servo"),
    (["simulate", "--drive", "servo", "--feedforward", "exact", "--set", "omega_target=1e-9"], 2,
     "omega_target=1e-09 rad/s with feedforward='exact'"),
    (["render", "--t-end", "1e9", "--out", "{f}/x.gif"], 2, "t_end=1e+09 is out of range"),  # no "simulating" line
    (["simulate", "--t-end", "0.01", "--out", ""], 2, "--out '' names no folder"),
    (["sweep", "--vary", "L=0.1,0.2", "--study", "", "--out", "{f}/s"], 2, "--study '' names no file"),
    (["simulate", "--engine", "mujoco", "--mujoco-model", "wheels", "--route", ""], 2, "--route '' names no file"),
]


@pytest.mark.parametrize("argv,code,fragment", CASES, ids=[" ".join(c[0])[:60] for c in CASES])
@pytest.mark.slow
def test_bad_input_is_one_line_with_the_right_exit_status_and_creates_nothing(capsys, files, argv, code, fragment):
    before = sorted(p.name for p in files.iterdir())
    got, _, err, caught = run_cli(capsys, [a.format(f=files) for a in argv])
    assert got == code, err
    assert err.count("\n") == 1 and fragment in err, err
    assert caught == []  # no library warning on the way
    assert sorted(p.name for p in files.iterdir()) == before  # no output folder left behind


def test_a_sweep_whose_every_design_fails_exits_1_naming_the_first_failure(capsys, tmp_path):
    code, _, err, _ = run_cli(capsys, ["sweep", "--vary", "L=0.1,0.2", "--variants", "analytic-approx", "--t-end",
                                       "0.5", "--timeout-per-design", "1e-6", "--out", tmp_path / "s"])
    assert code == 1 and err.strip().count("\n") == 0 or err.splitlines()[-1].startswith("ipir-mujoco sweep"), err
    last = err.splitlines()[-1]  # after the progress lines
    assert code == 1 and "every one of the 2 designs failed" in last and "timeout-per-design" in last, err


def test_a_sweep_on_a_full_disk_exits_1_in_one_line(capsys, tmp_path, monkeypatch):
    import errno

    import matplotlib.figure

    def full(self, path, *args, **kwargs):
        raise OSError(errno.ENOSPC, "No space left on device", str(path))

    monkeypatch.setattr(matplotlib.figure.Figure, "savefig", full)
    code, _, err, _ = run_cli(capsys, ["sweep", "--vary", "L=0.1,0.2", "--variants", "analytic-approx",
                                       "--t-end", "0.05", "--out", tmp_path / "s"])
    assert code == 1 and "No space left on device" in err.splitlines()[-1], err
    assert sum("ipir-mujoco sweep:" in line for line in err.splitlines()) == 1


def test_a_run_killed_while_staging_is_cleaned_by_the_next_run(capsys, tmp_path):
    """A validate (or any command) killed by SIGKILL leaves .NAME-partial-PID-* beside its output: the next
    run that writes there removes it; one of a live process is left alone."""
    gone = subprocess.Popen([sys.executable, "-c", "pass"])
    gone.wait()
    stale = tmp_path / f".out-partial-{gone.pid}-abc"
    live = tmp_path / f".out-partial-{os.getpid()}-abc"
    stale.mkdir()
    live.mkdir()
    code, _, err, _ = run_cli(capsys, ["simulate", "--t-end", "0.01", "--out", tmp_path / "out"])
    assert code == 0, err
    assert not stale.exists() and live.is_dir() and (tmp_path / "out" / "summary.json").is_file()


@pytest.mark.slow
def test_an_existing_output_folder_keeps_what_the_command_did_not_write(capsys, tmp_path):
    out = tmp_path / "out"
    out.mkdir()
    (out / "notes.txt").write_text("mine")
    for _ in range(2):  # the second run replaces the first run's files
        code, _, err, _ = run_cli(capsys, ["simulate", "--t-end", "0.01", "--out", out])
        assert code == 0, err
    assert (out / "notes.txt").read_text() == "mine" and (out / "timeseries.csv").is_file()


def test_an_unwritable_output_folder_is_refused_before_the_run(capsys, tmp_path):
    if os.geteuid() == 0:  # root writes through permission bits; sysfs refuses new files even to root
        if not Path("/sys/kernel").is_dir():
            pytest.skip("no sysfs: no folder here that root cannot write")
        target = Path("/sys/ipir-mujoco-test/out")
    else:
        locked = tmp_path / "locked"
        locked.mkdir(mode=0o555)
        target = locked / "out"
    code, out, err, _ = run_cli(capsys, ["simulate", "--t-end", "0.1", "--out", target])
    assert code == 2 and err.count("\n") == 1 and "cannot write in" in err and out == ""


def test_a_sample_of_any_size_draws_without_a_scipy_warning():
    study = Study((parse_vary("L=0.06:0.5"), parse_vary("m2=0.2:3")), sample=5)  # not a power of 2
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert len(study.designs()) == 5


def test_an_internal_error_is_one_line_and_debug_shows_the_traceback(capsys, monkeypatch):
    from ipir_mujoco.cli import simulate

    def broken(args):
        raise ZeroDivisionError("a bug")

    monkeypatch.setattr(simulate, "run_simulation", broken)
    code, _, err, _ = run_cli(capsys, ["simulate"])
    assert code == 1 and err.count("\n") == 1 and "internal error: ZeroDivisionError: a bug" in err
    assert "--debug" in err
    for argv in (["--debug", "simulate"], ["simulate", "--debug"]):
        with pytest.raises(ZeroDivisionError):
            main(argv)


# ---------------------------------------------------------------------------------------------
# the Python API

@pytest.mark.parametrize("value", [np.int64(2), np.float32(2.0), np.array(2.0), Fraction(2, 1), Decimal("2")])
def test_numbers_of_every_numeric_type_are_numbers(value):
    assert RobotParams(m1=value).m1 == 2.0 and type(RobotParams(m1=value).m1) is float
    assert check_run_options(value, Fraction(1, 1000)) == (2.0, 0.001)


# round 4 (issue 53): a wrong type anywhere in the public API is a ParameterTypeError (a ValueError and a
# TypeError) naming it, not an AttributeError or TypeError from inside pathlib or re
WRONG_TYPES = [
    (lambda: _route().read_route(None), "path=None (NoneType) is not a path"),
    (lambda: _route().read_route(3), "path=3 (int) is not a path"),
    (lambda: _route().read_route(b"route.toml"), "path=b'route.toml' (bytes) is not a path"),
    (lambda: _route().route_from_tables([{"kind": ["straight"], "length": 0.4}]),
     "kind=['straight'] is not a string"),
    (lambda: _route().route_from_tables("straight"), "is not a list of [[segment]] tables"),
    (lambda: _optimize().parse_objective(None), "objective=None (NoneType) is not a string"),
    (lambda: _optimize().parse_constraint(3), "constraint=3 (int) is not a string"),
    (lambda: Study(3), "axes=3 is not a list of axes"),
    (lambda: registry.timestep("mujoco-ratchet", None, 1.0, 1e-3), "params=None is not a RobotParams"),
    (lambda: registry.run(None, RobotParams(), 0.1), "variant None (NoneType) is not a variant's name"),
    (lambda: analytic.simulate(RobotParams(), None, "kinematic", 0.1), "geometry=None (NoneType) is not a string"),
    (lambda: load_params(None, "m1=2"), "overrides='m1=2' is not a list of NAME=VALUE strings"),
    (lambda: RobotParams(m1="1"), "m1='1' is not a number"),
    (lambda: RobotParams(drive=1), "drive=1 is not a string"),
    (lambda: _study("clutch_study").run_study(RobotParams(), (1e4,), (0.0,), "startup"), "points='startup'"),
    (lambda: _study("bend_study").run_study(RobotParams(), "2"), "ratios='2' (str) is not a list"),
    (lambda: _study("compare").compare_runs(None, None), "a=None is not a RunResult"),
    (lambda: _study("frames").read_sweep(None), "folder=None (NoneType) is not a path"),
]


@pytest.mark.parametrize("call,fragment", [
    (lambda: RobotParams(mass=1), "unknown parameter 'mass'"),
    (lambda: RobotParams(m1="1"), "m1='1' is not a number"),
    (lambda: RobotParams(m1=True), "m1=True is not a number"),
    (lambda: check_run_options(1e9, 1e-4), "t_end=1e+09 s"[:10]),
    (lambda: check_run_options(100, 1e-6), "would keep 1e+08 samples"),
    (lambda: check_run_options(1.0, float("nan")), "dt_out=nan"),
    (lambda: analytic.simulate(RobotParams(), t_end=1e9), "t_end=1e+09"),
    (lambda: analytic.simulate(RobotParams(), t_end=1.0, dt_out=1e-9), "samples"),
    (lambda: Study((parse_vary("L=0.1,0.2"),), engines="analytic-approx"), "engines='analytic-approx' is a single"),
    (lambda: Study("L=0.1,0.2"), "is not a list of axes"),
    (lambda: Study((parse_vary("L=0.1,0.2"),), seed=-1), "seed=-1"),
    (lambda: Study((parse_vary("L=0.1,0.2"),), t_end="abc"), "t_end='abc' is not a number"),
    (lambda: Study((parse_vary("L=0.1,0.2"),), base=None), "params=None is not a RobotParams"),
    (lambda: Study((parse_vary("L=0.1,0.2"),), engines=None), "engines=None is not a list"),
    (lambda: parse_vary(None), "vary=None is not a string"),
    (lambda: parse_vary(3), "vary=3 is not a string"),
    (lambda: analytic.simulate(RobotParams(), "exact", "kinematic", 0.1, torque="x"), "torque='x' is not callable"),
    (lambda: analytic.simulate(RobotParams(), "exact", "kinematic", 0.1, torque=lambda t, phi, w: "x"),
     "torque(t=0, phi=0, omega=0) failed"),
    (lambda: analytic.simulate(RobotParams(), "exact", "kinematic", 0.1, torque=lambda t, phi, w: np.nan),
     "is not finite"),
    (lambda: analytic.simulate(RobotParams(), "exact", "kinematic", 0.1, wall_budget_s=-1), "wall_budget_s=-1"),
    (lambda: load_params(3), "config=3 is not a path"),
    (lambda: run_sweep("x", "sweep"), "study='x'"),
    (lambda: run_sweep(Study((parse_vary("L=0.1,0.2"),)), 3), "out=3"),
    (lambda: registry.run("mujoco-ratchet", RobotParams(), timestep="x"), "timestep='x' is not a number"),
    (lambda: check_step_count(1.0, 1e-12), "would take 1e+12 MuJoCo steps"),
    # round 3: every public entry point
    (lambda: registry.run("analytic-approx", None, 0.1), "params=None is not a RobotParams"),
    (lambda: registry.run("analytic-approx", {"L": 0.2}, 0.1), "params={'L': 0.2} is not a RobotParams"),
    (lambda: registry.run("mujoco-ratchet", RobotParams(), 0.01, foo=1), "option foo=1 is unknown"),
    (lambda: registry.run("mujoco-ratchet", RobotParams(), 0.01, every_step="yes"), "every_step='yes' is not a bool"),
    (lambda: registry.run_batch("mujoco-ratchet", [RobotParams()], 0.01, 1e-3, nthread=0), "nthread=0"),
    (lambda: registry.run_batch("mujoco-ratchet", RobotParams(), 0.01, 1e-3), "is not a list of RobotParams"),
    (lambda: _optimize().Constraint("L", "<", 0.2), "Constraint op='<' is not allowed"),
    (lambda: _optimize().Constraint("L", "<=", float("nan")), "Constraint value=nan"),
    (lambda: _optimize().Objective("best", "L"), "Objective sense='best'"),
    (lambda: _optimize().Objective("max", "drive"), "'drive' is not a number"),
    (lambda: _optimize().Problem("L=0.1:0.3", (_optimize().Objective("max", "revolutions"),)),
     "Problem axes='L=0.1:0.3' is not a tuple of Axis"),
    (lambda: _optimize().Problem((parse_vary("L=0.1:0.3"),), "max:revolutions"),
     "Problem objectives='max:revolutions' is not a tuple of Objective"),
    (lambda: _optimize().run_optimize(_problem(), "o", workers=0), "workers=0"),
    (lambda: _optimize().run_optimize(_problem(), "o", resume="yes"), "resume='yes'"),
    (lambda: _sensitivity().run_sensitivity("L=0.1:0.3", ("revolutions",), "o"), "axes='L=0.1:0.3'"),
    (lambda: _sensitivity().run_sensitivity((parse_vary("L=0.1:0.3"),), "revolutions", "o"),
     "metrics='revolutions' is not a tuple"),
    (lambda: _sensitivity().run_sensitivity((parse_vary("L=0.1:0.3"),), ("revolutions",), "o", workers=0),
     "workers=0"),
    (lambda: _bend_study().run_study(RobotParams(), workers=0), "workers=0"),
    (lambda: _bend_study().run_study(None), "params=None"),
    (lambda: run_sweep(Study((parse_vary("L=0.1,0.2"),)), "s", resume="no"), "resume='no'"),
    (lambda: run_sweep(Study((parse_vary("L=0.1,0.2"),)), "s", workers=0), "workers=0"),
    (lambda: run_sweep(Study((parse_vary("L=0.1,0.2"),)), "s", on_row=3), "on_row=3 is not callable"),
    *WRONG_TYPES,  # round 4: a wrong type anywhere in the public API
])
def test_python_api_bad_input_is_a_parameter_error_naming_the_value(call, fragment, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)  # a call that wrongly went ahead would write here, and be seen below
    with pytest.raises(ParameterError) as info:
        call()
    assert fragment in str(info.value) and "\n" not in str(info.value)
    assert list(tmp_path.iterdir()) == []


def _optimize():
    from ipir_mujoco.studies import optimize

    return optimize


def _sensitivity():
    from ipir_mujoco.studies import sensitivity

    return sensitivity


def _bend_study():
    from ipir_mujoco.studies import bend_study

    return bend_study


def _route():
    from ipir_mujoco.core import route

    return route


def _study(name):
    import importlib

    return importlib.import_module(f"ipir_mujoco.studies.{name}")


def _problem():
    o = _optimize()
    return o.Problem((parse_vary("L=0.1:0.3"),), (o.Objective("max", "revolutions"),), budget=2, verify=None)


@pytest.mark.parametrize("call", [
    lambda: registry.run("analytic-approx", None, 0.1),
    lambda: registry.run("mujoco-ratchet", RobotParams(), 0.01, foo=1),
    lambda: _optimize().Problem("L=0.1:0.3", (_optimize().Objective("max", "revolutions"),)),
    lambda: run_sweep("x", "sweep"),
    *[call for call, _ in WRONG_TYPES],
])
def test_a_wrong_type_is_both_a_parameter_error_and_a_type_error(call):
    """docs/cli.md, 'From Python': one except ValueError catches every bad input; a wrong type is a TypeError
    too, as Python users expect."""
    with pytest.raises(ParameterError) as info:
        call()
    assert isinstance(info.value, TypeError) and isinstance(info.value, ValueError)


@pytest.mark.parametrize("keywords,fragment", [
    ({"settings": "x"}, "settings='x' (str) is not allowed"),
    ({"mjcf": 123}, "mjcf=123 (int) is not allowed"),
    ({"servo": 1}, "servo=1 (int) is not allowed"),
    ({"wall_budget_s": "1"}, "wall_budget_s='1'"),
])
def test_simulate_mujoco_checks_its_arguments(keywords, fragment):
    from ipir_mujoco.engine import simulate_mujoco

    with pytest.raises(ParameterError) as info:
        simulate_mujoco(RobotParams(), t_end=0.01, **keywords)
    assert fragment in str(info.value) and "\n" not in str(info.value)


def test_a_given_timestep_too_small_for_t_end_is_refused_before_the_run():
    from ipir_mujoco.engine import SolverSettings, simulate_mujoco

    with pytest.raises(ParameterError, match=r"t_end=1 s with timestep=1e-12 s would take 1e\+12 MuJoCo steps"):
        simulate_mujoco(RobotParams(), t_end=1.0, settings=SolverSettings(timestep=1e-12))


def test_every_run_has_a_wall_budget_by_default_and_inf_lifts_it():
    assert RunOptions().wall_budget_s == DEFAULT_WALL_BUDGET_S
    assert RunOptions(wall_budget_s=None).wall_budget_s == DEFAULT_WALL_BUDGET_S
    assert RunOptions(wall_budget_s=float("inf")).wall_budget_s is None  # no limit
    assert RunOptions(wall_budget_s=5).wall_budget_s == 5.0


def test_mujoco_never_runs_past_t_end_by_a_sample_interval_it_was_not_given():
    from ipir_mujoco.engine import simulate_mujoco

    with pytest.raises(ParameterError, match="dt_out <= t_end"):
        simulate_mujoco(RobotParams(), t_end=0.01, dt_out=0.1)


# ---------------------------------------------------------------------------------------------
# random text for the parsers: a ParameterError or a valid result, never anything else

@settings(max_examples=EXAMPLES)
@given(st.text(max_size=40))
@pytest.mark.slow
def test_vary_parser_accepts_or_refuses_cleanly(text):
    try:
        axis = parse_vary(text)
    except ParameterError as exc:
        assert "\n" not in str(exc)
        return
    assert all(np.isfinite(axis.values)) and len(axis.values) <= MAX_DESIGNS


@settings(max_examples=EXAMPLES)
@given(st.one_of(st.floats(), st.integers(), st.text(max_size=5), st.none()),
       st.one_of(st.floats(), st.integers(), st.text(max_size=5), st.none()))
def test_run_options_accept_or_refuse_cleanly(t_end, dt_out):
    try:
        t, dt = check_run_options(t_end, dt_out)
    except ParameterError as exc:
        assert "\n" not in str(exc)
        return
    assert 0 < dt <= t and t / dt + 1 <= MAX_SAMPLES


@settings(max_examples=EXAMPLES)
@given(st.dictionaries(st.sampled_from(["m1", "m2", "r", "L", "J_A", "M", "omega0", "phi0", "rod_mass"]),
                       st.one_of(st.floats(), st.integers(min_value=-10**400, max_value=10**400),
                                 st.text(max_size=4)), max_size=4))
def test_parameter_sets_accept_or_refuse_cleanly(values):
    try:
        params = RobotParams(**values)
    except ParameterError as exc:
        assert "\n" not in str(exc)
        return
    assert all(np.isfinite(v) for v in params.as_dict().values() if isinstance(v, float))


def test_json_of_a_run_never_holds_nan(capsys):
    code, out, _, _ = run_cli(capsys, ["simulate", "--json", "--t-end", "0.05"])
    assert code == 0 and json.loads(out)["summary"]["revolutions"] > 0
