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

The MuJoCo engine is imported only when a MuJoCo variant runs (its import is slow beside the rest).
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, Callable, Sequence

from . import interrupts
from .core.errors import ParameterError, ParameterTypeError
from .core.limits import CLUTCH_RULES as RULES  # the clutch rules (--clutch)
from .core.limits import MAX_T_END, check_run_options
from .core.params import RobotParams, check_real, check_whole, require_params
from .engine.kinds import KINDS  # the model kinds' declarations (no MuJoCo: engine/kinds/__init__.py)
from .engine.kinds.base import MUJOCO_CLUTCHES  # the MuJoCo clutches a variant names (--mujoco-clutch)

if TYPE_CHECKING:  # annotations only: the names, flags and checks above load without numpy (``--help``)
    from .core.control import FeedforwardTable
    from .core.results import RunResult

__all__ = ["NAMES", "VARIANTS", "Variant", "feedforward_table", "run", "timestep", "variant"]
# beside these, from_flags, check_options and prepare_for_many serve the command line and the studies (not part of
# the public surface: they may change with them)

ENGINES = ("analytic", "mujoco")  # the two engines; a variant (VARIANTS) is one model in one of them


@dataclass(frozen=True)
class Variant:
    """One model of the robot in one engine (see the module docstring for the names)."""

    name: str  # canonical
    engine: str  # 'analytic' | 'mujoco'
    rule: str  # the clutch rule: 'kinematic' (the paper's) | 'unilateral' (one-way clutches)
    geometry: str  # 'approx' | 'exact' (MuJoCo always models the exact linkage)
    clutch: str | None  # MuJoCo's clutch: 'ratchet' | 'lock'; None for the equations
    label: str  # in words, for figures and reports
    model: str = "slides"  # MuJoCo's model of the robot: 'slides' | 'wheels' (the equations: 'slides')
    clutches: str = ""  # its clutches in words, where its model has only those (for a refused flag's message)
    mechanism: str = ""  # its clutches' mechanism for a figure's title, where MuJoCo's clutch alone does not say it
    routes: bool = False  # whether it runs along a route of straights and bends (``route=``, ``--route``)

    @property
    def mechanism_words(self) -> str:
        """The clutches' mechanism in a title's words: MuJoCo's clutch ('ratchet' | 'lock'), or the model's own
        (``mechanism``: the wheels' hub ratchets)."""
        return self.mechanism or self.clutch or ""

    @property
    def is_mujoco(self) -> bool:
        return self.engine == "mujoco"

    def describe(self) -> dict[str, Any]:
        """The variant as a run's JSON records it: name, engine, geometry, clutch rule and MuJoCo's clutch."""
        described = {"variant": self.name, "engine": self.engine, "geometry": self.geometry, "clutch": self.rule,
                     "mujoco_clutch": self.clutch}
        if self.model != "slides":
            described["mujoco_model"] = self.model
        return described


# every variant by its canonical name: {name: Variant}; ``run(name, ...)`` runs one
VARIANTS: dict[str, Variant] = {v.name: v for v in (
    Variant("analytic-approx", "analytic", "kinematic", "approx", None, "paper's model"),
    Variant("analytic-exact", "analytic", "kinematic", "exact", None, "analytic, paper's rule", routes=True),
    Variant("analytic-approx-unilateral", "analytic", "unilateral", "approx", None,
            "analytic first order, one-way clutches"),
    Variant("analytic-unilateral", "analytic", "unilateral", "exact", None, "analytic one-way clutches",
            routes=True),
    # MuJoCo's: each model kind declares its own (engine/kinds/<kind>/__init__.py), in the kinds' order
    *(Variant(engine="mujoco", geometry="exact", model=kind.model, **row) for kind in KINDS.values()
      for row in kind.variants),
)}
ALIASES = {
    "analytic-approx-kinematic": "analytic-approx", "analytic-exact-kinematic": "analytic-exact",
    "analytic-exact-unilateral": "analytic-unilateral", "mujoco-ratchet-unilateral": "mujoco-ratchet",
    "mujoco-lock-kinematic": "mujoco-lock",
}
NAMES = tuple(VARIANTS)
# MuJoCo's models of the robot (``--mujoco-model``): the modules on slides, or on wheels on the pipe walls, ...
MUJOCO_MODELS = tuple(dict.fromkeys(v.model for v in VARIANTS.values() if v.engine == "mujoco"))
# MuJoCo's models that take ``--route``, and every variant that does (the exact equations, MuJoCo's wheels)
ROUTE_MODELS = tuple(dict.fromkeys(v.model for v in VARIANTS.values() if v.routes and v.is_mujoco))
ROUTE_VARIANTS = tuple(v.name for v in VARIANTS.values() if v.routes)
ANALYTIC_ROUTES = tuple(name for name in ROUTE_VARIANTS if not VARIANTS[name].is_mujoco)


