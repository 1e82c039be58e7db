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
from ..studies.design_eval import key_value


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
    for k, (kx, ky) in enumerate(pairs):
        ax = fig.add_subplot(rows_n, cols, k + 1)
        x, y = _values(evaluations, kx, problem), _values(evaluations, ky, problem)
        ax.scatter(x[~feasible], y[~feasible], marker="x", s=12, color="0.75", label="infeasible")
        ax.scatter(x[feasible], y[feasible], s=10, color="0.45", label="feasible")
        fx, fy = _values(front, kx, problem), _values(front, ky, problem)
        order = np.argsort(fx)
        ax.plot(fx[order], fy[order], "o-", color="C3", ms=5, label="optimum" if len(keys) == 1 else "front")
        if verified:
            vx, vy = _values(verified, kx, problem), _values(verified, ky, problem)
            ax.scatter(vx, vy, s=80, facecolors="none", edgecolors="C0", label=f"verified ({problem.verify})")
        for c in problem.constraints:  # a constraint on a plotted key: its bound
            if c.key == ky:
                ax.axhline(c.value, color="C2", lw=0.8, ls="--", label=f"{c.key} {c.op} {c.value:g}")
            elif c.key == kx:
                ax.axvline(c.value, color="C2", lw=0.8, ls="--", label=f"{c.key} {c.op} {c.value:g}")
        ax.set_xlabel(kx)
        ax.set_ylabel(ky)
        ax.legend(fontsize="small")
    senses = ", ".join(f"{o.sense} {o.key}" for o in problem.objectives)
    fig.suptitle(f"{problem.engine}: {senses}\n{len(evaluations)} evaluations", fontsize="small")
    path = out / "pareto.png"
    write_atomically(path, lambda staged: fig.savefig(staged, dpi=110))
    return path


def plot_indices(out: str | Path, indices: list[dict], metrics: list[str]) -> Path:
    """Draw OUT/sensitivity.png: S1 and ST per parameter with their confidence intervals, a panel per metric."""
    out = Path(out)
    fig = Figure(figsize=(8.0, 0.6 + 2.8 * len(metrics)), layout="constrained")
    FigureCanvasAgg(fig)
    for k, metric in enumerate(metrics):
        ax = fig.add_subplot(len(metrics), 1, k + 1)
        items = [i for i in indices if i["metric"] == metric]
        pos = np.arange(len(items))
        for shift, name, colour in ((-0.18, "S1", "C0"), (0.18, "ST", "C1")):
            ax.bar(pos + shift, [i[name] for i in items], width=0.36, yerr=[i[f"{name}_conf"] for i in items],
                   capsize=3, color=colour, label=name)
        ax.set_xticks(pos, [i["parameter"] for i in items])
        ax.set_ylabel(f"{metric}\nSobol index")
        ax.axhline(0.0, color="0.6", lw=0.6)
        ax.legend(fontsize="small")
    path = out / "sensitivity.png"
    write_atomically(path, lambda staged: fig.savefig(staged, dpi=110))
    return path
