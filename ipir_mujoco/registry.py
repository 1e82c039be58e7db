"""One way to run an engine: every model variant by name, and one ``run(variant, params, ...)`` for all.

A *variant* is one model of the robot in one engine: the analytic equations with the paper's first-order
geometry or the exact slider-crank, under the paper's clutch rule or with one-way clutches; MuJoCo's model
of the real linkage with joint-limit ratchets or velocity-triggered locks. Every study, the command line and
the report reach the engines through :func:`run` (and :func:`run_batch` for MuJoCo's batched ratchet), so
that an engine, an option or an effect is added in one place.

Names (one scheme everywhere: ``simulate``'s flags map to them, sweeps, ``climb`` and the report use them)::

    ENGINE-MODEL[-RULE]

``ENGINE`` is ``analytic`` or ``mujoco``; ``MODEL`` is the geometry for the equations (``approx``: the paper's
first order, L >> r; ``exact``: the exact slider-crank with the rod) and the clutch for MuJoCo (``ratchet``:
a joint-limit ratchet, one-way by construction; ``lock``: velocity-triggered locks); ``RULE`` is the clutch
rule (``kinematic``: the paper's, locks by the sign of S_dot; ``unilateral``: one-way clutches that can only
push), left out where it is the model's usual one (the paper's rule for the equations and the locks; the
ratchet has only one). So ``analytic-approx`` is the paper's model, ``mujoco-ratchet`` MuJoCo with one-way
clutches. ``analytic-unilateral`` (the exact one-way equations, the sweep's name since its first release) is
kept as the canonical name of ``analytic-exact-unilateral``; every name spelled with its rule in full is an
alias. ``simulate``'s ``--engine``, ``--geometry``, ``--clutch`` and ``--mujoco-clutch`` name a variant
through :func:`from_flags`.

What the parameter set decides stays in it: a finite ``clutch_stiffness`` makes a one-way variant's clutches
compliant (both engines), ``drive`` chooses the constant torque or the motor, ``incline`` the slope.

The MuJoCo engine is imported only when a MuJoCo variant runs (its import is slow beside the rest). The
variants' table and the flags that name one live in :mod:`ipir_mujoco.variants`, the speed controller's
feedforward table in :mod:`ipir_mujoco.feedforward`; each name is the registry's too.
"""

from __future__ import annotations

import functools
import inspect
from typing import TYPE_CHECKING, Any, Callable, ParamSpec, Sequence, TypeVar

from . import interrupts
from .core.errors import ParameterError, ParameterTypeError
from .core.limits import CLUTCH_RULES as RULES  # noqa: F401 (the clutch rules, --clutch: the command line's)
from .core.limits import check_run_options
from .core.params import RobotParams, check_real, check_whole, require_params
from .engine.kinds.base import MUJOCO_CLUTCHES  # noqa: F401 (the MuJoCo clutches a variant names, --mujoco-clutch)
from .feedforward import feedforward_table  # the speed controller's table, computed above the engines
# the variants' names and flags (ipir_mujoco/variants.py), the registry's by their first place
from .variants import (ALIASES, ANALYTIC_ROUTES, ENGINES, MUJOCO_MODELS, NAMES, ROUTE_MODELS,  # noqa: F401
                       ROUTE_VARIANTS, VARIANTS, Variant, check_route_flag, from_flags, variant)

if TYPE_CHECKING:  # annotations only: the names, flags and checks above load without numpy (``--help``)
    import os

    from .core.control import FeedforwardTable
    from .core.results import RunResult
    from .core.route import Route
    from .engine import CrankServo, SolverSettings

__all__ = ["NAMES", "VARIANTS", "Variant", "feedforward_table", "run", "timestep", "variant"]
# beside these, from_flags, check_options and prepare_for_many serve the command line and the studies (not part of
# the public surface: they may change with them)

# the keywords each engine's run takes beside the common ones of core.options.RunOptions (dt_out,
# until_steady, steady_tol, steady_cycles, progress, wall_budget_s)
ANALYTIC_OPTIONS = ("rtol", "atol", "max_switches", "method", "torque")
MUJOCO_OPTIONS = ("settings", "timestep", "mjcf", "accuracy", "servo", "every_step")
# what every engine takes: RunOptions' fields but t_end and max_switches (analytic), the servo's table, and a route
# (the variants whose ``routes`` says so: :data:`ROUTE_VARIANTS`)
COMMON_OPTIONS = ("dt_out", "until_steady", "steady_tol", "steady_cycles", "progress", "wall_budget_s", "feedforward",
                  "route")
