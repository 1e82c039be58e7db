"""Uncertain parameters: distributions from ``--dist`` and TOML, checked against each parameter's range, sampled.

A distribution is one of (scipy.stats, frozen)::

    NAME=normal:MEAN:SD              scipy.stats.norm(MEAN, SD)
    NAME=uniform:LO:HI               scipy.stats.uniform(LO, HI - LO)
    NAME=lognormal:MU:SIGMA          scipy.stats.lognorm(SIGMA, scale=exp(MU)): log(NAME) ~ normal(MU, SIGMA)
    NAME=truncnormal:MEAN:SD:LO:HI   scipy.stats.truncnorm: normal(MEAN, SD) cut to [LO, HI]

in the parameter's unit ('ipir-mujoco params'). A distribution that puts more than :data:`OUTSIDE_MASS` of its
probability outside the parameter's allowed range is bad input (a normal F_r1 of mean 0.1 N and SD 0.1 N
would draw negative resistances one time in six): use ``truncnormal`` to cut it. What remains outside (at most
OUTSIDE_MASS: a normal of mean 1 and SD 0.1 has 8e-24 below 0) is never drawn: samples come from the
distribution conditioned on the allowed range (inverse CDF on the range's share of the unit interval), whose
moments differ from the unconditioned ones by far less than any sampling error.

A TOML file (``--dist-file``) holds the same specifications, and optionally the correlation between them
(``calibrate`` writes one: a fitted posterior's parameters are correlated)::

    [dist]
    F_r1 = "normal:1.3:0.02"
    F_r2 = "truncnormal:0.8:0.03:0:2"

    [correlation]                 # optional: a Gaussian copula with this correlation matrix
    names = ["F_r1", "F_r2"]
    matrix = [[1.0, -0.4], [-0.4, 1.0]]

With a correlation, samples come through a Gaussian copula: correlated standard normals, mapped through the
normal CDF to uniforms and through each marginal's inverse CDF (for normal marginals: the multivariate normal
with that correlation exactly).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ipir_mujoco.core.errors import ParameterError
from ipir_mujoco.core.files import read_toml_file
from ipir_mujoco.core.params import PARAMETER_NAMES, RobotParams, allowed_text

KINDS = {"normal": ("MEAN", "SD"), "uniform": ("LO", "HI"), "lognormal": ("MU", "SIGMA"),
         "truncnormal": ("MEAN", "SD", "LO", "HI")}
OUTSIDE_MASS = 1e-6  # probability a distribution may put outside its parameter's range (never drawn)
FORMS = "normal:MEAN:SD, uniform:LO:HI, lognormal:MU:SIGMA or truncnormal:MEAN:SD:LO:HI"


@dataclass(frozen=True)
class Dist:
    """One uncertain parameter: ``name``, ``kind`` (a key of :data:`KINDS`) and its numbers, in the
    parameter's unit (lognormal: of its logarithm)."""

    name: str
    kind: str
    args: tuple[float, ...]

    @property
    def text(self) -> str:
        return f"{self.name}={self.kind}:" + ":".join(f"{a:g}" for a in self.args)

    def frozen(self):
        """The scipy.stats frozen distribution."""
        from scipy import stats

        a = self.args
        if self.kind == "normal":
            return stats.norm(a[0], a[1])
        if self.kind == "uniform":
            return stats.uniform(a[0], a[1] - a[0])
        if self.kind == "lognormal":
            return stats.lognorm(a[1], scale=math.exp(a[0]))
        return stats.truncnorm((a[2] - a[0]) / a[1], (a[3] - a[0]) / a[1], loc=a[0], scale=a[1])


def parse_dist(text: str, where: str = "--dist") -> Dist:
    """One ``NAME=KIND:A:B[:C:D]`` specification, checked (numbers, order, the parameter's range)."""
    if not isinstance(text, str):
        raise ParameterError(f"{where} {text!r} is not a string; allowed: NAME={FORMS}")
    name, sep, spec = text.partition("=")
    name = name.strip()
    if not sep:
        raise ParameterError(f"{where} {text!r} is malformed; expected NAME={FORMS}")
    kind, _, rest = spec.strip().partition(":")
    return make_dist(name, kind.strip(), rest.split(":") if rest else [], f"{where} {text!r}")


