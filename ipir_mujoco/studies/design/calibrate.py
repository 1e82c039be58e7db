"""Fit parameters to a measured run by least squares, with intervals, correlations and identifiability.

:func:`calibrate` runs one engine (default the equations with one-way clutches, ``analytic-unilateral``) on the
base parameters with the ``--fit`` parameters free in their ranges, interpolates each run's series onto the
measured times (:mod:`.measured`) and minimises the sum of squared residuals of every measured column, each
divided by its noise (``scipy.optimize.least_squares``, trust-region reflective within the ranges, Jacobian by
forward differences of relative step :data:`DIFF_STEP`, far above the equations' solver tolerance of 1e-10).

The columns' noise is not given: a first fit weighs each column by its range; each column's noise is then the
RMS of its residuals there (the part of the measurement the model cannot follow), floored at :data:`NOISE_FLOOR`
of its range, and a second fit, started from the first, weighs each column by it. The covariance of the fitted
parameters is s^2 (J^T J)^-1 (J the Jacobian of the weighted residuals at the optimum, s^2 the residual variance
per degree of freedom), the intervals +- t(0.975, n - p) times its diagonal's root, the correlation matrix its
normalised form.

Identifiability: the singular values of J with each parameter scaled by its value (or range); a parameter the
data cannot determine has a relative singular value below :data:`SINGULAR_TOL` in the direction it dominates, or
an interval wider than its fit range. Such parameters are listed in ``not_identifiable`` and named in a warning
(their value is then whatever the start or the range bound gave, not a measurement).

Files (:func:`write_files`): ``calibration.json`` (``estimates`` {NAME: value, interval}, ``correlation``
{"names", "matrix"}, ``not_identifiable``, ``residual_rms`` {COLUMN: ...}, and the noise, singular values, cost),
``posterior.toml`` (a ``[dist]`` of ``truncnormal:VALUE:SE:LO:HI`` per parameter and the ``[correlation]``:
``uncertainty --dist-file`` reads it), ``calibration.png`` (the measured columns with the fitted run, and the
residuals over time in noise units).
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Callable

import numpy as np

from ipir_mujoco import registry
from ipir_mujoco.core.checks import check_text
from ipir_mujoco.core.errors import ParameterError, SimulationError
from ipir_mujoco.core.params import PARAMETER_NAMES, RobotParams, allowed_text
from ipir_mujoco.core.results import write_json

from ..figure_errors import unusable_counts, why_unusable
from ..comparison.measured import Measured
from ..uq.uq_dists import inside

DIFF_STEP = 1e-5  # relative finite-difference step: its error ~ rtol / step = 1e-5 of a derivative at rtol 1e-10
NOISE_FLOOR = 1e-9  # a column's noise is at least this share of its range (a noiseless synthetic run)
SINGULAR_TOL = 1e-4  # relative singular value below which a direction of the parameters is not identifiable
MAX_FEV = 200  # runs per fit stage: a few parameters converge in tens


@dataclass(frozen=True)
class FitRange:
    name: str
    low: float
    high: float


def parse_fit(text: str) -> FitRange:
    """``NAME=LO:HI`` inside the parameter's allowed range, or a one-line ParameterError."""
    name, sep, spec = check_text("fit", text, "NAME=LO:HI").partition("=")
    name = name.strip()
    if not sep:
        raise ParameterError(f"--fit {text!r} is malformed; expected NAME=LO:HI")
    if name not in PARAMETER_NAMES or name in ("drive", "feedforward"):
        raise ParameterError(f"--fit {text!r}: unknown or non-numeric parameter {name!r}; 'ipir-mujoco params' lists "
                             "them")
    parts = spec.split(":")
    try:
        low, high = (float(p) for p in parts)
    except ValueError:
        raise ParameterError(f"--fit {text!r}: expected two numbers LO:HI") from None
    if not (math.isfinite(low) and math.isfinite(high) and low < high):
        raise ParameterError(f"--fit {text!r}: LO and HI must be finite with LO < HI")
    if not (inside(name, low) and inside(name, high)):
        raise ParameterError(f"--fit {text!r} reaches outside {name}'s allowed range {allowed_text(name)}; "
                             "allowed: LO:HI inside it")
    return FitRange(name, low, high)


