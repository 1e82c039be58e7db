"""optimize and sensitivity (issue 22): known answers, resuming without re-running, bad input."""

from __future__ import annotations

import csv
import json

import pytest
from cli_run import run_cli

from ipir_mujoco.core.params import RobotParams
from ipir_mujoco.studies import design_eval
from ipir_mujoco.studies.design_eval import StudyInterrupted
from ipir_mujoco.studies.optimize import (
    Problem,
    parse_constraint,
    parse_objective,
    run_optimize,
)
from ipir_mujoco.studies.sweep_space import parse_vary

MOTOR = RobotParams().replace(drive="motor")


def _min_stall(budget=60, verify="mujoco-ratchet"):
    return Problem((parse_vary("M_stall=0.1:1"),), (parse_objective("min:M_stall"),),
                   (parse_constraint("steady_speed_m_s>=0.5"),), MOTOR, verify=verify, t_end=10.0,
                   until_steady=True, budget=budget)


@pytest.mark.slow
def test_smallest_stall_torque_for_half_a_metre_per_second(tmp_path, capsys):
    """(a) The default motor line cruises at 0.5 m/s from M_stall ~ 0.3162 N m (the steady speed rises
    ~0.28 m/s per N m there, so the 0.316..0.321 window is 1.4 mm/s of speed wide): found in <= 60 runs,
    and MuJoCo agrees on the optimum's steady speed within 0.1 %."""
    code, _, err = run_cli(capsys, "optimize", "--drive", "motor", "--until-steady", "--objective", "min:M_stall",
                             "--constraint", "steady_speed_m_s>=0.5", "--vary", "M_stall=0.1:1", "--budget", "60",
                             "--workers", "1", "--out", tmp_path / "o")
    assert code == 0, err
    record = json.loads((tmp_path / "o" / "optimize.json").read_text())
    best = record["best"]
    assert 0.316 <= best["M_stall"] <= 0.321
    assert best["steady_speed_m_s"] >= 0.5
    assert record["evaluations"] <= 60
    assert abs(best["verify"]["divergence:steady_speed_m_s"]) < 1e-3
    with (tmp_path / "o" / "evaluations.csv").open() as fh:
        assert len(list(csv.DictReader(fh))) == record["evaluations"]
    assert (tmp_path / "o" / "pareto.png").stat().st_size > 0


@pytest.mark.slow
def test_energy_per_metre_depends_on_the_resistances_only(tmp_path, capsys):
    """(b) With rigid clutches at cruise the motor's work per metre is F_r1 + F_r2 whatever L: each
    resistance has half the variance (ST = S1 = 0.5; tolerance: twice SALib's 95 % half-width, about four
    standard errors of the bootstrap), L none (its share is below (5e-4 J/m)^2 / var(F_r1 + F_r2) ~ 1e-6:
    the engine's residual from the exact sum)."""
    code, _, err = run_cli(capsys, "sensitivity", "--drive", "motor", "--until-steady", "--vary", "F_r1=0.5:2",
                             "--vary", "F_r2=0.5:2", "--vary", "L=0.1:0.4", "--metric", "energy_per_metre_j_m",
                             "--samples", "32", "--workers", "1", "--out", tmp_path / "s")
    assert code == 0, err
    with (tmp_path / "s" / "indices.csv").open() as fh:
        reader = csv.DictReader(fh)
        assert reader.fieldnames == ["metric", "parameter", "S1", "S1_conf", "ST", "ST_conf"]
        rows = {r["parameter"]: {k: float(v) for k, v in r.items() if k not in ("metric", "parameter")}
                for r in reader}
    for name in ("F_r1", "F_r2"):
        assert abs(rows[name]["ST"] - 0.5) <= 2 * rows[name]["ST_conf"], rows[name]
        assert abs(rows[name]["S1"] - 0.5) <= 2 * rows[name]["S1_conf"], rows[name]
    assert abs(rows["L"]["ST"]) < 1e-3 and abs(rows["L"]["S1"]) < 1e-3
    assert (tmp_path / "s" / "sensitivity.png").is_file() and (tmp_path / "s" / "evaluations.csv").is_file()


