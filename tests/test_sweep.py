"""Geometry what-if sweeps: design spaces, batched = serial, nothing lost, Dask = local."""

from __future__ import annotations

import contextlib
import csv
import math
import json
import re
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from ipir_mujoco import analytic
from ipir_mujoco.analytic import ParameterError, RobotParams, SimulationError
from ipir_mujoco.core.results import COLUMNS, RunResult
from ipir_mujoco.studies.sweeps import sweep_design
from ipir_mujoco.cli import main
from ipir_mujoco.studies.sweep import run_sweep
from ipir_mujoco.engine.run.batch import run_ratchet_batch
import figure_checks
from ipir_mujoco.studies.sweep_metrics import batch_metrics, run_metrics
from ipir_mujoco.report.sweep_plots import best_designs, read_results
from ipir_mujoco.studies.sweep_space import Study, parse_vary, read_study


def rows_of(path: Path) -> list[dict]:
    with path.open(newline="") as fh:
        return list(csv.DictReader(fh))


def test_vary_specifications():
    assert parse_vary("L=0.1:0.3:3").values == pytest.approx((0.1, 0.2, 0.3))
    assert parse_vary("L=0.1:1:3:log").values == pytest.approx((0.1, np.sqrt(0.1), 1.0))
    assert parse_vary("L=0.1:1:3:log").log and not parse_vary("L=0.1:1:3").log  # drawn on a log axis
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
        metrics = batch_metrics(outcome)
        serial = run_metrics(simulate_mujoco(params, "unilateral", "ratchet", 0.4, dt_out=1e-3))
        for key in ("revolutions", "stalled", "steady"):
            assert metrics[key] == serial[key], key
        # the batch measures displacement as qpos - qpos(0) in one subtraction, the engine in
        # another order: equal to roundoff of the positions (~1e-16 m over ~0.1 m), which the
        # per-revolution figures amplify by ~1e3 at most
        for key in ("mean_speed_mps", "distance_per_rev_m"):
            assert metrics[key] == pytest.approx(serial[key], rel=1e-10), key
        assert np.isnan(metrics["accel_jump_mps2"]) and np.isnan(serial["accel_jump_mps2"])


def test_a_failing_design_is_recorded_and_the_sweep_goes_on(tmp_path):
    study = Study((parse_vary("L=0.03,0.2"),), engines=("analytic-approx", "mujoco-ratchet"), t_end=0.2)
    rows = rows_of(run_sweep(study, tmp_path / "s", progress=False, workers=1))
    by_id = {int(r["design_id"]): r for r in rows}
    assert "L=0.03 m with r=0.05 m" in by_id[0]["error"] and by_id[0]["analytic-approx:revolutions"] == ""
    assert by_id[1]["error"] == "" and float(by_id[1]["mujoco-ratchet:revolutions"]) > 0.3


# The command line in a child whose designs from L = HOLD_FROM on wait for the interrupt (pool workers fork with
# the patch): the sweep cannot end before the test's Ctrl-C, however busy the machine (a test that raced a
# running sweep failed when the sweep won); the designs before it run as the command runs them.
HELD_SWEEP = """
import sys, time
from ipir_mujoco.studies import sweep as sweep_module
from ipir_mujoco.studies.sweeps import sweep_design
HOLD_FROM = float(sys.argv.pop(1))
real_engine, real_chunk = sweep_design.run_engine, sweep_module.run_batch_chunk

def wait_for_the_interrupt():
    while True:
        time.sleep(1)

def run_engine(engine, params, *args):
    if params.L >= HOLD_FROM:
        wait_for_the_interrupt()
    return real_engine(engine, params, *args)

def run_batch_chunk(values, *args, **kwargs):
    if any(v["L"] >= HOLD_FROM for v in values):
        wait_for_the_interrupt()
    return real_chunk(values, *args, **kwargs)

sweep_design.run_engine, sweep_module.run_batch_chunk = run_engine, run_batch_chunk
from ipir_mujoco.cli import console
sys.exit(console())
"""


@contextlib.contextmanager
def held_sweep(hold_from: float, argv: list[str], **popen):
    """``ipir-mujoco sweep ARGV`` in a child whose designs with L >= ``hold_from`` never end (HELD_SWEEP), in a
    session of its own: whatever the test's outcome (a timeout included), the child and its pool's workers, which
    would otherwise wait for ever, are killed on the way out."""
    # run beside its --out folder: `python -c` puts its working folder first on sys.path, and from the repository's
    # root that would import the source tree rather than the installed package (and compile its kernels afresh)
    popen.setdefault("cwd", Path(argv[argv.index("--out") + 1]).parent)
    process = subprocess.Popen([sys.executable, "-c", HELD_SWEEP, repr(hold_from), "sweep", *argv],
                               start_new_session=True, **popen)
    try:
        yield process
    finally:
        with contextlib.suppress(ProcessLookupError):
            os.killpg(process.pid, signal.SIGKILL)
        process.wait()