def check_route_flag(route: str | None, model: "str | Variant") -> None:
    """ParameterError (one line) for ``--route`` with a variant, or MuJoCo's ``--mujoco-model``, that runs along no
    route: the command line's check before any work (:func:`run` refuses a Python caller's route)."""
    if route is None or isinstance(model, Variant) and model.routes:
        return
    wheels = " or ".join(f"--mujoco-model {m}" for m in ROUTE_MODELS)
    if isinstance(model, Variant) and not model.is_mujoco:
        raise ParameterError(f"--route {route} with {model.name}: the paper's first-order geometry has no linkage to "
                             f"span a bend's chord; allowed: --geometry exact ({', '.join(ANALYTIC_ROUTES)}), or "
                             f"--engine mujoco {wheels}")
    if (model.model if isinstance(model, Variant) else model) not in ROUTE_MODELS:
        raise ParameterError(f"--route {route}: of MuJoCo's models only the {' or '.join(ROUTE_MODELS)} model runs "
                             f"along a route; allowed: --engine mujoco {wheels}, or the equations: --engine analytic "
                             "--geometry exact")


# the keywords each engine's run takes beside the common ones of core.options.RunOptions (dt_out,
# until_steady, steady_tol, steady_cycles, progress, wall_budget_s)
ANALYTIC_OPTIONS = ("rtol", "atol", "max_switches", "method", "torque")
MUJOCO_OPTIONS = ("settings", "timestep", "mjcf", "accuracy", "servo", "every_step")
# what every engine takes: RunOptions' fields but t_end and max_switches (analytic), the servo's table, and a route
# (the variants whose ``routes`` says so: :data:`ROUTE_VARIANTS`)
COMMON_OPTIONS = ("dt_out", "until_steady", "steady_tol", "steady_cycles", "progress", "wall_budget_s", "feedforward",
                  "route")
_WHY_NOT = {"analytic": "the analytic engines hold their solver tolerance and have no timestep, clutch "
                        "implementation or MJCF",
            "mujoco": "MuJoCo's cost is its step count, t_end / timestep, and its accuracy its own monitor's"}


def variant(name: str | Variant) -> Variant:
    """The variant named ``name`` (canonical or an alias); ParameterError listing the names otherwise."""
    if isinstance(name, Variant):
        return name
    if not isinstance(name, str):
        raise ParameterTypeError(f"variant {name!r} ({type(name).__name__}) is not a variant's name; allowed: "
                                 f"{', '.join(NAMES)}")
    key = ALIASES.get(name, name)
    if key in VARIANTS:
        return VARIANTS[key]
    raise ParameterError(f"variant {name!r} is unknown (a model in an engine, ENGINE-MODEL[-RULE]); allowed: "
                         f"{', '.join(NAMES)}")


def from_flags(engine: str = "analytic", geometry: str | None = None, rule: str | None = "kinematic",
               clutch: str | None = None, model: str = "slides") -> Variant:
    """The variant the command line's ``--engine``, ``--geometry``, ``--clutch``, ``--mujoco-clutch`` and
    ``--mujoco-model`` name (each refused in one line where it does not apply): the analytic geometry defaults
    to the paper's first order, MuJoCo's clutch to the lock for the paper's rule and to the ratchet for one-way
    clutches; ``rule`` None is the paper's rule, or one-way clutches on the wheeled model (its only ones)."""
    if model not in MUJOCO_MODELS:
        raise ParameterError(f"--mujoco-model {model!r} is unknown; allowed: {', '.join(MUJOCO_MODELS)}")
    if model != "slides":
        return _model_from_flags(engine, geometry, rule, clutch, model)
    rule = "kinematic" if rule is None else rule
    if engine not in ENGINES:
        raise ParameterError(f"--engine {engine!r} is unknown; allowed: {', '.join(ENGINES)}")
    if rule not in RULES:
        raise ParameterError(f"--clutch {rule!r} is unknown; allowed: {', '.join(RULES)}")
    if engine == "analytic":
        if clutch is not None:
            raise ParameterError(f"--mujoco-clutch {clutch} applies only to --engine mujoco")
        geometry = geometry or "approx"
        if geometry not in ("approx", "exact"):
            raise ParameterError(f"--geometry {geometry!r} is unknown; allowed: approx, exact")
        return _find(engine, rule, geometry, None)
    if geometry == "approx":
        raise ParameterError("--geometry approx with --engine mujoco: MuJoCo always models the real linkage; "
                             "allowed: --geometry exact (or leave it out)")
    clutch = clutch or ("lock" if rule == "kinematic" else "ratchet")
    if clutch == "ratchet" and rule == "kinematic":
        raise ParameterError("--clutch kinematic with the ratchet: a ratchet is a one-way clutch; use "
                             "--mujoco-clutch lock for the paper's rule, or --clutch unilateral")
    if clutch not in MUJOCO_CLUTCHES:
        raise ParameterError(f"--mujoco-clutch {clutch!r} is unknown; allowed: {', '.join(MUJOCO_CLUTCHES)}")
    return _find(engine, rule, "exact", clutch)