def test_interrupted_optimization_resumes_without_rerunning(tmp_path, monkeypatch):
    """(d) Ctrl-C keeps the evaluations written; --resume replays the seeded search against them, runs only
    the rest, and writes the same files as a run never interrupted."""
    whole = tmp_path / "whole"
    run_optimize(_min_stall(budget=30, verify=None), whole, workers=1, progress=False)
    real, calls = design_eval.run_design, []

    def interrupting(*args, **kwargs):
        if len(calls) == 10:
            raise KeyboardInterrupt
        calls.append(args[0])
        return real(*args, **kwargs)

    monkeypatch.setattr(design_eval, "run_design", interrupting)
    part = tmp_path / "part"
    with pytest.raises(StudyInterrupted):
        run_optimize(_min_stall(budget=30, verify=None), part, workers=1, progress=False)
    with (part / "evaluations.csv").open() as fh:
        assert len(list(csv.DictReader(fh))) == 10
    seen = list(calls)
    calls.clear()
    monkeypatch.setattr(design_eval, "run_design", lambda *a, **k: (calls.append(a[0]), real(*a, **k))[1])
    record = run_optimize(_min_stall(budget=30, verify=None), part, resume=True, workers=1, progress=False)
    assert record["reused_on_resume"] == 10
    assert not any(c in seen for c in calls)  # nothing evaluated before ran again
    for name in ("evaluations.csv", "pareto.csv"):
        assert (part / name).read_bytes() == (whole / name).read_bytes()


BAD = [
    (["--objective", "min:nonsense"], "unknown key 'nonsense'"),
    (["--objective", "min:M_stall", "--constraint", "steady_speed_m_s>0.5"], "does not parse"),
    (["--objective", "min:M_stall", "--constraint", "steady_speed_m_s>=fast"], "does not parse"),
    (["--objective", "min:M_stall", "--vary", "L=0.5:0.1"], "LO < HI"),
    (["--objective", "min:M_stall", "--budget", "0"], "budget"),
    (["--objective", "best:M_stall"], "min:KEY or max:KEY"),
    (["--objective", "min:M_stall", "--constraint", "bogus<=1"], "unknown key 'bogus'"),
]


@pytest.mark.parametrize("extra, words", BAD)
def test_bad_optimize_input_is_one_line_and_writes_nothing(tmp_path, capsys, extra, words):
    """(e) Bad input: exit 2, one line naming it, no folder created."""
    code, _, err = run_cli(capsys, "optimize", "--vary", "M_stall=0.1:1", *extra, "--out", tmp_path / "o")
    assert code == 2
    assert len(err.strip().splitlines()) == 1 and words in err
    assert not (tmp_path / "o").exists()


@pytest.mark.parametrize("extra, words", [(["--metric", "nonsense"], "unknown key"),
                                          (["--metric", "steady_speed_m_s", "--vary", "L=0.4:0.1"], "LO < HI"),
                                          (["--metric", "steady_speed_m_s", "--samples", "1"], "samples")])
def test_bad_sensitivity_input_is_one_line_and_writes_nothing(tmp_path, capsys, extra, words):
    code, _, err = run_cli(capsys, "sensitivity", "--vary", "M_stall=0.1:1", *extra, "--out", tmp_path / "s")
    assert code == 2
    assert len(err.strip().splitlines()) == 1 and words in err
    assert not (tmp_path / "s").exists()


def test_two_objectives_give_a_front_of_non_dominated_designs(tmp_path):
    """Several objectives (NSGA-II): every row of pareto.csv feasible, none dominated by another evaluation."""
    problem = Problem((parse_vary("L=0.06:0.5"), parse_vary("m2=0.2:3")),
                      (parse_objective("max:steady_speed_m_s"), parse_objective("min:peak_clutch_force_n")),
                      base=MOTOR, verify=None, t_end=10.0, until_steady=True, budget=40)
    record = run_optimize(problem, tmp_path / "m", workers=1, progress=False)
    assert len(record["front"]) >= 2
    with (tmp_path / "m" / "evaluations.csv").open() as fh:
        rows = [{k: float(v) for k, v in r.items() if k in ("steady_speed_m_s", "peak_clutch_force_n")}
                for r in csv.DictReader(fh)]
    for point in record["front"]:
        s, f = point["steady_speed_m_s"], point["peak_clutch_force_n"]
        assert not any(r["steady_speed_m_s"] >= s and r["peak_clutch_force_n"] <= f
                       and (r["steady_speed_m_s"] > s or r["peak_clutch_force_n"] < f) for r in rows)


