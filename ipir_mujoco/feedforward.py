"""The speed controller's feedforward table (``params.feedforward``), computed above the engines by the package's
inverse kinetostatics and handed to each engine as data (the MuJoCo engine never runs the equations).
:func:`ipir_mujoco.registry.feedforward_table` is this module's, by its older place."""

from __future__ import annotations

import functools
import math
from typing import TYPE_CHECKING

from .core.errors import ParameterError
from .core.limits import MAX_T_END
from .core.params import RobotParams, require_params

if TYPE_CHECKING:
    from .core.control import FeedforwardTable

__all__ = ["feedforward_table"]

FEEDFORWARD_MODELS = {"paper": "approx", "exact": "exact"}  # feedforward -> the inverse kinetostatics' geometry
FEEDFORWARD_REVOLUTIONS = 2  # the table is the last: the modules start at rest and settle within the first


def feedforward_table(params: RobotParams) -> FeedforwardTable | None:
    """The speed controller's feedforward (``params.feedforward``): the torque [N m] a crank following its speed
    target exactly (``omega_target``, or the profile of ``speed_dip``) needs at each crank angle, by the
    package's inverse kinetostatics with one-way clutches
    (:func:`ipir_mujoco.analytic.inverse.inverse_kinetostatics`) on the paper's first-order geometry
    ('paper', L >> r) or the exact slider-crank ('exact'). Computed above the engines and handed to each as data
    (the MuJoCo engine never runs the equations); cached per parameter set.

    Parameters
    ----------
    params : RobotParams
        The robot: its ``drive``, ``feedforward``, ``omega_target``, ``speed_dip`` and ``phi0`` decide the table.

    Returns
    -------
    FeedforwardTable or None
        The table (crank angle [rad] to torque [N m]); None unless ``params.drive`` is 'servo' with a
        feedforward other than 'none'.

    Raises
    ------
    ParameterError
        A target speed so low that the table's revolutions last longer than a run may (one line).
    """
    if require_params(params).drive != "servo" or params.feedforward == "none":
        return None
    return _table(params)


@functools.lru_cache(maxsize=64)
def _table(params: RobotParams) -> FeedforwardTable:
    from .analytic.inverse import CrankMotion, inverse_kinetostatics
    from .core.control import TABLE_POINTS, FeedforwardTable, reference_motion

    omega, dip = params.omega_target, params.speed_dip
    lasts = FEEDFORWARD_REVOLUTIONS * 2 * math.pi / omega  # s: the table's motion, at the mean speed omega
    if lasts > MAX_T_END:  # named by what the user gave, not the table's derived run length
        raise ParameterError(f"omega_target={omega:g} rad/s with feedforward={params.feedforward!r}: the feedforward "
                             f"table follows the crank through {FEEDFORWARD_REVOLUTIONS} revolutions at that speed, "
                             f"{lasts:.3g} s, past the {MAX_T_END:g} s a run may take; allowed: omega_target >= "
                             f"{FEEDFORWARD_REVOLUTIONS * 2 * math.pi / MAX_T_END:.3g} rad/s with a feedforward, or "
                             "feedforward=none")
    if dip == 0.0:
        motion = CrankMotion.constant_speed(omega, params.phi0, FEEDFORWARD_REVOLUTIONS)
    else:  # the profile through the dead centres: phi(t) sampled finely, a spline through it
        motion = CrankMotion.from_samples(*reference_motion(omega, dip, params.phi0, FEEDFORWARD_REVOLUTIONS))
    run = inverse_kinetostatics(params, motion, FEEDFORWARD_MODELS[params.feedforward], "unilateral",
                                dt_out=2 * math.pi / omega / TABLE_POINTS)
    s = run.series
    last = s["phi"] >= params.phi0 + 2 * math.pi * (FEEDFORWARD_REVOLUTIONS - 1)
    return FeedforwardTable.from_samples(s["phi"][last], s["motor_torque"][last], params.feedforward, omega, dip)
