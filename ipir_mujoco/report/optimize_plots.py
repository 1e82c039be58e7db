"""Figures of an optimization (pareto.png) and a sensitivity study (sensitivity.png).

pareto.png: every evaluated design (feasible in grey, infeasible as light crosses), the feasible
non-dominated designs (the front, or the single optimum) in colour, the points verified in the other
engine ringed. One objective: the objective against the first varied parameter; two: the objective
plane; more: a panel per pair of objectives.
"""

from __future__ import annotations

import csv
import itertools
from pathlib import Path

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

from ..output import write_atomically
from ..studies.design.design_eval import key_value
from ..studies.sweeps.sweep_metrics import DESCRIBED, LEGACY, described


def axis_label(key: str) -> str:
    """A metric in words with its unit ('steady forward speed [m/s]'), a parameter as the user names it with
    its unit ('M_stall [N m]'); never a raw metric key."""
    if key in DESCRIBED or key in LEGACY:
        return described(key)
    from ipir_mujoco.core.params import describe_parameters

    units = {row["name"]: row["units"] for row in describe_parameters()}
    if key in units:
        return f"{key} [{units[key] or '-'}]"
    return key


def _words(key: str) -> str:
    """A metric in words, without its unit ('steady forward speed'); a parameter's name."""
    return DESCRIBED[LEGACY.get(key, key)][0] if key in DESCRIBED or key in LEGACY else key


def _rows(path: Path) -> list[dict]:
    if not path.is_file():
        return []
    with path.open(newline="", encoding="utf-8") as fh:
        return [{k: _num(v) for k, v in r.items()} for r in csv.DictReader(fh)]


def _num(v):
    try:
        return float(v) if v != "" else None
    except ValueError:
        return v


def _values(rows, key, problem) -> np.ndarray:
    return np.array([np.nan if key_value(key, r, problem.base) is None else key_value(key, r, problem.base)
                     for r in rows], dtype=float)


def plot_pareto(out: str | Path, problem) -> Path:
    """Draw OUT/pareto.png from OUT/evaluations.csv and OUT/pareto.csv; return its path."""
    path = Path(out) / "pareto.png"
    fig = pareto_figure(out, problem)
    write_atomically(path, lambda staged: fig.savefig(staged, dpi=110))
    return path


def pareto_figure(out: str | Path, problem) -> Figure:
    """The figure of :func:`plot_pareto` (a matplotlib Figure, for tests to read)."""
    out = Path(out)
    evaluations, front = _rows(out / "evaluations.csv"), _rows(out / "pareto.csv")
    keys = [o.key for o in problem.objectives]
    if len(keys) == 1:  # the objective against the first varied parameter, or the first constraint where they agree
        y = keys[0] if keys[0] != problem.names[0] else (problem.constraints[0].key if problem.constraints
                                                          else "steady_speed_m_s")
        pairs = [(problem.names[0], y)]
    else:
        pairs = list(itertools.combinations(keys, 2))
    cols = min(3, len(pairs))
    rows_n = (len(pairs) + cols - 1) // cols
    fig = Figure(figsize=(4.6 * cols, 0.8 + 3.8 * rows_n), layout="constrained")
    FigureCanvasAgg(fig)
    feasible = np.array([problem.feasible(r) for r in evaluations], dtype=bool)
    verified = [r for r in front if problem.verify and not r.get("verify_error")
                and any(k.startswith("divergence:") and r[k] is not None for k in r)]
    entries = {}  # legend label -> handle, once each, from what is drawn
    for k, (kx, ky) in enumerate(pairs):
        ax = fig.add_subplot(rows_n, cols, k + 1)
        x, y = _values(evaluations, kx, problem), _values(evaluations, ky, problem)
        drawn = []
        if (~feasible).any():  # listed only where there are some
            drawn.append(ax.scatter(x[~feasible], y[~feasible], marker="x", s=12, color="0.75",
                                    label=f"infeasible ({int((~feasible).sum())})"))
        if feasible.any():
            drawn.append(ax.scatter(x[feasible], y[feasible], s=10, color="0.45",
                                    label=f"feasible ({int(feasible.sum())})"))
        fx, fy = _values(front, kx, problem), _values(front, ky, problem)
        order = np.argsort(fx)
        if len(fx):
            drawn += ax.plot(fx[order], fy[order], "o-", color="C3", ms=5,
                             label="optimum" if len(keys) == 1 else "front")
        if verified:
            vx, vy = _values(verified, kx, problem), _values(verified, ky, problem)
            drawn.append(ax.scatter(vx, vy, s=80, facecolors="none", edgecolors="C0",
                                    label=f"verified ({problem.verify})"))
        for c in problem.constraints:  # a constraint on a plotted key: its bound
            text = f"constraint: {_words(c.key)} {c.op} {c.value:g}"
            if c.key == ky:
                drawn.append(ax.axhline(c.value, color="C2", lw=0.8, ls="--", label=text))
            elif c.key == kx:
                drawn.append(ax.axvline(c.value, color="C2", lw=0.8, ls="--", label=text))
        for artist in drawn:
            entries.setdefault(artist.get_label(), artist)
        ax.set_xlabel(axis_label(kx))
        ax.set_ylabel(axis_label(ky))
        ax.grid(alpha=0.3)
    fig.legend(list(entries.values()), list(entries), loc="outside lower center", ncols=min(3, len(entries)),
               fontsize="small")
    senses = ", ".join(f"{o.sense} {_words(o.key)}" for o in problem.objectives)
    fig.suptitle(f"{problem.engine}: {senses}\n{len(evaluations)} evaluations", fontsize="small")
    return fig


