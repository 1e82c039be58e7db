"""Design spaces for what-if studies: grids, explicit lists, space-filling samples.

A study is a base parameter set, the parameters varied, how designs are drawn
from them, the engines to run on each, and the simulated time. Every design is
a full, validated parameter set; a design that is not valid (say L <= r) is
kept, and the sweep records its error instead of results.

``--vary`` specifications (SI units):

=====================  ====================================================
``L=0.06:0.5:25``      25 values from 0.06 to 0.5, evenly spaced
``L=0.06:0.5:25:log``  25 values, log-spaced
``L=0.1,0.2,0.4``      exactly these values
``L=0.06:0.5``         a range for ``--sample N`` (space-filling Sobol points)
=====================  ====================================================

Several ``--vary`` make the full grid of their values (or, with ``--sample``,
a sample of the box). A TOML study file says the same::

    [sweep]
    vary = ["L=0.06:0.5:20", "m2=0.2:3:20"]
    engines = ["mujoco-ratchet", "analytic-unilateral"]
    t_end = 1.0
    # sample = 256        # instead of the grid
    # seed = 0

    [params]              # the base design (defaults: the paper's case)
    M = 0.25
"""

from __future__ import annotations

import hashlib
import itertools
import json
import math
import tomllib
from dataclasses import asdict, dataclass, field
from pathlib import Path

import numpy as np
from scipy.stats import qmc

from ipir_mujoco.analytic.errors import ParameterError
from ipir_mujoco.analytic.params import PARAMETER_NAMES, RobotParams

ENGINES = ("analytic-approx", "analytic-exact", "analytic-unilateral", "mujoco-lock", "mujoco-ratchet")
DEFAULT_ENGINES = ("mujoco-ratchet", "analytic-unilateral")


@dataclass(frozen=True)
class Axis:
    """One varied parameter: explicit values, or a range (lo, hi) for sampling."""

    name: str
    values: tuple[float, ...] = ()
    low: float | None = None
    high: float | None = None
    log: bool = False

    @property
    def is_range(self) -> bool:
        return not self.values


def parse_vary(text: str) -> Axis:
    """Parse one ``--vary`` specification (see the module docstring)."""
    name, sep, spec = text.partition("=")
    name = name.strip()
    if not sep or not spec:
        raise ParameterError(f"--vary {text!r} is malformed; expected NAME=START:STOP:N, NAME=A,B,C or NAME=LO:HI")
    if name not in PARAMETER_NAMES:
        raise ParameterError(f"--vary {text!r}: unknown parameter {name!r}; known parameters: {' '.join(PARAMETER_NAMES)}")
    try:
        if "," in spec:
            values = tuple(float(v) for v in spec.split(","))
            return Axis(name, values)
        parts = spec.split(":")
        log = parts[-1].strip() == "log"
        if log:
            parts = parts[:-1]
        numbers = [float(p) for p in parts]
    except ValueError:
        raise ParameterError(f"--vary {text!r}: {spec!r} is not a list of numbers") from None
    if not all(math.isfinite(v) for v in numbers):
        raise ParameterError(f"--vary {text!r}: every bound must be finite")
    if log and min(numbers[:2]) <= 0:
        raise ParameterError(f"--vary {text!r}: a log-spaced range needs positive bounds")
    if len(numbers) == 2:
        if not numbers[0] < numbers[1]:
            raise ParameterError(f"--vary {text!r}: the range needs LO < HI")
        return Axis(name, (), numbers[0], numbers[1], log)
    if len(numbers) == 3:
        count = numbers[2]
        if count != int(count) or count < 1:
            raise ParameterError(f"--vary {text!r}: N={count:g} must be a whole number >= 1")
        spaced = np.geomspace if log else np.linspace
        return Axis(name, tuple(float(v) for v in spaced(numbers[0], numbers[1], int(count))))
    raise ParameterError(f"--vary {text!r} is malformed; expected NAME=START:STOP:N[:log], NAME=A,B,C or NAME=LO:HI[:log]")


