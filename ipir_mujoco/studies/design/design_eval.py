"""Evaluate designs for the optimizer and the sensitivity study: on the sweep's pool, streamed, resumable.

:class:`Evaluator` runs one engine on designs given as {varied name: value} through
:func:`ipir_mujoco.studies.sweeps.sweep_design.run_design` (the sweep's own per-design task, its metrics
:data:`~ipir_mujoco.studies.sweep_metrics.METRICS`), on a process pool whose workers die with the
caller (:mod:`ipir_mujoco.studies.pool`), and appends one flushed row per design to
``evaluations.csv`` (:class:`~ipir_mujoco.studies.sweep_files.ResultsFile`, the sweep's streaming).

The varied parameters are written in full precision (``repr``), so that a resumed study's designs,
which a seeded optimizer proposes again in the same order, are found in the file exactly and never
re-run: resuming is replaying the study against the file.

An objective, constraint or sensitivity KEY is a metric or a parameter name (a parameter's value is the
design's: varied, or the base's).
"""

from __future__ import annotations

import math
import os
from concurrent import futures
from pathlib import Path

from ipir_mujoco.core.errors import ParameterError, ParameterTypeError, StudyInterrupted
from ipir_mujoco.core.params import PARAMETER_NAMES, RobotParams

from ..pool import end_pool, worker_init
from ..sweeps.sweep import run_design
from ..sweeps.sweep_files import Progress, ResultsFile, _cell
from ..sweeps.sweep_metrics import METRICS

# the parameters whose value is a word (drive, feedforward), not a number an objective can rank
WORDS = tuple(n for n in PARAMETER_NAMES if isinstance(getattr(RobotParams(), n), str))
KEYS = (*METRICS, *(n for n in PARAMETER_NAMES if n not in WORDS))


def check_key(key: str, option: str) -> str:
    """A metric or numeric parameter name, or a one-line ParameterError naming what is allowed."""
    if not isinstance(key, str):
        raise ParameterTypeError(f"{option}: key {key!r} is not a string; allowed: a metric or a parameter name")
    key = key.strip()
    if key in WORDS:
        raise ParameterError(f"{option}: {key!r} is not a number (it names a choice, e.g. "
                             f"{getattr(RobotParams(), key)!r}); allowed: a metric ({', '.join(METRICS)}) or a "
                             "numeric parameter")
    if key not in KEYS:
        raise ParameterError(f"{option}: unknown key {key!r}; allowed: a metric ({', '.join(METRICS)}) or a "
                             "parameter name ('ipir-mujoco params' lists them)")
    return key


def key_value(key: str, row: dict, base: RobotParams):
    """The value of KEY for an evaluated row: its metric, or the design's parameter."""
    if key in METRICS:
        return row.get(key)
    if key in row:
        return row[key]
    return getattr(base, key)


def _parse(raw: dict) -> dict:
    row = {k: _number(v) for k, v in raw.items()}
    row["notes"], row["error"], row["eval_id"] = raw["notes"], raw["error"], int(raw["eval_id"])
    return row


def _number(text: str):
    if text == "":
        return None
    try:
        return float(text)
    except ValueError:
        return text


