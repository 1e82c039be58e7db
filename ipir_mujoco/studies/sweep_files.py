"""A sweep's files and rows: results.csv streamed row by row, its header, progress on stderr.

Row columns: ``design_id``, the varied parameters, then ``ENGINE:METRIC`` for every engine and
metric (:mod:`ipir_mujoco.studies.sweep_metrics`), then ``divergence:ENGINE:METRIC``,
(ENGINE - first engine) / |first engine| for the metrics in :data:`DIVERGENCE`, then ``notes``
(stall reasons: a stalled design is a result) and ``error`` (why an engine gave no result).

A run that stopped at its steady state ends where its engine's detection fired, which two engines that
agree on the steady speed may do a revolution apart, so that their revolutions differ by a whole turn
out of the few the run made: the divergence of revolutions is left empty where either run stopped so;
the steady speed and energy per metre compare those runs.
"""

from __future__ import annotations

import csv
import math
import os
import time
from pathlib import Path

from ipir_mujoco.core.errors import ParameterError

from .. import terminal

from .sweep_metrics import METRICS
from .sweep_space import Study

# the legacy spellings (sweep_metrics.LEGACY) last, for scripts written against them
DIVERGENCE = ("revolutions", "mean_speed_m_s", "steady_speed_m_s", "energy_per_metre_j_m", "accel_jump_m_s2",
              "mean_speed_mps", "accel_jump_mps2")


def header_for(study: Study) -> list[str]:
    columns = ["design_id", *(a.name for a in study.axes)]
    columns += [f"{engine}:{metric}" for engine in study.engines for metric in METRICS]
    columns += [f"divergence:{engine}:{metric}" for engine in study.engines[1:] for metric in DIVERGENCE]
    return columns + ["notes", "error"]


def make_row(design_id: int, values: dict, results: dict[str, dict], engines: tuple[str, ...],
             until_steady: bool = False) -> dict:
    """One row of results.csv from {engine: metrics or {"error": ...}} (metrics may carry a "note");
    ``until_steady``: the runs stopped at their steady state where they reached it."""
    row = {"design_id": design_id, **values}
    for engine in engines:
        for metric in METRICS:
            row[f"{engine}:{metric}"] = results[engine].get(metric)
    reference = results[engines[0]]
    for engine in engines[1:]:
        # runs stopped at their steady state: their revolutions count when each detection fired (docstring)
        stopped = until_steady and (reference.get("steady") == 1 or results[engine].get("steady") == 1)
        for metric in DIVERGENCE:
            a, b = reference.get(metric), results[engine].get(metric)
            usable = a is not None and b is not None and math.isfinite(a) and math.isfinite(b) and a != 0
            usable = usable and not (metric == "revolutions" and stopped)
            row[f"divergence:{engine}:{metric}"] = (b - a) / abs(a) if usable else None
    row["notes"] = " | ".join(f"{e}: {results[e]['note']}" for e in engines if results[e].get("note"))
    row["error"] = " | ".join(results[e]["error"] for e in engines if "error" in results[e])
    return row


def _cell(value) -> str:
    if value is None or (isinstance(value, float) and math.isnan(value)):
        return ""
    return f"{value:.10g}" if isinstance(value, float) else " ".join(str(value).split())


def _read_complete_lines(path: Path) -> list[str]:
    """The lines of results.csv that end in a newline (a row cut by a crash is dropped); bytes that are not
    UTF-8 are refused in one line naming the file and the line."""
    data = path.read_bytes()
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError as exc:
        line = data[:exc.start].count(b"\n") + 1
        raise ParameterError(f"{str(path)!r} line {line} is not UTF-8 text (a corrupted file?); resume needs the "
                             f"{path.name} this study wrote: remove the line, or run again in another --out")
    return [ln for ln in text.splitlines(keepends=True) if ln.endswith("\n")]


def _parse_rows(path: Path, lines: list[str]) -> list[list[str]]:
    """The CSV rows of ``lines``, one per line (sweeps write no cell with a line break in it)."""
    rows = []
    for number, line in enumerate(lines, start=1):
        try:
            rows.extend(csv.reader([line]))
        except csv.Error as exc:
            raise ParameterError(f"{str(path)!r} line {number} is not a CSV row ({exc}); resume needs the "
                                 f"{path.name} this study wrote: remove the line, or run again in another "
                                 "--out") from None
    return rows


def _done_designs(path: Path, rows: list[list[str]], width: int) -> set[int]:
    """The design ids of the data rows, after checking that each has the header's ``width`` cells and a
    whole-number id (a garbage line is refused in one line naming the file and the line)."""
    done = set()
    for number, row in enumerate(rows[1:], start=2):
        if not row:
            continue
        if len(row) != width or not row[0].isdigit():
            what = (f"has {len(row)} cells; the header has {width}" if len(row) != width
                    else f"{rows[0][0]} {row[0][:20]!r} is not a whole number")
            raise ParameterError(f"{str(path)!r} line {number} {what} (a corrupted row?); resume needs the "
                                 f"{path.name} this study wrote: remove the line, or run again in another --out")
        if int(row[0]) in done:
            raise ParameterError(f"{str(path)!r} line {number} repeats {rows[0][0]} {row[0]} (a duplicated row?); "
                                 f"resume needs the {path.name} this study wrote: remove the line, or run again in "
                                 "another --out")
        done.add(int(row[0]))
    return done


