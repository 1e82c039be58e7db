"""MuJoCo's figures with their error bars in the studies, and the MuJoCo runs a study could not use, with why.

A MuJoCo run of the slide model on finite grip whose modules skid reports its figures as their rigid limit with
an estimated absolute error each (the summary's ``figure_errors``: revolutions, x1_final, x2_final at fixed time;
steady_speed_m_s, energy_per_metre_j_m to the steady state; :mod:`ipir_mujoco.engine.kinds.slides_grip.rigid_limit`). A study
takes such a figure with its error bar (:func:`figure_error`) instead of dropping the run, and says how many of
its MuJoCo runs gave it nothing and why (:func:`why_unusable`, :func:`unusable_counts`).
"""

from __future__ import annotations

from collections import Counter

# a study's own figure that is a mean of MuJoCo's figures: its error is the mean of theirs (at most)
MEANS = {"travel_m": ("x1_final", "x2_final")}


def figure_error(summary: dict, key: str) -> float | None:
    """The estimated absolute error of the figure ``key`` of a run's ``summary`` (its unit), or None where the run
    states none (the equations; MuJoCo without finite grip or without a skid; a metric the extrapolation does
    not report)."""
    errors = summary.get("figure_errors") or {}
    if key in errors:
        return float(errors[key])
    parts = MEANS.get(key)
    if parts and all(p in errors for p in parts):
        return sum(float(errors[p]) for p in parts) / len(parts)
    return None


def why_unusable(message: str, bad_input: bool = False) -> str:
    """A run's one-line failure ``message`` as the reason a study gives for not using it."""
    if bad_input:
        return "refused its parameters"
    if "rigid limit" in message:
        return "rigid limit not trustworthy (finite grip)"
    if "accuracy check failed" in message:
        return "accuracy monitor"
    if "wall-time budget" in message:
        return "wall-time budget"
    return "simulation failed"


def unusable_counts(reasons) -> dict[str, int]:
    """{reason: how many runs} of ``reasons`` (an iterable of :func:`why_unusable` results), most frequent first."""
    return dict(Counter(reasons).most_common())
