"""The rigid limit of the slide model on finite grip: a skidding run's figures extrapolated, with their errors.

Why: MuJoCo's one-way limits and friction rows are soft, and a skid's error grows with the rows' time constant
tau (each reversal of a skid is answered within it), with the step dt and with the carriage's inertia, a share
sigma of its module's mass that a skidding module carries along (:mod:`ipir_mujoco.engine.builders.grip_model`): to first order
f = f* + A tau + B dt + C sigma, each term at or above the stated accuracy at the automatic step (mjcf/README.md,
"Finite grip: the rigid limit", has the measurements). The three are scaled together: a run's *regularization*
h is its step, its grip rows' time constant STEPS_PER_TIME_CONSTANT h (in seconds; :mod:`ipir_mujoco.engine.kinds.timestep`) and its
carriage's share sigma_1 h / h_1 (the loop's time constant, two steps, with them), so that f(h) = f* + a h + ...

An automatically stepped run whose modules skid (beyond :func:`ipir_mujoco.engine.kinds.skid_check.skidded`'s floor) is the finest
member of a family (:func:`_choose`): at fixed time h, 2h, 4h (figures read at the first run's end, every step a
whole fraction of its duration), to the steady state h, 1.5h, 2h (figures read over the first run's steady
window, :func:`ipir_mujoco.core.cycles.window_figures`: where each run's steady test stops does not scatter
them). A coarser member that does not stay sane (:func:`clean_motion`) gives way to a closer one, or to a finer
run (ratio :data:`FINE`). Each figure (fixed time: revolutions, x1_final, x2_final; to the steady state:
steady_speed_m_s, energy_per_metre_j_m) then has (:func:`extrapolate`)

- its order of convergence measured from the three runs, p with (f3 - f2) / (f2 - f1) = (h3^p - h2^p) /
  (h2^p - h1^p);
- its rigid limit, the first-order extrapolation from the two finest runs, E12 = (h2 f1 - h1 f2) / (h2 - h1) (the
  measured order checks it; extrapolating with the measured order itself would amplify the runs' scatter);
- its error |E12 - E23| (E23 the same from the two coarser runs: the remainder beyond first order, larger in
  E23), plus :data:`SCATTER` of the correction |f1 - E12| (scatter three runs may not show), the
  solver's impedance leak (1e-4 of the figure, the same in every run) and a statistical steady window's own
  uncertainty.

A figure is *accepted* where its error is within the stated accuracy (:data:`ACCURACY`: 1e-3 at fixed time,
3e-4 steady; relative to the figure, travel to at least a tenth of a stroke) and three runs measured its order.
Runs closer than the accuracy leave nothing to extrapolate (:data:`FLAT`); otherwise the extrapolation is *not
trustworthy* where the measured order is below :data:`ORDER_RANGE` or the runs' differences disagree in sign,
and the accuracy monitor's mode decides: 'stop' raises an :class:`.monitor.AccuracyError` naming the figure and
the estimate it did reach, 'warn' records a violation and goes on. A higher order (the coarser runs' motion
error) keeps the finest run's figure within the runs' spread.

Reported: the summary's figures are the extrapolated ones (:attr:`RunResult.figures`), ``figure_errors`` each
one's estimated absolute error; ``settings['extrapolation']`` the runs (time constant, step, carriage share,
steps, wall time, accuracy figures), the steps used and each figure's measured order; the accuracy record
``rigid_limit`` ('extrapolated', 'no skid', 'failed', 'not extrapolated: timestep given' or 'not extrapolated:
compliant clutches'), ``figure_relative_errors``, ``figures_accepted``. The series is the first run's.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

from ipir_mujoco.core.results import RunResult
from ipir_mujoco.core.steady_test import LIMIT_ACCURACY

from ...builders.model import SolverSettings
from ...loop.monitor import RESIDUAL_TOL, AccuracyError
from ..skid_check import TRAVEL_FLOOR, SkidRule, skidded
from .rigid_family import (  # noqa: F401  (re-exported: every name stays importable from here)
    FIGURES, MEMBER_SLACK, Family, clean_motion, member_settings)

UNCERTAINTY = {"steady_speed_m_s": "steady_speed_uncertainty_m_s",
               "energy_per_metre_j_m": "energy_per_metre_uncertainty_j_m"}  # a steady figure's own
ACCURACY = {"fixed": RESIDUAL_TOL, "steady": LIMIT_ACCURACY["mujoco"]}
ORDER_RANGE = (0.5, 2.0)  # a measured order outside it: the runs are not in the first-order regime
FLAT = 1.0  # of the accuracy: runs closer than it leave nothing to extrapolate (the order is not measured)
# of the correction |f1 - E12|: the scatter three runs may not show (mjcf/README.md): fixed-time figures and a
# window's energy per metre (the motor's work less the energy in transit, both large) scatter up to 10-15 % of it;
# the steady speed, a periodic limit of the same revolutions in every run, is smooth in h
SCATTER = {"revolutions": 0.15, "x1_final": 0.15, "x2_final": 0.15, "energy_per_metre_j_m": 0.15,
           "steady_speed_m_s": 0.0}
BRACKET = 2.0  # the safety factor of a two-run bound (mjcf/README.md)
# the coarser members' ratios, where the motion allows them: fixed-time figures scatter with where the last skid's
# steps fall, which a wider family averages; steady figures, read over one window, are smooth in h, and a closer
# family keeps the extrapolation's remainder small (mjcf/README.md, "Finite grip: the rigid limit")
COARSE = {"fixed": (2.0, 4.0), "steady": (1.5, 2.0)}
FINE = 2.0 / 3.0  # the finer member's ratio, where it does not


@dataclass(frozen=True)
class Estimate:
    """One figure's rigid limit: ``value``, its estimated absolute ``error``, the measured ``order`` (None where
    not measured), whether it is ``trusted`` and, where not, ``reason`` (one phrase); ``verified``: whether three
    runs checked the error (two cannot measure an order: their error is a bound that is never *accepted*)."""

    value: float
    error: float
    order: float | None
    trusted: bool
    reason: str | None = None
    verified: bool = True


def measured_order(h: tuple[float, float, float], f: tuple[float, float, float]) -> float | None:
    """p with (f3 - f2) / (f2 - f1) = (h3^p - h2^p) / (h2^p - h1^p), h1 < h2 < h3 [any unit]; None where the
    differences disagree in sign or vanish (no order to measure). Solved by bisection on p in (1e-3, 8):
    the right side rises with p for h1 < h2 < h3."""
    d1, d2 = f[1] - f[0], f[2] - f[1]
    if not d1 * d2 > 0:
        return None
    target = d2 / d1
    ratio = lambda p: (h[2] ** p - h[1] ** p) / (h[1] ** p - h[0] ** p)  # noqa: E731
    lo, hi = 1e-3, 8.0
    if not ratio(lo) <= target <= ratio(hi):
        return lo if target < ratio(lo) else hi
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if ratio(mid) < target else (lo, mid)
    return 0.5 * (lo + hi)


def extrapolate(h: tuple[float, float, float], f: tuple[float, float, float], accuracy: float,
                figure: str) -> Estimate:
    """The rigid limit of one figure from its values ``f`` at the regularizations ``h`` (three runs, finest first;
    module docstring); ``accuracy``: the figure's stated accuracy, absolute; ``figure``: its name (:data:`SCATTER`)."""
    d1, d2 = f[1] - f[0], f[2] - f[1]
    e12 = (h[1] * f[0] - h[0] * f[1]) / (h[1] - h[0])
    e23 = (h[2] * f[1] - h[1] * f[2]) / (h[2] - h[1])
    order = measured_order(h, f)
    spread = max(abs(e12 - e23), abs(d1), abs(d2))
    if max(abs(d1), abs(d2)) <= FLAT * accuracy:  # within its accuracy the figure does not depend on h
        return Estimate(e12, spread, order, True)
    if order is not None and ORDER_RANGE[0] <= order <= ORDER_RANGE[1]:  # first order: E12, its remainder, scatter
        return Estimate(e12, abs(e12 - e23) + SCATTER[figure] * abs(f[0] - e12), order, True)
    if order is not None and order > ORDER_RANGE[1]:  # a higher order dominates the coarser runs: the finest, within
        return Estimate(f[0], spread, order, True)  # the spread of the runs and of both extrapolations
    reason = ("the runs' differences disagree in sign" if order is None
              else f"the measured order {order:.2f} is below {ORDER_RANGE[0]:g}")
    return Estimate(e12, spread, order, False, reason)