@pytest.mark.slow
def test_sigint_mid_sweep_then_resume_completes_every_design_once(tmp_path):
    out = tmp_path / "s"
    # L = 0.07 + k 0.33/23: designs 0-5 run, 6-23 wait (L >= 0.15) until the Ctrl-C
    with held_sweep(0.15, ["--vary", "L=0.07:0.4:24", "--variants", "analytic-unilateral", "--t-end", "1",
                           "--out", str(out), "--workers", "2"],
                    stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True) as process:
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
    assert main(["sweep", "--vary", "L=0.07:0.4:24", "--variants", "analytic-unilateral", "--t-end", "1",
                 "--out", str(out), "--resume", "--workers", "2"]) == 0
    ids = [int(r["design_id"]) for r in rows_of(results)]
    assert ids == list(range(24))  # every design exactly once, in design order once complete
    by_id = {r["design_id"]: r for r in rows_of(results)}
    assert all(by_id[p["design_id"]] == p for p in partial)  # the rows kept are the rows of the full sweep


@pytest.mark.slow
def test_resume_refuses_another_study_and_a_rerun_without_resume(tmp_path, capsys):
    out = tmp_path / "s"
    base = ["sweep", "--variants", "analytic-approx", "--t-end", "0.2", "--out", str(out)]
    assert main([*base, "--vary", "L=0.1,0.2"]) == 0
    assert main([*base, "--vary", "L=0.1,0.2"]) == 2 and "--resume" in capsys.readouterr().err
    assert main([*base, "--vary", "L=0.1,0.3", "--resume"]) == 2 and "another study" in capsys.readouterr().err


@pytest.mark.slow
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
        assert main(["sweep", "--vary", "L=0.08,0.2", "--vary", "m2=0.5,1.5", "--variants",
                     "analytic-approx,mujoco-ratchet", "--t-end", "0.3", "--out", str(tmp_path / "cli"),
                     "--scheduler", cluster.scheduler_address]) == 0
    by_id = lambda rows: sorted(rows, key=lambda r: int(r["design_id"]))  # noqa: E731
    assert by_id(local) == by_id(remote) == by_id(rows_of(tmp_path / "cli" / "results.csv"))


@pytest.mark.slow
def test_sweep_command_writes_results_heatmap_and_best_designs(tmp_path, capsys):
    out = tmp_path / "s"
    assert main(["sweep", "--vary", "L=0.08:0.3:3", "--vary", "m2=0.5,1.5", "--variants",
                 "analytic-unilateral,analytic-approx", "--t-end", "0.5", "--out", str(out)]) == 0
    printed = capsys.readouterr().out
    assert re.search(r"^  best mean_speed_m_s +\(highest\) ", printed, flags=re.M), printed
    # each best value keeps its 4 significant digits ('2.000 J/m' for the rigid clutches' F_r1 + F_r2, not '2')
    values = re.findall(r"^  best \S+ +\((?:highest|lowest ?)\) +\S+ +(\S+)(?: \S+)? at ", printed, flags=re.M)
    assert values and all(len(re.sub(r"[^0-9]", "", v.split("e")[0]).lstrip("0")) == 4 for v in values), printed
    ranking = json.loads((out / "best.json").read_text())["ranking"]
    assert set(ranking["analytic-unilateral"]) == {"steady_speed_m_s", "energy_per_metre_j_m"}
    assert (out / "sweep_heatmap.png").read_bytes()[:4] == b"\x89PNG"
    columns = read_results(out / "results.csv")
    best = best_designs(columns, ["L", "m2"], ["analytic-unilateral"])
    speed = next(b for b in best if b["metric"] == "mean_speed_m_s")
    assert speed["value"] == np.nanmax(columns["analytic-unilateral:mean_speed_m_s"])
    # the first spelling stays in every row, with the same values, for scripts written against it
    assert np.array_equal(columns["analytic-unilateral:mean_speed_mps"], columns["analytic-unilateral:mean_speed_m_s"])
    assert main(["sweep", "--vary", "L=0.1:0.3:3", "--variants", "analytic-approx", "--t-end", "0.3",
                 "--out", str(tmp_path / "line")]) == 0
    assert (tmp_path / "line" / "sweep_lines.png").is_file()
    for argv, fragment in ((["--vary", "foo=1,2"], "foo"), ([], "at least one --vary"),
                           (["--vary", "L=0.1,0.2", "--variants", "nope"], "nope")):
        assert main(["sweep", *argv, "--out", str(tmp_path / "bad")]) == 2
        assert fragment in capsys.readouterr().err


# ---------------------------------------------------------------------------------------------
# streaming, interrupts, orphans, determinism, budgets, the steady state

def _wait_for_rows(path: Path, count: int, process, deadline_s: float = 120.0) -> None:
    deadline = time.monotonic() + deadline_s
    while time.monotonic() < deadline and process.poll() is None:
        if path.exists() and len(path.read_text().splitlines()) >= count + 1:
            return
        time.sleep(0.02)


