"""Geometry what-if sweeps: design spaces, batched = serial, nothing lost, Dask = local."""

from __future__ import annotations

import csv
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from ipir_mujoco.analytic import ParameterError, RobotParams
from ipir_mujoco.cli import main
from ipir_mujoco.studies.sweep import run_sweep
from ipir_mujoco.engine.batch import run_ratchet_batch
from ipir_mujoco.studies.sweep_metrics import design_metrics
from ipir_mujoco.report.sweep_plots import best_designs, read_results
from ipir_mujoco.studies.sweep_space import Study, parse_vary, read_study


def rows_of(path: Path) -> list[dict]:
    with path.open(newline="") as fh:
        return list(csv.DictReader(fh))


def test_vary_specifications():
    assert parse_vary("L=0.1:0.3:3").values == pytest.approx((0.1, 0.2, 0.3))
    assert parse_vary("L=0.1:1:3:log").values == pytest.approx((0.1, np.sqrt(0.1), 1.0))
    assert parse_vary("m2=0.5,1,2").values == (0.5, 1.0, 2.0)
    axis = parse_vary("M=0.1:0.4")
    assert axis.is_range and (axis.low, axis.high) == (0.1, 0.4)
    for text, fragment in (("foo=1:2:3", "unknown parameter 'foo'"), ("L", "malformed"), ("L=a:b:3", "not a list"),
                           ("L=0.1:0.3:2.5", "whole number"), ("L=0:1:3:log", "positive"), ("L=0.3:0.1", "LO < HI")):
        with pytest.raises(ParameterError, match=fragment):
            parse_vary(text)


def test_grids_and_space_filling_samples():
    grid = Study((parse_vary("L=0.1:0.3:3"), parse_vary("m2=1,2")))
    designs = grid.designs()
    assert len(designs) == 6 and designs[0] == {"L": 0.1, "m2": 1.0} and designs[-1] == {"L": 0.3, "m2": 2.0}
    sample = Study((parse_vary("L=0.06:0.5"), parse_vary("M=0.01:1:log")), sample=64, seed=3)
    points = np.array([[d["L"], d["M"]] for d in sample.designs()])
    assert points.shape == (64, 2) and points[:, 0].min() >= 0.06 and points[:, 0].max() <= 0.5
    assert points[:, 1].min() >= 0.01 and points[:, 1].max() <= 1.0
    # space-filling: every quarter of each range is visited (a Sobol property, not luck)
    for column, (lo, hi) in ((points[:, 0], (0.06, 0.5)), (np.log(points[:, 1]), (np.log(0.01), 0.0))):
        assert len(np.unique(np.floor(4 * (column - lo) / (hi - lo)).clip(0, 3))) == 4
    assert sample.fingerprint() == Study(sample.axes, sample=64, seed=3).fingerprint() != grid.fingerprint()
    with pytest.raises(ParameterError, match="--sample"):
        Study((parse_vary("L=0.06:0.5"),))
    with pytest.raises(ParameterError, match="engine"):
        Study((parse_vary("L=0.1,0.2"),), engines=("warp-drive",))


def test_study_file(tmp_path):
    path = tmp_path / "study.toml"
    path.write_text('[sweep]\nvary = ["L=0.1:0.2:2"]\nengines = ["analytic-approx"]\nt_end = 0.5\n[params]\nM = 0.3\n')
    study = Study(**read_study(path, RobotParams()))
    assert study.engines == ("analytic-approx",) and study.t_end == 0.5 and study.base.M == 0.3
    path.write_text('[sweep]\nvary = ["L=0.1:0.2:2"]\nspeed = 3\n')
    with pytest.raises(ParameterError, match="unknown key 'speed'"):
        read_study(path, RobotParams())


def test_batched_mujoco_equals_the_serial_engine():
    """mujoco.batch steps the same models from the same states: the same numbers, bit for bit."""
    from ipir_mujoco.engine import simulate_mujoco

    designs = [RobotParams(L=0.08, m2=0.4), RobotParams(L=0.2, m2=2.0), RobotParams(L=0.35, F_r1=2.0)]
    batched = run_ratchet_batch(designs, 0.4, dt_out=1e-3)
    for params, outcome in zip(designs, batched):
        metrics = design_metrics(outcome["series"], outcome["motor_work_j"], outcome["friction_work_j"])
        s = simulate_mujoco(params, "unilateral", "ratchet", 0.4, dt_out=1e-3).series
        motor = params.M * (s["phi"][-1] - s["phi"][0])
        serial = design_metrics(s, motor, params.F_r1 * s["x1"][-1] + params.F_r2 * s["x2"][-1])
        for key in ("revolutions", "efficiency", "accel_jump_mps2", "stalled"):
            assert metrics[key] == serial[key], key
        # the batch measures displacement as qpos - qpos(0) in one subtraction, the engine in
        # another order: equal to roundoff of the positions (~1e-16 m over ~0.1 m)
        assert metrics["mean_speed_mps"] == pytest.approx(serial["mean_speed_mps"], rel=1e-12)