def bracket(h: tuple[float, float], f: tuple[float, float]) -> Estimate:
    """The finer of two runs (regularizations ``h``, finest first) with its error: BRACKET times the bound of a
    scheme of order one or higher, |f2 - f1| h1 / (h2 - h1) (no order measured: two runs cannot show it)."""
    return Estimate(f[0], BRACKET * abs(f[1] - f[0]) * h[0] / (h[1] - h[0]), None, True, verified=False)


def figure_scale(key: str, values, params) -> float:
    """What a figure's error is relative to: revolutions to at least TRAVEL_FLOOR revolutions, a module's travel
    to at least TRAVEL_FLOOR strokes (2 r), a steady figure to itself (the largest magnitude among ``values``)."""
    largest = max(abs(v) for v in values)
    if key == "revolutions":
        return max(largest, TRAVEL_FLOOR)
    if key in ("x1_final", "x2_final"):
        return max(largest, TRAVEL_FLOOR * 2 * params.r)
    return max(largest, 1e-300)

def _estimates(family: Family, ratios: list[float]) -> tuple[dict[str, Estimate], dict[str, float]]:
    """Each figure estimated from the members at ``ratios`` (finest first): three by :func:`extrapolate`, two by
    :func:`bracket`; added to the error, what no extrapolation in h removes: the solver's impedance leak, 1 - d of
    the figure (the same d in every member; d = 0.9999, MuJoCo's largest: 1e-4), and a statistical steady
    window's own uncertainty. Also each figure's scale (:func:`figure_scale`)."""
    kind, first = family.kind, family.first
    h = tuple(family.member(r).settings["timestep"] for r in ratios)
    read = [family.figures(r) for r in ratios]
    estimates, scales = {}, {}
    for key in FIGURES[kind]:
        values = tuple(figures[key] for figures in read)
        if any(v is None for v in values):  # a run without the figure (a stall's energy per metre): not reported
            continue
        scales[key] = figure_scale(key, values, first.params)
        estimate = (extrapolate(h, values, ACCURACY[kind] * scales[key], key) if len(ratios) == 3
                    else bracket(h, values))
        # what no member's regularization changes: every row leaks 1 - d of the acceleration it resists, d the
        # solver's impedance (the same in every member); and a statistical steady window's own uncertainty
        own = (1.0 - family.settings.solimp[1]) * scales[key]
        if kind == "steady" and first.summary.get("steady_test") == "statistical":
            own += first.summary[UNCERTAINTY[key]] or 0.0
        estimates[key] = replace(estimate, error=estimate.error + own)
    return estimates, scales