@pytest.mark.slow
def test_ctrl_c_halfway_through_a_default_engine_sweep_keeps_the_finished_designs(tmp_path):
    """The MuJoCo batch streams by chunks: rows of both engines reach the file before the sweep ends."""
    out = tmp_path / "s"
    designs = 32
    # L = 0.07 + k 0.33/31: from design 15 on (L >= 0.22) and the MuJoCo chunks that hold one wait for the Ctrl-C
    with held_sweep(0.22, ["--vary", f"L=0.07:0.4:{designs}", "--t-end", "0.5", "--out", str(out),
                           "--workers", "2", "--batch-size", "4"],
                    stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True) as process:
        _wait_for_rows(out / "results.csv", 2, process)
        seen = len(rows_of(out / "results.csv"))
        process.send_signal(signal.SIGINT)
        _, err = process.communicate(timeout=120)
    kept = rows_of(out / "results.csv")
    assert process.returncode == 130 and "--resume" in err and "Traceback" not in err
    assert seen >= 2 and seen <= len(kept) < designs
    for row in kept:  # each a finished design: both engines' figures, no error
        assert row["error"] == "" and float(row["mujoco-ratchet:revolutions"]) > 0
        assert float(row["analytic-unilateral:revolutions"]) > 0


def _alive(pid: int) -> bool:
    try:
        status = Path(f"/proc/{pid}/status").read_text()
    except OSError:
        return False
    return "\nState:\tZ" not in status  # a zombie has exited; only its parent's bookkeeping is left


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="reads /proc for the workers' process ids")
@pytest.mark.slow
def test_sigkill_of_the_main_process_leaves_no_worker_alive(tmp_path):
    out = tmp_path / "s"
    # from design 4 on (L >= 0.1) the workers wait: they are alive when the main process is killed
    with held_sweep(0.1, ["--vary", "L=0.07:0.4:40", "--variants", "analytic-unilateral", "--t-end", "1",
                          "--out", str(out), "--workers", "2"],
                    stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL) as process:
        _wait_for_rows(out / "results.csv", 1, process)
        workers = [int(p) for p in Path(f"/proc/{process.pid}/task/{process.pid}/children").read_text().split()]
        assert workers, "the sweep started no worker"
        process.kill()
        process.wait(timeout=10)
        deadline = time.monotonic() + 5.0
        while time.monotonic() < deadline and any(_alive(p) for p in workers):
            time.sleep(0.05)
        assert not [p for p in workers if _alive(p)]


def test_two_runs_of_one_study_write_the_same_bytes(tmp_path):
    study = Study((parse_vary("L=0.08,0.15,0.3"), parse_vary("m2=0.5,2")), t_end=0.2)
    first = run_sweep(study, tmp_path / "a", progress=False, workers=1, batch_size=2)
    second = run_sweep(study, tmp_path / "b", progress=False, workers=2, batch_size=6)
    assert first.read_bytes() == second.read_bytes()
    assert [int(r["design_id"]) for r in rows_of(first)] == list(range(6))


def _hang_on_short_rods(engine, params, t_end, dt_out, options):
    if params.L < 0.15:
        while True:  # a design that never finishes: only the budget can stop it
            pass
    return _real_run_engine(engine, params, t_end, dt_out, {})


_real_run_engine = sweep_design.run_engine


def test_a_design_past_its_time_budget_is_a_recorded_failure_not_a_hang(tmp_path, monkeypatch):
    monkeypatch.setattr(sweep_design, "run_engine", _hang_on_short_rods)  # pool workers fork with it
    study = Study((parse_vary("L=0.1,0.2"),), engines=("analytic-approx",), t_end=0.2)
    rows = {int(r["design_id"]): r for r in rows_of(run_sweep(study, tmp_path / "s", progress=False, workers=2,
                                                                timeout_per_design=0.5))}
    assert "exceeded --timeout-per-design 0.5 s" in rows[0]["error"]
    assert rows[1]["error"] == "" and float(rows[1]["analytic-approx:revolutions"]) > 0


def test_resume_needs_a_sweep_folder_and_bad_options_create_nothing(tmp_path, capsys):
    run_folder = tmp_path / "run"
    assert main(["simulate", "--t-end", "0.1", "--out", str(run_folder)]) == 0
    before = sorted(p.name for p in run_folder.iterdir())
    assert main(["sweep", "--vary", "L=0.1,0.2", "--variants", "analytic-approx", "--resume", "--out",
                 str(run_folder)]) == 2
    assert "holds no sweep" in capsys.readouterr().err and sorted(p.name for p in run_folder.iterdir()) == before
    assert main(["sweep", "--vary", "L=0.1:0.2", "--sample", "2", "--seed", "-1", "--out", str(tmp_path / "x")]) == 2
    assert "seed=-1" in capsys.readouterr().err and not (tmp_path / "x").exists()


def steady_run(engine: str = "analytic", omega: float = 20.0, pitch: float = 0.01, M: float = 0.25,
               efficiency: float = 0.8, t_end: float = 1.5) -> RunResult:
    """A run at its periodic steady state from the start: crank at omega [rad/s], travel pitch * phi [m]."""
    t = np.linspace(0.0, t_end, 3001)
    phi = omega * t
    series = {c: np.zeros_like(t) for c in COLUMNS}
    series.update(t=t, phi=phi, omega=np.full_like(t, omega), x1=pitch * phi, x2=pitch * phi,
                  v1=np.full_like(t, pitch * omega), v2=np.full_like(t, pitch * omega),
                  lambda1=np.full_like(t, 3.0), motor_work=M * phi, friction_work=efficiency * M * phi,
                  kinetic=np.zeros_like(t), potential=np.zeros_like(t))
    series["mode"] = np.full(t.size, 3)
    energy = {"motor_work_j": M * phi[-1], "kinetic_j": 0.0, "friction_j": efficiency * M * phi[-1],
              "residual_j": 0.0}
    return RunResult(engine, "exact", "unilateral", RobotParams(), t_end, series, energy)


