"""Uncertainty propagation with two fidelities: the equations on many samples, MuJoCo on a few of them.

:func:`run_uncertainty` draws N samples of the uncertain parameters (:mod:`.uq_dists`), runs the equations (the
analytic variant matching the engine, :func:`engine_pair`) on all of them and MuJoCo on the first M
(``mujoco_samples``; M << N, the same draws: paired), and gives per metric its mean, standard deviation and 5/50/95 %
quantiles with confidence intervals, and the probability of each event, by the estimators of :mod:`.uq_stats`:
plain Monte Carlo of the equations without MuJoCo samples; with them, the multi-fidelity estimate (the equations
as a control variate of MuJoCo) beside MuJoCo's plain Monte Carlo on its M samples, with the variance reduction.

A metric (``--metric KEY``) is any number of a run's summary (``simulate --json``'s ``summary``, its ``energy``
figures included: ``motor_work_j``, ...), any sweep metric (``mean_speed_m_s``, ``steady``, ``stalled``, ...: as
:mod:`.sweep_metrics` reads them, the same for every engine), or one of :data:`.uq_keys.DERIVED`. An event is
``KEY>V`` (also ``<``, ``>=``, ``<=``) or a name of :data:`.uq_keys.NAMED_EVENTS`. A metric a sample does not give (a
stalled run's energy per metre) leaves that sample out of the metric's statistics (their count is reported);
it is not the event ``KEY>V``. A run that fails (an invalid draw, a simulation failure) leaves its sample out of
everything, and is counted.

Files (written all at once at the end, nothing half-written): ``uncertainty.json`` (the contract's structure:
``metrics`` {KEY: mean, mean_interval, std, std_interval, quantiles, estimator, variance_reduction, ...},
``events`` {TEXT: probability, interval, ...}), ``samples.csv`` (one row per sample: the parameters, then
``ENGINE:KEY`` for each engine, metric and event key, and ``ENGINE:error``), ``uncertainty.png``.
"""

from __future__ import annotations

import csv
import math
import os
import time
from pathlib import Path
from typing import Callable

import numpy as np

from ipir_mujoco import registry
from ipir_mujoco.core.errors import ParameterError, SimulationError
from ipir_mujoco.core.options import MAX_T_END, refuse_steady_without_motor, study_dt_out
from ipir_mujoco.core.params import RobotParams, check_real, check_whole, refuse_idle_parameters
from ipir_mujoco.core.results import write_json

from . import uq_stats
from ..sweeps.sweep_files import Progress
from ..figure_errors import figure_error, unusable_counts, why_unusable
from ..sweeps.sweep_metrics import run_metrics
from .uq_dists import Dist, sample
from .uq_keys import (  # noqa: F401  (re-exported: every name stays importable from here)
    DERIVED, KEY_UNITS, KEYS, NAMED_EVENTS, NAMED_WORDS, OPERATORS, SUMMARY_KEYS, Event, check_metric, event_words,
    key_words, parse_event)

MAX_SAMPLES = 100_000
MIN_MUJOCO = 3  # pairs the multi-fidelity estimate needs (a correlation and a coefficient from them)
ERROR = "_error"  # a sample's figure's error bar, beside it (MuJoCo on finite grip: figure_errors)
# the equation's variant paired with each MuJoCo variant: the same clutch rule, the exact geometry
_ANALYTIC_OF = {"unilateral": "analytic-unilateral", "kinematic": "analytic-exact"}
_MUJOCO_OF = {"unilateral": "mujoco-ratchet", "kinematic": "mujoco-lock"}


def engine_pair(engine: str | None) -> tuple[str, str]:
    """(the equations' variant, MuJoCo's variant) for ``--variant``: either side names the other by its clutch
    rule (one-way clutches: analytic-unilateral and mujoco-ratchet, the default; the paper's rule:
    analytic-exact and mujoco-lock)."""
    if engine is None:
        return "analytic-unilateral", "mujoco-ratchet"
    v = registry.variant(engine)
    if v.is_mujoco:
        return _ANALYTIC_OF[v.rule], v.name
    return v.name, _MUJOCO_OF[v.rule]


def sample_values(run) -> dict[str, float]:
    """Every number of a run :data:`KEYS` names (NaN where the run has none)."""
    summary = run.summary
    flat = dict(summary)
    flat.update(summary.get("energy") or {})
    values = {k: _number(flat.get(k)) for k in SUMMARY_KEYS}
    values.update(run_metrics(run))
    values["travel_m"] = 0.5 * (values["x1_final"] + values["x2_final"])
    values["skid_m"] = max(values["slip1_m"], values["slip2_m"])
    return values