def check_cells(path: Path, rows: list[list[str]], numeric: set[str]) -> None:
    """Every cell of the ``numeric`` columns of the data rows ``rows[1:]`` is a number or empty (a text where a
    metric goes is a one-line ParameterError naming the file, the line and the cell)."""
    columns = [k for k, name in enumerate(rows[0]) if name in numeric]
    for number, row in enumerate(rows[1:], start=2):
        for k in columns if row else ():
            if row[k] == "":
                continue
            try:
                float(row[k])
            except ValueError:
                raise ParameterError(f"{str(path)!r} line {number}: {rows[0][k]}={row[k][:40]!r} is not a number "
                                     f"(an edited row?); resume needs the {path.name} this study wrote: remove "
                                     "the line, or run again in another --out") from None


class ResultsFile:
    """results.csv: header once, one flushed row per finished design; sorted by design_id when complete.

    Resumed, the file is checked before anything runs: its header is ``header``, every row has its cells, a
    whole-number id (its first column) found once, and a number or nothing in each column of ``numeric``;
    :attr:`rows` holds the data rows read ({id: {column: text}})."""

    def __init__(self, path: Path, header: list[str], resume: bool, numeric: set[str] = frozenset()):
        self.path, self.header = path, header
        self.done: set[int] = set()
        self.rows: dict[int, dict[str, str]] = {}
        if path.exists():
            if not resume:
                raise ParameterError(f"{str(path)!r} exists; use --resume to complete it, or another --out")
            complete = _read_complete_lines(path)
            rows = _parse_rows(path, complete)
            if not rows:
                raise ParameterError(f"{str(path)!r} is empty, not even its header (a damaged file?); resume needs "
                                     f"the {path.name} this study wrote: remove it, or run again in another --out")
            if rows[0] != header:
                raise ParameterError(f"{str(path)!r}'s header is not this study's (written for other engines, "
                                     f"metrics or parameters, or damaged); resume needs the {path.name} this study "
                                     "wrote, of the same version: run again in another --out")
            self.done = _done_designs(path, rows, len(header))
            check_cells(path, rows, set(numeric))
            self.rows = {int(r[0]): dict(zip(header, r)) for r in rows[1:] if r}
            path.write_text("".join(complete), encoding="utf-8")
        else:
            with path.open("w", newline="", encoding="utf-8") as fh:
                csv.writer(fh).writerow(header)
        self.handle = path.open("a", newline="", encoding="utf-8")
        self.writer = csv.writer(self.handle)

    def write(self, row: dict) -> None:
        self.writer.writerow([_cell(row.get(column)) for column in self.header])
        self.handle.flush()
        os.fsync(self.handle.fileno())

    def close(self) -> None:
        self.handle.close()

    def sort(self) -> None:
        """Rewrite the file in design order (atomically): two runs of one study give the same bytes."""
        with self.path.open(newline="", encoding="utf-8") as fh:
            rows = list(csv.reader(fh))
        staged = self.path.with_name(f".{self.path.name}.sorting")
        with staged.open("w", newline="", encoding="utf-8") as fh:
            writer = csv.writer(fh)
            writer.writerow(rows[0])
            writer.writerows(sorted(rows[1:], key=lambda r: int(r[0])))
        staged.replace(self.path)


class Progress:
    """Designs done, rate and time left, on stderr: on a terminal the status line, rewritten as each design
    ends and every second while one runs; in a log a line per tenth of the designs and, while designs run, at
    least every 5 s (:mod:`ipir_mujoco.terminal`; the ticker speaks only within a command of the command line)."""

    def __init__(self, total: int, already: int, enabled: bool = True, what: str = "sweep"):
        self.total, self.done, self.start, self.enabled = total, already, time.perf_counter(), enabled
        self.what = what  # the study's name, heading each line
        self.first = already
        self.next_line = already + max(1, total // 10)
        if enabled:
            terminal.ticker(self, Progress.text)

    @property
    def finished(self) -> bool:
        return self.done >= self.total

    def text(self) -> str:
        elapsed = time.perf_counter() - self.start
        rate = (self.done - self.first) / elapsed if elapsed > 0 else 0.0
        left = f"{(self.total - self.done) / rate:.0f} s left" if rate > 0 else f"{elapsed:.0f} s so far"
        return f"{self.what} {self.done}/{self.total} designs, {rate:.2f} designs/s, {left}"

    def advance(self, count: int = 1) -> None:
        self.done += count
        if not self.enabled:
            return
        text = self.text()
        if self.done >= self.total:
            terminal.say(text)
        elif self.done >= self.next_line and not terminal.on_terminal():  # a log: a line per tenth
            self.next_line = self.done + max(1, self.total // 10)
            terminal.say(text)
        else:
            terminal.say(text, status=True)