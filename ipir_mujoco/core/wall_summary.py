"""The wall's keys of a wheeled run's summary: the closed-form lift-off and scrub checks of
:mod:`.wheel_checks` on the run's own loads (with a route's bends, :mod:`.route_loads`) beside MuJoCo's outcome,
and what happened with no prediction, in words."""

from __future__ import annotations

import numpy as np

from .wheel_checks import MOVING_SPEED, check, ring_loads


def run_summary(params, series: dict, route_fit: dict | None = None, straight: bool = True) -> dict:
    """The wall's keys of a wheeled run's summary: the closed-form checks beside MuJoCo's outcome.

    With the linkage's force columns (``link_y1`` .. ``link_z2``, in each module's frame): the checks of
    :func:`check` on the run's own loads: the loop's pin force, the drive's torque, each module's grip use and
    rolling, the samples' interval, gravity across the pipe in each module's frame from its pose and, along a
    route, what its bends add while a module is in one (:func:`.route_loads.route_loads`: its mass's turn, its
    wheels' slip, the pipe's spread): ``least_press1_n``, ``least_press2_n``, ``lift_predicted``, ``side_use1``,
    ``side_use2``, ``scrub_predicted``. In a straight pipe (``straight``) beside them MuJoCo's outcome,
    ``across1_m``, ``across2_m`` and ``scrubbed`` (:func:`.side_check.side_summary`'s; along a route the wheels'
    own slide, the series' ``slid1``, ``slid2``, is the outcome, :mod:`ipir_mujoco.studies.comparison.route_compare`;
    ``route_fit`` keeps each bend's quasi-static closed form, reported, not predicting). A series without those
    columns: the quasi-static checks of :func:`.pipe.lift_summary` (with ``route_fit``'s bends) and, in a straight
    pipe with the pose columns, :func:`.side_check.side_summary`. Always: ``grip1_n``, ``grip2_n`` [N], each
    module's grip limit as MuJoCo has it, mu_wall times its measured mean press (None with unlimited grip: beside
    mu_wall F_ni, the equations'), and ``unpredicted``: a lift (``wheel_off_s`` > 0) or a slide across the pipe
    (``scrubbed``) the checks did not predict, in words, else None."""
    from .pipe import lift_summary
    from .route_loads import route_loads
    from .side_check import SCRUB_FLOOR, across_paths, side_summary

    out: dict = {}
    if "link_y1" in series:
        t = np.asarray(series["t"], dtype=float)
        loads = ring_loads(params, series["link_y1"], series["link_y2"], series["motor_torque"], series["link_z1"],
                           series["link_z2"])
        grip = tuple(series.get(f"grip_use{k}", 0.0) for k in (1, 2))
        # rolling: its hubs turn free (+1), or, not skidding, it moves on (a light wheel's hub can stick while its
        # module rolls: the state then says standing)
        rolling = tuple((np.asarray(series[f"wheels{k}"]) == 1.0) | ((np.asarray(series[f"wheels{k}"]) != -1.0)
                                                                    & (np.asarray(series[f"v{k}"]) > MOVING_SPEED))
                        for k in (1, 2))
        bends = route_loads(params, series, rolling)
        dt = float(np.median(np.diff(t))) if len(t) > 1 else None
        speed = (series["v1"], series["v2"])
        # a bend's side force at its two limits (route_loads): entering, through the wheels' compliance; settled,
        # held; in a straight pipe they are one
        result = check(params, {key: loads[key] + bends.pushes[key] for key in loads}, grip, rolling, dt, speed,
                       bends.gravity, bends.spread, bends.slips)
        if any(steady.any() for steady in bends.steady):
            settled = check(params, loads, grip, rolling, dt, speed, bends.gravity,
                            [a + b for a, b in zip(bends.spread, bends.steady)])
            result = merged(result, settled)
        out.update({key: result[key] for key in ("least_press1_n", "least_press2_n", "lift_predicted", "side_use1",
                                                 "side_use2", "scrub_predicted")})
        if straight:
            across = across_paths(series, params)
            out.update(across1_m=across[0], across2_m=across[1], scrubbed=max(across) >= SCRUB_FLOOR)
    else:
        out.update(lift_summary(params, route_fit))
        if straight and "yaw2" in series:
            out.update(side_summary(params, series))
    presses = (float(np.mean(series["press1"])), float(np.mean(series["press2"])))
    out.update({f"grip{k}_n": None if params.mu_wall is None else params.mu_wall * presses[k - 1] for k in (1, 2)})
    out["unpredicted"] = unpredicted(out, series)
    return out


def merged(a: dict, b: dict) -> dict:
    """Two checks of one run (:func:`check`'s dicts) as one: the least presses, the longer paths and the larger
    uses; a lift, a stuck wheel or a scrub where either predicts it."""
    out = {}
    for key, value in a.items():
        if key.startswith("least_press"):
            out[key] = min(value, b[key])
        elif key.startswith(("slid", "side_use")):
            out[key] = max(value, b[key])
        else:
            out[key] = bool(value or b[key])
    return out


def unpredicted(keys: dict, series: dict) -> str | None:
    """A lift or a slide across the pipe that happened with no prediction, in words (None if none): a wheel off
    its wall (the summary's ``wheel_off_s``, from the samples' ``wheels_off``) where ``lift_predicted`` is
    false; rings that slid (``scrubbed``) where ``scrub_predicted`` is false."""
    t, off = np.asarray(series["t"], dtype=float), np.asarray(series["wheels_off"], dtype=float)
    off_s = float(np.sum(np.diff(t)[off[:-1] > 0]))
    said = []
    if off_s > 0 and not keys.get("lift_predicted"):
        first = float(t[np.flatnonzero(off > 0)[0]])
        said.append(f"a wheel was off its wall {off_s:.3g} s from t = {first:.3g} s with no lift predicted (least "
                    f"press {keys['least_press1_n']:.3g} N / {keys['least_press2_n']:.3g} N)")
    if keys.get("scrubbed") and not keys.get("scrub_predicted"):
        said.append(f"the rings slid {1e3 * keys['across1_m']:.3g} mm / {1e3 * keys['across2_m']:.3g} mm across the "
                    "pipe with no slide predicted")
    return "; ".join(said) or None