def test_steady_state_metrics_come_from_the_run_summary():
    omega, pitch, M = 20.0, 0.01, 0.25
    metrics = run_metrics(steady_run(omega=omega, pitch=pitch, M=M))
    assert metrics["steady"] == 1 and metrics["stalled"] == 0
    # settled after the first STEADY_CYCLES = 3 revolutions, at 2 pi / omega each
    assert metrics["t_steady_s"] == pytest.approx(3 * 2 * np.pi / omega, rel=1e-9)
    assert metrics["steady_speed_m_s"] == pytest.approx(pitch * omega, rel=1e-9)
    assert metrics["distance_per_rev_m"] == pytest.approx(2 * np.pi * pitch, rel=1e-9)
    assert metrics["energy_per_metre_j_m"] == pytest.approx(M / pitch, rel=1e-9)  # M dphi / (pitch dphi)
    assert metrics["efficiency"] == pytest.approx(0.8, rel=1e-9)
    assert metrics["peak_clutch_force_n"] == 3.0
    assert np.isnan(metrics["residual_ratio"])  # the analytic engines have no accuracy monitor


@pytest.mark.parametrize("batch_mujoco", [True, False])
def test_until_steady_and_the_budget_reach_every_engine(tmp_path, monkeypatch, batch_mujoco):
    """The engines' until_steady keyword (and the analytic wall_budget_s) are passed; the batched
    MuJoCo series is read through core.cycles; a stalled design is marked, not failed. The fakes
    raise unless they get the keywords: pool and batch processes fork with them in place."""
    import ipir_mujoco.analytic as analytic_package
    import ipir_mujoco.engine as engine_package
    import ipir_mujoco.engine.run.batch as batch_module

    def fake_analytic(params, geometry, clutch, t_end, **kwargs):
        if not kwargs.get("until_steady") or kwargs.get("wall_budget_s") != 30:
            raise SimulationError(f"keywords not passed: {sorted(kwargs)}")
        run = steady_run()
        if params.L > 0.15:
            run.stall = "at rest on a dead centre from t=0.5 s"
        return run

    def fake_mujoco(params, clutch, implementation, t_end, **kwargs):
        if not kwargs.get("until_steady"):
            raise SimulationError("until_steady not passed")
        run = steady_run("mujoco", pitch=0.0101)
        run.accuracy = {"residual_ratio": 2e-4, "loop_gap_m": 3e-7}
        return run

    def fake_batch(designs, t_end, dt_out, nthread=0, **kwargs):
        if kwargs != {"until_steady": True}:
            raise SimulationError(f"batch keywords: {kwargs}")
        run = steady_run("mujoco")
        return [{"series": run.series, "motor_work_j": run.energy["motor_work_j"],
                 "friction_work_j": run.energy["friction_j"], "accuracy": {"residual_ratio": 1e-4, "loop_gap_m": 0.0}}
                for _ in designs]

    monkeypatch.setattr(analytic_package, "simulate", fake_analytic)
    monkeypatch.setattr(engine_package, "simulate_mujoco", fake_mujoco)
    monkeypatch.setattr(batch_module, "run_ratchet_batch", fake_batch)
    # under the motor: a sweep to steady state under the constant torque is refused up front
    study = Study((parse_vary("L=0.1,0.2"),), base=RobotParams(drive="motor"),
                  engines=("mujoco-ratchet", "analytic-unilateral", "mujoco-lock"), t_end=2.0, until_steady=True)
    rows = rows_of(run_sweep(study, tmp_path / "s", progress=False, workers=1, timeout_per_design=30,
                             batch_mujoco=batch_mujoco))
    assert all(r["error"] == "" for r in rows)
    for row in rows:
        # each fake's own residual: the ratchet went where it was sent
        assert float(row["mujoco-ratchet:steady"]) == 1
        assert float(row["mujoco-ratchet:residual_ratio"]) == (1e-4 if batch_mujoco else 2e-4)
        assert float(row["mujoco-lock:loop_gap_m"]) == 3e-7
        assert float(row["analytic-unilateral:steady_speed_m_s"]) == pytest.approx(0.2, rel=1e-9)
        # 0.0101 against the batch fake's 0.01 m per radian: the steady speed diverges by exactly 1 %; none
        # against the serial fake's own 0.0101
        assert float(row["divergence:mujoco-lock:steady_speed_m_s"]) == pytest.approx(0.01 if batch_mujoco else 0.0,
                                                                                     rel=1e-6, abs=1e-12)
    assert rows[0]["analytic-unilateral:stalled"] == "0" and rows[1]["analytic-unilateral:stalled"] == "1"
    assert "dead centre" in rows[1]["notes"]


