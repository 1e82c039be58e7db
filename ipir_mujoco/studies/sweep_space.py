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

import functools
import hashlib
import itertools
import json
import math
import warnings
from dataclasses import asdict, dataclass, field
from pathlib import Path

from ipir_mujoco import registry
from ipir_mujoco.core.errors import ParameterError, ParameterTypeError
from ipir_mujoco.core.limits import MAX_T_END, check_run_options, refuse_steady_without_motor, study_dt_out
from ipir_mujoco.core.params import (PARAMETER_NAMES, RobotParams, as_real, check_own_range, check_real, check_whole,
                                     read_toml_file, refuse_idle_names, refuse_idle_parameters, require_params)

# the variants a sweep runs by default (any of registry.NAMES, or their aliases, may be given)
DEFAULT_VARIANTS = ("mujoco-ratchet", "analytic-unilateral")
OLDER_NAMES = {"DEFAULT_ENGINES": "DEFAULT_VARIANTS"}  # see __getattr__ (and ENGINES: registry.NAMES)
# designs per sweep: hours of work for 1 s runs of the default engines on a few cores (runs to a steady
# state cost more; bench/targets.py measures the rate), and the grid stays small in memory; split a larger study
MAX_DESIGNS = 100_000
DT_OUT = 1e-3  # s: output interval of the sweep's runs; enough for the metrics, light on memory
T_END_STEADY = 10.0  # s: the default cap of a run to steady state (several times the default motor's settling)


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
    if not isinstance(text, str):
        raise ParameterTypeError(f"vary={text!r} is not a string; allowed: NAME=START:STOP:N, NAME=A,B,C or "
                                 "NAME=LO:HI")
    name, sep, spec = text.partition("=")
    name = name.strip()
    if not sep or not spec:
        raise ParameterError(f"--vary {text!r} is malformed; expected NAME=START:STOP:N, NAME=A,B,C or NAME=LO:HI")
    if name not in PARAMETER_NAMES:
        raise ParameterError(f"--vary {text!r}: unknown parameter {name!r}; known parameters: "
                             f"{' '.join(PARAMETER_NAMES)}")
    if "," in spec:
        try:
            values = tuple(float(v) for v in spec.split(","))
        except ValueError:
            raise ParameterError(f"--vary {text!r}: {spec!r} is not a list of numbers") from None
        if not all(math.isfinite(v) for v in values):
            raise ParameterError(f"--vary {text!r}: every value must be a finite number")
        if len(values) > MAX_DESIGNS:
            raise ParameterError(f"--vary {text!r} lists {len(values)} values; allowed: at most {MAX_DESIGNS}")
        return Axis(name, values)
    try:
        parts = spec.split(":")
        log = parts[-1].strip() == "log"
        if log:
            parts = parts[:-1]
        numbers = [float(p) for p in parts]
    except ValueError:
        raise ParameterError(f"--vary {text!r}: {spec!r} is not a list of numbers") from None
    if not all(math.isfinite(v) for v in numbers):
        raise ParameterError(f"--vary {text!r}: every bound must be finite")
    if len(numbers) not in (2, 3):  # NAME=log, NAME=1:2:3:4
        raise ParameterError(f"--vary {text!r} is malformed; expected NAME=START:STOP:N, NAME=A,B,C or "
                             "NAME=LO:HI (each with :log for log spacing)")
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
        if count > MAX_DESIGNS:
            raise ParameterError(f"--vary {text!r}: N={count:g} points would need {count * 8:.3g} bytes for the "
                                 f"axis alone; allowed: N <= {MAX_DESIGNS} (designs per sweep)")
        import numpy as np  # here only: the command line's parsers read this module's defaults without numpy

        spaced = np.geomspace if log else np.linspace
        return Axis(name, tuple(float(v) for v in spaced(numbers[0], numbers[1], int(count))), log=log)
    raise ParameterError(f"--vary {text!r} is malformed; expected NAME=START:STOP:N[:log], NAME=A,B,C or "
                         "NAME=LO:HI[:log]")


CORNERS = 4096  # combinations of the other axes' ends a range's end is tried with (2^12: twelve other axes)


