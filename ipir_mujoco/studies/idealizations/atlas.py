"""The idealization atlas: over a box of designs, where each of the paper's idealizations costs less than a
threshold, measured against the models that remove it, and which parameters make it fail.

For each idealization (:mod:`.atlas_space`: which two rungs of the model ladder measure it) and metric, the
cost is (idealized - real) / |real|; a design is safe for a threshold T where |cost| < T.

* The equations (milliseconds a pair): a dense quasi-random sample of the box, ``samples`` x (d + 2)
  designs for d varied parameters (Saltelli's scheme, SALib, whose points are scrambled Sobol points and
  also give the Sobol indices; scrambled Sobol points where SALib is not installed). The safe fraction is
  the sample's share of safe designs, its interval Wilson's 95 % binomial interval; along one parameter the
  crossings are narrowed on the equations themselves to 1e-3 of the range (:mod:`.atlas_adaptive`).
* MuJoCo (seconds a pair): ``budget`` runs, placed adaptively near the boundaries with a Gaussian-process
  surrogate (:mod:`.atlas_surrogate`, :mod:`.gp`) that gives the safe fraction's interval, the boundary and
  its uncertainty; the designs each region got (safe, unsafe, undecided) are counted.
* Sensitivity: Sobol first-order and total indices (SALib, as ``ipir-mujoco sensitivity``) of each |cost|:
  on the equations' sample directly, on MuJoCo's surrogate mean for MuJoCo (say so: ``"of": "surrogate"``).

Files: ``OUT/samples.csv`` (:mod:`.atlas_eval`: every pair, streamed, resumable), ``OUT/atlas.json``::

    {"idealizations": {NAME: {METRIC: {"threshold", "safe_fraction", "safe_fraction_interval": [lo, hi],
        "crossings": {PARAM: [values]}, "crossings_interval": {PARAM: [[value, lo, hi]]} (one varied
        parameter only), "sensitivity": {PARAM: {S1, S1_conf, ST, ST_conf}}, "runs", "measured_by":
        "equations" | "mujoco", "designs", "runs_by_region": {safe, unsafe, boundary} (MuJoCo),
        "by_threshold": [{threshold, safe_fraction, safe_fraction_interval, crossings...}] (every
        threshold, smallest first; the top level repeats the smallest), "equations": {...} (where MuJoCo
        measured it too)}}},
     "settings": ..., "fingerprint", "status", "wall_s", "runs": {equations, mujoco}, "stopped": {NAME: why}}
"""

from __future__ import annotations

import hashlib
import json
import math
import os
import time
import warnings
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Callable

import numpy as np

from ipir_mujoco.core.errors import ParameterError, ParameterTypeError
from ipir_mujoco.core.options import heartbeat
from ipir_mujoco.core.params import RobotParams, check_real, check_whole
from ipir_mujoco.core.results import write_json

from ..figure_errors import unusable_counts, why_unusable
from ...output import check_output_dir, study_folder
from .atlas_adaptive import explore, refine_crossings
from .atlas_eval import Samples
from .atlas_space import (DEFAULT_BUDGET, DEFAULT_METRICS, DEFAULT_SAMPLES, DEFAULT_TOLERANCE, IDEALIZATIONS,
                          MOTOR_METRICS, NAMES, TORQUE_METRICS, allowed)
from .atlas_surrogate import MAX_POINTS, CostSurrogate, regions, safe_fraction
from ..sweeps.sweep import refuse_all_invalid
from ..design.sensitivity import SALIB_MISSING
from ..sweeps.sweep_space import Axis, T_END_STEADY

CANDIDATES = 4096  # space-filling designs on which the surrogates are read (safe fractions, placement)


