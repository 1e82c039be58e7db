"""The analytic model of the two-module inchworm robot (numpy + scipy only).

This package never imports MuJoCo or the MuJoCo engine: it is the independent
half of the cross-check. Of the rest of ``ipir_mujoco`` it imports only the
shared vocabulary, :mod:`ipir_mujoco.core` (the parameter set, the result
container, the errors, the per-revolution figures), and re-exports its names
(``from ipir_mujoco.analytic import RobotParams`` works). It holds the
slider-crank kinematics, the paper's hybrid model, the one-way-clutch model
(rigid, or compliant with a finite ``clutch_stiffness``), kinetostatics and
inverse kinetostatics.
"""

from ipir_mujoco.core.errors import ParameterError, SimulationError
from ipir_mujoco.core.params import PARAMETER_NAMES, RobotParams, load_params, require_params
from ipir_mujoco.core.results import COLUMNS, MODE_NAMES, Mode, RunResult

from .compliant_run import simulate_compliant
from .kinematic_clutch import simulate_kinematic
from .kinematics import Geometry, Linkage
from .unilateral_clutch import simulate_unilateral

CLUTCH_RULES = ("kinematic", "unilateral")


def simulate(params: RobotParams, geometry: str = "approx", clutch: str = "kinematic",
             t_end: float = 1.0, **options) -> RunResult:
    """Run the analytic model; ``options`` go to the chosen solver.

    ``geometry``: 'approx' (the paper's first order) or 'exact'.
    ``clutch``: 'kinematic' (the paper's rule: lock by the sign of S_dot) or
    'unilateral' (one-way clutches that can only push; with a finite
    ``params.clutch_stiffness`` the compliant clutch model, which also models
    clutch damping and backlash; with a finite ``params.mu_wall`` the wheels
    grip the wall with at most mu_wall F_ni, and a held module may skid back).
    ``options``: ``dt_out``, ``rtol``, ``atol``, ``until_steady``, ``steady_tol``,
    ``steady_cycles``, ``progress``, ``max_switches``, ``wall_budget_s``, ``torque``
    (see :func:`simulate_kinematic`, :func:`simulate_unilateral` and
    :func:`simulate_compliant`).
    """
    params = require_params(params)
    try:
        geometry = Geometry(geometry).value
    except ValueError:
        raise ParameterError(f"geometry={geometry!r} is unknown; allowed: approx, exact") from None
    if clutch not in CLUTCH_RULES:
        raise ParameterError(f"clutch={clutch!r} is unknown; allowed: {', '.join(CLUTCH_RULES)}")
    if params.mu_wall is not None and clutch != "unilateral":
        raise ParameterError(f"mu_wall={params.mu_wall!r} with clutch={clutch!r}: the paper's rule locks its "
                             "modules whatever the load; allowed: clutch='unilateral' or mu_wall=unlimited")
    _refuse_unused_normal_force(params)
    if params.clutch_stiffness is not None:
        if clutch != "unilateral":
            raise ParameterError(f"clutch_stiffness={params.clutch_stiffness!r} N/m with clutch={clutch!r}: the "
                                 "paper's rule locks rigidly; allowed: clutch='unilateral' or clutch_stiffness=rigid")
        if params.mu_wall is not None:  # TEMPORARY: the compliant clutches' grip comes in its own commit
            raise ParameterError(f"mu_wall={params.mu_wall!r} with a compliant clutch is not modelled yet; "
                                 "allowed: mu_wall=unlimited")
        return simulate_compliant(params, geometry, t_end, **options)
    _refuse_unmodelled(params)
    if clutch == "unilateral":
        return simulate_unilateral(params, geometry, t_end, **options)
    return simulate_kinematic(params, geometry, t_end, **options)


def _refuse_unmodelled(params: RobotParams) -> None:
    """Clutch damping and backlash need a clutch with a spring: refused with rigid clutches, never ignored."""
    defaults = RobotParams()
    for name in ("clutch_damping", "clutch_backlash"):
        if getattr(params, name) != getattr(defaults, name):
            raise ParameterError(f"{name}={getattr(params, name)!r} needs a finite clutch_stiffness (a rigid clutch "
                                 f"has no spring for it to act with); allowed: {getattr(defaults, name)!r} with "
                                 "clutch_stiffness=rigid")


def _refuse_unused_normal_force(params: RobotParams) -> None:
    """The wheels' normal forces act only through a finite grip: refused with unlimited grip, never ignored."""
    defaults = RobotParams()
    for name in ("F_n1", "F_n2"):
        if params.mu_wall is None and getattr(params, name) != getattr(defaults, name):
            raise ParameterError(f"{name}={getattr(params, name)!r} N needs a finite mu_wall (with unlimited grip the "
                                 f"normal force holds nothing); allowed: {getattr(defaults, name)!r} with "
                                 "mu_wall=unlimited")


__all__ = [
    "COLUMNS", "CLUTCH_RULES", "Geometry", "Linkage", "MODE_NAMES", "Mode", "PARAMETER_NAMES",
    "ParameterError", "RobotParams", "RunResult", "SimulationError", "load_params",
    "simulate", "simulate_compliant", "simulate_kinematic", "simulate_unilateral",
]
