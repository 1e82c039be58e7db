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

from ipir_mujoco.core.checks import check_text
from ipir_mujoco.core.errors import ParameterError, SimulationError
from ipir_mujoco.core.older_paths import keep_older_paths, lazy_names
from ipir_mujoco.core.limits import CLUTCH_RULES
from ipir_mujoco.core.params import PARAMETER_NAMES, RobotParams, load_params, refuse_idle_parameters, require_params
from ipir_mujoco.core.results import COLUMNS, MODE_NAMES, Mode, RunResult

from .kinematic_clutch import simulate_kinematic
from .kinematics import Geometry, Linkage

# the one-way and compliant clutches' run loops load where a run needs them (PEP 562): the paper's case, the
# default `ipir-mujoco simulate`, starts without them
__getattr__, __dir__ = lazy_names(__name__, {"simulate_unilateral": "unilateral_run",
                                             "simulate_compliant": "compliant_run"})

# a model's modes or regimes are in *_model.py, the loop that runs it in *_run.py; their older names:
keep_older_paths({f"{__name__}.{older}": f"{__name__}.{now}" for older, now in (
    ("unilateral_clutch", "unilateral_run"), ("compliant_clutch", "compliant_model"), ("grip", "grip_model"))})


def simulate(params: RobotParams, geometry: str = "approx", clutch: str = "kinematic",
             t_end: float = 1.0, route=None, **options) -> RunResult:
    """Run the analytic model; ``options`` go to the chosen solver.

    ``geometry``: 'approx' (the paper's first order) or 'exact'.
    ``clutch``: 'kinematic' (the paper's rule: lock by the sign of S_dot) or
    'unilateral' (one-way clutches that can only push; with a finite
    ``params.clutch_stiffness`` the compliant clutch model, which also models
    clutch damping and backlash; with a finite ``params.mu_wall`` the wheels
    grip the wall with at most mu_wall F_ni, and a held module may skid back).
    ``route``: a :class:`ipir_mujoco.core.route.Route` to run along (:func:`.route_run.simulate_route`: the exact
    geometry, rigid clutches, the torque or the motor), or None (a straight pipe).
    ``options``: ``dt_out``, ``rtol``, ``atol``, ``until_steady``, ``steady_tol``,
    ``steady_cycles``, ``progress``, ``max_switches``, ``wall_budget_s``, ``torque``
    (see :func:`simulate_kinematic`, :func:`simulate_unilateral` and :func:`simulate_compliant`), and with
    ``drive = servo`` ``feedforward``, the speed controller's table (:mod:`ipir_mujoco.core.control`; the
    rigid clutches with unlimited grip).
    """
    params = require_params(params)
    check_text("geometry", geometry, "approx, exact")
    check_text("clutch", clutch, ", ".join(CLUTCH_RULES))
    try:
        geometry = Geometry(geometry).value
    except ValueError:
        raise ParameterError(f"geometry={geometry!r} is unknown; allowed: approx, exact") from None
    if clutch not in CLUTCH_RULES:
        raise ParameterError(f"clutch={clutch!r} is unknown; allowed: {', '.join(CLUTCH_RULES)}")
    if params.mu_wall is not None and clutch != "unilateral":
        raise ParameterError(f"mu_wall={params.mu_wall!r} with clutch={clutch!r}: the paper's rule locks its "
                             "modules whatever the load; allowed: clutch='unilateral' or mu_wall=unlimited")
    refuse_idle_parameters(params)
    if route is not None:
        from .route_run import check_route_run, simulate_route

        params = check_route_run(params, route, geometry, clutch, options)
        options.pop("feedforward", None)  # (None: the servo is refused along a route)
        return simulate_route(params, route, clutch, t_end, **options)
    if params.drive == "servo":
        _check_servo(params, options)
    elif options.get("feedforward") is not None:
        raise ParameterError(f"a feedforward table with drive={params.drive!r}; allowed: drive='servo'")
    else:
        options.pop("feedforward", None)
    if options.get("torque") is not None:
        _check_torque(options["torque"], params)
    if params.clutch_stiffness is not None:
        if clutch != "unilateral":
            raise ParameterError(f"clutch_stiffness={params.clutch_stiffness!r} N/m with clutch={clutch!r}: the "
                                 "paper's rule locks rigidly; allowed: clutch='unilateral' or clutch_stiffness=rigid")
        from .compliant_run import simulate_compliant

        return simulate_compliant(params, geometry, t_end, **options)
    if clutch == "unilateral":
        from .unilateral_run import simulate_unilateral

        return simulate_unilateral(params, geometry, t_end, **options)
    return simulate_kinematic(params, geometry, t_end, **options)