@dataclass(frozen=True)
class Atlas:
    """What an atlas covers (module docstring); every field checked here."""

    axes: tuple[Axis, ...]
    base: RobotParams = field(default_factory=RobotParams)
    idealizations: tuple[str, ...] = ()  # () = every one the options allow
    metrics: tuple[str, ...] = ()  # () = the drive's defaults
    thresholds: tuple[float, ...] = (0.01,)
    budget: int = DEFAULT_BUDGET
    samples: int = DEFAULT_SAMPLES
    seed: int = 0
    t_end: float | None = None  # s; None: 1 s under constant torque, the cap T_END_STEADY under the motor
    tolerance: float = DEFAULT_TOLERANCE

    def __post_init__(self) -> None:
        set_ = lambda k, v: object.__setattr__(self, k, v)  # noqa: E731
        if not isinstance(self.axes, (tuple, list)) or not all(isinstance(a, Axis) for a in self.axes):
            raise ParameterTypeError(f"axes={self.axes!r} is not a tuple of Axis; allowed: e.g. "
                                     "(parse_vary('L=0.1:0.3'),)")
        if not self.axes:
            raise ParameterError("atlas needs at least one --vary NAME=LO:HI[:log]")
        for axis in self.axes:
            if not axis.is_range:
                raise ParameterError(f"--vary {axis.name}: give a range NAME=LO:HI[:log] (the atlas samples it)")
        names = [a.name for a in self.axes]
        if len(set(names)) != len(names):
            raise ParameterError(f"--vary names a parameter twice: {names}")
        set_("budget", check_whole("budget", self.budget, low=0, high=100_000))
        set_("samples", check_whole("samples", self.samples, low=2, high=4096))
        set_("seed", check_whole("seed", self.seed, low=0))
        set_("tolerance", check_real("boundary_tol", self.tolerance, high=0.5))
        thresholds = tuple(check_real("threshold", t, high=10.0) for t in self.thresholds) or (0.01,)
        set_("thresholds", tuple(sorted(set(thresholds))))
        steady = self.base.drive != "torque"
        t_end = self.t_end if self.t_end is not None else (T_END_STEADY if steady else 1.0)
        set_("t_end", check_real("t_end", t_end, high=1000.0, unit="s"))
        allowed_metrics = MOTOR_METRICS if steady else TORQUE_METRICS
        metrics = tuple(m.strip() for m in self.metrics) or DEFAULT_METRICS[steady]
        for m in metrics:
            if m not in allowed_metrics:
                other = " (a steady-state metric: use --drive motor)" if m in MOTOR_METRICS else (
                    " (runs under the motor stop at their steady state: compare steady figures)"
                    if m in TORQUE_METRICS else "")
                raise ParameterError(f"--metric {m!r} is unknown for --drive {self.base.drive}{other}; allowed: "
                                     f"{', '.join(allowed_metrics)}")
        set_("metrics", tuple(dict.fromkeys(metrics)))
        refused = allowed(self.base, set(names), self.budget)
        chosen = tuple(i.strip() for i in self.idealizations)
        for name in chosen:
            if name not in IDEALIZATIONS:
                raise ParameterError(f"--idealization {name!r} is unknown; allowed: {', '.join(NAMES)}")
            if name in refused:
                raise ParameterError(f"--idealization {name} is not allowed with these options: {refused[name]}")
        set_("idealizations", tuple(dict.fromkeys(chosen)) or tuple(n for n in NAMES if n not in refused))

    @property
    def until_steady(self) -> bool:
        return self.base.drive != "torque"

    @property
    def names(self) -> list[str]:
        return [a.name for a in self.axes]

    def mujoco_names(self) -> list[str]:
        return [n for n in self.idealizations if IDEALIZATIONS[n].mujoco is not None and self.budget > 0]

    def to_json(self) -> dict:
        return {"axes": [asdict(a) for a in self.axes], "base": self.base.as_dict(),
                "idealizations": list(self.idealizations), "metrics": list(self.metrics),
                "thresholds": list(self.thresholds), "budget": self.budget, "samples": self.samples,
                "seed": self.seed, "t_end": self.t_end, "until_steady": self.until_steady,
                "boundary_tol": self.tolerance}

    def fingerprint(self) -> str:
        return hashlib.sha256(json.dumps(self.to_json(), sort_keys=True).encode()).hexdigest()[:16]

    # the unit box <-> parameter values (log ranges in log space)
    def values(self, U: np.ndarray) -> np.ndarray:
        U = np.atleast_2d(U)
        out = np.empty_like(U, dtype=float)
        for k, a in enumerate(self.axes):
            out[:, k] = (a.low * (a.high / a.low) ** U[:, k]) if a.log else a.low + U[:, k] * (a.high - a.low)
        return out

    def designs(self, U: np.ndarray) -> list[dict]:
        return [dict(zip(self.names, map(float, row))) for row in self.values(U)]


def _salib():
    try:
        from SALib.analyze import sobol as analyze
        from SALib.sample import sobol as sample
    except ImportError:
        return None
    return sample, analyze


def unit_sobol(n: int, d: int, seed: int) -> np.ndarray:
    from scipy.stats import qmc

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # scipy's note when n is not a power of 2
        return qmc.Sobol(d=d, scramble=True, seed=seed).random(n)