class Evaluator:
    """One engine on designs, cached by their exact values, rows streamed to ``path``.

    ``names``: the varied parameters (columns after ``eval_id``); ``options``: the sweep's engine options
    (until_steady). ``label``: the study's name on the progress lines (stderr), ``total``: the designs it may ask
    for (0: no progress lines). ``workers``: processes (1: here, one by one). Use as a context manager: the pool is
    ended on leaving, at once if interrupted.
    """

    def __init__(self, path: Path, names: list[str], base: RobotParams, engine: str, t_end: float,
                 dt_out: float, options: dict, resume: bool, workers: int | None, progress: bool = True,
                 label: str = "optimize", total: int = 0, executor: futures.Executor | None = None,
                 axes=()):
        self.names, self.base, self.engine = list(names), base, engine
        self.t_end, self.dt_out, self.options = t_end, dt_out, options
        self.header = ["eval_id", *self.names, *METRICS, "notes", "error"]
        self.file = ResultsFile(path, self.header, resume, numeric={*self.names, *METRICS})
        self.cache: dict[tuple, dict] = {}
        self.by_id: dict[int, tuple] = {}  # the resumed file's designs by eval_id: a replay must ask them so
        for number, (eval_id, raw) in enumerate(sorted(self.file.rows.items()), start=2):
            key = tuple(raw[n] for n in self.names)
            _check_resumed(path, eval_id, key, raw, self.names, axes, total, self.by_id, self.cache)
            self.cache[key] = _parse(raw)
            self.by_id[eval_id] = key
        self.asked = 0  # distinct designs asked for so far: the next one's eval_id (the same on every run)
        self.seen: set[tuple] = set()
        self.resumed = set(self.cache)  # designs of the file resumed, not yet asked for again
        self.reused = 0  # of those, how many the study asked for (and were not re-run)
        self.workers = workers or os.cpu_count() or 1
        self.pool = executor  # a Dask client's executor (--scheduler), else our own pool when first needed
        self.own_pool = executor is None
        self.bar = Progress(total, 0, progress, what=label) if total else None

    def __enter__(self):
        return self

    def __exit__(self, kind, exc, tb):
        interrupted = kind is not None
        if self.pool is not None and self.own_pool:  # a caller's executor is the caller's to end
            end_pool(self.pool, kill=interrupted)
        self.file.close()
        if not interrupted:
            self.file.sort()  # in eval_id order: two runs of one study give the same bytes
        if kind is KeyboardInterrupt:
            raise StudyInterrupted(f"interrupted; the {len(self.cache)} evaluations so far are in "
                                   f"{self.file.path}; run again with --resume to complete it") from None
        return False

    def key(self, design: dict) -> tuple:
        return tuple(repr(float(design[n])) for n in self.names)

    def evaluate(self, designs: list[dict]) -> list[dict]:
        """Rows ({eval_id, parameters, metrics, notes, error}) of ``designs`` in their order; designs already
        evaluated (this run or the file resumed) are not run again."""
        keys = [self.key(d) for d in designs]
        todo = {}
        ids = {}
        for k, d in zip(keys, designs):
            if k not in self.seen:
                self.seen.add(k)
                ids[k] = self.asked
                self._check_replay(k, self.asked)
                self.asked += 1
            if k in self.resumed:
                self.resumed.discard(k)
                self.reused += 1
            if k in self.cache:
                continue
            if k not in todo:  # ids in the order asked, not finished: a study's ids are the same every run
                todo[k] = {n: float(v) for n, v in zip(self.names, k)}
        if todo:
            if self.own_pool and (self.workers <= 1 or len(todo) == 1):
                for k, d in todo.items():
                    self._record(k, ids[k], d, self._task(d))
            else:
                if self.pool is None:
                    self.pool = futures.ProcessPoolExecutor(max_workers=self.workers, initializer=worker_init,
                                                            initargs=(os.getpid(),))
                pending = {self.pool.submit(run_design, d, self.base, (self.engine,), self.t_end, self.dt_out,
                                            self.options, True): k for k, d in todo.items()}
                for future in futures.as_completed(pending):
                    k = pending[future]
                    self._record(k, ids[k], todo[k], future.result())
        return [self.cache[k] for k in keys]

    def _check_replay(self, key: tuple, eval_id: int) -> None:
        """A resumed study asks its designs in the order it first did: the file's row ``eval_id`` is this
        design, and this design is no other row (else the file is another study's, or was edited)."""
        held = self.by_id.get(eval_id)
        found = self.cache.get(key)
        if (held is not None and held != key) or (found is not None and found["eval_id"] != eval_id):
            where = ", ".join(f"{n}={v}" for n, v in zip(self.names, key))
            raise ParameterError(f"{str(self.file.path)!r} does not belong to this study: its evaluation "
                                 f"{eval_id if held != key else found['eval_id']} is not the design this study "
                                 f"asks for as evaluation {eval_id} ({where}); it is another study's, or was "
                                 "edited: run again in another --out, or without --resume in an empty one")

    def _task(self, design: dict) -> dict:
        return run_design(design, self.base, (self.engine,), self.t_end, self.dt_out, self.options)

    def _record(self, key: tuple, eval_id: int, design: dict, results: dict) -> None:
        metrics = results[self.engine]
        row = {"eval_id": eval_id, **design, **{m: metrics.get(m) for m in METRICS},
               "notes": metrics.get("note", ""), "error": metrics.get("error", "")}
        row.update(zip(self.names, key))  # full precision: a resumed study finds its designs exactly
        self.file.write(row)
        # kept as the file holds it (metrics to 10 digits), so that a resumed study decides as the first run did
        self.cache[key] = _parse({c: _cell(row.get(c)) for c in self.header})
        if self.bar is not None:
            self.bar.advance()


