"""Whether the robot fits its pipe: the cross-field checks of ``pipe_diameter`` and ``wheel_radius``.

Kept beside :mod:`.params` (which defines the fields) because only the wheeled MuJoCo model has a pipe: the
slide model and the analytic equations never read these fields, so a design that would not fit a pipe is
still a valid slide design, and the checks run where a pipe is built (:func:`check_fit`).

A straight pipe of inside diameter D holds the planar mechanism when

- the crank pin's circle fits: the crank turns about A on the pipe's axis, its pin B sweeps |y| <= r, so
  2 r < D;
- each wheel fits between the axis and its wall: the wheel's centre sits at D / 2 - R from the axis, on an
  arm from the module's centreline, so 2 R < D / 2 (R < D / 4).

The rod length L does not enter a straight pipe's fit (the rod swings inside the crank pin's band, |y| <= r).
A bend's fit has three closed forms here, all reported beside MuJoCo's outcome of a route (``route_fit``): a
rigid box's (:func:`bend_max_length`), the spread sprung wheels need (:func:`bend_wheel_spread`) and the rod's
clearance from the inner wall (:func:`bend_rod_clearance`).

The wheeled model's legs keep their wall where the closed-form lift-off checks here say so (:func:`lift_check`,
:func:`bend_lift_check`, :func:`lift_summary`). The legs' geometry, masses and a ring's sideways grip and side
force live in :mod:`.wheel_legs`, the sideways-grip check in :mod:`.side_check`; this module re-exports their
names, so every import from ``core.pipe`` keeps working.
"""

from __future__ import annotations

import math

from .errors import ParameterError
from .wheel_legs import (  # noqa: F401  (re-exported: every name stays importable from here)
    ARM_SHARE, COCK_HALVINGS, WHEEL_SHARE, bend_cock, bend_slip_angle, hub_tangent, leg_direction, rigid_wheels,
    ring_side_force, ring_side_grip, rod_side_force, scrub_force, spread_unload, sprung_mass)
from .side_check import SCRUB_FLOOR, across_paths, side_grip_check, side_summary  # noqa: F401  (re-exported)


def check_fit(params) -> None:
    """ParameterError (one line) if the robot ``params`` (a RobotParams) does not fit its pipe (module docstring)."""
    D, R, r = params.pipe_diameter, params.wheel_radius, params.r
    if not 2 * r < D:
        raise ParameterError(f"pipe_diameter={D:g} m with r={r:g} m: the crank pin's circle does not fit the pipe; "
                             f"allowed: pipe_diameter > 2 r = {2 * r:g} m")
    if not 4 * R < D:
        raise ParameterError(f"wheel_radius={R:g} m with pipe_diameter={D:g} m: a wheel does not fit between the axis "
                             f"and its wall; allowed: wheel_radius < pipe_diameter / 4 = {D / 4:g} m")


def bend_max_length(width: float, radius: float, diameter: float) -> float:
    """The longest rigid module [m] of width ``width`` [m] (across the pipe) that passes a bend of centreline
    radius ``radius`` [m] in a pipe of inside diameter ``diameter`` [m]; 0.0 if none does (width >= D).

    Closed form, a rectangle in the annulus between the bend's inner wall (radius R - D/2) and outer wall
    (R + D/2): at its tightest the rectangle's inner side lies on the inner wall's tangent and its outer corners
    on the outer wall, so its half-length l/2 and the outer corners' distance from the bend's centre satisfy
    (R - D/2 + w)^2 + (l/2)^2 = (R + D/2)^2:

        l_max = 2 sqrt((R + D/2)^2 - (R - D/2 + w)^2)

    (for a straight pipe, R -> infinity, any length passes). A run along a route reports it for the wheeled
    model's rigid housing beside MuJoCo's outcome (``route_fit``); the housing is far from binding there, the
    wheels' springs bind first (:func:`bend_wheel_spread`).
    """
    if not (width >= 0 and radius > 0 and diameter > 0):
        raise ParameterError(f"bend fit: width={width!r} m, radius={radius!r} m, diameter={diameter!r} m; allowed: "
                             "width >= 0, radius > 0, diameter > 0")
    if radius < diameter / 2:
        raise ParameterError(f"bend radius={radius:g} m with pipe_diameter={diameter:g} m: the centreline radius "
                             f"must reach the pipe's half-width; allowed: radius >= {diameter / 2:g} m")
    if width >= diameter:
        return 0.0
    outer, inner = radius + diameter / 2, radius - diameter / 2 + width
    return 2.0 * (outer * outer - inner * inner) ** 0.5