def dense_sample(d: int, samples: int, seed: int) -> tuple[np.ndarray, bool]:
    """The equations' designs in the unit box, and whether they are Saltelli's (Sobol indices possible)."""
    salib = _salib()
    if salib is None:
        return unit_sobol(samples * (d + 2), d, seed), False
    problem = {"num_vars": d, "names": [f"u{k}" for k in range(d)], "bounds": [[0.0, 1.0]] * d}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return salib[0].sample(problem, samples, calc_second_order=False, seed=seed), True


def sobol_indices(names: list[str], y: np.ndarray, seed: int) -> dict:
    """{PARAM: {S1, S1_conf, ST, ST_conf}} of y over a Saltelli sample of the unit box (95 % bootstrap)."""
    _, analyze = _salib()
    problem = {"num_vars": len(names), "names": names, "bounds": [[0.0, 1.0]] * len(names)}
    with warnings.catch_warnings(), np.errstate(all="ignore"):
        warnings.simplefilter("ignore")
        result = analyze.analyze(problem, y, calc_second_order=False, conf_level=0.95, seed=seed + 1)
    clean = lambda v: float(v) if math.isfinite(v) else None  # noqa: E731
    return {n: {c: clean(result[c][k]) for c in ("S1", "S1_conf", "ST", "ST_conf")} for k, n in enumerate(names)}


def wilson(safe: int, n: int) -> list[float]:
    """Wilson's 95 % interval of a proportion safe / n."""
    if n == 0:
        return [0.0, 1.0]
    z, p = 1.96, safe / n
    centre = (p + z * z / (2 * n)) / (1 + z * z / n)
    half = z * math.sqrt(p * (1 - p) / n + z * z / (4 * n * n)) / (1 + z * z / n)
    return [max(0.0, min(p, centre - half)), min(1.0, max(p, centre + half))]  # p inside it, whatever the rounding


def top_drivers(entry: dict, count: int = 2) -> str:
    """'L (ST 0.95 +- 0.10), m2 (...)': the parameters of largest total Sobol index whose 95 % interval
    excludes 0 ('-' if none: too few samples to tell, or a cost that does not vary); where the indices were not
    computed, 'not computed: ' and why (SALib missing: the command that adds it)."""
    skipped = entry.get("sensitivity", {}).get("skipped")
    if skipped:
        return f"not computed: {skipped}"
    ranked = sorted(((p, v) for p, v in entry.get("sensitivity", {}).items() if isinstance(v, dict)
                     and v.get("ST") is not None and v.get("ST_conf") is not None and v["ST"] - v["ST_conf"] > 0),
                    key=lambda pv: -pv[1]["ST"])
    return ", ".join(f"{p} (ST {v['ST']:.2f} +- {v['ST_conf']:.2f})" for p, v in ranked[:count]) or "-"


def _costs(rows: list[dict], metric: str) -> np.ndarray:
    return np.array([np.nan if r["cost"].get(metric) is None else r["cost"][metric] for r in rows], dtype=float)


OUTPUT_FILES = ("atlas.json", "samples.csv")  # its declaration's (atlas_command), held equal by a test


def run_atlas(atlas: Atlas, out: str | Path, *, resume: bool = False, workers: int | None = None,
              progress: Callable[[str], None] = lambda _m: None, show_bars: bool = True) -> dict:
    """Run the atlas, write OUT/samples.csv and OUT/atlas.json; return atlas.json's content plus, under
    ``"_surrogates"`` {(name, fidelity): {metric: CostSurrogate}}, ``"_measured"`` {(name, fidelity): (unit
    designs, rows)} and ``"_candidates"`` (the space-filling designs the surrogates are read on), for the figures
    (not written)."""
    started = time.perf_counter()
    if workers is not None:
        check_whole("workers", workers, low=1, high=1024)
    workers = workers or os.cpu_count() or 1
    out = check_output_dir(out, files=OUTPUT_FILES)
    meta = out / "atlas.json"
    fingerprint = atlas.fingerprint()
    _check_resume(out, fingerprint, resume)
    d = len(atlas.axes)
    U, saltelli = dense_sample(d, atlas.samples, atlas.seed)
    designs = atlas.designs(U)
    refuse_all_invalid(atlas.base, designs)
    with study_folder(out):  # locked: a second run on this folder is refused
        _check_resume(out, fingerprint, resume)  # again, under the lock
        return _run(atlas, out, meta, fingerprint, U, saltelli, designs, resume, workers, progress, show_bars,
                    started)