def _number(value) -> float:
    if isinstance(value, bool):
        return float(value)
    if isinstance(value, (int, float)):
        return float(value)
    return math.nan


class SampleTask:
    """One sample in one engine (picklable, for the pool): (index, {parameter: value}) -> (index, values or
    {"error": message})."""

    def __init__(self, base: RobotParams, engine: str, t_end: float, dt_out: float, until_steady: bool,
                 keys: tuple[str, ...]):
        self.base, self.engine, self.t_end, self.dt_out = base, engine, t_end, dt_out
        self.until_steady, self.keys = until_steady, keys

    def __call__(self, item: tuple[int, dict]) -> tuple[int, dict]:
        index, design = item
        registry.prepare_for_many((self.engine,))
        try:
            params = self.base.replace(**design)
            run = registry.run(self.engine, params, self.t_end, dt_out=self.dt_out, until_steady=self.until_steady)
        except (ParameterError, ValueError) as exc:  # this draw is not a valid design, or not for this engine
            return index, {"error": " ".join(str(exc).split()), "bad_input": True}
        except SimulationError as exc:
            return index, {"error": " ".join(str(exc).split())}
        values = sample_values(run)
        out = {k: values[k] for k in self.keys}
        summary = run.summary
        # a MuJoCo figure on finite grip comes with its error bar (the rigid limit's): kept beside it
        out.update({f"{k}{ERROR}": e for k in self.keys if (e := figure_error(summary, k)) is not None})
        return index, out


def evaluate(task: SampleTask, designs: list[dict], workers: int, progress: Progress | None) -> list[dict]:
    """``task`` on every design, on ``workers`` processes: results in the designs' order."""
    from ..pool import map_unordered

    results: list[dict | None] = [None] * len(designs)

    def done(item, result):
        results[result[0]] = result[1]
        if progress is not None:
            progress.advance()

    map_unordered(task, list(enumerate(designs)), max(1, min(workers, len(designs))), done)
    return results  # type: ignore[return-value]


def run_uncertainty(dists: list[Dist], metrics: tuple[str, ...], events: tuple[Event, ...] = (), *,
                    base: RobotParams | None = None, engine: str | None = None, samples: int = 1000,
                    mujoco_samples: int = 0, t_end: float = 1.0, until_steady: bool = False, seed: int = 0,
                    correlation=None, workers: int | None = None, progress: bool = True) -> dict:
    """Run the study (module docstring); returns {"study": ..., "metrics": ..., "events": ..., "rows": ...}
    (``rows``: one dict per sample, what samples.csv holds). Nothing is written here (see :func:`write_files`)."""
    base = RobotParams() if base is None else base
    if not metrics and not events:
        raise ParameterError("uncertainty needs at least one --metric KEY or --event")
    samples = check_whole("samples", samples, low=2, high=MAX_SAMPLES)
    mujoco_samples = check_whole("mujoco_samples", mujoco_samples, low=0, high=samples)
    if 0 < mujoco_samples < MIN_MUJOCO:
        raise ParameterError(f"--mujoco-samples {mujoco_samples}: allowed: 0, or {MIN_MUJOCO} to --samples "
                             f"({samples}) (the pairs give the correlation the estimate uses)")
    seed = check_whole("seed", seed, low=0)
    t_end = check_real("t_end", t_end, high=MAX_T_END, unit="s")
    refuse_steady_without_motor(base.drive, until_steady)
    workers = check_whole("workers", workers, low=1, high=1024) if workers is not None else (os.cpu_count() or 1)
    cheap, faithful = engine_pair(engine)
    names = [d.name for d in dists]
    draws = sample(dists, samples, seed, correlation)
    designs = [dict(zip(names, map(float, row))) for row in draws]
    first = next((d for d in designs[:50] if _valid(base, d)), None)
    if first is None:
        base.replace(**designs[0])  # every draw invalid (say L <= r against the base): refuse, naming the first
    # a parameter that acts only through another the base leaves idle (F_n1 with unlimited grip): every run
    # would refuse it; refused here, once
    refuse_idle_parameters(base.replace(**first))
    keys = tuple(dict.fromkeys((*metrics, *(e.key for e in events))))
    dt_out = study_dt_out(t_end, min(1e-3, t_end))  # at most STUDY_SAMPLES a run
    started = time.perf_counter()
    cheap_rows = evaluate(SampleTask(base, cheap, t_end, dt_out, until_steady, keys), designs, workers,
                          Progress(samples, 0, progress, what=f"uncertainty {cheap}") if progress else None)
    faithful_rows = []
    if mujoco_samples:
        faithful_rows = evaluate(SampleTask(base, faithful, t_end, dt_out, until_steady, keys),
                                 designs[:mujoco_samples], workers,
                                 Progress(mujoco_samples, 0, progress, what=f"uncertainty {faithful}")
                                 if progress else None)
    result = {"study": {"dists": [d.text for d in dists], "metrics": list(metrics), "events": [e.text for e in events],
                        "engine": cheap, "mujoco_engine": faithful if mujoco_samples else None,
                        "samples": samples, "mujoco_samples": mujoco_samples, "t_end": t_end,
                        "until_steady": until_steady, "seed": seed, "base": base.as_dict(),
                        "correlation": None if correlation is None else {"names": correlation[0],
                                                                         "matrix": correlation[1].tolist()}}}
    result.update(estimate(cheap_rows, faithful_rows, metrics, events, seed))
    result["study"]["wall_s"] = time.perf_counter() - started
    result["rows"] = _rows(designs, cheap, cheap_rows, faithful, faithful_rows, keys)
    return result


