"""Global sensitivity: Sobol first-order (S1) and total (ST) indices of metrics over parameter ranges.

Saltelli's sampling (SALib 1.6, ``SALib.sample.sobol``, no second-order terms) draws N * (D + 2)
designs for D parameters; they run in one engine on the sweep's pool
(:class:`~ipir_mujoco.studies.design_eval.Evaluator`, streamed to ``OUT/evaluations.csv``, resumable),
and ``SALib.analyze.sobol`` gives every index with its 95 % bootstrap confidence half-width. S1 is the
share of a metric's variance a parameter explains alone; ST the share it takes part in, interactions
included (ST ~ 0: the metric does not depend on it over these ranges).

A metric a design does not give (a stalled design's energy per metre, a failed run) leaves its
indices undefined: the study refuses it in one line, naming how many designs lack it.
"""

from __future__ import annotations

import csv
import hashlib
import json
import math
import os
import warnings
from dataclasses import asdict
from pathlib import Path

import numpy as np

from ipir_mujoco.core.errors import ParameterError, ParameterTypeError, SimulationError
from ipir_mujoco.core.options import check_type
from ipir_mujoco.core.params import RobotParams, check_whole
from ipir_mujoco.core.results import write_json

from ..output import check_output_dir, study_folder, write_atomically
from .design_eval import Evaluator, check_key, key_value, usable
from .sweep_space import Axis, Study

COLUMNS = ("metric", "parameter", "S1", "S1_conf", "ST", "ST_conf")


# SALib is a dependency of the package: missing, only from an environment changed after the install
SALIB_MISSING = "needs SALib, a dependency of ipir-mujoco missing from this environment: pip install 'SALib>=1.6,<1.7'"


def _salib():
    try:
        from SALib.analyze import sobol as analyze
        from SALib.sample import sobol as sample
    except ImportError:
        raise ParameterError(f"sensitivity {SALIB_MISSING}") from None
    return sample, analyze


OUTPUT_FILES = ("evaluations.csv", "indices.csv", "sensitivity.json", "sensitivity.png")


def run_sensitivity(axes: tuple[Axis, ...], metrics: tuple[str, ...], out: str | Path, *,
                    base: RobotParams | None = None, engine: str = "analytic-unilateral", t_end: float = 1.0,
                    until_steady: bool = False, samples: int = 64, seed: int = 0, resume: bool = False,
                    workers: int | None = None, progress: bool = True, executor=None, figure=None) -> list[dict]:
    """Sobol indices of ``metrics`` over the ranges ``axes``; writes OUT/indices.csv, sensitivity.json,
    evaluations.csv; returns the rows of indices.csv.

    ``figure``: a function of the folder and the indices that draws into it (the command line's
    sensitivity.png), called before sensitivity.json says ``"status": "done"``, which it says last. Every
    argument, the folder and the file to resume are checked before the first design; the folder is locked while
    the study runs."""
    base = RobotParams() if base is None else base
    if not isinstance(axes, (tuple, list)) or not all(isinstance(a, Axis) for a in axes):
        raise ParameterTypeError(f"axes={axes!r} is not a tuple of Axis; allowed: e.g. (parse_vary('L=0.1:0.3'),)")
    if not isinstance(metrics, (tuple, list)) or not all(isinstance(m, str) for m in metrics):
        raise ParameterTypeError(f"metrics={metrics!r} is not a tuple of metric names; allowed: e.g. "
                             "('steady_speed_m_s',)")
    if not metrics:
        raise ParameterError("sensitivity needs at least one --metric KEY")
    metrics = tuple(check_key(m, f"metric {m!r}") for m in metrics)
    check_type("out", out, (str, os.PathLike), "the path of the results folder")
    for name, flag in (("until_steady", until_steady), ("resume", resume), ("progress", progress)):
        check_type(name, flag, bool, "True or False")
    if figure is not None and not callable(figure):
        raise ParameterTypeError(f"figure={figure!r} is not callable; allowed: a function of the results folder and "
                             "the indices, or None")
    if any(not a.is_range for a in axes):
        raise ParameterError("sensitivity needs every --vary as a range NAME=LO:HI")
    if any(a.log for a in axes):
        raise ParameterError("sensitivity samples ranges uniformly; allowed: NAME=LO:HI without :log")
    samples = check_whole("samples", samples, low=2, high=65536)
    if workers is not None:
        check_whole("workers", workers, low=1, high=1024)
    study = Study(tuple(axes), base, (engine,), t_end, sample=1, seed=seed, until_steady=until_steady)
    sample, analyze = _salib()
    out = check_output_dir(out, files=OUTPUT_FILES)
    settings = {"axes": [asdict(a) for a in axes], "metrics": list(metrics), "base": base.as_dict(),
                "engine": engine, "t_end": t_end, "until_steady": until_steady, "samples": samples, "seed": seed}
    fingerprint = hashlib.sha256(json.dumps(settings, sort_keys=True).encode()).hexdigest()[:16]
    _check_resume(out, fingerprint, resume)
    problem = {"num_vars": len(axes), "names": [a.name for a in axes], "bounds": [[a.low, a.high] for a in axes]}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # SALib's note when N is not a power of 2: the estimates stay unbiased
        points = sample.sample(problem, samples, calc_second_order=False, seed=seed)
    names = problem["names"]
    with study_folder(out):
        _check_resume(out, fingerprint, resume)  # again, under the lock
        ev = Evaluator(out / "evaluations.csv", names, study.base, engine, study.t_end, study.dt_out,
                       {"until_steady": until_steady}, resume, workers, progress, label="sensitivity",
                       total=len(points), executor=executor, axes=tuple(axes))
        meta = out / "sensitivity.json"
        if not (resume and meta.is_file()):  # resumed: the same study's (_check_resume), left as it is
            write_json(meta, {"fingerprint": fingerprint, "settings": settings, "status": "running"})
        with ev:
            rows = ev.evaluate([dict(zip(names, map(float, p))) for p in points])
        indices = _indices(problem, metrics, rows, study, seed, out)
        write_atomically(out / "indices.csv", lambda staged: _write_indices(staged, indices))
        if figure is not None:
            figure(out, indices)
        write_json(meta, {"fingerprint": fingerprint, "settings": settings, "status": "done", "evaluations": len(rows),
                          "indices": [{k: (None if isinstance(v, float) and not math.isfinite(v) else v)
                                       for k, v in i.items()} for i in indices]})  # last: "done" once all is written
    return indices


