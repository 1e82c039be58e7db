"""Finite grip with compliant clutches: a clutch's force is capped by its wheels' grip, its anchor slides.

A compliant clutch (:mod:`.compliant_model`) pushes its module with the force
of a spring and damper between the module and the clutch's *anchor*, the
locked wheels on the wall. The wheels hold at most G_i = mu_wall F_ni; where
the force k d - c v would exceed that, the anchor slides back (clutch state
SLIDING) and the force is G_i exactly (massless wheels: the spring and damper
carry what the wall's friction gives). The module's own resistance stays as in
the compliant model (Coulomb, F_ri either way), so a module moving back with
its anchor sliding meets G_i + F_ri in all, where the rigid model's skidding
module meets G_i (docs/model.md, "Finite grip", says why and what the
difference means in the stiff limit).

While the anchor slides, k d + c d_dot = G_i: the overlap relaxes as

    d(t) = G/k + (d0 - G/k) exp(-(t - t_s) k / c)        (c > 0; d = G/k at once for c = 0)

from d0 at the slide's start t_s, whatever the module does. The anchor
A = x + d moves at v + d_dot; the slide ends where that speed rises to zero
(the anchor would move forward: it stops, and the clutch is ENGAGED again with
its anchor where it stopped). Energy: the spring stores 1/2 k d^2, the damper
dissipates c d_dot^2, whose integral over the slide is closed-form
(:func:`slide_damper_work`), and the wall's friction dissipates G_i per metre
the anchor slides (the skid work). Everything about a slide is a function of
time given (t_s, d0), so the state vector does not grow.

Units: m, m/s, N, J, s. Functions take times as floats or ndarrays of one shape.
"""

from __future__ import annotations

import math

import numpy as np

from ipir_mujoco.core.results import grip_use

from . import kernels
from .compliant_state import _HYSTERESIS_FORCE, _HYSTERESIS_OVERLAP, NO_SLIDE, Clutch



def slide_overlap(t, slide: tuple[float, float], k: float, c: float, G: float):
    """d(t) [m] of a sliding anchor's clutch from its slide (t_s [s], d0 [m]) (module docstring)."""
    ts, d0 = slide
    if c == 0:
        return G / k + 0.0 * np.asarray(t, dtype=float)
    return G / k + (d0 - G / k) * np.exp(-(np.asarray(t, dtype=float) - ts) * k / c)


def slide_rate(t, slide: tuple[float, float], k: float, c: float, G: float):
    """d_dot(t) [m/s] of a sliding anchor's clutch: (G - k d) / c (0 without a damper); as the kernels'."""
    ts, d0 = slide
    if c == 0:
        return 0.0 * np.asarray(t, dtype=float)
    return (G - k * d0) / c * np.exp(-(np.asarray(t, dtype=float) - ts) * k / c)


def slide_damper_work(t, slide: tuple[float, float], k: float, c: float, G: float):
    """The damper's work [J] since the slide began: integral of c d_dot^2 = 1/2 k (d0 - G/k)^2 (1 - exp(-2 (t - t_s)
    k / c)); without a damper the spring drops to G/k at once and the same limit, 1/2 k (d0 - G/k)^2, is lost."""
    ts, d0 = slide
    u0 = d0 - G / k
    t = np.asarray(t, dtype=float)
    if c == 0:
        return 0.5 * k * u0 * u0 + 0.0 * t
    return 0.5 * k * u0 * u0 * -np.expm1(-2.0 * (t - ts) * k / c)


def head(grip: tuple[float, float], slide: tuple) -> list[float]:
    """The kernels' grip constants (:data:`.kernels.P_GR1` to :data:`.kernels.P_DS2`) of a regime."""
    return [grip[0], grip[1], *slide[0], *slide[1]]


def grip_hysteresis(model, G: float) -> float:
    """How far [N] beyond the grip G an engaged clutch's force goes before its anchor slides: 1e-10 of it, or
    twice the force of the overlap hysteresis (k * 1 pm, at which a clutch engages), what the positions
    resolve (a float overlap of a module 1 m along is known to 1e-16 m, k times that in force), whichever is
    larger: so that on no grip (G = 0) a clutch that engages is not beyond its grip at once."""
    return max(_HYSTERESIS_FORCE * max(1.0, G), 2.0 * model.k * _HYSTERESIS_OVERLAP)


def add_events(model, regime, i: int, add, hysteresis_speed: float) -> None:
    """The grip's events of module i in ``regime`` through ``add`` (:meth:`.CompliantModel.events`): 'grip' (an
    engaged clutch's force reaches G_i plus :func:`grip_hysteresis`: its anchor slides) and 'stick' (a sliding
    anchor's backward speed falls below minus a hysteresis: it stops)."""
    G = model.grip[i]
    if regime.clutch[i] is Clutch.ENGAGED and math.isfinite(G) and regime.slip[i] != 0:  # stuck: k d stays
        offset = G + grip_hysteresis(model, G)
        add("grip", i, -1.0, lambda t, y: offset - model._push(y, regime, i), kernels.EV_GRIP, offset)
    elif regime.clutch[i] is Clutch.SLIDING:
        def stick(t, y):
            v = y[3] if i == 0 else model.velocity2(y)
            return hysteresis_speed - v - slide_rate(t, regime.slide[i], model.k, model.c, G)
        add("stick", i, -1.0, stick, kernels.EV_STICK, hysteresis_speed)