class _Model:
    """The engine's run at parameter vector ``x``, interpolated onto the measured times: residuals / noise."""

    def __init__(self, measured: Measured, fits: list[FitRange], base: RobotParams, engine: str, progress=None):
        self.measured, self.fits, self.base, self.engine = measured, fits, base, engine
        self.progress = progress
        self.t_end = float(measured.t[-1])
        self.dt_out = min(1e-3, self.t_end / 200)
        self.scale = {c: max(float(np.ptp(v)), float(np.max(np.abs(v))), 1e-12) for c, v in measured.columns.items()}
        self.noise = dict(self.scale)
        self.runs = 0
        # MuJoCo answers every run ('warn'): a run whose accuracy check failed (its rigid limit on finite grip not
        # trustworthy, a monitor figure) is used with that recorded, not dropped; counted by why
        self.mujoco = registry.variant(engine).is_mujoco
        self.flagged: list[str] = []
        self.figure_errors: dict = {}

    def params(self, x) -> RobotParams:
        return self.base.replace(**{f.name: float(v) for f, v in zip(self.fits, x)})

    def series(self, x) -> dict[str, np.ndarray]:
        self.runs += 1
        if self.progress is not None and self.runs % 10 == 0:
            self.progress(f"{self.runs} runs of the model")
        try:
            run = registry.run(self.engine, self.params(x), self.t_end, dt_out=self.dt_out,
                               **({"accuracy": "warn"} if self.mujoco else {}))
        except (ParameterError, ValueError) as exc:
            raise ParameterError(f"calibrate: the model refuses {self._where(x)}: {' '.join(str(exc).split())}"
                                 ) from None
        if self.mujoco:
            self.flagged += [why_unusable(v.get("reason") or "accuracy check failed")
                             for v in (run.accuracy or {}).get("violations", [])[:1]]
            self.figure_errors = dict(run.summary.get("figure_errors") or {})
        s = run.series
        t = np.asarray(s["t"], dtype=float)
        keep = np.concatenate([[True], np.diff(t) > 0])  # an event instant is written twice: keep one
        # a stall ends a run early, at rest for good: np.interp holds its last sample, where the robot stays
        return {c: np.interp(self.measured.t, t[keep], np.asarray(s[c], dtype=float)[keep])
                for c in self.measured.columns}

    def _where(self, x) -> str:
        return ", ".join(f"{f.name}={v:.6g}" for f, v in zip(self.fits, x))

    def residuals(self, x) -> np.ndarray:
        model = self.series(x)
        return np.concatenate([(model[c] - v) / self.noise[c] for c, v in self.measured.columns.items()])


def calibrate(measured: Measured, fits: list[FitRange], *, base: RobotParams | None = None,
              engine: str = "analytic-unilateral", progress=None) -> dict:
    """Fit (module docstring); returns the calibration.json content plus ``model`` (the fitted run's columns on the
    measured times), ``residuals`` ({column: array, in noise units}) for the figure."""
    from scipy import optimize, stats

    base = RobotParams() if base is None else base
    if not fits:
        raise ParameterError("calibrate needs at least one --fit NAME=LO:HI")
    names = [f.name for f in fits]
    if len(set(names)) != len(names):
        raise ParameterError(f"--fit names a parameter twice: {names}")
    registry.variant(engine)
    model = _Model(measured, fits, base, engine, progress)
    low = np.array([f.low for f in fits])
    high = np.array([f.high for f in fits])
    x0 = np.array([min(max(getattr(base, f.name) if getattr(base, f.name) is not None else 0.5 * (f.low + f.high),
                           f.low), f.high) for f in fits], dtype=float)
    x0 = np.where((x0 <= low) | (x0 >= high), 0.5 * (low + high), x0)  # start inside: TRF needs an interior point
    typical = np.maximum(np.abs(x0), 1e-3 * (high - low))
    n = sum(len(v) for v in measured.columns.values())
    if n <= len(fits):
        raise ParameterError(f"the measured run holds {n} values for {len(fits)} parameters; allowed: more values "
                             "than parameters")
    started = time.perf_counter()
    fit = None
    for stage in ("range-weighted", "noise-weighted"):
        if progress is not None:
            progress(f"{stage} fit of {', '.join(names)} ({engine})")
        try:
            fit = optimize.least_squares(model.residuals, x0, bounds=(low, high), x_scale=typical,
                                         diff_step=DIFF_STEP, method="trf", max_nfev=MAX_FEV)
        except SimulationError as exc:
            raise SimulationError(f"calibrate: a run failed during the fit: {exc}") from None
        x0 = np.clip(fit.x, low + 1e-12 * (high - low), high - 1e-12 * (high - low))
        residual = {c: r for c, r in zip(measured.columns, np.split(fit.fun, np.cumsum(
            [len(v) for v in measured.columns.values()])[:-1]))}
        if stage == "range-weighted":
            model.noise = {c: max(float(np.sqrt(np.mean((r * model.noise[c]) ** 2))), NOISE_FLOOR * model.scale[c])
                           for c, r in residual.items()}
    assert fit is not None
    jac = fit.jac
    dof = max(n - len(fits), 1)
    s2 = float(np.sum(fit.fun ** 2) / dof)
    scaled = jac * typical  # columns per relative change of each parameter
    u, sing, vt = np.linalg.svd(scaled, full_matrices=False)
    relative = sing / sing[0] if sing[0] > 0 else np.zeros_like(sing)
    jtj_inv = np.linalg.pinv(jac.T @ jac, rcond=1e-15)
    cov = s2 * jtj_inv
    se = np.sqrt(np.clip(np.diag(cov), 0.0, None))
    half = float(stats.t.ppf(0.975, dof)) * se
    weak = set()
    for k, rel in enumerate(relative):
        if rel < SINGULAR_TOL:
            weak.add(names[int(np.argmax(np.abs(vt[k])))])
    for k, f in enumerate(fits):
        if not np.isfinite(half[k]) or 2 * half[k] > (f.high - f.low):
            weak.add(f.name)
    with np.errstate(invalid="ignore", divide="ignore"):
        corr = cov / np.outer(se, se)
    corr = np.where(np.isfinite(corr), corr, 0.0)
    corr = 0.5 * (corr + corr.T)  # exactly symmetric (the round-off of the two products differs)
    np.fill_diagonal(corr, 1.0)
    fitted = model.series(fit.x)
    residuals = {c: (fitted[c] - v) / model.noise[c] for c, v in measured.columns.items()}
    estimates = {}
    for k, f in enumerate(fits):
        value = float(fit.x[k])
        estimates[f.name] = {"value": value, "interval": [value - float(half[k]), value + float(half[k])],
                             "standard_error": float(se[k]), "range": [f.low, f.high],
                             "at_bound": bool(np.isclose(value, f.low, rtol=0, atol=1e-6 * (f.high - f.low))
                                              or np.isclose(value, f.high, rtol=0, atol=1e-6 * (f.high - f.low)))}
    return {
        "data": measured.path, "engine": engine, "columns": list(measured.columns), "points": int(n),
        "estimates": estimates,
        "correlation": {"names": names, "matrix": corr.tolist()},
        "not_identifiable": [f.name for f in fits if f.name in weak],
        "residual_rms": {c: float(np.sqrt(np.mean((fitted[c] - v) ** 2))) for c, v in measured.columns.items()},
        "noise": model.noise, "singular_values_relative": relative.tolist(),
        "cost": float(fit.cost), "reduced_chi2": s2, "runs": model.runs, "status": fit.message,
        # MuJoCo's runs used with their accuracy flagged, by why; the fitted run's figures' error bars (finite grip)
        "runs_flagged": unusable_counts(model.flagged), "model_figure_errors": model.figure_errors,
        "wall_s": time.perf_counter() - started, "base": base.as_dict(),
        "model": fitted, "residuals": residuals,
    }