def _check_resume(out: Path, fingerprint: str, resume: bool) -> None:
    meta = out / "sensitivity.json"
    if resume and out.is_dir() and any(out.iterdir()):
        try:
            previous = json.loads(meta.read_text(encoding="utf-8")).get("fingerprint")
        except (OSError, ValueError, UnicodeDecodeError, AttributeError):
            previous = None
        if previous != fingerprint:
            raise ParameterError(f"{str(out)!r} holds no sensitivity study with these settings; resume needs the "
                                 "same one")
    elif (out / "evaluations.csv").exists():
        raise ParameterError(f"{str(out / 'evaluations.csv')!r} exists; use --resume, or another --out")


def _indices(problem: dict, metrics: tuple[str, ...], rows: list[dict], study: Study, seed: int,
             out: Path) -> list[dict]:
    _, analyze = _salib()
    indices = []
    for metric in metrics:
        y = np.array([key_value(metric, r, study.base) if usable(key_value(metric, r, study.base)) else math.nan
                      for r in rows], dtype=float)
        missing = int(np.isnan(y).sum())
        if missing:
            raise SimulationError(f"{metric}: {missing} of {len(y)} designs give no value (stalled or failed; see "
                                  f"{out / 'evaluations.csv'}); narrow the ranges")
        with warnings.catch_warnings(), np.errstate(all="ignore"):
            warnings.simplefilter("ignore")
            # the bootstrap seeded too (SALib takes seed=0 for "unseeded"): the intervals repeat run to run
            result = analyze.analyze(problem, y, calc_second_order=False, conf_level=0.95, seed=seed + 1)
        for k, name in enumerate(problem["names"]):
            indices.append({"metric": metric, "parameter": name,
                            **{c: float(result[c][k]) for c in ("S1", "S1_conf", "ST", "ST_conf")}})
    return indices


def _write_indices(path: Path, indices: list[dict]) -> None:
    with path.open("w", newline="", encoding="utf-8") as fh:
        writer = csv.DictWriter(fh, fieldnames=COLUMNS)
        writer.writeheader()
        writer.writerows({k: (repr(v) if isinstance(v, float) else v) for k, v in i.items()} for i in indices)