def transitions(model, t: float, y: np.ndarray, fired, clutch: list, peak: list, slide: list) -> None:
    """What a 'grip' or 'stick' event changes, in place: the clutch's state, its slide, its anchor (``peak`` =
    anchor + backlash) and, at a slide's end, the damper work its slide dissipated, into y[6] (J)."""
    if fired is None or fired[0] not in ("grip", "stick"):
        return
    kind, i = fired
    x = y[2] if i == 0 else y[2] + float(model.linkage.gap(y[0])) - model.S0
    if kind == "grip":
        clutch[i], slide[i] = Clutch.SLIDING, (t, peak[i] - model.delta - x)
        return
    d = float(slide_overlap(t, slide[i], model.k, model.c, model.grip[i]))
    y[6] += float(slide_damper_work(t, slide[i], model.k, model.c, model.grip[i]))
    v = y[3] if i == 0 else float(model.velocity2(y))
    # the anchor stops where it would move forward, at k d - c v = G - c (hysteresis): on (almost) no grip the
    # damper would then pull (the clutch is clipped), and on none the spring has relaxed to nothing (released)
    if d <= _HYSTERESIS_OVERLAP:
        state = Clutch.TRACKING if model.delta == 0 else Clutch.FREE
    else:
        state = Clutch.ENGAGED if model.k * d - model.c * v > 0 else Clutch.CLIPPED
    clutch[i], peak[i], slide[i] = state, x + d + model.delta, NO_SLIDE


def start_slides(model, t: float, y: np.ndarray, regime, fired):
    """``regime`` with every engaged clutch whose force at state ``y`` (projected) exceeds its grip (beyond the
    hysteresis) sliding from t (an engagement at speed with a damper, which pushes with c |v| at once), but the
    one whose slide just ended (``fired``: its force is the grip); ``regime`` itself if none."""
    clutch, slide = list(regime.clutch), list(regime.slide)
    for i in (0, 1):
        G = model.grip[i]
        if clutch[i] is Clutch.ENGAGED and math.isfinite(G) and fired != ("stick", i) \
                and float(model._push(y, regime, i)) > G + grip_hysteresis(model, G):
            x = y[2] if i == 0 else y[2] + float(model.linkage.gap(y[0])) - model.S0
            clutch[i], slide[i] = Clutch.SLIDING, (t, regime.peak[i] - model.delta - x)
    if clutch == list(regime.clutch):
        return regime
    return regime._replace(clutch=tuple(clutch), slide=tuple(slide))


def piece_columns(model, regime, times: np.ndarray, columns: dict) -> None:
    """Correct one segment's ``columns`` (:func:`.compliant_run._piece`) for its sliding anchors, in place: the
    overlap d(t), the spring energy, the damper work so far (with the slide's); and with finite grip add
    ``grip_use1/2`` and ``wheels1/2`` (-1 anchor sliding, +1 rolling forward at its running maximum, 0 standing)."""
    finite = [math.isfinite(G) for G in model.grip]
    for i in (0, 1):
        if regime.clutch[i] is Clutch.SLIDING:
            G = model.grip[i]
            columns[f"clutch_overlap{i + 1}"] = slide_overlap(times, regime.slide[i], model.k, model.c, G)
            columns["clutch_damper_work"] = columns["clutch_damper_work"] + slide_damper_work(
                times, regime.slide[i], model.k, model.c, G)
    if any(regime.clutch[i] is Clutch.SLIDING for i in (0, 1)):
        columns["clutch_spring_energy"] = sum(0.5 * model.k * np.maximum(columns[f"clutch_overlap{i + 1}"], 0.0) ** 2
                                              for i in (0, 1))
    if not any(finite):
        return
    shape = np.shape(times)
    for i in (0, 1):
        G = model.grip[i]
        state = -1 if regime.clutch[i] is Clutch.SLIDING else \
            (1 if regime.clutch[i] is Clutch.TRACKING and regime.slip[i] == 1 else 0)
        columns[f"wheels{i + 1}"] = np.full(shape, float(state))
        columns[f"grip_use{i + 1}"] = grip_use(columns[f"lambda{i + 1}"], columns[f"wheels{i + 1}"], G)


def run_columns(series: dict, grip: tuple[float, float]) -> dict[str, np.ndarray]:
    """``slip1/2`` [m] (each anchor's backward slide so far: A = x + d falls only while it slides, so the sample
    intervals that end sliding telescope to each slide's travel) and ``skid_work`` = sum G_i slip_i [J]."""
    out, skid = {}, 0.0
    for i in (0, 1):
        anchor = np.asarray(series[f"x{i + 1}"], dtype=float) + np.asarray(series[f"clutch_overlap{i + 1}"])
        back = np.zeros(anchor.shape)
        back[1:] = np.where(series[f"wheels{i + 1}"][1:] == -1, anchor[:-1] - anchor[1:], 0.0)
        out[f"slip{i + 1}"] = np.cumsum(back)
        skid = skid + grip[i] * out[f"slip{i + 1}"]
    out["skid_work"] = skid
    return out