def test_the_batch_hands_what_it_does_not_model_to_the_serial_engine(monkeypatch):
    """A design whose drive the batched engine does not declare, or with compliant clutches (the batch has
    rigid ratchets only), is neither a silently different robot nor a failure: it runs in the serial engine
    and its row is the serial run's (the batch models the constant torque and the motor: a batch that
    declared only the torque must hand a motor design over). Before, both were failed rows."""
    from ipir_mujoco.engine.run import batch
    from ipir_mujoco.studies.sweep import engine_metrics, run_batch_chunk

    monkeypatch.setattr(batch, "MODELLED_DRIVES", ("torque",), raising=False)
    base = RobotParams(drive="motor")
    rows = run_batch_chunk([{"L": 0.1}, {"L": 0.2}], base, 0.1, 1e-3, 1)
    for row, L in zip(rows, (0.1, 0.2)):
        assert row["mujoco-ratchet"] == engine_metrics("mujoco-ratchet", base.replace(L=L), 0.1, 1e-3, {})
    compliant = RobotParams(clutch_stiffness=1e6)
    rows = run_batch_chunk([{"L": 0.1}, {"L": 0.2}], compliant, 0.1, 1e-3, 1)
    for row, L in zip(rows, (0.1, 0.2)):
        assert "error" not in row["mujoco-ratchet"], row
        assert row["mujoco-ratchet"] == engine_metrics("mujoco-ratchet", compliant.replace(L=L), 0.1, 1e-3, {})


def test_the_batch_runs_a_motor_design_as_the_motor(tmp_path):
    """run_ratchet_batch builds each design's actuator with the serial engine's builder, the motor line
    included: a batched motor design gives the serial MuJoCo run's figures (the same model, the same steps,
    the same reads of MuJoCo's state), not a constant torque's."""
    from ipir_mujoco.engine import simulate_mujoco
    from ipir_mujoco.studies.sweep_metrics import run_metrics

    study = Study((parse_vary("L=0.1,0.2"),), base=RobotParams(drive="motor"), engines=("mujoco-ratchet",),
                  t_end=0.1)
    rows = rows_of(run_sweep(study, tmp_path / "s", progress=False, workers=1))
    for row in rows:
        assert row["error"] == ""
        serial = run_metrics(simulate_mujoco(RobotParams(drive="motor", L=float(row["L"])), "unilateral", "ratchet",
                                             0.1, dt_out=1e-3))
        # results.csv keeps 10 significant digits
        assert float(row["mujoco-ratchet:revolutions"]) == pytest.approx(serial["revolutions"], rel=1e-9)
        assert float(row["mujoco-ratchet:efficiency"]) == pytest.approx(serial["efficiency"], rel=1e-6)


def test_mujoco_peak_forces_that_measure_the_numerics_are_left_empty():
    """A rigid MuJoCo clutch takes up its load within a few steps: the peak reaction read from the sweep's
    1 ms samples is whichever step a sample hits, and differs from the peak over every step of the same run
    (the same trajectory: only the output interval changes); where an engagement is hard its jolt reaches
    the rod, whose peak then changes with the step. The sweep leaves both empty, for the ratchet and the
    locks; a compliant clutch read at every step keeps its (physical) peaks."""
    from ipir_mujoco.engine import simulate_mujoco
    from ipir_mujoco.engine.builders.model import SolverSettings

    params = RobotParams()
    sampled = simulate_mujoco(params, "unilateral", "ratchet", 0.5, dt_out=1e-3)
    every_step = simulate_mujoco(params, "unilateral", "ratchet", 0.5, dt_out=sampled.settings["timestep"])
    assert sampled.settings["timestep"] < 1e-3
    # the artefact: the same run's peak differs by far more than its accuracy monitor's 1e-3 with the sampling
    assert abs(every_step.summary["peak_clutch_force_n"] / sampled.summary["peak_clutch_force_n"] - 1) > 1e-2
    # a hard engagement (from rest, light front module): the ratchet's peak rod force, read at every step,
    # moves by more than the monitor's 1e-3 when the step is halved
    hard = RobotParams(L=0.3742, m2=0.2)
    rod = [np.abs(simulate_mujoco(hard, "unilateral", "ratchet", 0.5, dt_out=dt, settings=SolverSettings(timestep=dt))
                  .series["rod_force"]).max() for dt in (1e-4, 5e-5)]
    assert abs(rod[1] / rod[0] - 1) > 1e-2
    for run in (sampled, every_step):
        metrics = run_metrics(run)
        assert np.isnan(metrics["peak_clutch_force_n"]) and np.isnan(metrics["peak_rod_force_n"])
    lock = run_metrics(simulate_mujoco(params, "kinematic", "lock", 0.3, dt_out=1e-3))
    assert np.isnan(lock["peak_clutch_force_n"]) and np.isnan(lock["peak_rod_force_n"])
    # the analytic engines keep theirs; MuJoCo with a compliant clutch read at every step keeps its peak
    assert run_metrics(steady_run())["peak_clutch_force_n"] == 3.0
    compliant = steady_run("mujoco")
    compliant.settings = {"clutch_model": "compliant", "mujoco_clutch": "ratchet", "timestep": 1e-5, "dt_out": 1e-5}
    compliant.series["rod_force"] = np.linspace(-5.0, 4.0, compliant.series["t"].size)
    kept = run_metrics(compliant)
    assert kept["peak_clutch_force_n"] == 3.0 and kept["peak_rod_force_n"] == 5.0
    compliant.settings = {**compliant.settings, "dt_out": 1e-3}
    assert np.isnan(run_metrics(compliant)["peak_clutch_force_n"])
    assert np.isnan(run_metrics(compliant)["peak_rod_force_n"])


