"""uncertainty.png: each metric's distribution with its estimates' intervals, and the events' probabilities.

One row per metric: left, histograms of the equations' samples (and MuJoCo's, where it ran) with the estimated
mean and 5/95 % quantiles, each as a line inside its shaded 95 % interval; right, the empirical CDFs of both
engines with the estimator's quantiles and their intervals as horizontal bars. A last row: every event's
probability with its 95 % interval (log scale when any is small), a hollow marker where the samples cannot
resolve it (the interval is then the statement).
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure


EQUATIONS, MUJOCO = "#1f77b4", "#d62728"


def _values(rows: list[dict], engine: str | None, key: str) -> np.ndarray:
    if engine is None:
        return np.array([])
    column = f"{engine}:{key}"
    v = np.array([r[column] if r.get(column) is not None else math.nan for r in rows if column in r], dtype=float)
    return v[np.isfinite(v)]


def _words(words: dict, key: str) -> tuple[str, str]:
    """(words, unit) of a metric key from the study's ``words``; the key itself where it has none."""
    return words.get("metrics", {}).get(key, (key, "-"))


def _label(name: str, unit: str) -> str:
    return f"{name} [{unit}]" if unit and unit != "-" else f"{name} [-]"


def plot_uncertainty(path: str | Path, result: dict, words: dict | None = None) -> Path:
    """Draw :func:`uncertainty_figure` at ``path``."""
    uncertainty_figure(result, words).savefig(path, dpi=110)
    return Path(path)


