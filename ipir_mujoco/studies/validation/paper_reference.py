"""What the paper reports for its simulation case, and how precisely it says it.

The paper gives its results in rounded words beside its figures (the figures
themselves are plots; see docs/model.md, "What the paper reports"). Each
:class:`ReportedFigure` holds the number as the paper words it and the
*precision* that wording implies: the place value of its last digit ("about
0.9 m" is stated to 0.1 m). The accepted interval is the set of values that
round to the stated number, ``[value - precision / 2, value + precision / 2]``;
no bound is set by hand. A model value lands

- ``inside``: strictly inside the interval;
- ``edge``: on a bound, to within what the solver can resolve
  (:data:`EDGE_RESOLUTION`): it rounds to the paper's number under one common
  rounding rule and to the next number under another;
- ``outside``: anywhere else.

Two statements of the paper are geometric identities of the slider-crank
(S_min = L - r, S_max = L + r): they hold for any run and are checked
separately (:func:`check_identities`), never counted as reproduced figures.

The checks only make sense at the paper's own design (:data:`PAPER_CASE`);
:func:`differences_from_paper` tells whether a parameter set is that design.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import numpy as np

from ipir_mujoco.core.params import RobotParams, describe_parameters, parameter_units
from ipir_mujoco.core.results import RunResult, mode_changes

# The paper's simulation case (its section on the Mathematica implementation),
# SI units; phi0 = 0 is our reading of "phi(0) near zero", omega0 = 0 of "start-up".
PAPER_CASE: dict[str, float] = {"m1": 1.0, "m2": 1.0, "r": 0.05, "L": 0.2, "J_A": 0.001, "F_r1": 1.0,
                                "F_r2": 1.0, "M": 0.25, "phi0": 0.0, "omega0": 0.0}
# Conditions of the paper's model that are parameters here: constant torque, a
# horizontal pipe, rigid clutches. (The rod's mass is not among them: the paper
# neglects it, and the paper-model rung always runs with a massless rod.)
PAPER_CONDITIONS: dict[str, object] = {"drive": "torque", "incline": 0.0, "clutch_stiffness": None,
                                       "clutch_damping": 0.0, "clutch_backlash": 0.0}

# A value closer to a bound than this (relative to the bound's size) cannot be
# told from the bound by a solver run at rtol 1e-10: it sits on the edge.
EDGE_RESOLUTION = 1e-9


def differences_from_paper(params: RobotParams) -> list[dict]:
    """The parameters in which ``params`` is not the paper's case: [{name, value, paper}] (empty if it is)."""
    wanted = {**PAPER_CASE, **PAPER_CONDITIONS}
    return [{"name": name, "value": getattr(params, name), "paper": paper}
            for name, paper in wanted.items() if getattr(params, name) != paper]


def describe_differences(differences: list[dict]) -> str:
    """'L = 0.3 m (paper: 0.2 m)' for each difference, in words."""
    rule_words = {row["name"]: row["default_text"] for row in describe_parameters() if row["default"] is None}

    def text(name, value):
        if value is None:  # a rule default, e.g. 'rigid' clutches
            return rule_words.get(name, "none")
        return f"{value:g} {parameter_units(name)}" if isinstance(value, float) else str(value)

    return ", ".join(f"{d['name']} = {text(d['name'], d['value'])} (paper: {text(d['name'], d['paper'])})"
                     for d in differences)


def classify(value: float, low: float, high: float) -> str:
    """'inside', 'edge' or 'outside' of the closed interval [low, high] (see the module docstring)."""
    if not np.isfinite(value):
        return "outside"
    for bound in (low, high):
        if abs(value - bound) <= EDGE_RESOLUTION * max(abs(bound), high - low):
            return "edge"
    return "inside" if low < value < high else "outside"


@dataclass(frozen=True)
class ReportedFigure:
    """One number the paper reports, how precisely, and how to measure it on a run."""

    key: str
    label: str
    wording: str  # the paper's words
    value: float  # the number in those words [units]
    precision: float  # place value of its last stated digit [units]
    units: str
    why: str  # why that precision
    measure: Callable[[RunResult], tuple[float, str]]  # (model value, note on how it was obtained)

    @property
    def low(self) -> float:
        return self.value - self.precision / 2

    @property
    def high(self) -> float:
        return self.value + self.precision / 2

    def check(self, run: RunResult) -> dict:
        return self.judge(*self.measure(run))

    def judge(self, value: float, note: str = "") -> dict:
        """The check's record for a model ``value``."""
        value = float(value)
        status = classify(value, self.low, self.high)
        margin = min(value - self.low, self.high - value) / self.precision if np.isfinite(value) else None
        return {"key": self.key, "label": self.label, "reported": self.wording, "reported_value": self.value,
                "precision": self.precision, "value": value, "low": self.low, "high": self.high,
                "units": self.units, "why": self.why, "note": note, "status": status,
                "margin_precisions": margin, "reproduced": status != "outside"}


def _revolutions(run: RunResult) -> tuple[float, str]:
    return run.summary["revolutions"], ""


def _x1(run: RunResult) -> tuple[float, str]:
    return run.summary["x1_final"], ""


