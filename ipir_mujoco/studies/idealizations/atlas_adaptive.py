"""Where the atlas spends its runs: MuJoCo designs placed near each threshold's boundary, and the exact
crossings of the equations along one parameter.

MuJoCo (:func:`explore`): each MuJoCo idealization starts from a small space-filling design (scrambled
Sobol points, :func:`initial_count`), then, round after round, gets a batch of designs where the surrogate
is least sure on which side of a threshold they lie: the candidate of largest min(p, 1 - p) over its metrics
and thresholds (p = P(|cost| < T), :mod:`.atlas_surrogate`), the batch's later designs chosen after the
earlier ones are added at the surrogate's own mean (kriging believer), so one batch spreads along the
boundary. An idealization stops when, for every metric and threshold, the designs whose side is not known at
95 % make up less than ``tolerance`` of the box (the boundary known to that accuracy), or when the budget of
runs (2 per design: the pair) is spent; the budget left by one that stops is shared by the others.

Equations along one parameter (:func:`refine_crossings`): between two neighbouring designs of the dense
sample on either side of a threshold the crossing is bracketed, then narrowed by k-section (k = the workers,
in parallel) until the bracket is below CROSSING_TOL of the range.
"""

from __future__ import annotations

import math
from typing import Callable

import numpy as np

from .atlas_surrogate import CONFIDENT, CostSurrogate, boundary_share

CROSSING_TOL = 1e-3  # of the parameter's range (unit coordinate): the equations' crossings' bracket
ROUNDS_MAX = 1000  # a bound on the adaptive loop's rounds whatever the budget (each round places >= 1 design)