def test_a_failing_design_is_recorded_and_the_sweep_goes_on(tmp_path):
    study = Study((parse_vary("L=0.03,0.2"),), engines=("analytic-approx", "mujoco-ratchet"), t_end=0.2)
    rows = rows_of(run_sweep(study, tmp_path / "s", progress=False, workers=1))
    by_id = {int(r["design_id"]): r for r in rows}
    assert "L=0.03 m with r=0.05 m" in by_id[0]["error"] and by_id[0]["analytic-approx:revolutions"] == ""
    assert by_id[1]["error"] == "" and float(by_id[1]["mujoco-ratchet:revolutions"]) > 0.3


def test_sigint_mid_sweep_then_resume_completes_every_design_once(tmp_path):
    out = tmp_path / "s"
    command = [sys.executable, "-m", "ipir_mujoco", "sweep", "--vary", "L=0.07:0.4:24", "--engines",
               "analytic-unilateral", "--t-end", "1", "--out", str(out), "--workers", "2"]
    process = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    results = out / "results.csv"
    deadline = time.monotonic() + 120
    while time.monotonic() < deadline:  # wait until some designs are written, then interrupt
        if results.exists() and len(results.read_text().splitlines()) >= 4:
            break
        time.sleep(0.05)
    process.send_signal(signal.SIGINT)
    _, err = process.communicate(timeout=120)
    assert process.returncode == 130 and "--resume" in err
    partial = rows_of(results)  # readable after the interrupt
    assert 3 <= len(partial) < 24
    assert main(["sweep", "--vary", "L=0.07:0.4:24", "--engines", "analytic-unilateral", "--t-end", "1",
                 "--out", str(out), "--resume", "--workers", "2"]) == 0
    ids = [int(r["design_id"]) for r in rows_of(results)]
    assert sorted(ids) == list(range(24))  # every design exactly once
    assert [r for r in rows_of(results) if r["design_id"] in {p["design_id"] for p in partial}] == partial


def test_resume_refuses_another_study_and_a_rerun_without_resume(tmp_path, capsys):
    out = tmp_path / "s"
    base = ["sweep", "--engines", "analytic-approx", "--t-end", "0.2", "--out", str(out)]
    assert main([*base, "--vary", "L=0.1,0.2"]) == 0
    assert main([*base, "--vary", "L=0.1,0.2"]) == 2 and "--resume" in capsys.readouterr().err
    assert main([*base, "--vary", "L=0.1,0.3", "--resume"]) == 2 and "another study" in capsys.readouterr().err


def test_dask_gives_the_same_results_as_the_local_pool(tmp_path):
    distributed = pytest.importorskip("distributed", reason="Dask is the optional 'dask' extra")
    study = Study((parse_vary("L=0.08,0.2"), parse_vary("m2=0.5,1.5")), engines=("analytic-approx", "mujoco-ratchet"),
                  t_end=0.3)
    # the local pool running the same per-design tasks (MuJoCo serially, as on a cluster);
    # the batched path is checked against the serial engine separately
    local = rows_of(run_sweep(study, tmp_path / "local", batch_mujoco=False, progress=False))
    with distributed.LocalCluster(n_workers=1, threads_per_worker=2, processes=False, dashboard_address=None) as cluster:
        with distributed.Client(cluster) as client:
            remote = rows_of(run_sweep(study, tmp_path / "dask", executor=client.get_executor(), progress=False))
        # and the command line's --scheduler against the same cluster
        assert main(["sweep", "--vary", "L=0.08,0.2", "--vary", "m2=0.5,1.5", "--engines",
                     "analytic-approx,mujoco-ratchet", "--t-end", "0.3", "--out", str(tmp_path / "cli"),
                     "--scheduler", cluster.scheduler_address]) == 0
    by_id = lambda rows: sorted(rows, key=lambda r: int(r["design_id"]))  # noqa: E731
    assert by_id(local) == by_id(remote) == by_id(rows_of(tmp_path / "cli" / "results.csv"))


def test_sweep_command_writes_results_heatmap_and_best_designs(tmp_path, capsys):
    out = tmp_path / "s"
    assert main(["sweep", "--vary", "L=0.08:0.3:3", "--vary", "m2=0.5,1.5", "--engines",
                 "analytic-unilateral,analytic-approx", "--t-end", "0.5", "--out", str(out)]) == 0
    assert "best mean_speed_mps" in capsys.readouterr().out
    assert (out / "sweep_heatmap.png").read_bytes()[:4] == b"\x89PNG"
    columns = read_results(out / "results.csv")
    best = best_designs(columns, ["L", "m2"], ["analytic-unilateral"])
    speed = next(b for b in best if b["metric"] == "mean_speed_mps")
    assert speed["value"] == np.nanmax(columns["analytic-unilateral:mean_speed_mps"])
    assert main(["sweep", "--vary", "L=0.1:0.3:3", "--engines", "analytic-approx", "--t-end", "0.3",
                 "--out", str(tmp_path / "line")]) == 0
    assert (tmp_path / "line" / "sweep_lines.png").is_file()
    for argv, fragment in ((["--vary", "foo=1,2"], "foo"), ([], "at least one --vary"),
                           (["--vary", "L=0.1,0.2", "--engines", "nope"], "nope")):
        assert main(["sweep", *argv, "--out", str(tmp_path / "bad")]) == 2
        assert fragment in capsys.readouterr().err
