"""Skids verified by the step on the wheeled model: a run whose wheels skidded is run again at half its step
until the halvings show each figure within the accuracy the model states for it, or the run says it cannot
(the slide model's check, :mod:`.skid_check`, with the wheels' figures, floors and acceptance).

Why: a skidding wheel is a sliding soft contact, and MuJoCo's convex friction pushes it off the wall by about
2 mu v tau (tau the contact's time constant, :data:`.wheels_model.ROW_TIMES`), within the time constant, as the
hub ratchets reverse within theirs: the skid a module makes converges at first order in step / tau or a little
faster, and a skidding module's net travel is the small difference of its strokes and its skid, so at the
default step (tau / 2) its error reaches 0.3-0.9 % of the travel where the model states 0.2 %
(``python bench/wheels_convergence.py``, mjcf/README.md "The round pipe: convergence"). Nothing known before
the run says how long a module will skid (the MuJoCo side does not ask the analytic equations), so the run
measures it: the same run at half the step, and again, and the differences of the figures the user reads
(revolutions, each module's travel and skid; to the steady state, the steady speed and energy per metre).

The figures and their accuracy (:data:`TOLERANCE`, issue 32): travel, revolutions and the steady figures
0.2 % (travel relative to at least a tenth of a stroke, as the slides'), a skid's length 1 % plus its
resolution (:func:`skid_resolution`: how closely soft contacts define a skid's ends, a length in metres). The
finest run is kept once, after two halvings at least, each figure's estimated error (:func:`estimate`) is
within its accuracy: where the last two differences have one sign and shrink (ratio q < 1; on the riser and
the 30 deg incline 0.3-0.66), the geometric sum of the differences still to come,
|d| q / (1 - q) (first order: q = 1/2, the last difference itself); else (differences that grow or change
sign: a pair of runs can agree by chance, as in a bend) both must lie within ACCEPT of the accuracy, the slide
model's rule. A run whose wheels skid less than :func:`skid_floor` is not checked.
"""

from __future__ import annotations

import math

from ipir_mujoco.core.results import RunResult

from .model import ROW_TIMES
from ..skid_check import ACCEPT, STEADY_FIGURES, TRAVEL_FLOOR, SkidRule, steady_difference

# issue 32's accuracy of the wheeled model at its step: travel, revolutions and steady figures 0.2 %, skid 1 %
TOLERANCE = {"revolutions": 2e-3, "x1_final": 2e-3, "x2_final": 2e-3, "slip1_m": 1e-2, "slip2_m": 1e-2,
             "steady_speed_m_s": 2e-3, "energy_per_metre_j_m": 2e-3, "steady": 2e-3}


def skid_floor(result: RunResult, k: int) -> float:
    """The shortest skid [m] of module ``k`` the check looks at: the travel's accuracy (0.2 %) of the module's
    travel (at least TRAVEL_FLOOR strokes, 2 r): a shorter skid, wrong by the whole of itself, moves the travel by
    less than its accuracy. (A cruise backs off 0.2-1e-6 m per second on its hubs' and contacts' give, not a
    skid: a fixed floor would be crossed by a long run that never skids.)"""
    travel = max(abs(result.summary[f"x{k}_final"]), TRAVEL_FLOOR * 2 * result.params.r)
    return TOLERANCE[f"x{k}_final"] * travel


def skid_resolution(result: RunResult, k: int) -> float:
    """How closely [m] module ``k``'s skid length is defined by the model: a skid starts and ends where its wheels'
    soft contacts let go and catch, each within the contact's time constant tau, while the module moves at up to
    its largest speed v_max; a module's stroke reverses once a revolution, so over the run's N revolutions the
    length is defined to about (N + 1) v_max tau (the +1: the start). The step decides where in tau each catch
    falls (the straight cases' skids moved by 0.4-0.9 of this between tau / 2 and tau / 4), so a skid is held to
    1 % of itself plus this, as the issue's agreement holds a skid to 5 % + 2 mm (a bend's scrub of a
    millimetre: mjcf/README.md, "The round pipe: convergence")."""
    v = result.series.get(f"v{k}")
    v_max = float(max(abs(v.max()), abs(v.min()))) if v is not None and v.size else 0.0
    revolutions = abs(result.summary.get("revolutions") or 0.0)
    return (revolutions + 1.0) * v_max * ROW_TIMES.contact


