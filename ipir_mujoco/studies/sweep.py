"""Run a what-if study: every design through every engine, results streamed to disk.

``run_sweep`` writes ``OUT/sweep.json`` (the study and its fingerprint) and
``OUT/results.csv``, one row per design, appended and flushed as each design
finishes, so a crash or Ctrl-C leaves a readable file; ``resume=True`` skips
the designs already in it (and refuses a file written by another study). A
design or engine that fails records its error in the row and the sweep goes on.

Where work runs:

* default: analytic engines in a process pool over all cores; MuJoCo's
  ratchet in batches through ``mujoco.batch`` (C threads) in the main process;
* ``executor=``: any ``concurrent.futures.Executor`` (a Dask ``Client``'s
  ``get_executor()`` for a cluster); every engine of a design runs as one
  task on it, MuJoCo serially.

Row columns: ``design_id``, the varied parameters, then ``ENGINE:METRIC`` for
every engine and metric (:mod:`ipir_mujoco.studies.sweep_metrics`), then
``divergence:ENGINE:revolutions`` and ``divergence:ENGINE:mean_speed_mps``,
(ENGINE - first engine) / |first engine|, then ``error``.
"""

from __future__ import annotations

import concurrent.futures as futures
import csv
import json
import math
import os
import signal
import sys
import time
from pathlib import Path
from typing import Callable

from ipir_mujoco import analytic
from ipir_mujoco.analytic.errors import ParameterError
from ipir_mujoco.analytic.params import RobotParams

from .sweep_metrics import METRICS, design_metrics
from .sweep_space import Study

DT_OUT = 1e-3  # s: output interval of the sweep's runs; enough for the metrics, light on memory
BATCH_SIZE = 64  # MuJoCo designs stepped together
DIVERGENCE = ("revolutions", "mean_speed_mps")


class SweepInterrupted(RuntimeError):
    """Ctrl-C (or SIGINT) stopped the sweep; the rows written so far are kept."""


def _run_engine(engine: str, params: RobotParams, t_end: float):
    if engine == "analytic-approx":
        return analytic.simulate(params, "approx", "kinematic", t_end, dt_out=DT_OUT)
    if engine == "analytic-exact":
        return analytic.simulate(params, "exact", "kinematic", t_end, dt_out=DT_OUT)
    if engine == "analytic-unilateral":
        return analytic.simulate(params, "exact", "unilateral", t_end, dt_out=DT_OUT)
    from ..engine import simulate_mujoco

    if engine == "mujoco-lock":
        return simulate_mujoco(params, "kinematic", "lock", t_end, dt_out=DT_OUT)
    return simulate_mujoco(params, "unilateral", "ratchet", t_end, dt_out=DT_OUT)


def engine_metrics(engine: str, params: RobotParams, t_end: float) -> dict:
    """Metrics of one engine on one design, or {"error": message}."""
    try:
        run = _run_engine(engine, params, t_end)
    except (ValueError, RuntimeError) as exc:
        return {"error": f"{engine}: {exc}"}
    s = run.series
    useful = params.F_r1 * s["x1"][-1] + params.F_r2 * s["x2"][-1]
    return design_metrics(s, run.summary["energy"]["motor_work_j"], useful)


def _batch_metrics(outcome: dict) -> dict:
    if "error" in outcome:
        return {"error": f"mujoco-ratchet: {outcome['error']}"}
    return design_metrics(outcome["series"], outcome["motor_work_j"], outcome["friction_work_j"])


def run_design(values: dict, base: RobotParams, engines: tuple[str, ...], t_end: float) -> dict[str, dict]:
    """Every engine of ``engines`` on the design ``base`` with ``values``: {engine: metrics}."""
    try:
        params = base.replace(**values)
    except ValueError as exc:
        return {engine: {"error": f"invalid design: {exc}"} for engine in engines}
    return {engine: engine_metrics(engine, params, t_end) for engine in engines}


def _ignore_sigint() -> None:  # pool workers leave Ctrl-C to the main process
    signal.signal(signal.SIGINT, signal.SIG_IGN)


class _ResultsFile:
    """results.csv: header once, one flushed row per finished design."""

    def __init__(self, path: Path, header: list[str], resume: bool):
        self.path, self.header = path, header
        self.done: set[int] = set()
        if path.exists():
            if not resume:
                raise ParameterError(f"{str(path)!r} exists; use --resume to complete it, or another --out")
            with path.open(newline="") as fh:
                lines = fh.read().splitlines(keepends=True)
            complete = [ln for ln in lines if ln.endswith("\n")]  # a row cut by a crash is dropped
            rows = list(csv.reader(complete))
            if not rows or rows[0] != header:
                raise ParameterError(f"{str(path)!r} was written for other engines or parameters; "
                                     "resume needs the same study")
            self.done = {int(r[0]) for r in rows[1:] if r}
            path.write_text("".join(complete))
        else:
            with path.open("w", newline="") as fh:
                csv.writer(fh).writerow(header)
        self.handle = path.open("a", newline="")
        self.writer = csv.writer(self.handle)

    def write(self, row: dict) -> None:
        self.writer.writerow([_cell(row.get(column)) for column in self.header])
        self.handle.flush()
        os.fsync(self.handle.fileno())

    def close(self) -> None:
        self.handle.close()


def _cell(value) -> str:
    if value is None or (isinstance(value, float) and math.isnan(value)):
        return ""
    return f"{value:.10g}" if isinstance(value, float) else str(value)