def _check_resumed(path: Path, eval_id: int, key: tuple, raw: dict, names: list[str], axes, total: int,
                   by_id: dict, cache: dict) -> None:
    """One row of a resumed evaluations.csv: an eval_id the study can ask for (< ``total``), a design inside the
    ``axes``' bounds, given once (a one-line ParameterError naming the file and what is wrong)."""
    fault = None
    if total and eval_id >= total:
        fault = f"eval_id {eval_id} is past the study's {total} designs"
    elif key in cache:
        fault = f"eval_id {eval_id} repeats the design of eval_id {cache[key]['eval_id']}"
    else:
        for name, axis in zip(names, axes):
            value = _number(raw[name])
            if axis.low is None:
                continue
            slack = 1e-12 * max(abs(axis.low), abs(axis.high))  # a log axis's exp(log(hi)) may round past hi
            if not isinstance(value, float) or not axis.low - slack <= value <= axis.high + slack:
                fault = f"eval_id {eval_id} has {name}={raw[name]!r}, outside the study's {axis.low:g}..{axis.high:g}"
                break
    if fault:
        raise ParameterError(f"{str(path)!r}: {fault} (another study's file, or an edited one); resume needs the "
                             "evaluations.csv this study wrote: run again in another --out")


def usable(value) -> bool:
    return isinstance(value, (int, float)) and math.isfinite(value)


def verify_rows(rows: list[dict], names: list[str], base: RobotParams, reference: str, engine: str,
                keys: list[str], t_end: float, dt_out: float, options: dict, workers: int | None,
                executor: futures.Executor | None = None) -> list[dict]:
    """Each row re-run in ``engine``: columns ``ENGINE:KEY`` and ``divergence:KEY``, (engine - reference) /
    |reference|, for every metric of ``keys``; ``verify_error`` why a run gave nothing. Runs on the pool."""
    from ..pool import map_unordered

    results: dict[int, dict] = {}
    designs = [{n: row[n] for n in names} for row in rows]
    task = _VerifyTask(base, engine, t_end, dt_out, options)
    if executor is not None:
        for k, r in enumerate(executor.map(task, list(enumerate(designs)))):
            results[k] = r
    else:
        map_unordered(task, list(enumerate(designs)), min(workers or os.cpu_count() or 1, max(1, len(designs))),
                      lambda item, r: results.__setitem__(item[0], r))
    out = []
    for k, row in enumerate(rows):
        metrics = results[k].get(engine, {})
        extra = {"verify_error": metrics.get("error", "")}
        for key in keys:
            if key not in METRICS:
                continue
            a, b = row.get(key), metrics.get(key)
            extra[f"{engine}:{key}"] = b
            extra[f"divergence:{key}"] = (b - a) / abs(a) if usable(a) and usable(b) and a != 0 else None
        out.append({**row, **extra})
    return out


class _VerifyTask:
    """A picklable task: one (index, design) in the verifying engine."""

    def __init__(self, base, engine, t_end, dt_out, options):
        self.base, self.engine, self.t_end, self.dt_out, self.options = base, engine, t_end, dt_out, options

    def __call__(self, item: tuple[int, dict]) -> dict:
        return run_design(item[1], self.base, (self.engine,), self.t_end, self.dt_out, self.options, True)