def bend_wheel_spread(half_base: float, wheel_radius: float, radius: float, diameter: float) -> float:
    """How much farther apart [m] the two wheels of a station must reach in a bend than in a straight pipe: a
    module tangent to the bend's centreline (radius ``radius`` [m], pipe diameter ``diameter`` [m]) with its
    stations ``half_base`` [m] either side of its middle and wheels of radius ``wheel_radius`` [m] on both walls.

    Closed form: the wheels' centres lie on the circles R + D/2 - R_w (outer wall) and R - D/2 + R_w (inner
    wall), on the station's line across the module, a distance b = half_base from the tangent point along the
    module, so

        spread = sqrt((R + D/2 - R_w)^2 - b^2) - sqrt((R - D/2 + R_w)^2 - b^2) - (D - 2 R_w)

    about b^2 D / (2 (R - D/2) (R + D/2)) for b << R - D/2: the pipe, measured across the module off its
    middle, is wider than D. Sprung wheels keep their wall while their springs reach that far."""
    if not (half_base >= 0 and wheel_radius > 0 and diameter > 4 * wheel_radius and radius > diameter / 2):
        raise ParameterError(f"bend wheel spread: half_base={half_base!r} m, wheel_radius={wheel_radius!r} m, "
                             f"radius={radius!r} m, diameter={diameter!r} m; allowed: half_base >= 0, "
                             "0 < 4 wheel_radius < diameter < 2 radius")
    outer, inner = radius + diameter / 2 - wheel_radius, radius - diameter / 2 + wheel_radius
    if half_base >= inner:
        return math.inf
    return (outer * outer - half_base * half_base) ** 0.5 - (inner * inner - half_base * half_base) ** 0.5 \
        - (diameter - 2 * wheel_radius)


def bend_rod_clearance(length: float, rod_radius: float, radius: float, diameter: float) -> float:
    """How far [m] a rod of ``length`` [m] and radius ``rod_radius`` [m], as a chord with both ends on a bend's
    centreline (radius ``radius`` [m], pipe diameter ``diameter`` [m]), clears the bend's inner wall; negative where
    it would cross it:

        clearance = sqrt(R^2 - (L/2)^2) - (R - D/2) - rod_radius

    (the chord's middle is nearest the bend's centre). The linkage's two ends ride near the pipe's axis, so a
    negative clearance says the rod must push them outward or bind."""
    if not (length > 0 and rod_radius >= 0 and radius > diameter / 2 and diameter > 0):
        raise ParameterError(f"bend rod clearance: length={length!r} m, rod_radius={rod_radius!r} m, radius={radius!r}"
                             f" m, diameter={diameter!r} m; allowed: length > 0, rod_radius >= 0, radius > diameter / 2")
    if length / 2 >= radius:
        return -math.inf
    return (radius * radius - length * length / 4) ** 0.5 - (radius - diameter / 2) - rod_radius


# ----------------------------------------------------------------------------------------------------
# The round pipe's wheel legs (the wheeled MuJoCo model): the closed-form lift-off checks (the legs' geometry,
# masses and grip: :mod:`.wheel_legs`)


def lift_check(params) -> dict:
    """The closed-form lift-off check of the wheeled model's legs (docs/model.md, "The round pipe").

    Each module has two rings ``ring_spacing`` = s apart of n = ``wheel_legs`` legs, each pressed on the wall by
    a linear spring with preload P_i = F_ni / (2 n). A force F across the pipe on a ring moves it by 2 F / (n k)
    (its legs' outward directions u_k: sum u_k u_k^T = n/2 I), which changes leg k's press by (2 / n) F . u_k:
    leg k lifts where F . u_k < -F_ni / 4, whatever n and k. The loads per ring, quasi-static: half the
    weight its springs carry across the pipe, :func:`sprung_mass` g cos(incline) / 2, down (each leg's own arm
    and wheel bear on the wall through its wheel); half the rod's side force at the ring pair's
    middle (:func:`rod_side_force`, the drive's largest torque: M, or M_stall for the motor); on module 1 the
    motor's reaction couple T about z as +-T / s on its two rings. The side loads are taken both ways. The
    wheels' sideways friction can carry side loads while they grip (MuJoCo's wheels do), so the check errs on
    the side of predicting a lift.

    Returns {'least_press1_n', 'least_press2_n': each module's least-pressed leg's closed-form press [N] (< 0: it
    lifts), 'lift_predicted': bool, 'weight_press_n': (module 1's, module 2's) least press under weight alone}.
    """
    n = int(params.wheel_legs)
    torque = abs(params.M) if params.drive == "torque" else params.M_stall
    side = rod_side_force(torque, params.r, params.L)
    across = math.cos(math.radians(params.incline)) * params.g
    legs = [leg_direction(k, n) for k in range(n)]
    out, weight_only = {}, []
    for i, Fn in enumerate((params.F_n1, params.F_n2), start=1):
        m = sprung_mass(params, i - 1)
        P = Fn / (2 * n)
        down = 0.5 * m * across
        couple = torque / params.ring_spacing if i == 1 else 0.0
        least = math.inf
        for lateral in (0.5 * side + couple, -(0.5 * side + couple), 0.5 * side - couple, couple - 0.5 * side):
            for (_, uy, uz) in legs:
                least = min(least, P + (2.0 / n) * (lateral * uy - down * uz))
        out[f"least_press{i}_n"] = least
        weight_only.append(min(P + (2.0 / n) * (-down * uz) for (_, _, uz) in legs))
    out["lift_predicted"] = out["least_press1_n"] < 0 or out["least_press2_n"] < 0
    out["weight_press_n"] = tuple(weight_only)
    return out


