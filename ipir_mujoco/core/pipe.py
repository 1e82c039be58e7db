"""Whether the robot fits its pipe: the cross-field checks of ``pipe_diameter`` and ``wheel_radius``.

Kept beside :mod:`.params` (which defines the fields) because only the wheeled MuJoCo model has a pipe: the
slide model and the analytic equations never read these fields, so a design that would not fit a pipe is
still a valid slide design, and the checks run where a pipe is built (:func:`check_fit`).

A straight pipe of inside diameter D holds the planar mechanism when

- the crank pin's circle fits: the crank turns about A on the pipe's axis, its pin B sweeps |y| <= r, so
  2 r < D;
- each wheel fits between the axis and its wall: the wheel's centre sits at D / 2 - R from the axis, on an
  arm from the module's centreline, so 2 R < D / 2 (R < D / 4).

The rod length L does not enter a straight pipe's fit (the rod swings inside the crank pin's band, |y| <= r);
a bend's fit is another matter.
"""

from __future__ import annotations

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

    (for a straight pipe, R -> infinity, any length passes). Not yet checked against MuJoCo: the route with
    bends is not built.
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