def axis_text(axis: Axis) -> str:
    """An axis as --vary spells it (a long list shortened), for messages."""
    if axis.is_range:
        return f"{axis.name}={axis.low:g}:{axis.high:g}" + (":log" if axis.log else "")
    shown = ",".join(f"{v:g}" for v in axis.values[:4]) + (",..." if len(axis.values) > 4 else "")
    return f"{axis.name}={shown}"


def _usable(base: RobotParams, values: dict) -> ParameterError | None:
    """None if ``values`` on ``base`` make a design a run can take, else why not (its one-line error)."""
    try:
        refuse_idle_parameters(base.replace(**values))
    except ParameterError as exc:
        return exc
    return None


def _idle(base: RobotParams, name: str, value: float) -> ParameterError | None:
    """Why a run would refuse ``name`` = ``value`` on ``base`` whatever the design (a parameter that acts only
    through another one the base leaves out: the speed controller's without the servo), or None (also where the
    value is refused only with the base's other parameters: that design's own error)."""
    try:
        params = base.replace(**{name: value})
    except ParameterError:
        return None
    try:
        refuse_idle_parameters(params)
    except ParameterError as exc:
        return exc
    return None


def _refuse_idle_base(base: RobotParams, varied: list[str]) -> None:
    """A parameter of ``base`` no run takes whatever the grid of ``varied`` gives (a speed-controller parameter
    with another drive), refused in one line."""
    try:
        refuse_idle_parameters(base)
    except ParameterError as exc:
        if "clutch_stiffness" not in varied:  # a varied stiffness gives the damping and the play their spring
            raise ParameterError(f"{exc} (in --set or --config)") from None


def check_axes(axes: tuple[Axis, ...], base: RobotParams) -> None:
    """Refuse, before the first design, a ``--vary`` no design of the study could use, in one line naming it: a
    parameter that is not a number (``drive``); a value, or a range's end, outside the parameter's own allowed
    range (``m1=-1:1``); a range over the whole number ``wheel_legs`` (a list varies it); a range one of whose ends
    makes no design a run takes with the base and any end of the other axes (``L=0.01:0.04`` below r = 0.05 m,
    ``omega_target`` with a drive other than servo); a list none of whose values a run takes for a reason of its
    own (a speed-controller parameter without the servo), and a base parameter no run takes (the same, set with
    --set or --config). A list's values refused only with the others' (L below
    r in a grid of L) stay designs of their own: a sweep records each one's error (:func:`.sweep.refuse_all_invalid`
    refuses a sweep none of whose designs is valid)."""
    _refuse_idle_base(base, [a.name for a in axes])
    for axis in axes:
        where = f"--vary {axis_text(axis)!r}"
        try:
            for value in ((axis.low, axis.high) if axis.is_range else axis.values):
                check_own_range(axis.name, value)
        except ParameterError as exc:
            raise ParameterError(f"{where}: {exc}") from None
        if axis.is_range and axis.name == "wheel_legs":
            raise ParameterError(f"{where}: wheel_legs is a whole number, and a range gives fractions; allowed: a "
                                 f"list of whole numbers, e.g. wheel_legs={int(math.ceil(axis.low))},"
                                 f"{int(math.floor(axis.high))}")
        others = [a for a in axes if a is not axis]
        names = [a.name for a in others]
        ends = [(a.low, a.high) if a.is_range else (min(a.values), max(a.values)) for a in others]
        for value in ((axis.low, axis.high) if axis.is_range else ()):
            first = None
            for combo in itertools.islice(itertools.product(*ends), CORNERS):
                why = _usable(base, {**dict(zip(names, combo)), axis.name: value})
                if why is None:
                    break
                first = first or why
            else:
                raise ParameterError(f"{where}: no design of the study can have {axis.name}={value:g}: "
                                     f"{' '.join(str(first).split())}")
        if not axis.is_range:
            idle = [_idle(base, axis.name, v) for v in axis.values[:CORNERS]]
            if all(idle):
                raise ParameterError(f"{where}: {' '.join(str(idle[0]).split())}")