def bend_lift_check(params, radius: float, toward: tuple[float, float], across) -> dict:
    """The lift-off check (:func:`lift_check`) of each module rolling through a bend of centreline radius ``radius``
    [m] that turns towards the unit (y, z) ``toward`` across the pipe (in the robot's frame at the route's start:
    y its left, z its up), under gravity's components across the pipe ``across`` [(g_y, g_z), m/s^2] at points
    along the bend. On top of the straight pipe's loads (half the sprung weight across, here as given; the rod's
    side force, the motor's couple on module 1) each ring carries

    - the wheels' side force (:func:`scrub_force`, the fore ring's) along +-toward: the bend's own load, growing
      with the rings' slip angle b / R while the wheels roll on it, capped at the rings' sideways friction where
      they slide (rigid wheels: the cap at any radius; at the defaults' 3 legs 2 mu_wall P across a horizontal
      bend, 1.73 mu_wall P across one turning up);
    - the rod's push or pull at its angle to the module: the rod is a chord of the bend of length at most r + L,
      (r + L) / (2 R) off the module's axis, carrying the moving module's rolling resistance and weight (at most
      max(F_ri + m_i g)) while neither module skids;
    - the pipe's spread off the ring's plane: the ring's plane cuts the bend obliquely, so the wall is farther by
      half :func:`bend_wheel_spread` along toward, which unloads leg k by P (u_k . toward)^2 spread / (2 travel).

    Returns {'least_press1_n', 'least_press2_n': the least-pressed leg's press [N] (< 0: it lifts),
    'lift_predicted': bool, 'scrub_n': (module 1's, module 2's) ring load [N]}."""
    n = int(params.wheel_legs)
    torque = abs(params.M) if params.drive == "torque" else params.M_stall
    side = rod_side_force(torque, params.r, params.L)
    push = max(params.F_r1 + params.m1 * params.g, params.F_r2 + params.m2 * params.g)
    chord = push * min(1.0, (params.r + params.L) / (2 * radius))
    half_base = 0.5 * params.ring_spacing
    spread = bend_wheel_spread(half_base, params.wheel_radius, radius, params.pipe_diameter)
    legs = [leg_direction(k, n) for k in range(n)]
    ty, tz = toward
    out, scrubs = {}, []
    for i, Fn in enumerate((params.F_n1, params.F_n2), start=1):
        m = sprung_mass(params, i - 1)  # across the pipe the springs carry the module less its legs
        P = Fn / (2 * n)
        scrub = scrub_force(params, i - 1, toward, radius)
        scrubs.append(scrub)
        couple = torque / params.ring_spacing if i == 1 else 0.0
        least = math.inf
        for gy, gz in across:
            for lateral in (0.5 * side + couple, -(0.5 * side + couple), 0.5 * side - couple, couple - 0.5 * side):
                for bend_load in (scrub + 0.5 * chord, -(scrub + 0.5 * chord)):
                    fy = 0.5 * m * gy + lateral + bend_load * ty
                    fz = 0.5 * m * gz + bend_load * tz
                    for (_, uy, uz) in legs:
                        spread_loss = spread_unload(params, P, uy * ty + uz * tz, spread)
                        least = min(least, P - spread_loss + (2.0 / n) * (fy * uy + fz * uz))
        out[f"least_press{i}_n"] = least
    out["lift_predicted"] = out["least_press1_n"] < 0 or out["least_press2_n"] < 0
    out["scrub_n"] = tuple(scrubs)
    return out


def lift_summary(params, fit: dict | None = None) -> dict:
    """The lift-off check's summary keys of a wheeled run: ``least_press1_n``, ``least_press2_n`` [N] and
    ``lift_predicted`` (:func:`lift_check`); along a route, with its ``fit`` (the run's ``route_fit``, whose bends
    carry :func:`bend_lift_check`'s least presses), the least over the straight pipe and every bend."""
    check = lift_check(params)
    out = {key: check[key] for key in ("least_press1_n", "least_press2_n", "lift_predicted")}
    for bend in (fit or {}).get("bends", ()):
        for key in ("least_press1_n", "least_press2_n"):
            if bend.get(key) is not None:
                out[key] = min(out[key], bend[key])
    out["lift_predicted"] = out["least_press1_n"] < 0 or out["least_press2_n"] < 0
    return out
