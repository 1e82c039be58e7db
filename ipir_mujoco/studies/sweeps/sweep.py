"""Run a what-if study: every design through every engine, results streamed to disk.

``run_sweep`` writes ``OUT/sweep.json`` (the study and its fingerprint) and
``OUT/results.csv`` (columns: :mod:`ipir_mujoco.studies.sweep_files`), one row
per design, appended and flushed as each design finishes, so a crash or Ctrl-C
keeps every finished design; ``resume=True`` skips the designs already in it
(and refuses a folder that holds another study, or no sweep at all). A design
or engine that fails records its error in the row and the sweep goes on; a
design that stalls is a result (``stalled`` = 1, the reason in ``notes``).
When every design is done the file is rewritten in design order, so two runs
of one study give byte-identical files.

Where work runs:

* default: every engine of a design, one after the other, as one task of a
  process pool (the serial MuJoCo engine steps and records in C, close to
  MuJoCo's own step cost: bench/ratchet_step.py measures it; so the analytic
  and MuJoCo work of the designs fills every core).
* with ``batch_size`` (``batch_mujoco=True``), or where the serial engine's
  compiled loop is not built (``registry.compiled_status``): MuJoCo's
  ratchet through ``mujoco.batch`` (``registry.run_batch``) in chunks of
  ``batch_size`` designs, each chunk in a process of its own on one thread,
  so rows stream as chunks finish; a design the batch does not model
  (``registry.batch_models``: compliant clutches, a drive it does not
  declare) runs in that process with the serial engine instead. The chunks
  and the pool (the other engines) run at once and share the cores: while
  both have work, the batch gets half of them (rounded up) and the pool the
  rest; whichever finishes first hands its cores to the other. Ctrl-C ends
  both pools' processes at once; the rows written are every design finished
  by then.
* ``executor=``: any ``concurrent.futures.Executor`` (a Dask ``Client``'s
  ``get_executor()`` for a cluster); every engine of a design runs as one task
  on it, MuJoCo serially.

Work budget: ``timeout_per_design`` [s] of wall time per design, passed to the
analytic engines as ``wall_budget_s`` and enforced in the pool's workers by an
alarm over all of a design's engines, MuJoCo's serial runs included (a design
past it is a recorded failure naming the budget; a design a batch chunk runs
serially is not timed); a worker that
stays stuck past twice the budget is abandoned and killed at the end. Batched
MuJoCo runs cost a fixed number of steps and are not timed. Pool workers die
with the main process (Linux: PR_SET_PDEATHSIG; elsewhere a watcher thread).

The tasks it hands its pools, one design's engines with their alarm (``run_design``) and a batch chunk
(``run_batch_chunk``), live in :mod:`.sweep_design`, re-exported here.
"""

from __future__ import annotations

import concurrent.futures as futures
import json
import os
import queue
import time
from collections import deque
from pathlib import Path
from typing import Callable

from ipir_mujoco import registry
from ipir_mujoco.core.errors import ParameterError, ParameterTypeError, StudyInterrupted
from ipir_mujoco.core.options import check_type
from ipir_mujoco.core.params import RobotParams, check_real, check_whole, refuse_idle_parameters

from ipir_mujoco.core.results import write_json

from ...output import check_output_dir, study_folder
from ..pool import end_pool, worker_init
from .sweep_design import (  # noqa: F401  (re-exported: every name stays importable from here)
    DesignTimeout, engine_metrics, run_batch_chunk, run_design, run_engine)
from .sweep_files import Progress, ResultsFile, _cell, header_for, make_row
from .sweep_space import Study

# MuJoCo designs stepped together: enough work per chunk that its process's start costs little, few enough
# that rows stream as chunks finish (bench/sweep_throughput.py measures a batch's designs per second)
BATCH_SIZE = 64


SweepInterrupted = StudyInterrupted  # the sweep's name for it (Ctrl-C: the rows written so far are kept)