def _relative(a: float, b: float, floor: float) -> float:
    """(a - b) over the larger of |a|, |b| and ``floor``: signed."""
    return (a - b) / max(abs(a), abs(b), floor, 1e-300)


class WheelSkids(SkidRule):
    """The wheeled model's rule for :func:`.skid_check.verify_skids` (module docstring)."""

    name = "wheels"

    def skidded(self, result: RunResult) -> bool:
        return any((result.summary[f"slip{k}_m"] or 0.0) > skid_floor(result, k) for k in (1, 2))

    def differences(self, coarse: RunResult, fine: RunResult) -> tuple[str, dict[str, float]]:
        """('steady' | 'fixed', {figure: signed relative difference coarse - fine}); a steady figure's own
        uncertainty (the finer run's, where the statistical test found it) is added to its magnitude."""
        a, b = coarse.summary, fine.summary
        if a["steady"] or b["steady"]:
            if not (a["steady"] and b["steady"]):
                return "steady", {"steady": math.inf}
            out = {}
            for key, spread in STEADY_FIGURES:
                if (d := steady_difference(a, b, key, spread)) is not None:
                    out[key] = d
            return "steady", out
        floor = TRAVEL_FLOOR * 2 * fine.params.r
        out = {"revolutions": _relative(a["revolutions"], b["revolutions"], TRAVEL_FLOOR)}
        for k in (1, 2):
            out[f"x{k}_final"] = _relative(a[f"x{k}_final"], b[f"x{k}_final"], floor)
            # relative to the skid plus its resolution over the accuracy: within the accuracy where the difference
            # is within 1 % of the skid plus its resolution
            skids = a[f"slip{k}_m"] or 0.0, b[f"slip{k}_m"] or 0.0
            scale = max(skids) + skid_resolution(fine, k) / TOLERANCE[f"slip{k}_m"]
            out[f"slip{k}_m"] = (skids[0] - skids[1]) / scale
        return "fixed", out

    def judge(self, history: list) -> tuple[bool, str, float, float]:
        """(passed, the figure furthest from its accuracy, its estimated error, its accuracy) after the halvings
        of ``history``; records them in its last entry (``figure``, ``difference``: the estimate, ``estimates``)."""
        last = history[-1]
        if len(history) < 2:
            ratios = {key: abs(d) / TOLERANCE[key] for key, d in last["differences"].items()}
            estimates = {key: abs(d) for key, d in last["differences"].items()}
        else:
            before = history[-2]["differences"]
            estimates = {key: estimate(before.get(key, math.inf), d) for key, d in last["differences"].items()}
            ratios = {key: e / TOLERANCE[key] for key, e in estimates.items()}
        worst = max(ratios, key=ratios.get)
        last.update(figure=worst, difference=estimates[worst], estimates=estimates)
        return len(history) >= 2 and ratios[worst] <= 1.0, worst, estimates[worst], TOLERANCE[worst]

    def failure(self, history: list) -> str:
        last = history[-1]
        return (f"after halving the timestep to {last['half']:.3g} s the estimated error of {last['figure']} is "
                f"{last['difference']:.2e} of it, more than its accuracy {TOLERANCE[last['figure']]:.3g} (from the "
                "last two halvings' differences; the skids' error under the step)")


def estimate(before: float, last: float) -> float:
    """The finer run's estimated relative error from the signed differences of two successive halvings,
    ``before`` then ``last`` (module docstring): |last| q / (1 - q), q = |last| / |before|, where they have one
    sign and shrink; else max(|before|, |last|) / ACCEPT (both must lie within ACCEPT of the accuracy)."""
    if math.isfinite(before) and before * last > 0.0 and abs(last) < abs(before):
        q = abs(last) / abs(before)
        return abs(last) * q / (1.0 - q)
    return max(abs(before), abs(last)) / ACCEPT


WHEELS_RULE = WheelSkids()
