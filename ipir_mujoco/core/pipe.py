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