class _Cores:
    """How the cores are shared between the batch processes and the pool while both have work.

    Each batch chunk runs in a process of its own on one thread: the batch's per-step Python work
    (the ratchet's bounds) then runs in parallel too, where threads of one batch would wait for it
    (bench/sweep_throughput.py times both ways).
    """

    def __init__(self, total: int, batch: bool, pool: bool):
        self.total = max(1, total)
        self.batch_active, self.pool_active = batch, pool

    def batch_slots(self) -> int:
        if not self.pool_active:
            return self.total
        return max(1, (self.total + 1) // 2)

    def pool_slots(self) -> int:
        if not self.batch_active:
            return self.total
        return max(1, self.total - self.batch_slots())




OUTPUT_FILES = ("results.csv", "sweep.json", "best.json")  # its declaration's (sweep_command), held equal by a test


def check_sweep_options(out: str | Path, resume: bool, workers, timeout_per_design, batch_size) -> Path:
    """The options of a sweep beside the study, checked before anything is created."""
    if workers is not None:
        check_whole("workers", workers, low=1, high=1024)
    if timeout_per_design is not None:
        check_real("timeout_per_design", timeout_per_design, high=1e6, unit="s")
    if batch_size is not None:
        check_whole("batch_size", batch_size, low=1, high=100_000)
    out = check_output_dir(out, files=OUTPUT_FILES)
    meta = out / "sweep.json"
    if resume and out.is_dir() and any(out.iterdir()) and not meta.is_file():
        raise ParameterError(f"--resume --out {str(out)!r}: the folder holds no sweep (no sweep.json); give the "
                             "folder of the sweep to complete")
    return out


def refuse_all_invalid(base: RobotParams, designs: list[dict]) -> None:
    """A study none of whose designs is a valid parameter set (``L=0.01,0.02`` with r = 0.05: L <= r) is
    refused before anything is written, naming the first design's fault (a parameter its drive does not use,
    ``M_stall`` varied under the constant torque, included: every engine would refuse it); one valid design is
    enough to run (the invalid ones are then recorded as failed rows)."""
    first = None
    for values in designs:
        try:
            refuse_idle_parameters(base.replace(**values))
            return
        except ValueError as exc:
            first = first or (values, exc)
    if first is not None:
        where = ", ".join(f"{k}={v:g}" for k, v in first[0].items())
        raise ParameterError(f"every one of the {len(designs)} designs is invalid; the first ({where}): "
                             f"{' '.join(str(first[1]).split())}")


def run_sweep(study: Study, out: str | Path, *, executor: futures.Executor | None = None,
              batch_mujoco: bool | None = None, resume: bool = False, workers: int | None = None,
              progress: bool = True, on_row: Callable[[dict], None] | None = None,
              timeout_per_design: float | None = None, batch_size: int | None = None) -> Path:
    """Run ``study``, writing OUT/results.csv; return its path (see the module docstring).

    ``batch_mujoco``: True steps the MuJoCo ratchet designs through ``mujoco.batch``, False one by one in
    the serial engine; None (default) the batch only when ``batch_size`` is given or the serial engine's
    compiled loop is not built."""
    check_type("study", study, Study, "a Study (ipir_mujoco.studies.sweep_space.Study)")
    check_type("out", out, (str, os.PathLike), "the path of the results folder")
    for name, flag in (("resume", resume), ("progress", progress)):
        check_type(name, flag, bool, "True or False")
    check_type("batch_mujoco", batch_mujoco, (bool, type(None)), "True, False or None")
    if on_row is not None and not callable(on_row):
        raise ParameterTypeError(f"on_row={on_row!r} is not callable; allowed: a function of a row, or None")
    out = check_sweep_options(out, resume, workers, timeout_per_design, batch_size)
    meta = out / "sweep.json"
    record = {"fingerprint": study.fingerprint(), "study": study.to_json()}
    if resume and meta.is_file():
        try:
            previous = json.loads(meta.read_text(encoding="utf-8")).get("fingerprint")
        except (ValueError, UnicodeDecodeError, AttributeError):
            previous = None
        if previous != record["fingerprint"]:
            raise ParameterError(f"{str(out)!r} holds another study (its sweep.json differs); resume needs the "
                                 "same one")
    designs = study.designs()
    refuse_all_invalid(study.base, designs)
    with study_folder(out):  # locked against a second run while this one writes
        results_file = _open_results(out, study, designs, resume)
        write_json(meta, record)
        _run_designs(study, designs, out, results_file, executor, batch_mujoco, workers, progress, on_row,
                     timeout_per_design, batch_size)
    return out / "results.csv"


def _open_results(out: Path, study: Study, designs: list[dict], resume: bool) -> ResultsFile:
    """OUT/results.csv, new or resumed; a resumed row must be this study's design of its id (else the file is
    another study's, or was edited: refused in one line before any design runs)."""
    header = header_for(study)
    numeric = {c for c in header if c not in ("design_id", "notes", "error")}
    results_file = ResultsFile(out / "results.csv", header, resume, numeric=numeric)
    for design_id, row in sorted(results_file.rows.items()):
        expected = designs[design_id] if design_id < len(designs) else None
        if expected is None or any(row[name] != _cell(float(value)) for name, value in expected.items()):
            found = ", ".join(f"{a.name}={row[a.name]}" for a in study.axes)
            raise ParameterError(f"{str(results_file.path)!r}: design_id {design_id} ({found}) is not this study's "
                                 f"design {design_id} (another study's file, or an edited one); resume needs the "
                                 "results.csv this sweep wrote: run again in another --out")
    return results_file


def _run_designs(study: Study, designs: list[dict], out: Path, results_file: ResultsFile, executor, batch_mujoco,
                 workers, progress: bool, on_row, timeout_per_design, batch_size) -> None:
    todo = [i for i in range(len(designs)) if i not in results_file.done]
    bar = Progress(len(designs), len(designs) - len(todo), progress)
    engines = study.engines
    if batch_mujoco is None:
        batch_mujoco = batch_size is not None or not registry.compiled_status()[0]
    batched = tuple(e for e in engines if registry.batched(e))[:1] if batch_mujoco and executor is None else ()
    pooled = tuple(e for e in engines if e not in batched)
    options = {"until_steady": study.until_steady, "wall_budget_s": timeout_per_design}
    partial: dict[int, dict[str, dict]] = {i: {} for i in todo}
    cores = _Cores(workers or os.cpu_count() or 1, bool(batched and todo), bool(pooled and todo))
    events: queue.Queue = queue.Queue()  # (kind, None, future) as futures finish: "pool" or "batch"

    def finish(i: int, results: dict[str, dict]) -> None:
        if i not in partial:  # a late answer for a design already written (abandoned, then done)
            return
        partial[i].update(results)
        if len(partial[i]) == len(engines):
            row = make_row(i, designs[i], partial.pop(i), engines, study.until_steady)
            results_file.write(row)
            if on_row is not None:
                on_row(row)
            bar.advance()

    own_pool = executor is None and bool(pooled) and bool(todo)
    pool = (futures.ProcessPoolExecutor(max_workers=cores.total, initializer=worker_init, initargs=(os.getpid(),))
            if own_pool else executor)
    chunks = deque([todo[k:k + (batch_size or BATCH_SIZE)] for k in range(0, len(todo), batch_size or BATCH_SIZE)]
                   if batched else [])
    batch_pool = (futures.ProcessPoolExecutor(max_workers=cores.total, initializer=worker_init,
                                              initargs=(os.getpid(),)) if chunks else None)
    waiting = deque(todo if pooled else [])
    running: dict[futures.Future, list] = {}  # pool future -> [design, first seen running (monotonic s) or None]
    batch_running: dict[futures.Future, list[int]] = {}  # batch future -> its chunk
    abandoned = False
    try:
        def submit_more() -> None:
            while chunks and len(batch_running) < cores.batch_slots():  # on the cores the pool leaves
                chunk = chunks.popleft()
                future = batch_pool.submit(run_batch_chunk, [designs[i] for i in chunk], study.base, study.t_end,
                                           study.dt_out, 1, study.until_steady, batched[0])
                batch_running[future] = chunk
                future.add_done_callback(lambda f: events.put(("batch", None, f)))
            # beside the batch no task is queued ahead (an idle worker would take it and overrun the cores the
            # batch holds); alone, one per worker is, so that no worker waits for the main process between designs
            slots = (cores.pool_slots() * (1 if cores.batch_active else 2)) if own_pool else len(waiting)
            while waiting and len(running) < slots:
                i = waiting.popleft()
                try:
                    future = pool.submit(run_design, designs[i], study.base, pooled, study.t_end, study.dt_out,
                                         options, own_pool)
                except futures.BrokenExecutor as exc:  # a worker was killed (out of memory?): no more pool work
                    for j in (i, *waiting):
                        finish(j, {e: {"error": f"{e}: the process pool broke: {exc}"} for e in pooled})
                    waiting.clear()
                    return
                running[future] = [i, None]
                future.add_done_callback(lambda f: events.put(("pool", None, f)))

        submit_more()
        while partial:
            try:
                kind, _, future = events.get(timeout=0.25)
            except queue.Empty:
                kind = None
            if kind == "batch" and future in batch_running:
                chunk = batch_running.pop(future)
                try:
                    outcomes = future.result()
                except Exception as exc:  # noqa: BLE001 (the batch's process died: recorded, the sweep goes on)
                    outcomes = [{batched[0]: {"error": f"{batched[0]}: the batch process failed: "
                                                       f"{type(exc).__name__}: {exc}"}}] * len(chunk)
                for i, result in zip(chunk, outcomes):
                    finish(i, result)
            elif kind == "pool" and future in running:
                i, _ = running.pop(future)
                try:
                    finish(i, future.result())
                except Exception as exc:  # noqa: BLE001 (a worker that died: recorded, the sweep goes on)
                    finish(i, {e: {"error": f"{e}: the worker failed: {type(exc).__name__}: {exc}"} for e in pooled})
            abandoned |= _abandon_stuck(running, timeout_per_design, pooled, finish)
            cores.batch_active = bool(chunks or batch_running)
            cores.pool_active = bool(waiting or running)
            submit_more()
    except KeyboardInterrupt:
        raise SweepInterrupted(f"interrupted after {bar.done} of {len(designs)} designs; the rows so far are in "
                               f"{out / 'results.csv'}; run again with --resume to complete it") from None
    finally:
        interrupted = bool(partial)
        for own, kill in ((pool if own_pool else None, interrupted or abandoned), (batch_pool, interrupted)):
            if own is not None:  # workers ignore Ctrl-C and may be deep in a long design: killed then
                end_pool(own, kill=kill)
        if executor is not None:
            for future in running:
                future.cancel()
        results_file.close()
    results_file.sort()


def _abandon_stuck(running: dict, budget: float | None, pooled, finish) -> bool:
    """Record as failed the designs whose worker stayed busy past twice the budget (+5 s); True if any."""
    if not budget:
        return False
    now, gave_up = time.monotonic(), False
    for future, slot in list(running.items()):
        if slot[1] is None:
            if future.running():
                slot[1] = now
        elif now - slot[1] > 2 * budget + 5.0:
            del running[future]
            finish(slot[0], {e: {"error": f"{e}: exceeded --timeout-per-design {budget:g} s of wall time "
                                          "(the worker did not stop; killed)"} for e in pooled})
            gave_up = True
    return gave_up