def test_the_heatmap_colours_the_first_engine_that_gives_the_metric():
    """--plot-metric peak_clutch_force_n with the default engines: the batched MuJoCo ratchet gives no peak
    forces, and colouring its empty column drew a blank map with a meaningless colour bar."""
    from ipir_mujoco.report.sweep_plots import coloured_engine

    nan = np.full(4, np.nan)
    columns = {"mujoco-ratchet:peak_clutch_force_n": nan, "analytic-unilateral:peak_clutch_force_n": np.arange(4.0),
               "mujoco-ratchet:revolutions": np.ones(4), "analytic-unilateral:revolutions": np.ones(4)}
    engines = ["mujoco-ratchet", "analytic-unilateral"]
    engine, heading = coloured_engine(columns, engines, "peak_clutch_force_n")
    assert engine == "analytic-unilateral" and "mujoco-ratchet gives no peak clutch force" in heading
    assert coloured_engine(columns, engines, "revolutions") == ("mujoco-ratchet", "crank revolutions of mujoco-ratchet")
    columns["analytic-unilateral:peak_clutch_force_n"] = nan
    assert coloured_engine(columns, engines, "peak_clutch_force_n")[0] is None


def test_the_line_plot_does_not_draw_a_stalled_design_as_a_point_of_the_curve():
    """A stalled design's figures are those of a robot at rest (the sizing sweep at M_stall 0.02 N m: speed 0,
    0.06 m 'per revolution' of a partial turn, efficiency 1): a cross, not a point joined to the curve."""
    from types import SimpleNamespace

    from ipir_mujoco.report.sweep_plots import lines_figure

    x = np.array([0.02, 0.04, 0.06, 0.08])
    columns = {"M_stall": x, "a:stalled": np.array([1.0, 0.0, 0.0, 0.0])}
    for metric in ("mean_speed_m_s", "distance_per_rev_m"):
        columns[f"a:{metric}"] = np.array([0.06, 0.11, 0.12, 0.125])
    for metric in ("steady_speed_m_s", "energy_per_metre_j_m", "efficiency", "peak_clutch_force_n",
                   "peak_rod_force_n", "accel_jump_m_s2", "mean_omega_rad_s", "speed_ripple"):
        columns[f"a:{metric}"] = np.full(4, np.nan)
    fig = lines_figure(columns, SimpleNamespace(name="M_stall", log=False), ["a"])
    lines = {line.get_gid(): line for ax in fig.axes for line in ax.get_lines() if line.get_gid()}
    curve = lines["a:distance_per_rev_m"].get_ydata()
    assert np.isnan(curve[0]) and list(curve[1:]) == [0.11, 0.12, 0.125]
    assert list(lines["stalled:a:distance_per_rev_m"].get_xdata()) == [0.02]


def test_a_metric_equal_in_every_design_names_no_best_design():
    """Runs too short for a whole crank revolution have mean speed 0 in every design: the sweep printed
    'best mean_speed_mps ... 0 at L=0.1, m2=0.5', the first design, as if it had been found best."""
    from ipir_mujoco.report.sweep_plots import best_designs

    columns = {"design_id": np.arange(3.0), "L": np.array([0.1, 0.2, 0.3]), "a:revolutions": np.ones(3),
               "a:stalled": np.zeros(3)}
    for metric in ("mean_speed_m_s", "t_steady_s", "steady_speed_m_s", "distance_per_rev_m", "energy_per_metre_j_m",
                   "efficiency", "peak_clutch_force_n", "peak_rod_force_n", "accel_jump_m_s2", "mean_omega_rad_s", "speed_ripple"):
        columns[f"a:{metric}"] = np.full(3, np.nan)
    columns["a:mean_speed_m_s"] = np.zeros(3)
    columns["a:efficiency"] = np.array([0.1, 0.3, 0.2])
    best = best_designs(columns, ["L"], ["a"])
    assert [(b["metric"], b["L"]) for b in best] == [("efficiency", 0.2)]


def test_the_default_sweep_runs_mujoco_serially_where_its_loop_is_compiled(tmp_path):
    """Where the serial engine steps in C, the default sweep runs the ratchet designs through it: each row
    is the serial run's metrics, not the batch's."""
    from ipir_mujoco.engine.loop.stepper import compiled_status
    from ipir_mujoco.studies.sweep import engine_metrics
    from ipir_mujoco.studies.sweep_files import _cell, make_row

    compiled, why = compiled_status()
    if not compiled:
        pytest.skip(f"no compiled loop here: {why}")
    study = Study((parse_vary("L=0.1,0.2"),), engines=("mujoco-ratchet",), t_end=0.2)
    rows = rows_of(run_sweep(study, tmp_path / "s", progress=False, workers=1))
    for i, row in enumerate(rows):
        design = {"L": (0.1, 0.2)[i]}
        serial = engine_metrics("mujoco-ratchet", study.base.replace(**design), study.t_end, study.dt_out, {})
        expected = make_row(i, design, {"mujoco-ratchet": serial}, study.engines)
        assert row == {k: _cell(v) for k, v in expected.items()}
        assert float(row["mujoco-ratchet:revolutions"]) > 0