def _check_resume(out: Path, fingerprint: str, resume: bool) -> None:
    """An atlas resumed in a folder that holds another one, or started over one, refused in one line."""
    if resume and out.is_dir() and any(out.iterdir()):
        try:
            previous = json.loads((out / "atlas.json").read_text(encoding="utf-8")).get("fingerprint")
        except (OSError, ValueError, UnicodeDecodeError, AttributeError):
            previous = None
        if previous != fingerprint:
            raise ParameterError(f"{str(out)!r} holds no atlas with these settings; resume needs the same one")
    elif (out / "samples.csv").exists():
        raise ParameterError(f"{str(out / 'samples.csv')!r} exists; use --resume to complete it, or another --out")


def _run(atlas: Atlas, out: Path, meta: Path, fingerprint: str, U: np.ndarray, saltelli: bool, designs: list,
         resume: bool, workers: int, progress, show_bars: bool, started: float) -> dict:
    d = len(atlas.axes)
    write_json(meta, {"fingerprint": fingerprint, "settings": atlas.to_json(), "status": "running"})
    candidates = unit_sobol(CANDIDATES, d, atlas.seed + 7)
    scale = min(atlas.thresholds)
    result: dict = {"idealizations": {}, "fingerprint": fingerprint, "settings": atlas.to_json(), "stopped": {}}
    surrogates: dict = {}
    measured: dict = {}  # (name, fidelity): (unit designs, rows), for the figures
    with Samples(out / "samples.csv", atlas.names, atlas.metrics, atlas.base, atlas.t_end, atlas.until_steady,
                 resume, workers, show_bars) as store:
        def fit(name: str, fidelity: str, Uf: np.ndarray, rows: list[dict], limit: int | None = None) -> dict:
            fitted = surrogates.setdefault((name, fidelity), {})
            prior = surrogates.get((name, "equations"), {}) if fidelity == "mujoco" else {}
            for m in atlas.metrics:
                s = fitted.get(m) or CostSurrogate(scale, prior.get(m))
                fitted[m] = s.update(Uf[:limit], _costs(rows, m)[:limit])
            return fitted

        for name in atlas.idealizations:
            if IDEALIZATIONS[name].equations is None:
                continue
            distinct = len({tuple(repr(float(d[n])) for n in atlas.names) for d in designs})
            progress(f"{name} (equations): the sample's {distinct} designs (Saltelli's {len(designs)} points, some "
                     "the same), each run idealized and real; then designs placed at the crossings")
            with heartbeat(progress, f"{name} (equations)"):  # the runs, the fits and the indices: tens of s
                rows = store.evaluate(name, "equations", designs)
                measured[(name, "equations")] = (U, rows)
                entry = result["idealizations"].setdefault(name, {})
                try:
                    fit(name, "equations", U, rows, MAX_POINTS)
                except ValueError:
                    pass  # no design gave a cost: reported per metric below
                for m in atlas.metrics:
                    entry[m] = _equations_entry(atlas, name, m, U, rows, saltelli, store, workers)
            for m in atlas.metrics:  # the dense sample and every metric's crossings: the idealization's runs
                entry[m]["runs"] = 2 * store.count(name, "equations")

        mj_names = atlas.mujoco_names()
        if mj_names:
            def evaluate(asked: dict) -> dict:
                names = list(asked)
                rows = store.evaluate_many([(n, "mujoco", atlas.designs(asked[n])) for n in names])
                return dict(zip(names, rows))

            state = explore(mj_names, evaluate, lambda n, Um, rows: fit(n, "mujoco", Um, rows),
                            lambda n, s: unit_sobol(n, d, s), atlas.budget, d, atlas.thresholds, atlas.tolerance,
                            candidates, max(1, workers), atlas.seed, progress)
            for name in mj_names:
                st = state[name]
                measured[(name, "mujoco")] = (st["U"], st["rows"])
                result["stopped"][name] = st["stopped"]
                entry = result["idealizations"].setdefault(name, {})
                for m in atlas.metrics:
                    mj = _mujoco_entry(atlas, st, m, candidates)
                    if m in entry:
                        mj["equations"] = entry[m]
                    entry[m] = mj
        result["runs"] = dict(store.runs)
    result.update(status="done", wall_s=time.perf_counter() - started, workers=workers)
    write_json(meta, result)
    result["_surrogates"], result["_measured"], result["_candidates"] = surrogates, measured, candidates
    return result


def _by_threshold(atlas: Atlas, entry: dict) -> dict:
    """The contract's top level (the first threshold) beside every threshold's figures."""
    first = entry["by_threshold"][0]
    return {**{k: v for k, v in first.items()}, **entry}