def _row(design_id: int, values: dict, results: dict[str, dict], engines: tuple[str, ...]) -> dict:
    row = {"design_id": design_id, **values}
    errors = [r["error"] for r in results.values() if "error" in r]
    for engine in engines:
        for metric in METRICS:
            row[f"{engine}:{metric}"] = results[engine].get(metric)
    reference = results[engines[0]]
    for engine in engines[1:]:
        for metric in DIVERGENCE:
            a, b = reference.get(metric), results[engine].get(metric)
            row[f"divergence:{engine}:{metric}"] = (b - a) / abs(a) if a and b is not None else None
    row["error"] = " | ".join(errors)
    return row


def header_for(study: Study) -> list[str]:
    columns = ["design_id", *(a.name for a in study.axes)]
    columns += [f"{engine}:{metric}" for engine in study.engines for metric in METRICS]
    columns += [f"divergence:{engine}:{metric}" for engine in study.engines[1:] for metric in DIVERGENCE]
    return columns + ["error"]


class Progress:
    """Designs done, rate and time left, on stderr (a line per tenth when not a terminal)."""

    def __init__(self, total: int, already: int, enabled: bool = True):
        self.total, self.done, self.start, self.enabled = total, already, time.perf_counter(), enabled
        self.first = already
        self.tty = sys.stderr.isatty()
        self.next_line = already + max(1, total // 10)

    def advance(self, count: int = 1) -> None:
        self.done += count
        if not self.enabled:
            return
        elapsed = time.perf_counter() - self.start
        rate = (self.done - self.first) / elapsed if elapsed > 0 else 0.0
        left = (self.total - self.done) / rate if rate > 0 else float("inf")
        text = f"sweep {self.done}/{self.total} designs, {rate:.2f} designs/s, {left:.0f} s left"
        if self.tty:
            print("\r" + text, end="\n" if self.done >= self.total else "", file=sys.stderr, flush=True)
        elif self.done >= self.next_line or self.done >= self.total:
            print(text, file=sys.stderr, flush=True)
            self.next_line = self.done + max(1, self.total // 10)


def run_sweep(study: Study, out: str | Path, *, executor: futures.Executor | None = None,
              batch_mujoco: bool = True, resume: bool = False, workers: int | None = None,
              progress: bool = True, on_row: Callable[[dict], None] | None = None) -> Path:
    """Run ``study``, writing OUT/results.csv; return its path (see the module docstring)."""
    out = Path(out)
    if out.exists() and not out.is_dir():
        raise ParameterError(f"--out {str(out)!r} exists and is not a folder")
    out.mkdir(parents=True, exist_ok=True)
    meta = out / "sweep.json"
    record = {"fingerprint": study.fingerprint(), "study": study.to_json()}
    if resume and meta.exists() and json.loads(meta.read_text()).get("fingerprint") != record["fingerprint"]:
        raise ParameterError(f"{str(out)!r} holds another study (its sweep.json differs); resume needs the same one")
    designs = study.designs()
    results_file = _ResultsFile(out / "results.csv", header_for(study), resume)
    meta.write_text(json.dumps(record, indent=2) + "\n")
    todo = [i for i in range(len(designs)) if i not in results_file.done]
    bar = Progress(len(designs), len(designs) - len(todo), progress)
    engines = study.engines
    batched = ("mujoco-ratchet",) if batch_mujoco and executor is None and "mujoco-ratchet" in engines else ()
    pooled = tuple(e for e in engines if e not in batched)
    partial: dict[int, dict[str, dict]] = {i: {} for i in todo}

    def finish(i: int, results: dict[str, dict]) -> None:
        partial[i].update(results)
        if len(partial[i]) == len(engines):
            row = _row(i, designs[i], partial.pop(i), engines)
            results_file.write(row)
            if on_row is not None:
                on_row(row)
            bar.advance()

    own_pool = executor is None and bool(pooled)
    pool = futures.ProcessPoolExecutor(max_workers=workers or os.cpu_count(), initializer=_ignore_sigint) \
        if own_pool else executor
    pending: dict[futures.Future, int] = {}
    try:
        if pooled:
            for i in todo:
                pending[pool.submit(run_design, designs[i], study.base, pooled, study.t_end)] = i
        if batched:
            from ..engine.batch import run_ratchet_batch

            for start in range(0, len(todo), BATCH_SIZE):
                chunk = todo[start:start + BATCH_SIZE]
                params = []
                for i in chunk:
                    try:
                        params.append(study.base.replace(**designs[i]))
                    except ValueError:
                        params.append(None)
                valid = [p for p in params if p is not None]
                outcome = iter(run_ratchet_batch(valid, study.t_end, DT_OUT, nthread=workers or 0) if valid else [])
                for i, p in zip(chunk, params):
                    metrics = _batch_metrics(next(outcome)) if p is not None else {"error": "invalid design"}
                    finish(i, {"mujoco-ratchet": metrics})
                done_now, _ = futures.wait(list(pending), timeout=0)
                for future in done_now:
                    finish(pending.pop(future), future.result())
        for future in futures.as_completed(list(pending)):
            finish(pending.pop(future), future.result())
    except KeyboardInterrupt:
        for future in pending:
            future.cancel()
        raise SweepInterrupted(f"interrupted after {bar.done} of {len(designs)} designs; the rows so far are in "
                               f"{out / 'results.csv'}; run again with --resume to complete it") from None
    finally:
        if own_pool:
            pool.shutdown(wait=True, cancel_futures=True)
        results_file.close()
    return out / "results.csv"