@dataclass(frozen=True)
class Study:
    """What a sweep runs: base parameters, axes, sampling, engines, simulated time [s].

    ``until_steady``: every engine stops at the periodic steady state (``t_end`` is the cap).
    Every field is checked here, the one place the command line, study files and the Python API
    meet: numbers of any numeric type, strings where lists are wanted refused by name, the count
    of designs bounded (:data:`MAX_DESIGNS`).
    """

    axes: tuple[Axis, ...]
    base: RobotParams = field(default_factory=RobotParams)
    engines: tuple[str, ...] = DEFAULT_VARIANTS
    t_end: float = 1.0
    sample: int | None = None
    seed: int = 0
    until_steady: bool = False

    def __post_init__(self) -> None:
        set_ = functools.partial(object.__setattr__, self)
        if not isinstance(self.axes, (list, tuple)) or not all(isinstance(a, Axis) for a in self.axes):
            raise ParameterTypeError(f"axes={self.axes!r} is not a list of axes; build them with "
                                     "parse_vary('NAME=SPEC')")
        set_("axes", tuple(self.axes))
        if not self.axes:
            raise ParameterError("a sweep needs at least one --vary")
        names = [a.name for a in self.axes]
        if len(set(names)) != len(names):
            raise ParameterError(f"--vary names a parameter twice: {names}")
        set_("base", require_params(self.base))
        refuse_idle_names(self.base.drive, names)  # M_stall varied under the constant torque: every run refuses it
        if isinstance(self.engines, str):
            raise ParameterError(f"engines={self.engines!r} is a single string; allowed: a list of engine names, "
                                 f"e.g. [{self.engines!r}], from: {', '.join(registry.NAMES)}")
        if not isinstance(self.engines, (list, tuple)):
            raise ParameterError(f"engines={self.engines!r} is not a list; allowed: a list of engine names from: "
                                 f"{', '.join(registry.NAMES)}")
        set_("engines", tuple(self.engines))
        if not self.engines:
            raise ParameterError(f"engines=[] names no engine; allowed: one or more of {', '.join(registry.NAMES)}")
        # names as given (aliases included) head the results' columns; the variants they name must differ
        variants = [registry.variant(e).name for e in self.engines]
        if len(set(variants)) != len(variants):
            raise ParameterError(f"engines={list(self.engines)} names an engine twice")
        set_("t_end", check_run_options(self.t_end, self.dt_out)[0])
        if self.sample is not None:
            set_("sample", check_whole("sample", self.sample, low=1, high=MAX_DESIGNS, why=" designs"))
        set_("seed", check_whole("seed", self.seed, low=0))
        if not isinstance(self.until_steady, bool):
            raise ParameterError(f"until_steady={self.until_steady!r} is not true or false")
        refuse_steady_without_motor(self.base.drive, self.until_steady)
        check_axes(self.axes, self.base)
        ranges = [a for a in self.axes if a.is_range]
        if self.sample is None and ranges:
            raise ParameterError(f"--vary {ranges[0].name}=LO:HI is a range: give --sample N, or N points (LO:HI:N)")
        if self.sample is not None and any(not a.is_range for a in self.axes):
            raise ParameterError("--sample N needs every --vary given as a range LO:HI")
        if self.sample is None:
            count = math.prod(len(a.values) for a in self.axes)
            if count > MAX_DESIGNS:
                raise ParameterError(f"the grid of {' x '.join(str(len(a.values)) for a in self.axes)} = {count:.3g} "
                                     f"designs is too large; allowed: at most {MAX_DESIGNS} designs per sweep")

    @property
    def dt_out(self) -> float:
        """Output interval of the sweep's runs [s]: enough for the metrics, light on memory (at most STUDY_SAMPLES
        samples a run: :func:`ipir_mujoco.core.options.study_dt_out`)."""
        t_end = as_real(self.t_end)
        return DT_OUT if t_end is None or not t_end > 0 else study_dt_out(t_end, min(DT_OUT, t_end))

    def designs(self) -> list[dict[str, float]]:
        """Every design as {varied name: value}, in a fixed order (its index is the design id)."""
        names = [a.name for a in self.axes]
        if self.sample is None:
            return [dict(zip(names, combo)) for combo in itertools.product(*(a.values for a in self.axes))]
        from scipy.stats import qmc  # loaded when a sample is drawn: scipy.stats is slow to import

        with warnings.catch_warnings():
            # scipy warns unless N is a power of 2 (the sequence's balance is exact only then); the first
            # N points of the scrambled sequence are still space-filling, and N is the user's choice
            warnings.filterwarnings("ignore", message=".*balance properties of Sobol", category=UserWarning)
            unit = qmc.Sobol(d=len(self.axes), scramble=True, seed=self.seed).random(self.sample)
        designs = []
        for point in unit:
            design = {}
            for axis, u in zip(self.axes, point):
                if axis.log:
                    lo, hi = math.log(axis.low), math.log(axis.high)
                    design[axis.name] = float(math.exp(lo + u * (hi - lo)))
                else:
                    design[axis.name] = float(axis.low + u * (axis.high - axis.low))
            designs.append(design)
        return designs

    def to_json(self) -> dict:
        return {"axes": [asdict(a) for a in self.axes], "base": self.base.as_dict(), "engines": list(self.engines),
                "t_end": self.t_end, "sample": self.sample, "seed": self.seed,
                **({"until_steady": True} if self.until_steady else {})}

    def fingerprint(self) -> str:
        """A hash that changes whenever the set of designs or what is run on them changes."""
        return hashlib.sha256(json.dumps(self.to_json(), sort_keys=True).encode()).hexdigest()[:16]


