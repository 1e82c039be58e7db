"""Skids verified by the step: a run whose modules skidded is run again at half its step until two runs agree to
the stated accuracy, or the run says it cannot. :func:`verify_skids` is the loop; a model's rule (the wheels', in
:mod:`.wheels.skids`) says when a run skidded, which figures it compares and when they agree. Also the floor below
which a skid does not count (:func:`skidded`), which the slide model's rigid limit (:mod:`.slides_grip.rigid_limit`) shares.

Why: a skid ends and starts where the steps fall, and soft constraints answer a reversal within their time
constant: the skid a module makes per stroke is off by an amount that shrinks with the step and that no figure
of the accuracy monitor shows. The slide model on finite grip was checked this way until its rows' time
constants were set in seconds and its figures extrapolated to the rigid limit instead (:mod:`.slides_grip.rigid_limit`:
with the time constant tied to the step, a 60 deg design's travel was off by 1.90e-3, 1.91e-3, 1.36e-3, 5.0e-4,
3.9e-4 over four halvings, so that agreeing halvings could not tell a converged run from a stalled one).

The finest run is kept once the differences of its last two halvings are within the rule's share (:data:`ACCEPT`
by default) of the accuracy stated for the figures, at most :data:`HALVINGS` halvings; where they do not reach
it, the accuracy monitor's mode decides, as for its own figures: 'stop' raises an :class:`.monitor.AccuracyError`
naming the figure, 'warn' returns the finest run with the figure in its accuracy record. Runs whose timestep was
given, and compliant clutches, are not rerun: their accuracy record says the skids were not verified.
"""

from __future__ import annotations

import math

from ipir_mujoco.core.errors import SimulationError
from ipir_mujoco.core.results import RunResult
from ipir_mujoco.core.steady_test import LIMIT_ACCURACY

from ..loop.monitor import RESIDUAL_TOL, AccuracyError

HALVINGS = 3  # the most halvings of the step a skid check makes (1e-4 s down to 1.25e-5 s)
TRAVEL_FLOOR = 0.1  # strokes (2 r): the smallest travel a module's difference is taken relative to
SKID_TOL = {"fixed": RESIDUAL_TOL, "steady": LIMIT_ACCURACY["mujoco"]}
# the share of the tolerance a halving's difference may take, over the last two halvings: a difference estimates
# the finer run's error only where the skids converge steadily, and they need not. A 60 deg design (M_stall
# 1.5 N m, mu_wall 0.5, F_n 40 N, 1 s) had module 2's travel off the equations by 1.90e-3, 1.91e-3, 1.36e-3,
# 5.0e-4 and 3.9e-4 at 1e-4 s halved four times: the first pair agrees within 1e-5 while both miss by 1.9e-3
ACCEPT = 0.5
SKID_FLOOR = 1e-4  # of the travel floor: a skid below it is not checked (:func:`skidded`)


def skidded(result: RunResult) -> bool:
    """Whether either module of ``result`` skidded by more than SKID_FLOOR of the travel floor (TRAVEL_FLOOR
    strokes): a shorter skid (a held module's soft rows creep ~1e-9 m per revolution) could not move the travel
    by the tolerance even if it were wrong by the whole of itself."""
    summary = result.summary
    least = SKID_FLOOR * TRAVEL_FLOOR * 2 * result.params.r
    return (summary["slip1_m"] or 0.0) > least or (summary["slip2_m"] or 0.0) > least


STEADY_FIGURES = (("steady_speed_m_s", "steady_speed_uncertainty_m_s"),
                  ("energy_per_metre_j_m", "energy_per_metre_uncertainty_j_m"))  # (figure, its own uncertainty)


def steady_difference(a: dict, b: dict, key: str, spread: str) -> float | None:
    """Two summaries' (coarse ``a``, fine ``b``) relative difference a - b of the steady figure ``key``, signed, its
    magnitude grown by the finer run's own uncertainty ``spread`` where the statistical test found it (what is
    left to trust is the difference and that together); None where either lacks the figure."""
    if a[key] is None or b[key] is None:
        return None
    scale = max(abs(a[key]), abs(b[key]), 1e-300)
    own = (b[spread] or 0.0) if b["steady_test"] == "statistical" else 0.0
    return math.copysign((abs(a[key] - b[key]) + own) / scale, a[key] - b[key])