OPTIONS = (*COMMON_OPTIONS, *ANALYTIC_OPTIONS, *MUJOCO_OPTIONS)  # run()'s keyword-only options, every one
_WHY_NOT = {"analytic": "the analytic engines hold their solver tolerance and have no timestep, clutch "
                        "implementation or MJCF",
            "mujoco": "MuJoCo's cost is its step count, t_end / timestep, and its accuracy its own monitor's"}


def check_options(name: str | Variant, options: dict[str, Any], spelled: Callable[[str], str] = str) -> Variant:
    """The variant, after refusing (one line) each option in ``options`` whose value is not None and that
    its engine does not take; ``spelled(keyword)`` is how the message names it (e.g. as a command-line flag)."""
    v = variant(name)
    foreign = MUJOCO_OPTIONS if v.engine == "analytic" else ANALYTIC_OPTIONS
    for key, value in options.items():
        if key in foreign and value is not None and value is not False:
            own = "the MuJoCo engine" if v.engine == "analytic" else "the analytic engines"
            raise ParameterError(f"{spelled(key)} {value!r} applies only to {own} ({_WHY_NOT[v.engine]})")
    return v


def prepare_for_many(names) -> None:
    """A process about to run many designs of the variants ``names`` (a sweep's worker): compile the analytic
    kernels now rather than after their first half second in Python (:mod:`ipir_mujoco.analytic.accel`); for
    MuJoCo variants there is nothing to prepare. Cheap when already done."""
    if any(not variant(n).is_mujoco for n in names):
        from .analytic import accel

        accel.accelerate()


def timestep(name: str | Variant, params: RobotParams, t_end: float, dt_out: float, route=None) -> float | None:
    """The timestep [s] MuJoCo chooses by itself for a run of ``t_end`` [s] sampled every ``dt_out`` [s] (along
    ``route``, a :class:`ipir_mujoco.core.route.Route`, for the wheeled model): the
    variant's model kind's (:meth:`ipir_mujoco.engine.kinds.base.ModelKind.settings`), the step every such run
    starts from; a run whose wheels skid is kept at this step halved as many times as its skid check records
    (``RunResult.settings['skid_check']``, one entry a halving; its ``settings['timestep']`` is the step kept), and
    a slide run on finite grip whose modules skid is this run, its figures extrapolated from coarser ones
    (``settings['extrapolation']``).

    Parameters
    ----------
    name : str or Variant
        The variant (:func:`variant`).
    params : RobotParams
        The robot.
    t_end : float
        The run's simulated time [s].
    dt_out : float
        Its output interval [s].
    route : Route, optional
        A route (:class:`ipir_mujoco.core.route.Route`) for the wheeled model; None: a straight pipe.

    Returns
    -------
    float or None
        The timestep [s]; None for the analytic engines.

    Raises
    ------
    ParameterError
        An unknown variant, or ``t_end`` or ``dt_out`` outside their ranges (one line).
    """
    v, params = variant(name), require_params(params)
    t_end, dt_out = check_run_options(t_end, dt_out)
    if not v.is_mujoco:
        return None
    from .engine.kinds import kind_for

    return kind_for(v.model, params).settings(params, t_end, dt_out, None, v.clutch, route=route)[0].timestep


_P, _R = ParamSpec("_P"), TypeVar("_R")


def _unknown_options_refused(func: Callable[_P, _R]) -> Callable[_P, _R]:
    """``func`` (:func:`run`) with a misspelt or unknown keyword refused as bad input, a one-line
    :class:`ParameterTypeError` naming it and the options the variant's engine takes, rather than Python's bare
    TypeError; its signature stays ``func``'s for editors, type checkers and ``inspect.signature``."""
    known = inspect.signature(func).parameters

    @functools.wraps(func)
    def checked(*args: _P.args, **kwargs: _P.kwargs) -> _R:
        unknown = [k for k in kwargs if k not in known]
        if unknown:
            v = variant(args[0] if args else kwargs.get("name"))
            allowed = (*COMMON_OPTIONS, *(MUJOCO_OPTIONS if v.is_mujoco else ANALYTIC_OPTIONS))
            raise ParameterTypeError(f"option {unknown[0]}={kwargs[unknown[0]]!r} is unknown to {v.name}; "
                                     f"allowed: {', '.join(allowed)}")
        return func(*args, **kwargs)
    return checked