def test_no_batch_with_a_batch_size_is_refused(tmp_path, capsys):
    code = main(["sweep", "--vary", "L=0.1,0.2", "--t-end", "0.1", "--out", str(tmp_path / "s"), "--no-batch",
                 "--batch-size", "4"])
    err = capsys.readouterr().err
    assert code == 2 and "--batch-size 4 with --no-batch" in err and len(err.strip().splitlines()) == 1
    assert not (tmp_path / "s").exists()


def test_mean_speed_counts_its_revolutions_back_from_the_end():
    """Two runs of an accelerating crank that end 1.3e-3 of a turn apart, one just past its 6th turn and one
    just short of it, average over the same last three turns: their mean speeds differ by less than the
    windows' offset (1.3e-3 of 3 turns) times the speed's change across them, not by a whole turn's
    acceleration (counted from the start, the windows were turns 4-6 and 3-5: 14 % apart in a real sweep)."""
    from ipir_mujoco.studies.sweep_metrics import mean_speed

    alpha, pitch = 80.0, 0.02  # crank acceleration [rad/s^2], travel per radian [m]

    def run(revolutions):
        t_end = math.sqrt(2 * 2 * math.pi * revolutions / alpha)
        t = np.linspace(0.0, t_end, 4001)
        phi = 0.5 * alpha * t**2
        return {"t": t, "phi": phi, "x1": pitch * phi, "x2": pitch * phi}

    past, short = mean_speed(run(6.0005)), mean_speed(run(5.9992))
    # exact for this motion: pitch * (mean crank speed over the last 3 turns), to the linear interpolation of
    # the window's start between samples (below 1e-6 here)
    t_end = math.sqrt(2 * 2 * math.pi * 6.0005 / alpha)
    t_start = math.sqrt(2 * 2 * math.pi * 3.0005 / alpha)
    assert past == pytest.approx(pitch * 2 * math.pi * 3 / (t_end - t_start), rel=1e-6)
    assert abs(short / past - 1) < 1.3e-3 / 3


def test_the_acceleration_jump_is_read_exactly_at_the_event_instants():
    """The analytic engines write each clutch event twice, before and after: the metric is the largest
    |a_after - a_before| there, which on the paper's model is r omega^2 per module at each dead centre (its
    acceleration jump, exactly; test_paper_model checks the sum); MuJoCo, whose soft clutches engage over a
    few steps, leaves it empty."""
    from ipir_mujoco.engine import simulate_mujoco
    from ipir_mujoco.studies.sweep_metrics import accel_jump

    params = RobotParams()
    run = analytic.simulate(params, "approx", "kinematic", 0.5, dt_out=1e-3)
    s = run.series
    twins = np.flatnonzero(np.diff(s["t"]) == 0)
    assert twins.size > 3
    # rel 1e-6: the solver's rtol 1e-10 on omega, squared, and the event location's own tolerance
    expected = max(params.r * s["omega"][i] ** 2 for i in twins)
    assert run_metrics(run)["accel_jump_mps2"] == pytest.approx(expected, rel=1e-6)
    # no event instant, no jump; and MuJoCo's runs leave the metric empty
    assert accel_jump({"t": np.array([0.0, 1.0]), "a1": np.zeros(2), "a2": np.array([0.0, 5.0])}) == 0.0
    assert np.isnan(run_metrics(simulate_mujoco(params, "unilateral", "ratchet", 0.2, dt_out=1e-3))["accel_jump_mps2"])


def test_revolutions_of_runs_stopped_at_their_steady_state_are_not_compared():
    """Under --until-steady a run ends where its engine's detection fired, which two engines agreeing on
    the steady speed may do a revolution apart: the divergence of revolutions is left empty there (the
    steady speed still compares them); runs of the same length keep it."""
    from ipir_mujoco.studies.sweep_files import make_row

    engines = ("a", "b")
    a = {"revolutions": 11.0, "steady": 1.0, "steady_speed_m_s": 0.2}
    b = {"revolutions": 12.0, "steady": 1.0, "steady_speed_m_s": 0.20004}
    stopped = make_row(0, {"L": 0.1}, {"a": a, "b": b}, engines, until_steady=True)
    assert stopped["divergence:b:revolutions"] is None
    assert stopped["divergence:b:steady_speed_m_s"] == pytest.approx(2e-4, rel=1e-9)
    full = make_row(0, {"L": 0.1}, {"a": a, "b": b}, engines)
    assert full["divergence:b:revolutions"] == pytest.approx(1 / 11, rel=1e-12)


def test_the_heatmap_compares_the_steady_speed_where_revolutions_are_not_compared():
    """--until-steady --plot-metric t_steady_s: t_steady has no divergence column, and the revolutions of runs
    stopped at their steady state are not compared; the map's contours then follow the steady speed."""
    from ipir_mujoco.report.sweep_plots import compared_metric

    engines = ["mujoco-ratchet", "analytic-unilateral"]
    columns = {f"divergence:analytic-unilateral:{m}": np.full(3, np.nan)
               for m in ("revolutions", "steady_speed_m_s", "mean_speed_m_s")}
    columns["divergence:analytic-unilateral:steady_speed_m_s"] = np.array([1e-4, np.nan, 2e-4])
    assert compared_metric(columns, engines, "t_steady_s") == "steady_speed_m_s"
    assert compared_metric(columns, engines, "mean_speed_m_s") == "mean_speed_m_s"
    columns["divergence:analytic-unilateral:revolutions"] = np.array([3e-4, 1e-4, 2e-4])
    assert compared_metric(columns, engines, "t_steady_s") == "revolutions"


