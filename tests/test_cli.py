"""The command-line contract (docs/cli.md) for `simulate`."""

from __future__ import annotations

import json
import re
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from ipir_mujoco.core.results import COLUMNS, read_csv
from ipir_mujoco.cli import main

from cli_run import exit_code, run_cli

SUMMARY_KEYS = {"revolutions", "x1_final", "x2_final", "v1_max", "v2_max", "first_contraction_end_s",
                "mode_switches", "min_clutch_reaction_n", "energy"}
ENERGY_KEYS = {"motor_work_j", "kinetic_j", "friction_j", "residual_j"}


def test_simulate_json_follows_the_contract(capsys):
    code, out, err = run_cli(capsys, "simulate", "--json")
    assert code == 0 and err == ""
    record = json.loads(out)
    assert (record["engine"], record["geometry"], record["clutch"], record["t_end"]) == \
        ("analytic", "approx", "kinematic", 1.0)
    assert SUMMARY_KEYS <= set(record["summary"]) and ENERGY_KEYS <= set(record["summary"]["energy"])
    assert record["params"]["L"] == 0.2 and record["wall_time_s"] > 0
    assert record["summary"]["revolutions"] == pytest.approx(8.43, abs=0.01)


def test_set_and_config_reach_the_model(capsys, tmp_path):
    config = tmp_path / "c.toml"
    config.write_text("[params]\nL = 0.5\nm2 = 3\n")
    code, out, _ = run_cli(capsys, "simulate", "--json", "--config", str(config), "--set", "m2=2",
                           "--geometry", "exact", "--t-end", "0.3")
    record = json.loads(out)
    assert code == 0 and record["params"]["L"] == 0.5 and record["params"]["m2"] == 2.0
    assert record["geometry"] == "exact" and record["t_end"] == 0.3


@pytest.mark.slow
def test_out_writes_csv_summary_and_figures(capsys, tmp_path):
    out_dir = tmp_path / "run"
    code, out, _ = run_cli(capsys, "simulate", "--out", str(out_dir), "--t-end", "0.5")
    assert code == 0 and "crank revolutions" in out
    series = read_csv(out_dir / "timeseries.csv")
    assert list(series)[:len(COLUMNS)] == list(COLUMNS)  # the contract's columns first, then extras
    assert {"rod_force", "crank_pin_force", "motor_power", "resistance1", "resistance2"} <= set(series)
    assert series["t"][0] == 0 and series["t"][-1] == 0.5 and np.all(np.diff(series["t"]) >= 0)
    summary = json.loads((out_dir / "summary.json").read_text())
    assert summary["summary"]["x1_final"] == pytest.approx(series["x1"][-1], abs=1e-11)
    for name in ("fig2_crank.png", "fig3_modules.png", "fig4_gap.png"):
        assert (out_dir / name).read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["run"]  # no staging folder left behind


@pytest.mark.parametrize("argv,fragment", [
    (["--geometry", "exact", "--set", "L=0.04"], "L=0.04"),
    (["--set", "m1=-1"], "m1=-1.0"),
    (["--set", "M=nan"], "M=nan"),
    (["--set", "foo=1"], "'foo'"),
    (["--set", "L"], "NAME=VALUE"),
    (["--t-end", "-1"], "t_end=-1.0"),
    (["--t-end", "nan"], "t_end=nan"),
    (["--t-end", "abc"], "'abc'"),
    (["--geometry", "sideways"], "'sideways'"),
    (["--engine", "mujoco", "--geometry", "approx"], "--geometry approx"),
    (["--mujoco-clutch", "lock"], "--mujoco-clutch"),
])
def test_bad_input_exits_2_with_one_line_naming_the_value(capsys, tmp_path, argv, fragment):
    out_dir = tmp_path / "never"
    code, _, err = run_cli(capsys, "simulate", "--out", str(out_dir), *argv)
    assert code == 2
    assert err.count("\n") == 1 and fragment in err
    assert not out_dir.exists() and list(tmp_path.iterdir()) == []


def test_malformed_toml_exits_2_and_names_the_file(capsys, tmp_path):
    bad = tmp_path / "bad.toml"
    bad.write_text("L = = 3\n")
    code, _, err = run_cli(capsys, "simulate", "--config", str(bad))
    assert code == 2 and "bad.toml" in err and "not valid TOML" in err and err.count("\n") == 1


def test_out_that_is_a_file_is_bad_input(capsys, tmp_path):
    target = tmp_path / "file"
    target.write_text("keep me")
    code, _, err = run_cli(capsys, "simulate", "--out", str(target))
    assert code == 2 and "not a folder" in err and target.read_text() == "keep me"