def _model_from_flags(engine: str, geometry: str | None, rule: str | None, clutch: str | None,
                      model: str) -> Variant:
    """The one variant of MuJoCo's model ``model`` (not the slides: ``mujoco-wheels`` for 'wheels'), after
    refusing the flags it does not take (one line each)."""
    v = next(v for v in VARIANTS.values() if v.model == model)
    if engine != "mujoco":
        raise ParameterError(f"--mujoco-model {model} applies only to --engine mujoco")
    if geometry == "approx":
        raise ParameterError("--geometry approx with --engine mujoco: MuJoCo always models the real linkage; "
                             "allowed: --geometry exact (or leave it out)")
    if rule not in (None, v.rule):
        raise ParameterError(f"--clutch {rule} with --mujoco-model {model}: its clutches are {v.clutches}; "
                             f"allowed: --clutch {v.rule} (or leave it out)")
    if clutch not in (None, v.clutch):
        raise ParameterError(f"--mujoco-clutch {clutch} with --mujoco-model {model}: its clutches are {v.clutches}; "
                             f"allowed: --mujoco-clutch {v.clutch} (or leave it out)")
    return v


def _find(engine: str, rule: str, geometry: str, clutch: str | None) -> Variant:
    return next(v for v in VARIANTS.values()
                if (v.engine, v.rule, v.geometry, v.clutch, v.model) == (engine, rule, geometry, clutch, "slides"))


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
    (``settings['extrapolation']``); None for the analytic engines."""
    v, params = variant(name), require_params(params)
    t_end, dt_out = check_run_options(t_end, dt_out)
    if not v.is_mujoco:
        return None
    from .engine.kinds import kind_for

    return kind_for(v.model, params).settings(params, t_end, dt_out, None, v.clutch, route=route)[0].timestep


def run(name: str | Variant, params: RobotParams, t_end: float = 1.0, **options) -> RunResult:
    """Run the variant ``name`` on ``params`` for ``t_end`` [s] (with ``until_steady``, the cap).

    Parameters
    ----------
    name : str or Variant
        A name of :data:`VARIANTS` (or an alias, e.g. ``"mujoco-ratchet-unilateral"``).
    params : RobotParams
        The robot; what it decides stays in it (a finite ``clutch_stiffness`` makes a one-way variant's
        clutches compliant, a finite ``mu_wall`` its grip finite, ``drive`` the drive, ``incline`` the slope).
    t_end : float
        Simulated time [s]; with ``until_steady`` the cap.
    **options
        Every engine: ``dt_out`` [s], ``until_steady``, ``steady_tol``, ``steady_cycles``, ``progress``,
        ``wall_budget_s`` [s] (:class:`ipir_mujoco.core.options.RunOptions`); the variants of
        :data:`ROUTE_VARIANTS` ``route`` (a :class:`ipir_mujoco.core.route.Route`). The analytic engines also
        ``rtol``, ``atol``, ``max_switches``, ``method`` (compliant clutches) and ``torque`` (a torque
        profile); MuJoCo ``settings`` (:class:`ipir_mujoco.engine.SolverSettings`), ``timestep`` [s] (short for
        settings with that step), ``mjcf``, ``accuracy`` ('stop' | 'warn'), ``servo`` and
        ``every_step`` (sample at every step of the timestep MuJoCo chooses, :func:`timestep`: a sample holds
        its step's force, so a mean over a window is the impulse and no engagement peak falls between
        samples). With ``params.drive = 'servo'`` the speed controller's ``feedforward`` table
        (:func:`feedforward_table`) is computed here unless given.

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
    v = check_options(name, options)
    require_params(params)
    unknown = [k for k in options if k not in (*COMMON_OPTIONS, *ANALYTIC_OPTIONS, *MUJOCO_OPTIONS)]
    if unknown:  # (an option of the other engine given as None or False counts as not given: check_options)
        known = (*COMMON_OPTIONS, *(MUJOCO_OPTIONS if v.is_mujoco else ANALYTIC_OPTIONS))
        raise ParameterTypeError(f"option {unknown[0]}={options[unknown[0]]!r} is unknown to {v.name}; "
                                 f"allowed: {', '.join(known)}")
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


FEEDFORWARD_MODELS = {"paper": "approx", "exact": "exact"}  # feedforward -> the inverse kinetostatics' geometry
FEEDFORWARD_REVOLUTIONS = 2  # the table is the last: the modules start at rest and settle within the first


def feedforward_table(params: RobotParams) -> FeedforwardTable | None:
    """The speed controller's feedforward (``params.feedforward``): the torque [N m] a crank following its speed
    target exactly (``omega_target``, or the profile of ``speed_dip``) needs at each crank angle, by the
    package's inverse kinetostatics with one-way clutches
    (:func:`ipir_mujoco.analytic.inverse.inverse_kinetostatics`) on the paper's first-order geometry
    ('paper', L >> r) or the exact slider-crank ('exact'); None for 'none'. Computed above the engines and
    handed to each as data (the MuJoCo engine never runs the equations); cached per parameter set."""
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
