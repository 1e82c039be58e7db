"""A measured run: a CSV of ``t`` and any of the model's columns, as a real robot's sensors give them.

Columns (header row; any order; other columns are ignored and named in :attr:`Measured.ignored`):

=======  =====  ================================================================
column   unit   meaning (as ``simulate --out`` writes them)
=======  =====  ================================================================
t        s      time since the run's start (>= 0, never decreasing; irregular
                spacing is fine)
x1, x2   m      module 1 (rear) / 2 (front) displacement since the run's start
phi      rad    crank angle (0 = full extension; the run starts at phi0)
omega    rad/s  crank speed
v1, v2   m/s    module velocities
=======  =====  ================================================================

At least one of the model's columns and two rows are needed; a cell that is empty or not a number is bad input
(one line naming the line and column).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ipir_mujoco.core.errors import ParameterError
from ipir_mujoco.core.files import read_text_file

MEASURED_COLUMNS = ("x1", "x2", "phi", "omega", "v1", "v2")
UNITS = {"t": "s", "x1": "m", "x2": "m", "phi": "rad", "omega": "rad/s", "v1": "m/s", "v2": "m/s"}
MAX_ROWS = 1_000_000


@dataclass
class Measured:
    """The measured columns (``t`` and those of :data:`MEASURED_COLUMNS` present), each shape (n,)."""

    path: str
    t: np.ndarray
    columns: dict[str, np.ndarray]
    ignored: list[str] = field(default_factory=list)


def is_measured_csv(path: str | Path) -> bool:
    """Whether ``path`` is a file (a measured CSV) rather than a run folder."""
    return Path(path).is_file()


def read_measured(path: str | Path) -> Measured:
    """Read and check a measured CSV (module docstring); every fault a one-line ParameterError."""
    where = f"measured run {str(path)!r}"
    lines = [ln for ln in read_text_file(path, "measured run").splitlines() if ln.strip() and not ln.startswith("#")]
    if not lines:
        raise ParameterError(f"{where} is empty; allowed: a CSV with a header row t,x1,... (docs/uncertainty.md)")
    names = [n.strip() for n in lines[0].split(",")]
    if "t" not in names:
        raise ParameterError(f"{where} has no column 't' in its header row ({', '.join(names)[:200]}); allowed: t "
                             f"[s] and any of {' '.join(MEASURED_COLUMNS)}")
    if len(set(names)) != len(names):
        raise ParameterError(f"{where} names a column twice in its header row")
    present = [c for c in MEASURED_COLUMNS if c in names]
    if not present:
        raise ParameterError(f"{where} has none of the columns {' '.join(MEASURED_COLUMNS)} beside t; allowed: any "
                             "of them (units: docs/uncertainty.md)")
    rows = lines[1:]
    if len(rows) < 2:
        raise ParameterError(f"{where} has {len(rows)} data row(s); allowed: at least 2")
    if len(rows) > MAX_ROWS:
        raise ParameterError(f"{where} has {len(rows)} rows; allowed: at most {MAX_ROWS}")
    wanted = {c: names.index(c) for c in ("t", *present)}
    table = np.empty((len(rows), len(wanted)))
    for i, line in enumerate(rows):
        cells = line.split(",")
        if len(cells) != len(names):
            raise ParameterError(f"{where} line {i + 2} has {len(cells)} cells; the header has {len(names)}")
        for k, (column, j) in enumerate(wanted.items()):
            try:
                value = float(cells[j])
            except ValueError:
                raise ParameterError(f"{where} line {i + 2}: {column}={cells[j].strip()[:40]!r} is not a number"
                                     ) from None
            if not math.isfinite(value):
                raise ParameterError(f"{where} line {i + 2}: {column}={cells[j].strip()!r} is not a finite number")
            table[i, k] = value
    t = table[:, 0]
    if t[0] < 0 or np.any(np.diff(t) < 0) or not t[-1] > t[0]:
        raise ParameterError(f"{where}: the times t must start at 0 or later and never decrease from row to row")
    columns = {c: table[:, k + 1] for k, c in enumerate(present)}
    return Measured(str(path), t, columns, [n for n in names if n not in wanted])


def compare_measured(measured: Measured, run, tolerance: float = 0.01, measured_is_a: bool = True) -> dict:
    """A measured run against a simulated one (a :class:`~ipir_mujoco.core.results.RunResult`) on the columns
    both have, at the measured times up to the shorter one's end (the run interpolated linearly onto them):
    per column the RMS and largest |b - a|, the scale (largest |measured|, at least the stroke 2r for x1 x2,
    a turn for phi, r x the largest crank speed for v1 v2, the largest crank speed for omega), and the first
    time |b - a| exceeds ``tolerance`` x scale. ``measured_is_a``: which side the measurement is (the
    differences are b - a)."""
    if not (math.isfinite(tolerance) and tolerance > 0):
        raise ParameterError(f"tolerance={tolerance} is out of range; allowed: > 0")
    s = run.series
    t_run = np.asarray(s["t"], dtype=float)
    keep = np.concatenate([[True], np.diff(t_run) > 0])
    within = measured.t <= t_run[-1] + 1e-12
    if within.sum() < 2:
        raise ParameterError(f"the run ends at {t_run[-1]:.6g} s, before the measured run's second sample "
                             f"({measured.t[1]:.6g} s); allowed: a run at least as long as the measurement")
    t = measured.t[within]
    crank = float(np.max(np.abs(s["omega"]))) if len(s["omega"]) else 0.0
    r = run.params.r
    floors = {"x1": 2 * r, "x2": 2 * r, "phi": 2 * math.pi, "v1": r * crank, "v2": r * crank, "omega": crank}
    columns = {}
    for c, values in measured.columns.items():
        model = np.interp(t, t_run[keep], np.asarray(s[c], dtype=float)[keep])
        meas = values[within]
        a, b = (meas, model) if measured_is_a else (model, meas)
        diff = b - a
        scale = max(float(np.max(np.abs(meas))), floors[c])
        over = np.flatnonzero(np.abs(diff) > tolerance * scale)
        columns[c] = {"rms": float(np.sqrt(np.mean(diff ** 2))), "max": float(np.max(np.abs(diff))),
                      "mean": float(np.mean(diff)), "scale": scale,
                      "first_exceedance": float(t[over[0]]) if over.size else None}
    label = f"measured {measured.path}"
    other = f"{run.engine}/{run.geometry}/{run.clutch}"
    return {"a": label if measured_is_a else other, "b": other if measured_is_a else label,
            "measured": True, "columns": columns, "points": int(within.sum()), "t_compared_s": float(t[-1]),
            "ignored_columns": measured.ignored, "tolerance": tolerance}


def format_measured_comparison(result: dict) -> str:
    """:func:`compare_measured`'s result as a table (units per column)."""
    lines = [f"b = {result['b']} against a = {result['a']}: {result['points']} measured times up to "
             f"{result['t_compared_s']:.4g} s, the run interpolated onto them", ""]
    rows = [("column", "unit", "RMS b - a", "mean b - a", "largest |b - a|", "scale", "first over [s]")]
    for c, v in result["columns"].items():
        first = v["first_exceedance"]
        rows.append((c, UNITS[c], f"{v['rms']:.4g}", f"{v['mean']:+.4g}", f"{v['max']:.4g}", f"{v['scale']:.4g}",
                     "never" if first is None else f"{first:.4g}"))
    widths = [max(len(row[i]) for row in rows) for i in range(len(rows[0]))]
    for k, row in enumerate(rows):
        lines.append("  " + "  ".join(cell.ljust(w) if i < 2 else cell.rjust(w)
                                      for i, (cell, w) in enumerate(zip(row, widths))).rstrip())
        if k == 0:
            lines.append("  " + "  ".join("-" * w for w in widths))
    tol = result["tolerance"]
    lines += ["", "scale = largest |measured| (at least the stroke 2r for positions, a turn for the crank angle, r x "
              "the largest crank speed for speeds, the largest crank speed for omega);",
              f"first over = first time |b - a| > {tol:g} x scale"]
    if result["ignored_columns"]:
        lines.append(f"note: measured columns not compared (not model columns): {' '.join(result['ignored_columns'])}")
    return "\n".join(lines)