def _valid(base: RobotParams, design: dict) -> bool:
    try:
        base.replace(**design)
        return True
    except ValueError:
        return False


def _column(rows: list[dict], key: str) -> np.ndarray:
    return np.array([r.get(key, math.nan) if "error" not in r else math.nan for r in rows], dtype=float)


def estimate(cheap_rows: list[dict], faithful_rows: list[dict], metrics, events, seed: int = 0) -> dict:
    """The statistics of every metric and event from the two engines' per-sample values (module docstring):
    {"metrics": {KEY: {...}}, "events": {TEXT: {...}}, "failures": {...}}."""
    m = len(faithful_rows)
    ok_cheap = np.array(["error" not in r for r in cheap_rows])
    ok_pair = np.array(["error" not in r for r in faithful_rows], dtype=bool) & ok_cheap[:m] if m else np.array([])
    failures = {"equations": int((~ok_cheap).sum()), "mujoco": int(m - ok_pair.sum()) if m else 0,
                "first_error": next((r["error"] for r in [*cheap_rows, *faithful_rows] if "error" in r), None),
                "mujoco_reasons": unusable_counts(why_unusable(r["error"], bool(r.get("bad_input")))
                                                  for r in faithful_rows if "error" in r),
                "mujoco_used": int(ok_pair.sum()) if m else 0}
    if not ok_cheap.any():
        if all(r.get("bad_input") for r in cheap_rows):
            raise ParameterError(f"every sample was refused by the equations; the first: {failures['first_error']}")
        raise SimulationError(f"every sample failed in the equations; the first: {failures['first_error']}")
    out: dict = {"metrics": {}, "events": {}, "failures": failures}
    for key in metrics:
        g = _column(cheap_rows, key)
        usable_g = np.isfinite(g)
        entry: dict
        f = _column(faithful_rows, key) if m else np.array([])
        pair = np.isfinite(f) & usable_g[:m] if m else np.array([], dtype=bool)
        if m and pair.sum() >= MIN_MUJOCO:
            rest = usable_g.copy()
            rest[:m] = False
            entry = uq_stats.multi_fidelity(f[pair], g[:m][pair], g[rest], seed)
            entry["estimator"] = "multi-fidelity"
            entry["mujoco_mc"] = uq_stats.mc_statistics(f[pair], seed)
            bar = _error_bar(faithful_rows, key, pair)
            if bar is not None:  # MuJoCo's figures carry their error bars: their mean widens the means' intervals
                entry["mujoco_error_bar"] = bar
                for stats in (entry, entry["mujoco_mc"]):
                    lo, hi = stats["mean_interval"]
                    stats["mean_interval"] = [lo - bar, hi + bar]
            entry["equations_mc"] = uq_stats.mc_statistics(g[usable_g], seed)
            entry["missing"] = int((~usable_g).sum() + (~np.isfinite(f)).sum())
        else:
            if usable_g.sum() < 2:
                raise SimulationError(f"{key}: only {int(usable_g.sum())} of the {len(g)} samples give it (stalled "
                                      "or failed runs); statistics need 2")
            entry = uq_stats.mc_statistics(g[usable_g], seed)
            entry.update(estimator="mc", variance_reduction=None, missing=int((~usable_g).sum()))
            if m:  # MuJoCo ran but gives too few values of this metric to pair (a rigid clutch's peak force: none)
                entry["note"] = (f"only {int(pair.sum())} of the {m} MuJoCo runs give {key} (MuJoCo leaves some "
                                 "metrics empty, e.g. a rigid clutch's peak force; or they stalled or failed): the "
                                 f"equations' Monte Carlo alone (multi-fidelity needs {MIN_MUJOCO} pairs)")
        out["metrics"][key] = _finite(entry)
    for event in events:
        g = _column(cheap_rows, event.key)[ok_cheap]
        if m:
            f = _column(faithful_rows, event.key)
            g_pair = _column(cheap_rows, event.key)[:m]
            entry = uq_stats.multi_fidelity_event(event.hits(f[ok_pair]), event.hits(g_pair[ok_pair]), event.hits(g))
            entry["mujoco_mc"] = uq_stats.event_probability(event.hits(f[ok_pair]))
            entry["equations_mc"] = uq_stats.event_probability(event.hits(g))
        else:
            entry = uq_stats.event_probability(event.hits(g))
        out["events"][event.text] = _finite(entry)
    return out