def posterior_toml(result: dict) -> str:
    """posterior.toml: each fitted parameter as truncnormal:VALUE:SE:LO:HI (the fit's range), and their
    correlation; what ``uncertainty --dist-file`` reads. A parameter with no usable standard error (zero or
    infinite) is uniform over its fit range."""
    lines = [f"# ipir-mujoco calibrate: the fitted parameters of {result['data']} ({result['engine']}), as",
             "# normal distributions cut to the fit ranges, with their correlation: 'ipir-mujoco uncertainty",
             "# --dist-file posterior.toml' propagates them.", "", "[dist]"]
    for name, e in result["estimates"].items():
        lo, hi = e["range"]
        se = e["standard_error"]
        if name in result["not_identifiable"] or not (math.isfinite(se) and se > 0):
            lines.append(f'{name} = "uniform:{lo!r}:{hi!r}"  # not identifiable from the data: its whole fit range')
        else:
            lines.append(f'{name} = "truncnormal:{e["value"]!r}:{se!r}:{lo!r}:{hi!r}"')
    corr = result["correlation"]
    if len(corr["names"]) > 1:
        lines += ["", "[correlation]", "names = [" + ", ".join(f'"{n}"' for n in corr["names"]) + "]",
                  "matrix = [" + ", ".join("[" + ", ".join(repr(float(v)) for v in row) + "]"
                                           for row in corr["matrix"]) + "]"]
    return "\n".join(lines) + "\n"


def write_files(out: str | Path, result: dict, measured: Measured, *, figure: Callable) -> Path:
    """calibration.json, posterior.toml and calibration.png into ``out``, all or nothing; returns the figure's path.
    ``figure(path, result, measured)`` draws it (the report's
    :func:`ipir_mujoco.report.calibration_figure.plot_calibration`: the report stands above the studies)."""
    from ...output import staged_output

    with staged_output(out) as staging:
        write_json(staging / "calibration.json",
                   {k: v for k, v in result.items() if k not in ("model", "residuals")})
        (staging / "posterior.toml").write_text(posterior_toml(result), encoding="utf-8")
        figure(staging / "calibration.png", result, measured)
    return Path(out) / "calibration.png"