def make_dist(name: str, kind: str, numbers, where: str) -> Dist:
    """A :class:`Dist` from its parts, every fault a one-line ParameterError starting with ``where``."""
    if name not in PARAMETER_NAMES:
        raise ParameterError(f"{where}: unknown parameter {name!r}; 'ipir-mujoco params' lists them")
    if name in ("drive", "feedforward") or not isinstance(getattr(RobotParams(), name, 0.0), (float, int, type(None))):
        raise ParameterError(f"{where}: {name} is a choice, not a number; allowed: a numeric parameter")
    if kind not in KINDS:
        raise ParameterError(f"{where}: unknown distribution {kind!r}; allowed: {FORMS}")
    if len(numbers) != len(KINDS[kind]):
        raise ParameterError(f"{where}: {kind} takes {len(KINDS[kind])} numbers ({':'.join(KINDS[kind])}); "
                             f"got {len(numbers)}")
    try:
        args = tuple(float(v) for v in numbers)
    except (TypeError, ValueError):
        raise ParameterError(f"{where}: {':'.join(map(str, numbers))!r} are not all numbers") from None
    if not all(math.isfinite(a) for a in args):
        raise ParameterError(f"{where}: every number must be finite")
    if kind in ("normal", "truncnormal", "lognormal") and not args[1] > 0:
        raise ParameterError(f"{where}: {KINDS[kind][1]}={args[1]:g} must be > 0")
    if kind == "uniform" and not args[0] < args[1]:
        raise ParameterError(f"{where}: uniform needs LO < HI")
    if kind == "truncnormal" and not args[2] < args[3]:
        raise ParameterError(f"{where}: truncnormal needs LO < HI")
    dist = Dist(name, kind, args)
    if kind == "truncnormal" and not (inside(name, args[2]) and inside(name, args[3])):
        raise ParameterError(f"{where} cuts to [{args[2]:g}, {args[3]:g}], reaching outside {name}'s allowed range "
                             f"{allowed_text(name)}; allowed: LO:HI inside it")
    outside = outside_mass(dist)
    if outside > OUTSIDE_MASS:
        raise ParameterError(f"{where} puts {_percent(outside)} of its probability outside {name}'s allowed range "
                             f"{allowed_text(name)}; allowed: a distribution inside it (at most {OUTSIDE_MASS:g} "
                             "outside; truncnormal:MEAN:SD:LO:HI cuts a normal to a range)")
    return dist


def _percent(p: float) -> str:
    return f"{100 * p:.3g} %" if p >= 1e-4 else f"{p:.3g}"


def parameter_range(name: str) -> tuple[float, float]:
    """(low, high) of parameter ``name``'s allowed range (open or closed ends alike: a continuous distribution
    gives either end probability 0)."""
    import dataclasses

    meta = {f.name: f.metadata for f in dataclasses.fields(RobotParams)}[name]
    return float(meta["low"]), float(meta["high"])


def inside(name: str, value: float) -> bool:
    """Whether ``value`` lies in parameter ``name``'s allowed range, its open ends excluded."""
    import dataclasses

    meta = {f.name: f.metadata for f in dataclasses.fields(RobotParams)}[name]
    low_ok = value > meta["low"] if meta["low_open"] else value >= meta["low"]
    high_ok = value < meta["high"] if meta["high_open"] else value <= meta["high"]
    return low_ok and high_ok


def outside_mass(dist: Dist) -> float:
    """The probability ``dist`` puts outside its parameter's allowed range."""
    low, high = parameter_range(dist.name)
    frozen = dist.frozen()
    return float(frozen.cdf(low) + frozen.sf(high))