@pytest.mark.slow
def test_console_script_and_module_behave_the_same(tmp_path):
    script = shutil.which("ipir-mujoco", path=str(Path(sys.executable).parent)) or shutil.which("ipir-mujoco")
    if script is None:
        pytest.skip("console script not on PATH (package not installed in this environment)")
    outputs = []
    for command in ([script], [sys.executable, "-m", "ipir_mujoco"]):
        done = subprocess.run([*command, "simulate", "--json", "--t-end", "0.2"], cwd=tmp_path,
                              capture_output=True, text=True, check=False)
        assert done.returncode == 0, done.stderr
        outputs.append(json.loads(done.stdout)["summary"])
        bad = subprocess.run([*command, "simulate", "--set", "m1=-1"], cwd=tmp_path,
                             capture_output=True, text=True, check=False)
        assert bad.returncode == 2 and "m1=-1.0" in bad.stderr
    assert outputs[0] == outputs[1]
    assert list(tmp_path.iterdir()) == []  # nothing written into the working folder


def test_every_subcommand_has_help(capsys):
    for argv in (["--help"], ["simulate", "--help"]):
        with pytest.raises(SystemExit) as info:
            main(argv)
        assert info.value.code == 0
    assert "NAME=VALUE" in capsys.readouterr().out


def test_help_and_params_start_without_the_numerics(tmp_path):
    """`--help` (the command list, every subcommand's parser built), `params` and a subcommand's --help load
    neither numpy nor the engines: the start-up a user waits for most often is the interpreter and the parsers
    (bench/startup.py times it against `python -c "import numpy"`). Each in a fresh interpreter. Of the MuJoCo
    engine only the model kinds' declarations may load (``engine/kinds``' package modules: their names and
    variants, which the registry lists); nothing that builds, steps or runs a model."""
    heavy = ("numpy", "scipy", "matplotlib", "mujoco", "numba", "ipir_mujoco.analytic", "ipir_mujoco.engine.run",
             "ipir_mujoco.engine.loop", "ipir_mujoco.engine.builders", "ipir_mujoco.engine.kinds.common",
             "ipir_mujoco.engine.kinds.timestep")
    for argv in (["--help"], ["params"], ["params", "--json"], ["sweep", "--help"], ["atlas", "--help"]):
        code = ("import sys; from ipir_mujoco.cli import main\n"
                f"try:\n    main({argv!r})\nexcept SystemExit:\n    pass\n"
                f"print(sorted(m for m in {heavy!r} if m in sys.modules), file=sys.stderr)")
        done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=tmp_path)
        assert done.returncode == 0 and done.stdout and done.stderr.strip() == "[]", (argv, done.stderr)


def test_params_lists_every_parameter_with_unit_default_and_range(capsys):
    from ipir_mujoco.core.params import PARAMETER_NAMES

    code, out, err = run_cli(capsys, "params", "--json")
    rows = json.loads(out)
    assert code == 0 and err == "" and [r["name"] for r in rows] == list(PARAMETER_NAMES)
    by_name = {r["name"]: r for r in rows}
    assert by_name["L"]["units"] == "m" and by_name["L"]["default"] == 0.2 and "L > r" in by_name["L"]["allowed"]
    code, out, _ = run_cli(capsys, "params")
    assert code == 0 and all(name in out for name in PARAMETER_NAMES) and "N/m" in out


def test_drive_option_is_checked(capsys):
    assert exit_code(["simulate", "--drive", "wheel"]) == 2


def test_dt_out_defaults_to_whole_timesteps_of_a_given_timestep(capsys):
    """--timestep alone must not make the default --dt-out (1e-4 s) invalid: it becomes 3 steps of 3e-5 s."""
    code, out, _ = run_cli(capsys, "simulate", "--engine", "mujoco", "--clutch", "unilateral", "--json",
                           "--t-end", "0.01", "--timestep", "3e-5")
    record = json.loads(out)
    assert code == 0 and record["settings"]["timestep"] == 3e-5
    assert record["settings"]["dt_out"] == pytest.approx(9e-5, rel=1e-12)



def test_a_reader_that_leaves_early_ends_the_command_quietly(monkeypatch, capsys):
    """``ipir-mujoco compare A B | head``: stdout's reader closes the pipe and the next write raises
    BrokenPipeError. Unix tools end quietly then (status 141, as a shell reports SIGPIPE); it printed
    'ipir-mujoco compare: cannot read or write: Broken pipe' on stderr."""
    from ipir_mujoco.cli import params as params_command

    def closed_pipe(args):
        raise BrokenPipeError(32, "Broken pipe")

    original = params_command.add_parser

    def add_parser(commands):
        original(commands)
        commands.choices["params"].set_defaults(handler=closed_pipe)

    monkeypatch.setattr(params_command, "add_parser", add_parser)
    assert main(["params"]) == 141
    assert capsys.readouterr().err == ""


def _digits(number: str) -> int:
    """Significant digits a printed number shows ('0.10000' -> 5, '2.0009' -> 5)."""
    mantissa = number.split("e")[0].lstrip("-").replace(".", "").lstrip("0")
    return len(mantissa)