@_unknown_options_refused
def run(name: str | Variant, params: RobotParams, t_end: float = 1.0, *,
        dt_out: float | None = None, until_steady: bool | None = None, steady_tol: float | None = None,
        steady_cycles: int | None = None, progress: Callable[[float], None] | None = None,
        wall_budget_s: float | None = None, feedforward: FeedforwardTable | None = None, route: Route | None = None,
        rtol: float | None = None, atol: float | None = None, max_switches: int | None = None,
        method: str | None = None, torque: Callable[[float, float, float], float] | None = None,
        settings: SolverSettings | None = None, timestep: float | None = None, mjcf: str | os.PathLike | None = None,
        accuracy: str | None = None, servo: CrankServo | None = None, every_step: bool | None = None) -> RunResult:
    """Run the variant ``name`` on ``params`` for ``t_end`` [s] (with ``until_steady``, the cap).

    Every option is keyword-only; None (the default of each) is the engine's own default. An option of the other
    engine given as None or False counts as not given; given otherwise it is refused.

    Parameters
    ----------
    name : str or Variant
        A name of :data:`VARIANTS` (or an alias, e.g. ``"mujoco-ratchet-unilateral"``).
    params : RobotParams
        The robot; what it decides stays in it (a finite ``clutch_stiffness`` makes a one-way variant's
        clutches compliant, a finite ``mu_wall`` its grip finite, ``drive`` the drive, ``incline`` the slope).
    t_end : float
        Simulated time [s]; with ``until_steady`` the cap.
    dt_out : float, optional
        Every engine: the output interval [s] (default 1e-4; MuJoCo: a whole number of its timesteps).
    until_steady : bool, optional
        Every engine: stop at the end of the revolution where the periodic steady state is reached.
    steady_tol : float, optional
        Every engine: the steady-state test's relative tolerance (:class:`ipir_mujoco.core.options.RunOptions`).
    steady_cycles : int, optional
        Every engine: the revolutions the steady-state test compares.
    progress : callable, optional
        Every engine: ``progress(t)``, called with the simulated time [s] about every 0.1 s of it.
    wall_budget_s : float, optional
        Every engine: the most wall-clock time [s] the run may take (None: the package's default budget;
        ``math.inf``: none).
    feedforward : FeedforwardTable, optional
        Every engine, with ``params.drive = 'servo'``: the speed controller's table; computed here
        (:func:`feedforward_table`) unless given.
    route : Route, optional
        The variants of :data:`ROUTE_VARIANTS`: a :class:`ipir_mujoco.core.route.Route` to run along.
    rtol, atol : float, optional
        The analytic engines: the integrator's relative and absolute tolerances.
    max_switches : int, optional
        The analytic engines: the most mode switches a run may make.
    method : str, optional
        The analytic engines with compliant clutches: the integrator's method.
    torque : callable, optional
        The analytic engines: a torque profile ``torque(t, phi, omega)`` [N m] in place of the drive.
    settings : SolverSettings, optional
        MuJoCo: its solver settings (:class:`ipir_mujoco.engine.SolverSettings`); None: chosen from the motion.
    timestep : float, optional
        MuJoCo: short for ``settings`` with that timestep [s] (not with ``settings``).
    mjcf : str or os.PathLike, optional
        MuJoCo: an MJCF template in place of the shipped one.
    accuracy : str, optional
        MuJoCo: 'stop' (a failed accuracy check is a SimulationError) or 'warn' (recorded); None: the model
        kind's own.
    servo : CrankServo, optional
        MuJoCo: a crank servo in place of the drive.
    every_step : bool, optional
        MuJoCo: sample at every step of the timestep it chooses (:func:`timestep`): a sample holds its step's
        force, so a mean over a window is the impulse and no engagement peak falls between samples.

    Returns
    -------
    RunResult
        The run: series (shape (n,) each), energy audit, summary, settings, accuracy record.

    Raises
    ------
    ParameterError
        An unknown name, an option the variant's engine does not take, or parameters it refuses (one line).
    SimulationError
        A run that cannot go on (one line with the time and the reason).
    KeyboardInterrupt
        Ctrl-C during the run, wherever it landed (compiled code included), never another exception or a result.
    """
    options = {key: value for key, value in locals().items() if key in OPTIONS and value is not None}
    v = check_options(name, options)
    require_params(params)
    if options.get("route") is not None and not v.routes:
        raise ParameterError(f"route: {v.name} runs along no route; allowed: {', '.join(ROUTE_VARIANTS)} (the exact "
                             "equations, MuJoCo's wheeled model)")
    if not isinstance(options.get("every_step", False), (bool, type(None))):
        raise ParameterTypeError(f"every_step={options['every_step']!r} is not a bool; allowed: True or False")
    # Ctrl-C during the run is KeyboardInterrupt, whatever the code it landed in made of it (ipir_mujoco.interrupts)
    with interrupts.as_keyboard_interrupt():
        result = _run(v, params, t_end, options)
    return result


