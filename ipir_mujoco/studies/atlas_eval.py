"""The atlas's evaluations: pairs of runs on designs, on a process pool, streamed to samples.csv, resumable.

``samples.csv`` columns: ``sample_id``, ``idealization``, ``fidelity`` (``equations`` or ``mujoco``), the
varied parameters (full precision), then for every metric ``idealized:METRIC``, ``real:METRIC`` (the two
runs' values) and ``cost:METRIC`` ((idealized - real) / |real|) and ``cost_error:METRIC`` (its error bar, where a run's figure has
one: MuJoCo's rigid limit on finite grip), then ``notes`` (stalls) and ``error`` (why a pair gave nothing). One flushed row per evaluated pair (:class:`~.sweep_files.ResultsFile`, the sweep's
streaming), so Ctrl-C or a crash keeps every finished pair; resumed, the study asks for the same designs in
the same order (its samples are seeded, its adaptive choices are made on the values as the file holds them)
and finds them in the file instead of running them again. Sorted by sample_id at the end.
"""

from __future__ import annotations

import concurrent.futures as futures
import csv
import os
from pathlib import Path

from ipir_mujoco.core.errors import StudyInterrupted
from ipir_mujoco.core.params import RobotParams

from .atlas_space import IDEALIZATIONS, measure
from .pool import end_pool, worker_init
from .sweep_files import Progress, ResultsFile, _cell

CHUNK = 8  # analytic pairs per pool task: a pair costs tens of ms, a task's round trip about one


def header(names: list[str], metrics: tuple[str, ...]) -> list[str]:
    columns = ["sample_id", "idealization", "fidelity", *names]
    for m in metrics:
        columns += [f"idealized:{m}", f"real:{m}", f"cost:{m}", f"cost_error:{m}"]
    return columns + ["notes", "error"]


def _measure_many(base: RobotParams, name: str, fidelity: str, designs: list[dict], metrics, t_end, until_steady):
    """A pool task: the pair of ``name`` at ``fidelity`` on each design ({varied name: value})."""
    from ipir_mujoco import registry

    pair = IDEALIZATIONS[name].pair(fidelity)
    registry.prepare_for_many((pair.real.variant,))
    out = []
    for design in designs:
        try:
            params = base.replace(**design)
        except ValueError as exc:
            out.append({"idealized": {}, "real": {}, "cost": {}, "cost_error": {}, "note": "",
                        "error": f"invalid design: {exc}"})
            continue
        out.append(measure(pair, params, metrics, t_end, until_steady))
    return out


def _number(text: str):
    return None if text == "" else float(text)