def read_dist_file(path: str | Path) -> tuple[list[Dist], tuple[list[str], np.ndarray] | None]:
    """The ``[dist]`` table of a TOML file (module docstring) and its ``[correlation]`` (names, matrix) or None."""
    where = f"--dist-file {str(path)!r}"
    data = read_toml_file(path, "dist file")
    unknown = set(data) - {"dist", "correlation"}
    if unknown:
        raise ParameterError(f"{where}: unknown table {sorted(unknown)[0]!r}; allowed: [dist], [correlation]")
    table = data.get("dist")
    if not isinstance(table, dict) or not table:
        raise ParameterError(f"{where} has no [dist] table of NAME = \"KIND:A:B\" lines")
    dists = []
    for name, spec in table.items():
        if not isinstance(spec, str):
            raise ParameterError(f"{where}: {name} = {spec!r} is not a string; allowed: {name} = \"{FORMS}\"")
        dists.append(parse_dist(f"{name}={spec}", where))
    correlation = None
    if "correlation" in data:
        correlation = _read_correlation(data["correlation"], where)
    return dists, correlation


def _read_correlation(table, where: str) -> tuple[list[str], np.ndarray]:
    if not isinstance(table, dict) or set(table) != {"names", "matrix"}:
        raise ParameterError(f"{where}: [correlation] needs exactly 'names' (a list) and 'matrix' (a list of rows)")
    names = table["names"]
    if not isinstance(names, list) or not all(isinstance(n, str) for n in names) or len(set(names)) != len(names):
        raise ParameterError(f"{where}: [correlation] names = {names!r}; allowed: a list of distinct parameter names")
    try:
        matrix = np.array(table["matrix"], dtype=float)
    except (TypeError, ValueError):
        raise ParameterError(f"{where}: [correlation] matrix is not a list of rows of numbers") from None
    k = len(names)
    if matrix.shape != (k, k) or not np.all(np.isfinite(matrix)):
        raise ParameterError(f"{where}: [correlation] matrix must be {k} x {k} finite numbers (one row per name)")
    if not np.allclose(matrix, matrix.T, atol=1e-9) or not np.allclose(np.diag(matrix), 1.0, atol=1e-9):
        raise ParameterError(f"{where}: [correlation] matrix must be symmetric with ones on its diagonal")
    if np.linalg.eigvalsh(matrix).min() < -1e-9:
        raise ParameterError(f"{where}: [correlation] matrix is not positive semi-definite (not a correlation)")
    return list(names), matrix


def combine(given: list[Dist], from_file: list[Dist]) -> list[Dist]:
    """Distributions of the file, then the command line's (which win for a parameter both name)."""
    dists = {d.name: d for d in from_file}
    seen = set()
    for d in given:
        if d.name in seen:
            raise ParameterError(f"--dist names {d.name} twice")
        seen.add(d.name)
        dists[d.name] = d
    if not dists:
        raise ParameterError("uncertainty needs at least one --dist NAME=KIND:... or --dist-file FILE.toml")
    return list(dists.values())


def sample(dists: list[Dist], n: int, seed: int,
           correlation: tuple[list[str], np.ndarray] | None = None) -> np.ndarray:
    """``n`` independent draws (plain Monte Carlo, numpy's PCG64 seeded with ``seed``): array of shape
    (n, len(dists)), column k parameter ``dists[k].name``, every value inside its parameter's range (module
    docstring). Draws are nested: the first m of a draw of n are the draw of m with the same seed."""
    from scipy import stats

    rng = np.random.default_rng(seed)
    normals = rng.standard_normal((n, len(dists)))
    if correlation is not None:
        names, matrix = correlation
        index = [k for k, d in enumerate(dists) if d.name in names]
        order = [names.index(dists[k].name) for k in index]
        sub = matrix[np.ix_(order, order)]
        # a symmetric square root (eigendecomposition): semi-definite matrices too
        w, v = np.linalg.eigh(sub)
        root = v @ np.diag(np.sqrt(np.clip(w, 0.0, None))) @ v.T
        normals[:, index] = normals[:, index] @ root.T
    u = stats.norm.cdf(normals)
    out = np.empty_like(u)
    for k, d in enumerate(dists):
        frozen = d.frozen()
        low, high = parameter_range(d.name)
        a, b = float(frozen.cdf(low)), float(frozen.cdf(high))
        x = frozen.ppf(a + u[:, k] * (b - a))
        out[:, k] = np.clip(x, low, high)  # the conditioned draw's round-off only
    return out