class SkidRule:
    """What a run does with a skid rule (a subclass gives its floor ``skidded(result)``, and, for
    :func:`verify_skids`, its figures ``differences(coarse, fine)``, its acceptance ``judge(history)`` and
    ``failure(history)``): a model kind gives its own (:meth:`ipir_mujoco.engine.kinds.base.ModelKind.skid_rule`).
    A rule that checks otherwise (the slides' rigid limit,
    :class:`ipir_mujoco.engine.kinds.slides_grip.rigid_limit.RigidLimit`) overrides :meth:`verify`,
    :meth:`unverified` and :meth:`given_settings`."""

    def given_settings(self, params, settings, automatic) -> tuple:
        """(the settings a run whose timestep was given runs with, what the run records of them): ``settings`` as
        given; ``automatic()`` gives the settings the engine would have chosen."""
        return settings, {}

    def unverified(self, result: RunResult, why: str) -> RunResult:
        """``result``, not checked (``why``), its accuracy record saying so where it skidded."""
        if self.skidded(result):
            result.accuracy["skid_check"] = f"not verified: {why}"
        return result

    def given(self, result: RunResult) -> RunResult:
        """``result``, of a run whose timestep was given: not rerun."""
        return self.unverified(result, "timestep given")

    def verify(self, result: RunResult, rerun, mode: str, dt_min: float,
               wall_budget_s: float | None = None) -> RunResult:
        """``result`` (an automatically stepped run) or a finer run of the same design, verified by this rule
        (:func:`verify_skids`) within the run's wall-time budget ``wall_budget_s`` [s]; ``rerun`` as
        :func:`verify_skids` takes it."""
        return verify_skids(result, rerun, mode, dt_min, self, wall_budget_s)


class NoSkids(SkidRule):
    """The rule of a kind whose modules cannot skid (unlimited grip): nothing is checked, nothing recorded."""

    name = "none"

    def skidded(self, result: RunResult) -> bool:
        return False

    def verify(self, result: RunResult, rerun, mode: str, dt_min: float,
               wall_budget_s: float | None = None) -> RunResult:
        return result


class Unverified(SkidRule):
    """A rule whose runs are not checked (``why``: compliant clutches, whose skid is the anchor's slide on the
    spring, not a limit's reversal, and whose spring already sets a step of a few microseconds): a run that
    skidded (by ``rule``'s floor) says so in its accuracy record, in ``rule``'s words."""

    def __init__(self, rule: SkidRule, why: str):
        self.rule, self.why, self.name = rule, why, rule.name

    def skidded(self, result: RunResult) -> bool:
        return self.rule.skidded(result)

    def unverified(self, result: RunResult, why: str) -> RunResult:
        return self.rule.unverified(result, why)

    def verify(self, result: RunResult, rerun, mode: str, dt_min: float,
               wall_budget_s: float | None = None) -> RunResult:
        return self.rule.unverified(result, self.why)


NO_SKIDS = NoSkids()