def rigid_limit(first: RunResult, rerun, mode: str, t_cap: float) -> RunResult:
    """``first`` (an automatically stepped run of the slide model on finite grip) with its figures replaced by
    their rigid limit and errors where its modules skidded (module docstring), else as it is, marked 'no skid'.

    ``rerun(settings, t_end)`` runs the design again without the steady test (its monitor recording, never
    stopping); ``mode``: the accuracy monitor's ('stop' | 'warn'); ``t_cap`` [s]: the run's t_end (with
    until_steady the cap).
    """
    if not skidded(first):
        first.accuracy["rigid_limit"] = "no skid"
        first.figures = {"values": {}, "errors": {}}
        return first
    family = Family(first, rerun, t_cap)
    ratios, plan = _choose(family)
    first.wall_time_s = family.wall_time_s
    if not ratios:
        return _untrusted(family, mode, plan)
    estimates, scales = _estimates(family, ratios)
    kind = family.kind
    first.figures = {"values": {k: e.value for k, e in estimates.items()},
                     "errors": {k: e.error for k, e in estimates.items()}}
    first.settings["extrapolation"] = {
        "figures": kind, "plan": plan, "runs": family.record(),
        "used": [family.member(r).settings["timestep"] for r in ratios],
        "order": {k: e.order for k, e in estimates.items()}}
    record = first.accuracy
    record["rigid_limit"] = "extrapolated"
    record["figure_relative_errors"] = {k: e.error / scales[k] for k, e in estimates.items()}
    record["figures_accepted"] = {k: bool(e.trusted and e.verified and e.error <= ACCURACY[kind] * scales[k])
                                  for k, e in estimates.items()}
    record.setdefault("tolerances", {})["figure_relative_errors"] = ACCURACY[kind]
    distrusted = [(k, e) for k, e in estimates.items() if not e.trusted]
    if distrusted:
        key, e = distrusted[0]
        taus = ", ".join(f"{family.member(r).settings['grip_time_constant']:.3g}" for r in ratios)
        message = (f"MuJoCo accuracy check failed at t={first.t_end:.6g} s: the modules skid, and the rigid limit of "
                   f"{key} is not trustworthy: {e.reason}; its estimate {e.value:.6g} +- {e.error:.2g} (runs at time "
                   f"constants {taus} s); use --accuracy warn to finish the run and record it")
        if mode == "stop":
            raise AccuracyError(message)
        record["ok"] = False
        record.setdefault("violations", []).append({"figure": key, "t_s": float(first.t_end), "value": e.value,
                                                    "tolerance": ACCURACY[kind], "reason": message})
    return first