def plot_indices(out: str | Path, indices: list[dict], metrics: list[str]) -> Path:
    """Draw OUT/sensitivity.png: S1 and ST per parameter with their confidence intervals, a panel per metric."""
    path = Path(out) / "sensitivity.png"
    fig = indices_figure(indices, metrics)
    write_atomically(path, lambda staged: fig.savefig(staged, dpi=110))
    return path


VISIBLE = 0.005  # a difference of Sobol indices a reader sees on the bars


def indices_figure(indices: list[dict], metrics: list[str]) -> Figure:
    """The figure of :func:`plot_indices` (a matplotlib Figure, for tests to read)."""
    fig = Figure(figsize=(8.0, 0.6 + 2.8 * len(metrics)), layout="constrained")
    FigureCanvasAgg(fig)
    for k, metric in enumerate(metrics):
        ax = fig.add_subplot(len(metrics), 1, k + 1)
        items = [i for i in indices if i["metric"] == metric]
        pos = np.arange(len(items))
        for shift, name, colour, words in ((-0.18, "S1", "C0", "S1: alone"), (0.18, "ST", "C1", "ST: with interactions")):
            ax.bar(pos + shift, [i[name] for i in items], width=0.36, yerr=[i[f"{name}_conf"] for i in items],
                   capsize=3, color=colour, label=words)
        ax.set_xticks(pos, [i["parameter"] for i in items])
        ax.set_xlabel("parameter varied")
        ax.set_ylabel("Sobol index [-]")
        ax.axhline(0.0, color="0.6", lw=0.6)
        title = f"{described(metric) if metric in DESCRIBED or metric in LEGACY else metric}: share of its variance"
        # S1 <= ST in exact arithmetic; a sampled S1 above ST is sampling error when the intervals overlap.
        # "Above": by more than VISIBLE, half of the 0.01 a bar's height can be read to (no comment on -0.000)
        above = [i for i in items if i["S1"] > i["ST"] + VISIBLE]
        if above:
            overlap = all(i["S1"] - i["S1_conf"] <= i["ST"] + i["ST_conf"] for i in above)
            above = [i["parameter"] for i in above]
            title += (f"\nS1 > ST for {', '.join(above)}: " + ("within the 95 % intervals, sampling error (more "
                                                               "--samples narrows them)" if overlap else
                                                               "beyond the intervals: raise --samples"))
        ax.set_title(title, fontsize="small")
        if k == 0:
            fig.legend(*ax.get_legend_handles_labels(), loc="outside lower center", ncols=2, fontsize="small")
    return fig