def _error_bar(rows: list[dict], key: str, used: np.ndarray) -> float | None:
    """The mean error bar of ``key`` over the MuJoCo runs ``used`` (boolean, shape (len(rows),)) that state one
    (:func:`.figure_errors.figure_error`), or None where none does: every such run's figure may be off by its
    bar, so their mean by at most the bars' mean, which the estimators' means (their MuJoCo values with weight
    1) inherit."""
    bars = [r[f"{key}{ERROR}"] for r, u in zip(rows, used) if u and f"{key}{ERROR}" in r]
    return float(np.mean(bars)) if bars else None


def _finite(value):
    """JSON has no NaN or infinity: None in their place (an interval the samples cannot bound on one side)."""
    if isinstance(value, dict):
        return {k: _finite(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_finite(v) for v in value]
    if isinstance(value, float) and not math.isfinite(value):
        return None
    return value


def _rows(designs, cheap, cheap_rows, faithful, faithful_rows, keys) -> list[dict]:
    rows = []
    for i, design in enumerate(designs):
        row = {"sample": i, **design}
        for engine, results in ((cheap, cheap_rows), (faithful, faithful_rows)):
            if i < len(results):
                r = results[i]
                row.update({f"{engine}:{k}": r.get(k) for k in keys})
                row.update({f"{engine}:{k}{ERROR}": r[f"{k}{ERROR}"] for k in keys if f"{k}{ERROR}" in r})
                row[f"{engine}:error"] = r.get("error", "")
        rows.append(row)
    return rows


def write_files(out: str | Path, result: dict, *, figure: Callable) -> Path:
    """uncertainty.json, samples.csv and uncertainty.png into ``out``, all or nothing; returns the figure's path.
    ``figure(path, result, words)`` draws it (the report's :func:`ipir_mujoco.report.uncertainty_figure.plot_uncertainty`:
    the report stands above the studies)."""
    from ...output import staged_output

    with staged_output(out) as staging:
        rows = result["rows"]
        header = list(dict.fromkeys(k for r in rows for k in r))
        with (staging / "samples.csv").open("w", newline="", encoding="utf-8") as fh:
            writer = csv.DictWriter(fh, fieldnames=header)
            writer.writeheader()
            writer.writerows({k: _cell(v) for k, v in r.items()} for r in rows)
        write_json(staging / "uncertainty.json", {k: v for k, v in result.items() if k != "rows"})
        words = {"metrics": {k: key_words(k) for k in result["metrics"]},
                 "events": {e: event_words(e) for e in result["events"]},
                 "engines": {e: registry.variant(e).label for e in (result["study"]["engine"],
                                                                     result["study"]["mujoco_engine"]) if e}}
        figure(staging / "uncertainty.png", result, words)
    return Path(out) / "uncertainty.png"


def _cell(value) -> str:
    if value is None or (isinstance(value, float) and not math.isfinite(value)):
        return ""
    return repr(value) if isinstance(value, float) else str(value)