def _equations_entry(atlas: Atlas, name: str, metric: str, U: np.ndarray, rows: list[dict], saltelli: bool,
                     store: Samples, workers: int) -> dict:
    cost = _costs(rows, metric)
    ok = np.isfinite(cost)
    entry: dict = {"measured_by": "equations", "designs": int(len(rows)), "missing": int((~ok).sum()),
                   "by_threshold": []}
    for t in atlas.thresholds:
        safe = int(np.sum(np.abs(cost[ok]) < t))
        item = {"threshold": t, "safe_fraction": safe / max(1, int(ok.sum())),
                "safe_fraction_interval": wilson(safe, int(ok.sum()))}
        if len(atlas.axes) == 1 and ok.any():
            def evaluate(Ux: np.ndarray) -> list:
                return [r["cost"].get(metric) for r in store.evaluate(name, "equations", atlas.designs(Ux),
                                                                      label=f"{name} crossing")]

            # the range's two ends too: a crossing between an end and the sample's first design is not missed
            ends = np.array([[0.0], [1.0]])
            end_costs = np.array([np.nan if c is None else c for c in evaluate(ends)], dtype=float)
            found = refine_crossings(np.concatenate([U[:, 0], ends[:, 0]]), np.concatenate([cost, end_costs]), t,
                                     evaluate, workers)
            values = [atlas.values(np.array([[x]]))[0, 0] for x, _, _ in found]
            item["crossings"] = {atlas.names[0]: [float(v) for v in values]}
            item["crossings_interval"] = {atlas.names[0]: [
                [float(v), *map(float, atlas.values(np.array([[lo], [hi]]))[:, 0])] for v, (_, lo, hi)
                in zip(values, found)]}
        entry["by_threshold"].append(item)
    if saltelli and ok.all():
        entry["sensitivity"] = {"of": "equations", **sobol_indices(atlas.names, np.abs(cost), atlas.seed)}
    elif saltelli:
        entry["sensitivity"] = {"of": "equations", "skipped": f"{int((~ok).sum())} designs gave no value"}
    else:
        entry["sensitivity"] = {"skipped": SALIB_MISSING}
    return _by_threshold(atlas, entry)


def _mujoco_entry(atlas: Atlas, st: dict, metric: str, candidates: np.ndarray) -> dict:
    rows = st["rows"]
    entry: dict = {"measured_by": "mujoco", "designs": len(rows), "runs": 2 * len(rows), "stopped": st["stopped"],
                   "missing": int(np.sum(~np.isfinite(_costs(rows, metric)))), "by_threshold": []}
    # the pairs it could not use and why; the largest error bar of a cost it did use (MuJoCo's rigid limit)
    entry["unusable"] = unusable_counts(why_unusable(r["error"]) for r in rows if r["error"])
    bars = [r["cost_error"].get(metric) for r in rows if r.get("cost_error", {}).get(metric) is not None]
    entry["cost_error_max"] = max(bars) if bars else None
    s = st["surrogates"].get(metric)
    if s is None:
        entry["by_threshold"] = [{"threshold": t, "safe_fraction": None, "safe_fraction_interval": None}
                                 for t in atlas.thresholds]
        entry["sensitivity"] = {"skipped": "no surrogate"}
        return _by_threshold(atlas, entry)
    from .atlas_surrogate import crossings_1d

    for t in atlas.thresholds:
        frac, interval = safe_fraction(s.p_safe(candidates, t))
        item = {"threshold": t, "safe_fraction": frac, "safe_fraction_interval": interval,
                "runs_by_region": {k: 2 * v for k, v in regions(s.p_safe(st["U"], t)).items()}}
        if len(atlas.axes) == 1:
            found = crossings_1d(s, t)
            vals = [[float(v) for v in atlas.values(np.array([[x], [lo], [hi]]))[:, 0]] for x, lo, hi in found]
            item["crossings"] = {atlas.names[0]: [v[0] for v in vals]}
            item["crossings_interval"] = {atlas.names[0]: vals}
        entry["by_threshold"].append(item)
    salib = _salib()
    if salib is not None:
        d = len(atlas.axes)
        problem = {"num_vars": d, "names": atlas.names, "bounds": [[0.0, 1.0]] * d}
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            points = salib[0].sample(problem, 512, calc_second_order=False, seed=atlas.seed)
        entry["sensitivity"] = {"of": "surrogate", **sobol_indices(atlas.names, s.cost(points)[0], atlas.seed)}
    else:
        entry["sensitivity"] = {"skipped": SALIB_MISSING}
    return _by_threshold(atlas, entry)