def test_the_steady_state_line_shows_every_figure_to_its_precision():
    """The paper's model advances exactly 2 r = 0.1 m per revolution: printed '0.1' beside '0.42702 m/s' and
    '2.0009 J/m', it hid its five digits; every figure of the line now shows them."""
    from ipir_mujoco import analytic
    from ipir_mujoco.analytic import RobotParams
    from ipir_mujoco.cli.simulate import format_summary
    from ipir_mujoco.labels import significant

    assert [significant(v, 4) for v in (0.1, 0.11083, 1234.0, 1.5e-5, -1e-17 * 0, 16)] == \
        ["0.1000", "0.1108", "1234", "1.500e-05", "0.000", "16"]
    run = analytic.simulate(RobotParams(drive="motor"), "approx", "kinematic", 3.0, until_steady=True)
    line = next(s for s in format_summary(run, until_steady=True).splitlines() if "steady state from" in s)
    figures = re.findall(r"(\S+) (?:m/s|m per revolution|J/m)|efficiency (\S+)$", line)
    numbers = [a or b for a, b in figures]
    assert len(numbers) == 4 and "0.10000 m per revolution" in line, line
    assert all(_digits(n) == 5 for n in numbers), line


def test_the_text_summary_prints_no_negative_zero_and_no_round_off_terms():
    """A held module's round-off below zero printed 'peak speed -0.000 m/s'; MuJoCo's compliant clutch with
    no damping printed 'clutch dampers -5.99456e-16' in the energy balance."""
    from ipir_mujoco.analytic import RobotParams
    from ipir_mujoco.core.results import COLUMNS, RunResult
    from ipir_mujoco.cli.simulate import format_summary

    t = np.linspace(0.0, 1.0, 11)
    series = {c: np.zeros_like(t) for c in COLUMNS}
    series["t"] = t
    series["v2"] = np.full_like(t, -3e-12)  # held, within round-off
    series["x2"] = np.full_like(t, -1e-13)
    energy = {"motor_work_j": 3.0, "kinetic_j": 1.0, "friction_j": 2.0, "residual_j": 0.0, "clutch_damper_j": -6e-16,
              "clutch_spring_j": 0.25}
    text = format_summary(RunResult("mujoco", "exact", "unilateral", RobotParams(), 1.0, series, energy))
    assert "-0.0" not in text and "module 2 (front) moved   0.0000 m   peak speed 0.000 m/s" in text
    assert "clutch dampers" not in text and "clutch springs 0.25" in text


def test_the_accuracy_line_tells_one_story():
    """A run past a tolerance with 'warn' (a route's wheels): each figure's largest value over the run with its
    tolerance, and for the one past it when it first crossed and its value there. The two numbers once stood side
    by side with nothing saying which was which ('energy residual 8.9e-02 of the energy' beside 'OUT OF
    TOLERANCE: residual_ratio 0.00199')."""
    from ipir_mujoco.cli.simulate import accuracy_line

    record = {"residual_ratio": 0.089, "loop_gap_m": 2e-6, "worst_at_s": {"residual_ratio": 3.1, "loop_gap_m": 0.4},
              "tolerances": {"residual_ratio": 1e-3, "loop_gap_m": 5e-5, "excursion_m": 1e-5}, "ok": False,
              "violations": [{"figure": "residual_ratio", "value": 0.00199, "tolerance": 1e-3, "t_s": 0.52}]}
    line = accuracy_line(record)
    assert line == ("  accuracy: energy residual at most 0.089 of the energy put through (at t=3.1 s), tolerance 0.001; "
                    "loop gap at most 2e-06 m (at t=0.4 s), tolerance 5e-05\n"
                    "  OUT OF TOLERANCE: energy residual first past its 0.001 at t=0.52 s (0.00199 there)")
    assert "OUT OF" not in accuracy_line({**record, "ok": True, "violations": []})


def test_every_file_a_command_names_carries_its_folder(tmp_path, capsys):
    """'files: fit/calibration.json, posterior.toml' named posterior.toml without the folder it is in."""
    from ipir_mujoco.cli.common import files_line

    assert files_line("fit", "calibration.json", "posterior.toml", "fit/calibration.png") == \
        "fit/calibration.json, fit/posterior.toml, fit/calibration.png"
    code, out, _ = run_cli(capsys, "simulate", "--t-end", "0.05", "--out", tmp_path / "run")
    named = out.splitlines()[-1].split("wrote ", 1)[1].split(", ")
    assert code == 0 and len(named) == 6 and all((tmp_path / "run" / Path(n).name).is_file() and
                                                  Path(n).parent == tmp_path / "run" for n in named)


def test_help_texts_say_what_the_models_are(capsys):
    """simulate's --help calls the wheeled model what it is (a 3-D robot in its round pipe, not 'free in the
    plane'); no help prints a doubled percent sign (argparse does not %-format descriptions)."""
    for command in ("simulate", "sensitivity", "uncertainty", "calibrate"):
        with pytest.raises(SystemExit):
            main([command, "--help"])
        text = " ".join(capsys.readouterr().out.split())
        assert "%%" not in text and "free in the plane" not in text
        if command == "simulate":
            assert "wheels = the robot in 3-D in its round pipe" in text
        if command in ("uncertainty", "calibrate"):
            assert "DIR/samples.csv" in text or "DIR/posterior.toml" in text