def _run(v: Variant, params: RobotParams, t_end: float, options: dict[str, Any]) -> RunResult:
    if params.drive == "servo" and options.get("feedforward") is None:
        options["feedforward"] = feedforward_table(params)
    foreign = MUJOCO_OPTIONS if not v.is_mujoco else ANALYTIC_OPTIONS  # given as None or False: not given
    options = {k: value for k, value in options.items() if value is not None and k not in foreign}
    if not v.is_mujoco:
        from . import analytic

        return analytic.simulate(params, v.geometry, v.rule, t_end, **options)
    from .engine import SolverSettings, simulate_mujoco

    step = options.pop("timestep", None)
    if step is not None:
        if "settings" in options:
            raise ParameterError("timestep and settings given together; allowed: one of them")
        options["settings"] = SolverSettings(timestep=check_real("timestep", step, high=1e-2, unit="s"))
    if options.pop("every_step", False):
        settings = options.get("settings")
        options["dt_out"] = settings.timestep if settings is not None else timestep(
            v, params, t_end, options.get("dt_out", 1e-4))
    if v.model != "slides":
        options["model"] = v.model
    return simulate_mujoco(params, v.rule, v.clutch, t_end, **options)


def halved_settings(run: RunResult):
    """MuJoCo's settings of ``run`` (a MuJoCo run) at half its timestep: the run again, one step finer."""
    from .engine import SolverSettings

    s = run.settings
    return SolverSettings(timestep=s["timestep"] / 2, integrator=s["integrator"], solimp=tuple(s["solimp"]))


def mujoco_defaults() -> dict[str, Any]:
    """MuJoCo's default solver settings as a run records them (timestep [s], integrator, constraint time
    constant [s], solimp): the largest step the engine chooses by itself."""
    from .engine import SolverSettings

    return SolverSettings().as_dict()


def batched(name: str | Variant) -> bool:
    """Whether the variant has a batched engine (:func:`run_batch`): MuJoCo's ratchet."""
    return variant(name).name == "mujoco-ratchet"


def run_batch(name: str | Variant, designs: Sequence[RobotParams], t_end: float, dt_out: float, *,
              nthread: int = 1, until_steady: bool = False) -> list[dict]:
    """The variant on many designs at once through ``mujoco.batch`` (:func:`batched` variants only): one
    outcome per design, as :func:`ipir_mujoco.engine.kinds.slides.batch.run_ratchet_batch` gives them."""
    if not batched(name):
        raise ParameterError(f"variant {variant(name).name!r} has no batched runs; allowed: mujoco-ratchet")
    if not isinstance(designs, (list, tuple)):
        raise ParameterTypeError(f"designs={designs!r} is not a list of RobotParams")
    for params in designs:
        require_params(params)
    check_whole("nthread", nthread, low=1, high=1024)
    from .core.options import check_type
    from .engine.kinds.slides import batch

    check_type("until_steady", until_steady, bool, "True or False")

    steady = {"until_steady": True} if until_steady else {}
    with interrupts.as_keyboard_interrupt():  # as run(): Ctrl-C is KeyboardInterrupt, never a failed design
        outcomes = batch.run_ratchet_batch(list(designs), t_end, dt_out, nthread=nthread, **steady)
    return outcomes


def batch_models(params: RobotParams) -> bool:
    """Whether the batched engine models the design (:data:`ipir_mujoco.engine.kinds.slides.batch.MODELLED_DRIVES`, rigid
    clutches); others run serially."""
    from .engine.kinds.slides import batch

    return params.drive in batch.MODELLED_DRIVES and params.clutch_stiffness is None


def compiled_status() -> tuple[bool, str]:
    """(whether serial MuJoCo runs step in compiled code, why not if they do not)."""
    from .engine.loop.stepper import compiled_status as status

    return status()