def read_study(path: str | Path, base: RobotParams) -> dict:
    """The [sweep] table of a TOML study file as Study keyword arguments; [params] updates ``base``.

    Every value is checked here, with the file named in the one-line message: lists where lists
    are wanted (a string is refused by name), numbers where numbers are wanted.
    """
    where = f"study file {str(path)!r}"
    data = read_toml_file(path, "study file")
    unknown = set(data) - {"sweep", "params"}
    if unknown:
        raise ParameterError(f"{where}: unknown table {sorted(unknown)[0]!r}; allowed: sweep, params")
    sweep, params = data.get("sweep", {}), data.get("params", {})
    for table, value in (("sweep", sweep), ("params", params)):
        if not isinstance(value, dict):
            raise ParameterError(f"{where}: {table} = {value!r} must be a table [{table}]")
    allowed = {"vary", "engines", "t_end", "sample", "seed", "until_steady"}
    if set(sweep) - allowed:
        raise ParameterError(f"{where}: unknown key {sorted(set(sweep) - allowed)[0]!r} in [sweep]; "
                             f"allowed: {', '.join(sorted(allowed))}")
    kwargs: dict = {}
    try:
        for key, example in (("vary", '"L=0.1,0.2"'), ("engines", '"analytic-approx"')):
            if key not in sweep:
                continue
            items = sweep[key]
            if not isinstance(items, list):
                raise ParameterError(f"{key}={items!r} is not a list; allowed: a list of strings, e.g. "
                                     f"{key} = [{example}]")
            for k, item in enumerate(items):
                if not isinstance(item, str):
                    raise ParameterError(f"{key}[{k}]={item!r} is not a string; allowed: a list of strings, e.g. "
                                         f"{key} = [{example}]")
            kwargs["axes" if key == "vary" else key] = (tuple(parse_vary(v) for v in items) if key == "vary"
                                                        else tuple(items))
        if "t_end" in sweep:
            kwargs["t_end"] = check_real("t_end", sweep["t_end"], high=MAX_T_END, unit="s")
        if "sample" in sweep:
            kwargs["sample"] = check_whole("sample", sweep["sample"], low=1, high=MAX_DESIGNS, why=" designs")
        if "seed" in sweep:
            kwargs["seed"] = check_whole("seed", sweep["seed"], low=0)
        if "until_steady" in sweep:
            if not isinstance(sweep["until_steady"], bool):
                raise ParameterError(f"until_steady={sweep['until_steady']!r} is not true or false")
            kwargs["until_steady"] = sweep["until_steady"]
        kwargs["base"] = base.replace(**params)
    except ParameterError as exc:
        raise ParameterError(f"{where}: {exc}") from None
    return kwargs


def __getattr__(name: str):
    """The older names of this module's constants: ``ENGINES`` (every variant: ``registry.NAMES``) and
    ``DEFAULT_ENGINES`` named variants (the registry's ``ENGINES`` names the two engines, analytic and mujoco)."""
    if name == "ENGINES":
        return registry.NAMES
    if name in OLDER_NAMES:
        return globals()[OLDER_NAMES[name]]
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