class Samples:
    """Every pair evaluated, cached by (idealization, fidelity, exact design), rows streamed to ``path``.

    ``evaluate(name, fidelity, designs)`` returns, per design, {"cost": {metric: value or None}, "error",
    "note", "sample_id"}, as the file holds them (10 significant digits), so a resumed study decides as the
    first run did. Use as a context manager (the pool ends on leaving; at once if interrupted).
    """

    def __init__(self, path: Path, names: list[str], metrics: tuple[str, ...], base: RobotParams, t_end: float,
                 until_steady: bool, resume: bool, workers: int, progress: bool = True):
        self.names, self.metrics, self.base = list(names), tuple(metrics), base
        self.t_end, self.until_steady, self.workers = t_end, until_steady, max(1, workers)
        self.header = header(self.names, self.metrics)
        self.file = ResultsFile(path, self.header, resume)
        self.cache: dict[tuple, dict] = {}
        with path.open(newline="", encoding="utf-8") as fh:
            for raw in csv.DictReader(fh):
                self.cache[(raw["idealization"], raw["fidelity"], *(raw[n] for n in self.names))] = self._parse(raw)
        self.asked = 0
        self.ids: dict[tuple, int] = {}
        self.runs = {"equations": 0, "mujoco": 0}  # runs of this invocation (2 per pair), resumed ones not counted
        self.pool: futures.ProcessPoolExecutor | None = None
        self.progress = progress

    def __enter__(self):
        return self

    def __exit__(self, kind, exc, tb):
        if self.pool is not None:
            end_pool(self.pool, kill=kind is not None)
        self.file.close()
        if kind is None:
            self.file.sort()
        if kind is KeyboardInterrupt:
            raise StudyInterrupted(f"interrupted; the {len(self.cache)} pairs so far are in {self.file.path}; run "
                                   "again with --resume to complete it") from None
        return False

    def count(self, name: str, fidelity: str) -> int:
        """Distinct pairs of ``name`` at ``fidelity`` asked for so far (resumed or run)."""
        return sum(1 for key in self.ids if key[:2] == (name, fidelity))

    def _parse(self, raw: dict) -> dict:
        return {"sample_id": int(raw["sample_id"]), "cost": {m: _number(raw[f"cost:{m}"]) for m in self.metrics},
                "cost_error": {m: _number(raw[f"cost_error:{m}"]) for m in self.metrics},
                "note": raw["notes"], "error": raw["error"]}

    def evaluate(self, name: str, fidelity: str, designs: list[dict], label: str = "") -> list[dict]:
        """Rows of the pair of ``name`` at ``fidelity`` on ``designs``, in their order (pairs already evaluated,
        this run or resumed, are not run again)."""
        return self.evaluate_many([(name, fidelity, designs)], label)[0]

    def evaluate_many(self, requests: list[tuple[str, str, list[dict]]], label: str = "") -> list[list[dict]]:
        """:meth:`evaluate` of several (name, fidelity, designs) at once, all on the pool together (so that one
        idealization's slow runs do not leave cores idle while the others wait for their turn)."""
        asked, todo = [], {}
        for name, fidelity, designs in requests:
            keys = [(name, fidelity, *(repr(float(d[n])) for n in self.names)) for d in designs]
            asked.append(keys)
            for key in keys:
                if key not in self.ids:
                    self.ids[key] = self.asked
                    self.asked += 1
                if key not in self.cache and key not in todo:
                    todo[key] = {n: float(v) for n, v in zip(self.names, key[2:])}
        if todo:
            what = label or ", ".join(dict.fromkeys(f"{n} ({f})" for n, f, _d in requests))
            # a bar for batches worth waiting for (MuJoCo's adaptive batches of a few designs have their own lines)
            bar = Progress(len(todo), 0, self.progress and len(todo) >= 8, what=f"atlas {what}")
            groups = []
            for (name, fidelity) in dict.fromkeys(k[:2] for k in todo):
                items = [(k, d) for k, d in todo.items() if k[:2] == (name, fidelity)]
                chunk = CHUNK if fidelity == "equations" else 1
                groups += [(name, fidelity, items[k:k + chunk]) for k in range(0, len(items), chunk)]
            if self.workers <= 1 or len(groups) == 1:
                for name, fidelity, group in groups:
                    self._record(name, fidelity, group, _measure_many(self.base, name, fidelity, [d for _, d in group],
                                                                      self.metrics, self.t_end, self.until_steady))
                    bar.advance(len(group))
            else:
                if self.pool is None:
                    self.pool = futures.ProcessPoolExecutor(max_workers=self.workers, initializer=worker_init,
                                                            initargs=(os.getpid(),))
                pending = {self.pool.submit(_measure_many, self.base, name, fidelity, [d for _, d in group],
                                            self.metrics, self.t_end, self.until_steady): (name, fidelity, group)
                           for name, fidelity, group in groups}
                for future in futures.as_completed(pending):
                    name, fidelity, group = pending[future]
                    self._record(name, fidelity, group, future.result())
                    bar.advance(len(group))
        return [[self.cache[k] for k in keys] for keys in asked]

    def _record(self, name: str, fidelity: str, group: list, results: list[dict]) -> None:
        for (key, design), result in zip(group, results):
            row = {"sample_id": self.ids[key], "idealization": name, "fidelity": fidelity, **design,
                   "notes": result["note"], "error": result["error"]}
            for m in self.metrics:
                row[f"idealized:{m}"] = result["idealized"].get(m)
                row[f"real:{m}"] = result["real"].get(m)
                row[f"cost:{m}"] = result["cost"].get(m)
                row[f"cost_error:{m}"] = result["cost_error"].get(m)
            cells = {c: _cell(row.get(c)) for c in self.header}
            cells.update(zip(self.names, key[2:]))  # full precision: a resumed study finds its designs exactly
            self.file.writer.writerow([cells[c] for c in self.header])
            self.file.handle.flush()
            self.cache[key] = self._parse(cells)
            self.runs[fidelity] += 2
        os.fsync(self.file.handle.fileno())
