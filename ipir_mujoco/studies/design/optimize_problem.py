"""What an optimization asks: its parameters' ranges, objectives and constraints, its engines and budget.

:class:`Problem` holds them, checked as it is made, and maps the search's unit box to designs (log axes in log
space) and a design's row to its objective values and feasibility; :class:`Objective` and :class:`Constraint`
are its terms, :func:`parse_objective` and :func:`parse_constraint` read them from the command line's words.
:mod:`.optimize` searches it.
"""

from __future__ import annotations

import hashlib
import json
import math
import re
from dataclasses import asdict, dataclass, field

import numpy as np

from ipir_mujoco.core.checks import check_text
from ipir_mujoco.core.errors import ParameterError, ParameterTypeError
from ipir_mujoco.core.options import check_type
from ipir_mujoco.core.params import RobotParams, check_real, check_whole

from ..sweeps.sweep_space import Axis, Study
from .design_eval import check_key, key_value, usable


DEFAULT_ENGINE = "analytic-unilateral"
DEFAULT_VERIFY = "mujoco-ratchet"
DEFAULT_BUDGET = 100
POPULATION = 20  # NSGA-II designs per generation (fewer if the budget is small)


@dataclass(frozen=True)
class Objective:
    sense: str  # "min" or "max"
    key: str

    def __post_init__(self) -> None:
        check_text("Objective sense", self.sense, "'min' or 'max'")
        if self.sense not in ("min", "max"):
            raise ParameterError(f"Objective sense={self.sense!r} is not allowed; allowed: 'min' or 'max'")
        object.__setattr__(self, "key", check_key(self.key, f"Objective key={self.key!r}"))


@dataclass(frozen=True)
class Constraint:
    key: str
    op: str  # "<=" or ">="
    value: float

    def __post_init__(self) -> None:
        object.__setattr__(self, "key", check_key(self.key, f"Constraint key={self.key!r}"))
        check_text("Constraint op", self.op, "'<=' or '>='")
        if self.op not in ("<=", ">="):
            raise ParameterError(f"Constraint op={self.op!r} is not allowed; allowed: '<=' or '>=' (a design is "
                                 "feasible where KEY <= VALUE, or KEY >= VALUE)")
        object.__setattr__(self, "value", check_real("Constraint value", self.value, low=-math.inf, low_open=False))

    def slack(self, value) -> float:
        """>= 0 where satisfied; -inf where the value is missing (a stalled or failed design)."""
        if not usable(value):
            return -math.inf
        return self.value - value if self.op == "<=" else value - self.value


def parse_objective(text: str) -> Objective:
    """``min:KEY`` or ``max:KEY`` (``--objective``) as an Objective; one-line ParameterError otherwise."""
    sense, sep, key = check_text("objective", text, "'min:KEY' or 'max:KEY'").partition(":")
    if not sep or sense.strip() not in ("min", "max"):
        raise ParameterError(f"--objective {text!r} is malformed; expected min:KEY or max:KEY")
    return Objective(sense.strip(), check_key(key, f"--objective {text!r}"))


def parse_constraint(text: str) -> Constraint:
    """``KEY<=VALUE`` or ``KEY>=VALUE`` (``--constraint``) as a Constraint; one-line ParameterError otherwise."""
    check_text("constraint", text, "'KEY<=VALUE' or 'KEY>=VALUE'")
    match = re.fullmatch(r"\s*([A-Za-z_][A-Za-z0-9_]*)\s*(<=|>=)\s*(\S+)\s*", text)
    try:
        value = float(match.group(3)) if match else math.nan
    except ValueError:
        value = math.nan
    if not match or not math.isfinite(value):
        raise ParameterError(f"--constraint {text!r} does not parse; expected 'KEY<=VALUE' or 'KEY>=VALUE' with a "
                             "finite number")
    return Constraint(check_key(match.group(1), f"--constraint {text!r}"), match.group(2), value)


@dataclass(frozen=True)
class Problem:
    """What to optimize: ranges, objectives, constraints, the model and its engines, the budget."""

    axes: tuple[Axis, ...]
    objectives: tuple[Objective, ...]
    constraints: tuple[Constraint, ...] = ()
    base: RobotParams = field(default_factory=RobotParams)
    engine: str = DEFAULT_ENGINE
    verify: str | None = DEFAULT_VERIFY
    t_end: float = 1.0
    until_steady: bool = False
    budget: int = DEFAULT_BUDGET
    seed: int = 0

    def __post_init__(self) -> None:
        for name, kind in (("axes", Axis), ("objectives", Objective), ("constraints", Constraint)):
            value = getattr(self, name)
            if not isinstance(value, (tuple, list)) or not all(isinstance(v, kind) for v in value):
                raise ParameterTypeError(f"Problem {name}={value!r} is not a tuple of {kind.__name__}; allowed: e.g. "
                                     f"({kind.__name__}(...),)" + (" or (parse_vary('L=0.1:0.3'),)" if kind is Axis
                                                                  else ""))
            object.__setattr__(self, name, tuple(value))
        if not self.objectives:
            raise ParameterError("optimize needs at least one --objective min:KEY or max:KEY")
        for axis in self.axes:
            if not axis.is_range:
                raise ParameterError(f"--vary {axis.name}: give a range NAME=LO:HI[:log]")
        object.__setattr__(self, "budget", check_whole("budget", self.budget, low=1, high=100_000))
        check_type("engine", self.engine, str, "a model variant's name, e.g. 'analytic-unilateral'")
        check_type("verify", self.verify, (str, type(None)), "a model variant's name, or None (no verification)")
        engines = (self.engine,) + ((self.verify,) if self.verify is not None and self.verify != self.engine else ())
        # the sweep's checks of axes, base, engines, t_end, seed and until_steady, in one place
        object.__setattr__(self, "study", Study(self.axes, self.base, engines, self.t_end, sample=self.budget, seed=self.seed,
                           until_steady=self.until_steady))

    @property
    def names(self) -> list[str]:
        return [a.name for a in self.axes]

    def to_json(self) -> dict:
        return {"axes": [asdict(a) for a in self.axes], "objectives": [asdict(o) for o in self.objectives],
                "constraints": [asdict(c) for c in self.constraints], "base": self.base.as_dict(),
                "engine": self.engine, "verify": self.verify, "t_end": self.t_end,
                "until_steady": self.until_steady, "budget": self.budget, "seed": self.seed}

    def fingerprint(self) -> str:
        return hashlib.sha256(json.dumps(self.to_json(), sort_keys=True).encode()).hexdigest()[:16]

    # the unit box <-> parameters (log axes in log space)
    def design(self, u) -> dict:
        out = {}
        for axis, x in zip(self.axes, np.clip(np.asarray(u, dtype=float), 0.0, 1.0)):
            if axis.log:
                lo, hi = math.log(axis.low), math.log(axis.high)
                out[axis.name] = float(math.exp(lo + x * (hi - lo)))
            else:
                out[axis.name] = float(axis.low + x * (axis.high - axis.low))
        return out

    def objective_values(self, row: dict) -> list[float]:
        """Every objective as a value to minimise (max: negated); nan where missing."""
        values = []
        for o in self.objectives:
            v = key_value(o.key, row, self.base)
            values.append((-v if o.sense == "max" else v) if usable(v) else math.nan)
        return values

    def feasible(self, row: dict) -> bool:
        if row.get("error") or row.get("stalled") == 1:
            return False
        if not all(math.isfinite(v) for v in self.objective_values(row)):
            return False
        return all(c.slack(key_value(c.key, row, self.base)) >= 0 for c in self.constraints)