def test_a_panel_flat_within_what_the_runs_resolve_says_so_and_names_no_best():
    """At steady state energy per metre is F_r1 + F_r2 whatever L (rigid clutches): a design-to-design wiggle of
    1e-4 is the steady window's numerics. Drawn across the resolved band with a note, and ranked nowhere; a
    metric that does vary is drawn to its own range and ranked."""
    from types import SimpleNamespace

    from ipir_mujoco.report.sweep_plots import RESOLVED, best_designs, lines_figure

    x = np.array([0.1, 0.2, 0.3, 0.4])
    columns = {"design_id": np.arange(4.0), "L": x, "a:stalled": np.zeros(4), "a:revolutions": np.ones(4)}
    for metric in ("mean_speed_m_s", "t_steady_s", "steady_speed_m_s", "distance_per_rev_m", "efficiency",
                   "peak_clutch_force_n", "peak_rod_force_n", "accel_jump_m_s2", "mean_omega_rad_s", "speed_ripple"):
        columns[f"a:{metric}"] = np.full(4, np.nan)
    columns["a:energy_per_metre_j_m"] = 2.0 * (1 + np.array([1e-4, -2e-4, 3e-4, 0.0]))  # within RESOLVED
    columns["a:steady_speed_m_s"] = np.array([0.55, 0.54, 0.53, 0.53])
    fig = lines_figure(columns, SimpleNamespace(name="L", log=False), ["a"], caption="a sweep")
    # the note is the panel's title (above it: a note inside the panel lay on a curve)
    notes = {ax.get_title(loc="right"): ax for ax in fig.axes if ax.get_title(loc="right")}
    energy_axis = next(ax for ax in fig.axes if ax.get_ylabel().startswith("energy per"))
    assert energy_axis.get_title(loc="right").startswith("flat: within")
    assert all("steady" not in ax.get_ylabel() for ax in notes.values())
    assert not figure_checks.texts_over_data(fig) and not figure_checks.undrawn_legend_entries(fig)
    low, high = energy_axis.get_ylim()
    assert high - low == pytest.approx(3 * RESOLVED * 2.0, rel=1e-3)  # the band, not the wiggle's own 1e-3 J/m
    assert [b["metric"] for b in best_designs(columns, ["L"], ["a"])] == ["steady_speed_m_s"]


def test_a_stalled_design_has_no_per_revolution_figures_in_either_engine():
    """A robot at rest for good in a vertical riser: its 'distance per revolution' of a partial turn and its
    efficiency are not figures of a design; the row leaves them empty, and says it stalled."""
    from ipir_mujoco import registry
    from ipir_mujoco.studies.sweep_metrics import PER_REVOLUTION, run_metrics

    params = RobotParams(incline=90.0)
    for engine in ("analytic-unilateral", "mujoco-ratchet"):
        run = registry.run(engine, params, 1.0, dt_out=1e-3)
        assert run.stall is not None, engine
        metrics = run_metrics(run)
        assert metrics["stalled"] == 1 and all(np.isnan(metrics[m]) for m in PER_REVOLUTION), (engine, metrics)


def test_the_first_metric_spellings_still_name_their_metrics():
    from ipir_mujoco.report.sweep_plots import check_plot_metric

    assert check_plot_metric("mean_speed_mps", False) == "mean_speed_m_s"
    assert check_plot_metric("accel_jump_mps2", False) == "accel_jump_m_s2"
    assert check_plot_metric(None, False) == "mean_speed_m_s"
    with pytest.raises(ParameterError, match="--plot-metric 'speed' is unknown"):
        check_plot_metric("speed", False)


def _sleep_long(seconds: float) -> float:  # a pool task still running when its pool is ended
    time.sleep(seconds)
    return seconds


def test_a_pool_ended_at_once_has_its_workers_killed_and_its_manager_thread_ended(monkeypatch):
    """studies.pool.end_pool after Ctrl-C: the workers (deep in a 60 s task) killed, the pending task cancelled,
    and the pool's manager thread ended before it returns, so that Python's exit hook never wakes a manager still
    closing its pipe (a traceback after the one-line message). Joined without a time limit here: the test holds
    what end_pool waits for, not how long it takes."""
    from concurrent import futures

    from ipir_mujoco.studies import pool as pool_module

    monkeypatch.setattr(pool_module, "MANAGER_JOIN_S", None)
    pool = futures.ProcessPoolExecutor(max_workers=1, initializer=pool_module.worker_init, initargs=(os.getpid(),))
    running, pending = pool.submit(_sleep_long, 60.0), pool.submit(_sleep_long, 60.0)
    while not running.running():
        time.sleep(0.01)
    workers = list(pool._processes.values())
    manager = pool._executor_manager_thread
    pool_module.end_pool(pool, kill=True)
    assert not manager.is_alive()
    assert all(w.exitcode is not None for w in workers)  # killed, not left to finish their minute
    assert pending.cancelled() or isinstance(pending.exception(timeout=0), futures.process.BrokenProcessPool)