def uncertainty_figure(result: dict, words: dict | None = None) -> Figure:
    """The figure of :func:`ipir_mujoco.studies.uncertainty.run_uncertainty`'s ``result``; ``words``: {"metrics":
    {key: (words, unit)}, "events": {text: words}, "engines": {variant: label}} for the axes, titles and legends
    (the study's ``key_words`` and ``event_words``, handed in: this module imports no study, which calls it)."""
    words = {} if words is None else words
    study, rows = result["study"], result["rows"]
    metrics, events = list(result["metrics"]), list(result["events"])
    cheap, faithful = study["engine"], study["mujoco_engine"]
    engines = words.get("engines", {})
    cheap_name, faithful_name = engines.get(cheap, cheap), engines.get(faithful, faithful)
    n_rows = len(metrics) + (1 if events else 0)
    event_height = 0.9 + 0.45 * len(events)  # inches: a line per event, and the legend below
    heights = [4.2] * len(metrics) + ([event_height] if events else [])
    fig = Figure(figsize=(11, 0.9 + sum(heights)), layout="constrained")
    FigureCanvasAgg(fig)
    grid = fig.add_gridspec(n_rows, 2, height_ratios=heights)
    for k, key in enumerate(metrics):
        entry = result["metrics"][key]
        name, unit = _words(words, key)
        g, f = _values(rows, cheap, key), _values(rows, faithful, key)
        hist = fig.add_subplot(grid[k, 0])
        both = np.concatenate([g, f])
        lo, hi = (float(both.min()), float(both.max())) if both.size else (0.0, 1.0)
        bins = np.linspace(lo, hi if hi > lo else lo + max(abs(lo), 1.0) * 1e-6, 41)
        hist.hist(g, bins=bins, density=True, color=EQUATIONS, alpha=0.45,
                  label=f"{cheap_name} ({len(g)} samples)")
        if f.size:
            hist.hist(f, bins=bins, density=True, histtype="step", color=MUJOCO, linewidth=1.6,
                      label=f"{faithful_name} ({len(f)} samples)")
        what = "multi-fidelity" if entry["estimator"] == "multi-fidelity" else "Monte Carlo"
        _band(hist, entry["mean"], entry["mean_interval"], "black", f"mean ({what}) and 95 % interval")
        for q in ("5", "95"):
            _band(hist, entry["quantiles"][q], entry["quantile_intervals"][q], "#2ca02c",
                  "5 and 95 % quantiles, 95 % intervals" if q == "5" else None)
        hist.set_xlabel(_label(name, unit))
        per = f"({unit})" if any(c in unit for c in "/ ^") else unit  # 1/m, 1/(J/m)
        hist.set_ylabel("probability density" + (f" [1/{per}]" if unit and unit != "-" else " [-]"))
        std = entry["std"]
        shown_unit = f" {unit}" if unit and unit != "-" else ""
        hist.set_title(f"{name}: mean {entry['mean']:.4g}{shown_unit}, SD {std:.3g}{shown_unit}" if std is not None
                       else name, fontsize=10)
        # below the panel: inside, it would cover the histogram
        hist.legend(fontsize=7, loc="upper center", bbox_to_anchor=(0.5, -0.2), ncols=1, frameon=False)
        ecdf = fig.add_subplot(grid[k, 1])
        for values, colour, engine in ((g, EQUATIONS, cheap_name), (f, MUJOCO, faithful_name)):
            if values.size:
                x = np.sort(values)
                ecdf.step(x, np.arange(1, x.size + 1) / x.size, where="post", color=colour,
                          label=f"{engine} (empirical distribution)")
        for q, (est, interval) in ((q, (entry["quantiles"][q], entry["quantile_intervals"][q]))
                                   for q in entry["quantiles"]):
            lo_q, hi_q = (v if v is not None else est for v in interval)
            ecdf.errorbar([est], [int(q) / 100], xerr=[[est - lo_q], [hi_q - est]], fmt="o", color="black",
                          capsize=4, markersize=4, label="quantile estimate, 95 % interval" if q == "5" else None)
        ecdf.set_xlabel(_label(name, unit))
        ecdf.set_ylabel("share of samples at most x [-]")
        ecdf.set_ylim(-0.02, 1.02)
        ecdf.grid(True, alpha=0.3)
        ecdf.legend(fontsize=7, loc="upper center", bbox_to_anchor=(0.5, -0.2), ncols=1, frameon=False)
        if entry.get("variance_reduction"):
            ecdf.set_title(f"variance reduction {entry['variance_reduction']:.3g}x\n(correlation "
                           f"{entry['correlation']:.4f}, {entry['mujoco_samples']} MuJoCo runs)", fontsize=10)
    if events:
        ax = fig.add_subplot(grid[n_rows - 1, :])
        probs = [result["events"][e]["probability"] for e in events]
        intervals = [result["events"][e]["interval"] for e in events]
        y = np.arange(len(events))
        small = any(i[1] is not None and i[1] < 0.05 for i in intervals)
        for k, (p, (lo, hi), e) in enumerate(zip(probs, intervals, events)):
            resolved = result["events"][e].get("resolved", True)
            left = max(lo, 1e-6) if small else lo
            shown = max(p, 1e-6) if small else p
            ax.plot([left, hi], [k, k], color="black", linewidth=2, label="95 % interval" if k == 0 else None)
            alone = result["events"][e].get("equations_mc")
            if alone is not None:  # the equations' own Monte Carlo, for comparison
                a_lo, a_hi = alone["interval"]
                ax.plot([max(a_lo, 1e-6) if small else a_lo, a_hi], [k - 0.18, k - 0.18], color=EQUATIONS,
                        linewidth=1.5, label=f"{cheap_name} alone" if k == 0 else None)
            ax.plot([shown], [k], "o", color="black", markerfacecolor="black" if resolved else "white",
                    markersize=7, label="estimate (hollow: not resolved)" if k == 0 else None)
            ax.annotate(f"{p:.3g}  [{lo:.3g}, {hi:.3g}]" + ("" if resolved else "  (not resolved)"), (hi, k),
                        textcoords="offset points", xytext=(6, -3), fontsize=8)
        if small:
            ax.set_xscale("log")
            ax.set_xlim(1e-6 if min(max(i[0], 1e-6) for i in intervals) < 1e-3 else 1e-4, 1.5)
        else:
            ax.set_xlim(-0.02, 1.3)
        ax.set_yticks(y, [words.get("events", {}).get(e, e) for e in events])
        ax.set_ylim(-0.6, len(events) - 0.4)
        ax.set_xlabel("probability [-] (dot: estimate; line: 95 % interval; hollow: not resolved by the samples)")
        ax.grid(True, axis="x", alpha=0.3)
        ax.set_title("events", fontsize=10)
        ax.legend(fontsize=7, loc="upper center", bbox_to_anchor=(0.5, -0.35), ncols=2, frameon=False)
    mf = f", {faithful_name} on the first {study['mujoco_samples']} (paired)" if study["mujoco_samples"] else ""
    fig.suptitle(f"Uncertainty: {', '.join(study['dists'])}\n{cheap_name} on {study['samples']} samples{mf}",
                 fontsize=10)
    return fig


def _band(ax, value, interval, colour, label) -> None:
    if value is None:
        return
    lo, hi = interval
    if lo is not None and hi is not None:
        ax.axvspan(lo, hi, color=colour, alpha=0.15, linewidth=0)
    ax.axvline(value, color=colour, linewidth=1.2, label=label)