@pytest.mark.parametrize("module, argv, fix", [
    ("pymoo", ["optimize", "--vary", "L=0.1:0.3", "--objective", "max:mean_speed_m_s",
               "--objective", "min:peak_clutch_force_n"], "pip install 'ipir-mujoco[optimize]'"),
    ("SALib", ["sensitivity", "--vary", "L=0.1:0.3", "--metric", "mean_speed_m_s"], "pip install 'SALib>=1.6")])
def test_missing_extra_is_a_one_line_refusal(tmp_path, capsys, monkeypatch, module, argv, fix):
    """Without the 'optimize' extra (pymoo), or SALib (a dependency) removed after the install: exit 2, one line
    naming the command that adds it, nothing written."""
    import sys

    for name in [m for m in sys.modules if m == module or m.startswith(module + ".")]:
        monkeypatch.delitem(sys.modules, name)
    monkeypatch.setitem(sys.modules, module, None)  # import fails as if not installed
    code, _, err = run_cli(capsys, *argv, "--out", tmp_path / "o")
    assert code == 2
    assert len(err.strip().splitlines()) == 1 and fix in err
    assert not (tmp_path / "o").exists()


def test_scheduler_gives_the_local_pool_s_files(tmp_path, capsys):
    """--scheduler: the same evaluations and front on a Dask cluster as on the local pool."""
    distributed = pytest.importorskip("distributed", reason="Dask is the optional 'dask' extra")
    argv = ["optimize", "--drive", "motor", "--until-steady", "--vary", "L=0.06:0.5", "--vary", "m2=0.2:3",
            "--objective", "max:steady_speed_m_s", "--objective", "min:peak_clutch_force_n", "--budget", "20",
            "--verify", "none"]
    code, _, err = run_cli(capsys, *argv, "--workers", "2", "--out", tmp_path / "local")
    assert code == 0, err
    with distributed.LocalCluster(n_workers=1, threads_per_worker=2, processes=False, dashboard_address=None) as cluster:
        code, _, err = run_cli(capsys, *argv, "--scheduler", cluster.scheduler_address, "--out", tmp_path / "dask")
    assert code == 0, err
    for name in ("evaluations.csv", "pareto.csv"):
        assert (tmp_path / "dask" / name).read_bytes() == (tmp_path / "local" / name).read_bytes()


def test_an_objective_that_cannot_tell_designs_apart_is_said(tmp_path, capsys):
    """0.05 s is a fifth of the first crank revolution: the mean speed over the last whole revolutions is 0
    in every design, so the 'best' is arbitrary; the command says so on stderr (and optimize.json lists it),
    and a run long enough to tell the designs apart says nothing."""
    argv = ("optimize", "--vary", "m2=0.5:2", "--objective", "max:mean_speed_m_s", "--budget", "4",
            "--variant", "analytic-unilateral", "--verify", "none", "--workers", "1")
    code, _, err = run_cli(capsys, *argv, "--t-end", "0.05", "--out", tmp_path / "short")
    assert code == 0 and "note: mean_speed_m_s is the same in every feasible design" in err
    assert json.loads((tmp_path / "short" / "optimize.json").read_text())["flat_objectives"] == ["mean_speed_m_s"]
    code, _, err = run_cli(capsys, *argv, "--t-end", "0.6", "--out", tmp_path / "long")
    assert code == 0 and "note:" not in err
    assert json.loads((tmp_path / "long" / "optimize.json").read_text())["flat_objectives"] == []
