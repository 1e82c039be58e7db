"""Compare two runs of any engines: where and by how much they diverge.

Both runs are resampled on a common time grid and, when both cranks turn
forward monotonically, on a common crank-angle grid too: comparing at matching
crank angle removes the error a small phase lag inflates at matching time
(there ``phi`` itself is replaced by the time t(phi) each run needs to reach it).

:func:`compare_runs` returns a plain dict (JSON-ready)::

    time_grid / angle_grid   {quantity: {rms, max, scale}} for phi omega x1 x2 v1 v2 S S_dot: RMS and largest
                             |a - b| and the scale (largest |a|) they compare to; on the time grid
                             at least the mechanism's own (a turn 2 pi for phi, the stroke 2r for
                             x1 x2 S, r x the largest crank speed for v1 v2 S_dot), so that a module
                             a holds still is not judged against a scale of 0;
                             angle_grid is null when a crank does not turn monotonically
    summary                  {figure: {a, b, relative}}: (b - a) / |a| for revolutions,
                             x1_final, x2_final, v1_max, v2_max (at, and up to, t_compared_s: the
                             shorter run's end, e.g. of two runs to steady state), first_contraction_end_s and the
                             periodic steady state's t_steady_s, steady_speed_m_s, distance_per_rev_m,
                             energy_per_metre_j_m, efficiency, peak_clutch_force_n (null where a run
                             has no such figure, e.g. a run that did not reach steady state)
    switches                 {matched, unmatched_a, unmatched_b, dt: [...], max_abs_dt}:
                             mode changes matched one by one (same from->to, in order)
    first_exceedance         {quantity: t or null}: first time |a - b| exceeds
                             tolerance * scale on the time grid
    tolerance                the relative tolerance used there
    notes                    [str]: what a figure above does not mean (MuJoCo's rigid clutch's peak force),
                             one line each
    t_end_a_s, t_end_b_s     where each run ends; t_compared_s, the shorter of them
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from ipir_mujoco.core.checks import check_path, check_real
from ipir_mujoco.core.errors import ParameterError, ParameterTypeError
from ipir_mujoco.core.params import RobotParams, read_text_file
from ipir_mujoco.core.results import COLUMNS, RunResult, mode_changes

QUANTITIES = ("phi", "omega", "x1", "x2", "v1", "v2", "S", "S_dot")
SUMMARY_FIGURES = ("revolutions", "x1_final", "x2_final", "v1_max", "v2_max", "first_contraction_end_s")
AT_COMPARED_TIME = ("revolutions", "x1_final", "x2_final", "v1_max", "v2_max")  # depend on how long a run is
# the periodic steady state (core.cycles, through RunResult.summary): over the steady window when a
# run reached it, else (distance, efficiency, peak force) over the whole run, or null
STEADY_FIGURES = ("t_steady_s", "steady_speed_m_s", "distance_per_rev_m", "energy_per_metre_j_m", "efficiency",
                  "peak_clutch_force_n")


def relative_change(new: float | None, old: float | None) -> float | None:
    """(new - old) / |old|, or None where either is missing or old is zero."""
    if new is None or old is None or old == 0:
        return None
    return (new - old) / abs(old)


def cost(idealized: float | None, real: float | None) -> float | None:
    """An idealization's cost: (the model with it - the model without it) / |the model without it|, the sign
    convention of every cost in the validation report (the atlas's, :func:`.atlas_space.signed_cost`; the L/r
    study's; the ladder's brackets; the opening figure's)."""
    return relative_change(idealized, real)


def load_run(folder: str | Path) -> RunResult:
    """A run written by ``simulate --out`` (timeseries.csv and summary.json).

    Anything that is not such a run is a one-line ParameterError naming the folder and what is
    wrong: a missing or unreadable file, a time series with fewer than two samples, a row torn or
    ragged, a value that is not a finite number, a summary that is not the one simulate writes.
    """
    folder = Path(check_path("folder", folder, "the path of a run folder 'simulate --out' wrote"))
    if not folder.is_dir():
        raise ParameterError(f"{str(folder)!r} is not a run folder (it does not exist or is a file); "
                             "write one with 'ipir-mujoco simulate --out DIR'")
    csv, summary = folder / "timeseries.csv", folder / "summary.json"
    for path in (csv, summary):
        if not path.is_file():
            raise ParameterError(f"{str(folder)!r} is not a run folder: {path.name} is missing "
                                 "(write one with 'ipir-mujoco simulate --out DIR')")
    series = read_series(csv)
    try:
        record = json.loads(read_text_file(summary, "summary"))
        params = RobotParams(**record["params"])
        return RunResult(record["engine"], record["geometry"], record["clutch"], params, float(record["t_end"]),
                         series, record["summary"]["energy"], record.get("wall_time_s", 0.0),
                         record.get("settings", {}), stall=record["summary"].get("stall_reason"),
                         accuracy=record["summary"].get("accuracy"))
    except ParameterError as exc:
        raise ParameterError(f"run folder {str(folder)!r}: summary.json: {exc}") from None
    except (ValueError, KeyError, TypeError, AttributeError) as exc:
        what = f"lacks {exc}" if isinstance(exc, KeyError) else f"cannot be read: {exc}"
        raise ParameterError(f"run folder {str(folder)!r}: summary.json {what}") from None


def read_series(path: str | Path) -> dict[str, np.ndarray]:
    """A timeseries.csv as columns (shape (n,), n >= 2, every value finite), or a one-line ParameterError."""
    path = Path(path)
    lines = read_text_file(path, "time series").splitlines()
    where = f"time series {str(path)!r}"
    if not lines or not lines[0].strip():
        raise ParameterError(f"{where} is empty; allowed: the file 'ipir-mujoco simulate --out' writes")
    names = [name.strip() for name in lines[0].split(",")]
    missing = [c for c in COLUMNS if c not in names]
    if missing:
        raise ParameterError(f"{where} lacks the columns {' '.join(missing)} in its header row")
    rows = [line for line in lines[1:] if line.strip()]
    if len(rows) < 2:
        raise ParameterError(f"{where} has {len(rows)} sample row(s); a run needs at least 2")
    try:
        table = np.loadtxt(rows, delimiter=",", ndmin=2)
    except ValueError as exc:  # a torn or ragged row: numpy says which, in its first line
        raise ParameterError(f"{where}: {str(exc).splitlines()[0]}") from None
    if table.shape[1] != len(names):
        raise ParameterError(f"{where}: rows have {table.shape[1]} values, the header {len(names)}")
    bad = np.argwhere(~np.isfinite(table))
    if bad.size:
        row, column = bad[0]
        raise ParameterError(f"{where} line {row + 2}: {names[column]}={table[row, column]} is not a finite "
                             "number (simulate never writes one: the file was changed)")
    series = {name: table[:, k] for k, name in enumerate(names)}
    if np.any(np.diff(series["t"]) < 0) or not series["t"][-1] > series["t"][0]:
        raise ParameterError(f"{where}: the times t do not increase from the first row to the last")
    series["mode"] = series["mode"].astype(int)
    return series


def _unique_times(t: np.ndarray, values: np.ndarray):
    """Drop the second sample of a duplicated instant (a mode switch sampled once per mode)."""
    keep = np.concatenate([[True], np.diff(t) > 0])
    return t[keep], values[keep]


def _errors(a: np.ndarray, b: np.ndarray) -> dict:
    difference = b - a
    return {"rms": float(np.sqrt(np.mean(difference**2))), "max": float(np.max(np.abs(difference))),
            "scale": float(np.max(np.abs(a)))}


def _monotonic(phi: np.ndarray) -> bool:
    return bool(np.all(np.diff(phi) >= 0) and phi[-1] > phi[0])


def match_switches(a: RunResult, b: RunResult) -> dict:
    """Pair the mode changes of two runs in order, each with the next of the same kind in the other."""
    changes_a, changes_b = mode_changes(a.series), mode_changes(b.series)
    dts, j = [], 0
    unmatched_a = 0
    for change in changes_a:
        k = j
        while k < len(changes_b) and (changes_b[k]["from"], changes_b[k]["to"]) != (change["from"], change["to"]):
            k += 1
        if k == len(changes_b):
            unmatched_a += 1
            continue
        dts.append(changes_b[k]["t"] - change["t"])
        j = k + 1
    return {"matched": len(dts), "unmatched_a": unmatched_a, "unmatched_b": len(changes_b) - len(dts),
            "dt": dts, "max_abs_dt": float(np.max(np.abs(dts))) if dts else None}


def compare_runs(a: RunResult, b: RunResult, tolerance: float = 0.01, n_grid: int = 2000) -> dict:
    """Compare run ``b`` against run ``a`` (see the module docstring)."""
    for name, run in (("a", a), ("b", b)):
        if not isinstance(run, RunResult):
            raise ParameterTypeError(f"{name}={run!r} is not a RunResult; allowed: a run (registry.run, or "
                                     "load_run of a 'simulate --out' folder)")
    tolerance = check_real("tolerance", tolerance)  # > 0
    t_end = min(a.series["t"][-1], b.series["t"][-1])
    grid = np.linspace(0.0, t_end, n_grid)
    on_time = {}
    for run in (a, b):
        on_time[id(run)] = {q: np.interp(grid, *_unique_times(run.series["t"], run.series[q])) for q in QUANTITIES}
    time_errors = {q: _errors(on_time[id(a)][q], on_time[id(b)][q]) for q in QUANTITIES}
    # a quantity a holds at zero (a held module: x2 = 0, v2 = 0) has no scale of its own: every round-off of b
    # (a soft constraint's give) would then exceed 'tolerance x 0'
    crank_speed = float(np.max(np.abs(a.series["omega"])))
    floors = {"phi": 2 * np.pi, "x1": 2 * a.params.r, "x2": 2 * a.params.r, "S": 2 * a.params.r,
              "v1": a.params.r * crank_speed, "v2": a.params.r * crank_speed, "S_dot": a.params.r * crank_speed}
    for q, floor in floors.items():
        time_errors[q]["scale"] = max(time_errors[q]["scale"], floor)

    angle_errors = None
    if _monotonic(a.series["phi"]) and _monotonic(b.series["phi"]):
        lo = max(a.series["phi"][0], b.series["phi"][0])
        hi = min(a.series["phi"][-1], b.series["phi"][-1])
        angles = np.linspace(lo, hi, n_grid)
        resampled = {}
        for run in (a, b):
            t, phi = _unique_times(run.series["t"], run.series["phi"])
            resampled[id(run)] = {"t": np.interp(angles, phi, t)}
            for q in QUANTITIES[1:]:
                resampled[id(run)][q] = np.interp(angles, phi, _unique_times(run.series["t"], run.series[q])[1])
        angle_errors = {q: _errors(resampled[id(a)][q], resampled[id(b)][q]) for q in ("t",) + QUANTITIES[1:]}

    summary = {}
    summary_a, summary_b = a.summary, b.summary
    if a.series["t"][-1] != b.series["t"][-1]:
        # runs of different length (two runs to steady state stop at their own times): the figures that grow
        # with the run are compared at the shorter run's end, not each at its own
        summary_a, summary_b = (dict(summary, **_figures_until(run, t_end))
                                for run, summary in ((a, summary_a), (b, summary_b)))
    for key in SUMMARY_FIGURES + STEADY_FIGURES:
        va, vb = summary_a.get(key), summary_b.get(key)
        relative = None if va in (None, 0) or vb is None else (vb - va) / abs(va)
        summary[key] = {"a": va, "b": vb, "relative": relative}

    first = {}
    for q in QUANTITIES:
        scale = time_errors[q]["scale"]
        over = np.flatnonzero(np.abs(on_time[id(b)][q] - on_time[id(a)][q]) > tolerance * scale)
        first[q] = float(grid[over[0]]) if over.size and scale > 0 else None

    return {"a": f"{a.engine}/{a.geometry}/{a.clutch}", "b": f"{b.engine}/{b.geometry}/{b.clutch}",
            "t_compared_s": float(t_end), "t_end_a_s": float(a.series["t"][-1]), "t_end_b_s": float(b.series["t"][-1]),
            "time_grid": time_errors, "angle_grid": angle_errors,
            "summary": summary, "switches": match_switches(a, b), "first_exceedance": first,
            "tolerance": tolerance, "notes": [n for label, run in (("a", a), ("b", b)) for n in _notes(label, run)]}


def _notes(label: str, run: RunResult) -> list[str]:
    """What a MuJoCo run's figures do not mean (measured at the default motor: mjcf/README.md, "Reactions and
    held modules"): a rigid clutch's peak force."""
    if run.engine != "mujoco" or run.clutch == "none" or run.settings.get("clutch_model") == "compliant":
        return []
    return [f"peak clutch force of {label} (MuJoCo, rigid clutch): the overshoot of its soft engagement, set by "
            "the timestep and by the step a sample falls on (16.3 N at every 0.1 ms step, 11.8 N read every 1 ms, "
            "against the equations' 12.1 N at the default motor's cruise), not a physical figure"]


def _figures_until(run: RunResult, t_end: float) -> dict:
    """The figures of :data:`AT_COMPARED_TIME` (revolutions, travels [m] at ``t_end`` [s] and peak speeds [m/s]
    up to it, as RunResult.summary has them at the run's end), from the series interpolated at ``t_end``."""
    s = run.series
    at = {q: float(np.interp(t_end, *_unique_times(s["t"], s[q]))) for q in ("phi", "x1", "x2", "v1", "v2")}
    within = s["t"] <= t_end
    figures = ((at["phi"] - s["phi"][0]) / (2 * np.pi), at["x1"] - s["x1"][0], at["x2"] - s["x2"][0],
               max(float(np.max(s["v1"][within])), at["v1"]), max(float(np.max(s["v2"][within])), at["v2"]))
    return dict(zip(AT_COMPARED_TIME, figures))


def format_comparison(result: dict) -> str:
    """A readable table of :func:`compare_runs`' result: names with units, aligned columns, the tolerance."""
    from ..labels import SERIES, SUMMARY, significant

    def unit_of(table, key):
        name, unit = table.get(key, (key, ""))
        return name, ("" if unit == "-" else unit)

    lines = [f"b = {result['b']} against a = {result['a']}, over {result['t_compared_s']:.4g} s", ""]
    ends = result.get("t_end_a_s"), result.get("t_end_b_s")
    if None not in ends and ends[0] != ends[1]:
        lines[-1:-1] = [f"a ends at {ends[0]:.6g} s, b at {ends[1]:.6g} s: revolutions, travels and peak speeds "
                        f"are compared at {result['t_compared_s']:.6g} s, the shorter run's end"]
    rows = [("summary figure", "unit", "a", "b", "(b - a) / |a|")]
    for key, v in result["summary"].items():
        if key in STEADY_FIGURES and v["a"] is None and v["b"] is None:
            continue  # neither run has it (neither reached its steady state): not a row of empty cells
        name, unit = unit_of(SUMMARY, key)
        rows.append((name, unit, "none" if v["a"] is None else significant(v["a"], 6),
                     "none" if v["b"] is None else significant(v["b"], 6),
                     "n/a" if v["relative"] is None else f"{100 * v['relative']:+.3f} %"))
    lines += _aligned(rows)
    tolerance = result["tolerance"]
    lines += ["", "largest |b - a| over the run, in the quantity's unit; scale = largest |a| (at least a turn for phi, "
              "the stroke 2r for x1 x2 S, r x the largest crank speed for v1 v2 S_dot);",
              f"first over = first time |b - a| > tolerance x scale (tolerance {tolerance:g} = {100 * tolerance:g} %)"]
    rows = [("quantity", "unit", "at same time", "at same crank angle", "scale", "first over [s]")]
    for q in QUANTITIES:
        name, unit = unit_of(SERIES, q)
        at_angle = "n/a"
        if result["angle_grid"] is not None:
            at_angle = f"{result['angle_grid']['t' if q == 'phi' else q]['max']:.4g}"
            if q == "phi":
                at_angle += " s (time to reach it)"
        first = result["first_exceedance"][q]
        rows.append((name, unit, f"{result['time_grid'][q]['max']:.4g}", at_angle,
                     f"{result['time_grid'][q]['scale']:.4g}", "never" if first is None else f"{first:.4g}"))
    lines += _aligned(rows)
    sw = result["switches"]
    lines += ["", f"mode switches: {sw['matched']} matched, largest time difference "
              + ("n/a" if sw["max_abs_dt"] is None else f"{sw['max_abs_dt']:.3g} s")
              + f"; unmatched: {sw['unmatched_a']} in a, {sw['unmatched_b']} in b"]
    lines += [f"note: {note}" for note in result.get("notes", [])]
    return "\n".join(lines)


def _aligned(rows: list[tuple[str, ...]]) -> list[str]:
    """Rows as text columns: the first two left-aligned, the numbers right-aligned, a rule under the header."""
    widths = [max(len(row[i]) for row in rows) for i in range(len(rows[0]))]

    def line(row):
        return "  " + "  ".join(cell.ljust(w) if i < 2 else cell.rjust(w)
                                for i, (cell, w) in enumerate(zip(row, widths))).rstrip()

    return [line(rows[0]), "  " + "  ".join("-" * w for w in widths)] + [line(row) for row in rows[1:]]