def initial_count(d: int, budget_designs: int) -> int:
    """Space-filling MuJoCo designs an idealization starts with: 2 d + 2 (a line through the box needs a few,
    each parameter's effect two more), at most half of its share of the budget, at least 2."""
    return max(2, min(2 * d + 2, budget_designs // 2))


def acquisition(surrogates: dict, thresholds, U: np.ndarray) -> np.ndarray:
    """min(p, 1 - p), largest over the metrics and thresholds, at each design of U."""
    score = np.zeros(len(U))
    for s in surrogates.values():
        for t in thresholds:
            p = s.p_safe(U, t)
            score = np.maximum(score, np.minimum(p, 1 - p))
    return score


def uncertain(surrogates: dict, thresholds, U: np.ndarray) -> float:
    """The largest boundary share (designs whose side is not known at 95 %) over metrics and thresholds."""
    return max(boundary_share(s.p_safe(U, t)) for s in surrogates.values() for t in thresholds)


def explore(names: list[str], evaluate: Callable, fit: Callable, unit_designs: Callable, budget: int, d: int,
            thresholds, tolerance: float, candidates: np.ndarray, batch: int, seed: int,
            progress: Callable[[str], None]) -> dict:
    """Run the adaptive loop (module docstring). ``evaluate({name: U}) -> {name: rows}`` runs MuJoCo pairs at
    unit designs U, every idealization's at once; ``fit(name, U, rows) -> {metric: CostSurrogate}``;
    ``unit_designs(n, seed)``: n Sobol points.
    Returns {name: {"U", "rows", "surrogates", "stopped": why, "rounds"}}."""
    from scipy.stats import qmc  # noqa: F401 (unit_designs uses it; imported here to fail early)

    state = {}
    share = budget // 2 // max(1, len(names))  # designs per idealization, before any stops early
    spent, first = 0, {}
    for k, name in enumerate(names):
        n0 = min(initial_count(d, share), (budget - spent) // 2)
        first[name] = unit_designs(n0, seed + 101 + k) if n0 >= 1 else np.zeros((0, d))
        spent += 2 * len(first[name])
    rows = evaluate({name: U for name, U in first.items() if len(U)})
    for name, U in first.items():
        state[name] = {"U": U, "rows": rows.get(name, []), "surrogates": {}, "rounds": 0, "used": set(),
                       "stopped": None if len(U) else "no budget"}
    for _ in range(ROUNDS_MAX):
        active = []
        for name in names:
            st = state[name]
            if st["stopped"]:
                continue
            try:
                st["surrogates"] = fit(name, st["U"], st["rows"])
            except ValueError as exc:  # no design gave a cost: nothing to model
                st["stopped"] = f"no surrogate: {exc}"
                continue
            st["uncertain"] = uncertain(st["surrogates"], thresholds, candidates)
            if st["uncertain"] < tolerance:
                st["stopped"] = (f"boundary known: {100 * st['uncertain']:.2g} % of the box undecided "
                                 f"(< {100 * tolerance:g} %)")
            elif budget - spent < 2:
                st["stopped"] = f"budget spent ({100 * st['uncertain']:.2g} % of the box undecided)"
            else:
                active.append(name)
            progress(f"{name} (MuJoCo): {len(st['U'])} designs, {100 * st['uncertain']:.3g} % of the box "
                     f"undecided{'; ' + st['stopped'] if st['stopped'] else ''}")
        if not active:
            break
        per = max(1, min(batch, (budget - spent) // 2 // len(active)))
        picks, picks_index = {}, {}
        for name in active:
            surrogates = state[name]["surrogates"]
            chosen = []
            used = state[name]["used"]
            for _j in range(per):
                score = acquisition(surrogates, thresholds, candidates)
                score[list(used.union(chosen))] = -1.0  # never a design twice
                best = int(np.argmax(score))
                chosen.append(best)
                for s in surrogates.values():
                    s.believe(candidates[best])
            picks[name] = candidates[chosen]
            picks_index[name] = chosen
        for name in list(picks):
            if budget - spent < 2 * len(picks[name]):
                picks[name] = picks[name][:max(0, (budget - spent) // 2)]
            spent += 2 * len(picks[name])
            if not len(picks[name]):
                del picks[name]
        if not picks:
            break
        rows = evaluate(picks)
        for name, U in picks.items():
            st = state[name]
            st["used"].update(int(i) for i in picks_index[name][:len(U)])
            st["rows"] = st["rows"] + rows[name]
            st["U"] = np.vstack([st["U"], U])
            st["rounds"] += 1
    return state


def refine_crossings(u: np.ndarray, cost: np.ndarray, threshold: float, evaluate: Callable, workers: int,
                     tol: float = CROSSING_TOL) -> list[list[float]]:
    """Crossings of |cost| = threshold along the one parameter (unit coordinate u): [[u*, lo, hi]], each
    bracketed between the dense sample's neighbours and narrowed by k-section through ``evaluate(U) ->
    costs`` (None where a pair gave nothing) to ``tol``."""
    order = np.argsort(u)
    u, above = u[order], np.abs(cost[order]) > threshold
    ok = np.isfinite(cost[order])
    u, above = u[ok], above[ok]
    out = []
    for k in np.flatnonzero(above[1:] != above[:-1]):
        lo, hi, lo_above = float(u[k]), float(u[k + 1]), bool(above[k])
        while hi - lo > tol:
            inner = np.linspace(lo, hi, max(2, workers) + 2)[1:-1]
            values = evaluate(inner[:, None])
            sides = [None if v is None or not math.isfinite(v) else abs(v) > threshold for v in values]
            if any(s is None for s in sides):  # a pair failed inside the bracket: keep what is known
                break
            new_lo, new_hi = lo, hi
            for x, s in zip(inner, sides):  # the first crossing of the bracket
                if s == lo_above:
                    new_lo = float(x)
                else:
                    new_hi = float(x)
                    break
            lo, hi = new_lo, new_hi
        out.append([0.5 * (lo + hi), lo, hi])
    return out


__all__ = ["CONFIDENT", "CostSurrogate", "explore", "refine_crossings"]
