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
"""

from __future__ import annotations

import math

from .errors import ParameterError


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