@dataclass(frozen=True)
class Study:
    """What a sweep runs: base parameters, axes, sampling, engines, simulated time [s]."""

    axes: tuple[Axis, ...]
    base: RobotParams = field(default_factory=RobotParams)
    engines: tuple[str, ...] = DEFAULT_ENGINES
    t_end: float = 1.0
    sample: int | None = None
    seed: int = 0

    def __post_init__(self) -> None:
        if not self.axes:
            raise ParameterError("a sweep needs at least one --vary")
        names = [a.name for a in self.axes]
        if len(set(names)) != len(names):
            raise ParameterError(f"--vary names a parameter twice: {names}")
        unknown = [e for e in self.engines if e not in ENGINES]
        if unknown or not self.engines:
            raise ParameterError(f"engine {unknown[0] if unknown else None!r} is unknown; allowed: {', '.join(ENGINES)}")
        if not (math.isfinite(self.t_end) and self.t_end > 0):
            raise ParameterError(f"t_end={self.t_end} is out of range; allowed: a finite number > 0")
        ranges = [a for a in self.axes if a.is_range]
        if self.sample is None and ranges:
            raise ParameterError(f"--vary {ranges[0].name}=LO:HI is a range: give --sample N, or N points (LO:HI:N)")
        if self.sample is not None and (self.sample < 1 or any(not a.is_range for a in self.axes)):
            raise ParameterError("--sample N needs N >= 1 and every --vary given as a range LO:HI")

    def designs(self) -> list[dict[str, float]]:
        """Every design as {varied name: value}, in a fixed order (its index is the design id)."""
        names = [a.name for a in self.axes]
        if self.sample is None:
            return [dict(zip(names, combo)) for combo in itertools.product(*(a.values for a in self.axes))]
        unit = qmc.Sobol(d=len(self.axes), scramble=True, seed=self.seed).random(self.sample)
        designs = []
        for point in unit:
            design = {}
            for axis, u in zip(self.axes, point):
                if axis.log:
                    design[axis.name] = float(math.exp(math.log(axis.low) + u * (math.log(axis.high) - math.log(axis.low))))
                else:
                    design[axis.name] = float(axis.low + u * (axis.high - axis.low))
            designs.append(design)
        return designs

    def to_json(self) -> dict:
        return {"axes": [asdict(a) for a in self.axes], "base": self.base.as_dict(), "engines": list(self.engines),
                "t_end": self.t_end, "sample": self.sample, "seed": self.seed}

    def fingerprint(self) -> str:
        """A hash that changes whenever the set of designs or what is run on them changes."""
        return hashlib.sha256(json.dumps(self.to_json(), sort_keys=True).encode()).hexdigest()[:16]


def read_study(path: str | Path, base: RobotParams) -> dict:
    """The [sweep] table of a TOML study file as Study keyword arguments; [params] updates ``base``."""
    path = Path(path)
    try:
        data = tomllib.loads(path.read_text())
    except FileNotFoundError:
        raise ParameterError(f"study file {str(path)!r} does not exist") from None
    except tomllib.TOMLDecodeError as exc:
        raise ParameterError(f"study file {str(path)!r} is not valid TOML: {exc}") from None
    unknown = set(data) - {"sweep", "params"}
    if unknown:
        raise ParameterError(f"study file {str(path)!r}: unknown table {sorted(unknown)[0]!r}; allowed: sweep, params")
    sweep = dict(data.get("sweep", {}))
    allowed = {"vary", "engines", "t_end", "sample", "seed"}
    if set(sweep) - allowed:
        raise ParameterError(f"study file {str(path)!r}: unknown key {sorted(set(sweep) - allowed)[0]!r} in [sweep]; "
                             f"allowed: {', '.join(sorted(allowed))}")
    kwargs: dict = {}
    if "vary" in sweep:
        kwargs["axes"] = tuple(parse_vary(v) for v in sweep["vary"])
    if "engines" in sweep:
        kwargs["engines"] = tuple(sweep["engines"])
    for key in ("t_end", "sample", "seed"):
        if key in sweep:
            kwargs[key] = sweep[key]
    params = data.get("params", {})
    try:
        kwargs["base"] = base.replace(**params)
    except TypeError as exc:
        raise ParameterError(f"study file {str(path)!r}: [params] {exc}") from None
    return kwargs