def _x2_absolute(run: RunResult) -> tuple[float, str]:
    """Module 2's absolute position (the paper plots C's position, which starts at S(phi0)).

    Under the paper's rule module 2 moves only while the gap opens, and each
    expansion opens it from L - r to L + r: module 2 advances by exactly the
    stroke 2r per expansion, so after n completed expansions (and outside an
    expansion) it stands at S(phi0) + 2 r n exactly. That exact value is the
    model's answer; the integrated one differs from it by the solver's error.
    """
    s, r = run.series, run.params.r
    start = float(s["S"][0])
    integrated = run.summary["x2_final"] + start
    n = sum(1 for change in mode_changes(s) if change["from"] == "expansion")
    exact = start + 2 * r * n
    ends = [c["t"] for c in mode_changes(s) if c["from"] == "expansion"]
    if n and abs(integrated - exact) <= 1e-6 * 2 * r:
        return exact, (f"quantised: module 2 moves only in expansions, each exactly one stroke 2r = {2 * r:g} m; "
                       f"after {n} expansions (the last ending at {ends[-1]:.3f} s) it stands at "
                       f"S(0) + {n} x 2r = {exact:.6g} m exactly (integrated: {integrated:.13g} m)")
    return integrated, ""


def _peak_speed(run: RunResult) -> tuple[float, str]:
    return max(run.summary["v1_max"], run.summary["v2_max"]), ""


def _first_minimum(run: RunResult) -> tuple[float, str]:
    value = run.summary["first_contraction_end_s"]
    return (float("nan"), "no minimum of S in the run") if value is None else (value, "")


def _peak_acceleration(run: RunResult) -> tuple[float, str]:
    s = run.series
    a = np.maximum(np.abs(s["a1"]), np.abs(s["a2"]))
    i = int(np.argmax(a))
    jump = run.params.r * s["omega"][i] ** 2
    return float(a[i]), (f"the largest jump at a mode switch, at {s['t'][i]:.3f} s: a module starts or stops with "
                         f"r omega^2 = {jump:.5g} m/s^2 (the paper's plotted spike height also depends on its "
                         "sampling)")


REPORTED: tuple[ReportedFigure, ...] = (
    ReportedFigure("revolutions", "crank revolutions at 1 s", "approximately 8.5 revolutions (Fig. 2a)", 8.5, 0.5,
                   "rev", "8.5 ends in a half: a count read off Fig. 2a to the nearest half turn (read to one "
                   "decimal, the paper would have written the model's value as 8.4)", _revolutions),
    ReportedFigure("x1_final", "module 1 (rear) displacement at 1 s", "approximately 0.9 m (Fig. 3a)", 0.9, 0.1,
                   "m", "stated to one decimal: 0.1 m", _x1),
    ReportedFigure("x2_absolute", "module 2 (front) position at 1 s", "approximately 1.0 m (Fig. 3a)", 1.0, 0.1, "m",
                   "stated to one decimal: 0.1 m; the paper plots C's absolute position, which starts at "
                   "S(0) = L + r", _x2_absolute),
    ReportedFigure("peak_speed", "peak module speed", "nearly 4 m/s by t = 1 s (Fig. 3b)", 4.0, 1.0, "m/s",
                   "stated to one significant digit: 1 m/s", _peak_speed),
    ReportedFigure("first_contraction_end_s", "first minimum of the gap S",
                   "approximately t = 0.23 s (Fig. 4)", 0.23, 0.01, "s", "stated to two decimals: 0.01 s",
                   _first_minimum),
    ReportedFigure("peak_acceleration", "largest module acceleration", "spikes up to 1000 m/s^2 (Fig. 3c)",
                   1000.0, 1000.0, "m/s^2", "stated to one significant digit: 1000 m/s^2", _peak_acceleration),
)


def check_paper_figures(run: RunResult) -> list[dict]:
    """Each reported figure against ``run`` (the paper's model at the paper's case)."""
    return [figure.check(run) for figure in REPORTED]


def _passes(phi: np.ndarray, angle: float) -> bool:
    """Whether the crank angle series reaches ``angle`` + 2 k pi for some integer k."""
    lo, hi = float(phi.min()), float(phi.max())
    return np.floor((hi - angle) / (2 * np.pi)) >= np.ceil((lo - angle) / (2 * np.pi) - 1e-12)


def check_identities(run: RunResult) -> list[dict]:
    """The slider-crank's identities the paper also states: the gap stays in [L - r, L + r].

    They hold by construction for any engine and design, so they are no
    evidence for the model and are never counted as reproduced figures. The
    record shows the run's extreme gap against L -+ r; ``holds`` when the gap
    never leaves [L - r, L + r] and reaches the bound whenever the crank passes
    the dead centre that gives it (to 1e-9 of the stroke: rounding, not physics).
    """
    p, s = run.params, run.series
    tol = 1e-9 * 2 * p.r
    inside = bool(s["S"].min() >= p.L - p.r - tol and s["S"].max() <= p.L + p.r + tol)
    rows = []
    for key, label, wording, expected, value, dead_centre in (
            ("S_min", "smallest gap S", "S_min = L - r = 1.5 dm (Fig. 4)", p.L - p.r, float(s["S"].min()), np.pi),
            ("S_max", "largest gap S", "S_max = L + r = 2.5 dm (Fig. 4)", p.L + p.r, float(s["S"].max()), 0.0)):
        reached = abs(value - expected) <= tol or not _passes(s["phi"], dead_centre)
        rows.append({"key": key, "label": label, "reported": wording, "expected": expected, "value": value,
                     "units": "m", "holds": inside and bool(reached)})
    return rows