def verify_skids(result: RunResult, rerun, mode: str, dt_min: float, rule,
                 wall_budget_s: float | None = None) -> RunResult:
    """``result`` (an automatically stepped run that may skid) or a finer run of the same design, verified as
    the module docstring says. ``rerun(timestep)`` runs the design again at that step [s] and returns its
    RunResult; ``mode``: the accuracy monitor's ('stop' | 'warn'); ``dt_min`` [s]: the smallest step a run may
    take (halving stops before it); ``rule``: the model's floor, figures and acceptance
    (:data:`ipir_mujoco.engine.kinds.wheels.skids.WHEELS_RULE`); ``wall_budget_s`` [s]: the run's wall-time budget,
    which its repeats share (each RunResult's ``wall_time_s`` counts from the run's start): a repeat predicted
    past it (:func:`_past_budget`) is not started, and the run says which steps the check needed."""
    if not rule.skidded(result):
        result.accuracy["skid_check"] = "no skid"
        return result
    coarse, history = result, []
    fine, spent_before = result, 0.0
    for _ in range(HALVINGS):
        dt = coarse.settings["timestep"] / 2
        if dt < dt_min:
            break
        late = _past_budget(coarse, spent_before, dt, len(history), wall_budget_s)
        if late is not None:
            if mode == "stop":
                raise SimulationError(late)
            history = history or [{"timestep": coarse.settings["timestep"], "half": dt, "kind": "fixed",
                                   "figure": "none", "difference": math.inf, "differences": {}}]
            return _verified(coarse, history, ACCEPT * SKID_TOL[history[-1]["kind"]], late)
        spent_before = coarse.wall_time_s
        fine = rerun(dt)
        kind, diff = rule.differences(coarse, fine)
        history.append({"timestep": coarse.settings["timestep"], "half": dt, "kind": kind, "differences": diff})
        passed, _, _, tolerance = rule.judge(history)
        if passed:
            return _verified(fine, history, tolerance, None)
        coarse = fine
    if len(history) < 2:  # the step cannot be halved twice above the smallest a run may take: unverifiable
        message = (f"MuJoCo accuracy check failed at t={fine.t_end:.6g} s: the modules skid, and their error under "
                   f"the step cannot be checked: the timestep {result.settings['timestep']:.3g} s cannot be halved "
                   f"twice above {dt_min:g} s; use --accuracy warn to finish the run and record it")
        if mode == "stop":
            raise AccuracyError(message)
        history = history or [{"timestep": result.settings["timestep"], "half": result.settings["timestep"],
                               "kind": "fixed", "figure": "none", "difference": math.inf, "differences": {}}]
        return _verified(fine, history, ACCEPT * SKID_TOL["fixed"], message)
    _, _, _, tolerance = rule.judge(history)
    message = (f"MuJoCo accuracy check failed at t={fine.t_end:.6g} s: the modules skid, and {rule.failure(history)}; "
               f"use a smaller --timestep (e.g. {history[-1]['half'] / 2:.3g}), or --accuracy warn to finish the run "
               "and record it")
    if mode == "stop":
        raise AccuracyError(message)
    return _verified(fine, history, tolerance, message)


def _past_budget(coarse: RunResult, spent_before: float, dt: float, done: int,
                 wall_budget_s: float | None) -> str | None:
    """Why the next repeat, at ``dt`` [s], is not started (one line), or None: the check still needs at least
    max(2 - ``done``, 1) halvings, each about twice the last run's wall time (half the step, twice the steps;
    the last run took ``coarse.wall_time_s`` - ``spent_before`` [s], counted from the run's start), and the run
    has spent ``coarse.wall_time_s`` of its ``wall_budget_s`` [s]."""
    if wall_budget_s is None:
        return None
    spent, last = coarse.wall_time_s, max(coarse.wall_time_s - spent_before, 0.0)
    steps = [dt / 2 ** k for k in range(max(2 - done, 1))]
    needed = sum(last * 2 ** (k + 1) for k in range(len(steps)))
    if spent + needed <= wall_budget_s:
        return None
    return (f"the run exceeded its wall-time budget of {wall_budget_s:g} s in its skid check (the modules skid, and "
            f"the check runs the design again at a finer step): it would need runs at "
            f"{' and '.join(f'{h:.3g} s' for h in steps)} (about {needed:.3g} s of wall time more, after "
            f"{spent:.3g} s); raise the budget, or give the timestep yourself (a given step is not checked)")


def _verified(run: RunResult, history: list, tolerance: float, failed: str | None) -> RunResult:
    """``run`` with the check recorded: ``settings['skid_check']`` (each halving's differences) and, in its
    accuracy record, ``skid_difference`` (the last one), its ``tolerance`` (the share ACCEPT of the stated
    accuracy a halving may move the figures by) and, where the check ``failed`` (its one-line reason), a
    violation."""
    finite = lambda x: float(x) if math.isfinite(x) else None  # noqa: E731  (JSON has no inf: None, not compared)
    clean = lambda v: ({k: finite(x) for k, x in v.items()} if isinstance(v, dict)  # noqa: E731
                       else finite(v) if isinstance(v, float) else v)
    history = [{key: clean(value) for key, value in h.items()} for h in history]
    last = history[-1]
    run.settings["skid_check"] = history
    record = run.accuracy
    record["skid_check"] = "verified" if failed is None else "failed"
    record["skid_difference"] = last["difference"]
    record.setdefault("tolerances", {})["skid_difference"] = float(tolerance)
    if failed is not None:
        record["ok"] = False
        record.setdefault("violations", []).append({"figure": "skid_difference", "t_s": float(run.t_end),
                                                    "value": last["difference"],
                                                    "tolerance": float(tolerance), "reason": failed})
    return run