def compile_kernels() -> bool:
    """Compile the analytic kernels now (numba, where it may: :mod:`.accel`, which says so on logger
    'ipir_mujoco' when it compiles rather than loads them) and call every model once briefly, as numba compiles
    each kernel at its first call: for a command about to run many designs, before its pool starts, so that
    the kernels are compiled once and its workers load them from numba's cache. True if they run compiled."""
    from . import accel

    if not accel.accelerate():
        return False
    for geometry, clutch, params in (("approx", "kinematic", RobotParams()), ("exact", "kinematic", RobotParams()),
                                     ("exact", "unilateral", RobotParams()),
                                     ("exact", "unilateral", RobotParams(clutch_stiffness=1e5))):
        simulate(params, geometry, clutch, 0.02, dt_out=1e-3)
    from ipir_mujoco.core.route import route_from_tables  # and along a route (its kernels' first calls)

    bend = route_from_tables([dict(kind="straight", length=0.4), dict(kind="bend", radius=0.5, angle=30.0)])
    simulate(RobotParams(drive="motor"), "exact", "unilateral", 0.02, route=bend, dt_out=1e-3)
    return True


def _check_servo(params: RobotParams, options: dict) -> None:
    """What the speed controller runs on, refused in one line elsewhere: rigid clutches (the paper's rule or
    one-way) with unlimited grip, either geometry, without a torque profile (both would set the torque)."""
    if params.clutch_stiffness is not None or params.mu_wall is not None:
        raise ParameterError("drive='servo' runs on rigid clutches with unlimited grip in the analytic engine; "
                             "allowed: clutch_stiffness=rigid and mu_wall=unlimited")
    if options.get("torque") is not None:
        raise ParameterError("a torque profile with drive='servo': one thing sets the crank's torque; allowed: one")


def _check_torque(torque, params: RobotParams) -> None:
    """A torque profile is a function torque(t, phi, omega) [N m] of floats giving a finite number: refused in
    one line, naming the argument, before the solver calls it deep inside (tried once at the start state)."""
    import math

    import numpy as np

    if not callable(torque):
        raise ParameterError(f"torque={torque!r} is not callable; allowed: a function torque(t, phi, omega) "
                             "[N m], or None (the drive of params)")
    try:
        value = float(np.asarray(torque(np.float64(0.0), np.float64(params.phi0), np.float64(params.omega0))))
    except Exception as exc:  # noqa: BLE001 (whatever the user's function raises, said in one line)
        raise ParameterError(f"torque(t=0, phi={params.phi0:g}, omega={params.omega0:g}) failed: "
                             f"{type(exc).__name__}: {' '.join(str(exc).split())[:200]}; allowed: a function "
                             "of floats returning a torque [N m]") from None
    if not math.isfinite(value):
        raise ParameterError(f"torque(t=0, phi={params.phi0:g}, omega={params.omega0:g})={value} is not finite; "
                             "allowed: a function returning a finite torque [N m]")


__all__ = [
    "COLUMNS", "CLUTCH_RULES", "Geometry", "Linkage", "MODE_NAMES", "Mode", "PARAMETER_NAMES",
    "ParameterError", "RobotParams", "RunResult", "SimulationError", "load_params",
    "simulate", "simulate_compliant", "simulate_kinematic", "simulate_unilateral",
]