def _choose(family: Family) -> tuple[list[float], str]:
    """The members' ratios to estimate from, finest first, and the plan in words: the first run and the coarser
    members (:data:`COARSE`) where they stay sane (:func:`clean_motion`); where only the coarsest does not, the
    first, the next coarser and one halfway between; else a finer member (:data:`FINE`) and the first run; none
    where that fails too. A member found unsound stops the coarser ones being run."""
    coarse = COARSE[family.kind]
    if family.usable(coarse[0]):
        if family.usable(coarse[1]):
            return [1.0, *coarse], "coarser members"
        closer = (0.5 * (1.0 + coarse[0]), coarse[0])
        if family.usable(closer[0]):
            return [1.0, *closer], "coarser members, the closer pair (the coarsest was not sound)"
    if family.usable(FINE):
        return [FINE, 1.0], "a finer member (no coarser one was sound)"
    return [], "no member at a finer or coarser regularization stayed within the monitor's tolerances"


def _untrusted(family: Family, mode: str, why: str) -> RunResult:
    """The first run, its figures not extrapolated (``why``): 'stop' raises, 'warn' records a violation."""
    base = family.first
    message = (f"MuJoCo accuracy check failed at t={base.t_end:.6g} s: the modules skid, and their rigid limit "
               f"cannot be extrapolated: {why}; use --accuracy warn to finish the run and record it")
    if mode == "stop":
        raise AccuracyError(message)
    base.settings["extrapolation"] = {"figures": None, "runs": family.record(), "used": [], "order": {}, "plan": why}
    base.figures = {"values": {}, "errors": {}}
    record = base.accuracy
    record["rigid_limit"] = "failed"
    record["ok"] = False
    record.setdefault("violations", []).append({"figure": "rigid_limit", "t_s": float(base.t_end), "value": None,
                                                "tolerance": None, "reason": message})
    return base


def not_extrapolated(result: RunResult, why: str) -> None:
    """Mark a skidding run whose figures were not extrapolated (``why``: 'timestep given' | 'compliant
    clutches'): its figures are its own, ``figure_errors`` empty."""
    result.accuracy["rigid_limit"] = f"not extrapolated: {why}"
    result.figures = {"values": {}, "errors": {}}


class RigidLimit(SkidRule):
    """The slide model's skid rule on finite grip (:meth:`ipir_mujoco.engine.kinds.base.ModelKind.skid_rule`): its
    floor (:func:`ipir_mujoco.engine.kinds.skid_check.skidded`), its figures extrapolated to the rigid limit (:func:`rigid_limit`), not
    halved; a run whose timestep is given keeps the grip rows' time constant the automatic run would have, in
    seconds (:func:`ipir_mujoco.engine.kinds.timestep.given_settings`)."""

    name = "slides"

    def skidded(self, result: RunResult) -> bool:
        return skidded(result)

    def given_settings(self, params, settings: SolverSettings, automatic) -> tuple:
        from ..timestep import given_settings

        settings, rule = given_settings(params, settings, automatic)
        return settings, {"grip_time_constant_rule": rule}

    def unverified(self, result: RunResult, why: str) -> RunResult:
        if self.skidded(result):
            not_extrapolated(result, why)
        return result

    def verify(self, result: RunResult, rerun, mode: str, dt_min: float,
               wall_budget_s: float | None = None) -> RunResult:
        """``rerun.member(settings, t_end)``: the design run again (:func:`rigid_limit`), ``rerun.t_cap`` [s] its
        t_end."""
        return rigid_limit(result, rerun.member, mode, rerun.t_cap)


RIGID_LIMIT = RigidLimit()
