"""What a model kind is: :class:`ModelKind`, the abstract base every kind subclasses.

A *model kind* is one MuJoCo model of the robot. It owns everything that differs between the models: its checks
(which clutches, options and parameters it takes), its settings (the automatic timestep, what a run records of it),
its build (its MJCF template, :attr:`ModelKind.mjcf`, to an ``MjModel``), its initial state, its clutch controller
(:class:`ipir_mujoco.engine.loop.controller.ClutchController`), its stepping loop's options (the work rates the loop
counts), its extra series columns, its skid rule, its variants (the registry's names that run it) and how it is drawn
and replayed (``render``, the viewer). The run loop, the recorder, the accuracy monitor and the run setup name no kind:
they ask it.

A kind lives in a folder of its own under ``engine/kinds/`` whose ``__init__.py`` defines the kind (a subclass of
:class:`ModelKind`) and names its instance ``KIND``; :mod:`ipir_mujoco.engine.kinds` finds every such folder.
``__init__.py`` stays light (the registry reads the kinds' variants when the package is imported, before MuJoCo
is): the kind's methods import its modules (builder, controllers, columns) when called.

Every member below marked *required* must be given by a concrete kind: a class that leaves one out fails where it
is defined (``TypeError`` naming the members), not at its first run. A base meant to be subclassed further says so
with ``class Base(ModelKind, abstract=True)``.

The joint and body contract: what the shared run path reads of every kind's model by name
(``docs/architecture.md``, "The joint and body contract"; :data:`CONTRACT`, checked by
``tests/test_model_kinds.py``).
"""

from __future__ import annotations

import abc
from pathlib import Path
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:  # annotations only: this module is imported before MuJoCo is
    import mujoco
    import numpy as np

    from ipir_mujoco.core.params import RobotParams
    from ipir_mujoco.core.results import RunResult

    from ..builders.model import SolverSettings

# The elements every kind's model names, which the shared run path reads by name, by type: the joints the recorder,
# the run setup and the block checks read (the crank's and the rod's hinges; each module's slide along the pipe,
# whose position and speed are x1, x2, v1, v2), the bodies (the modules: the loop gap's and a route's reference
# points; the rod: the replay's), the rod end's site and the loop-closing equality (the loop gap, the rod force),
# the crank's actuator (the drive) and the housings' geoms (render and the viewer colour them by the clutches).
# builders/model.py holds the names; this is the contract's list (docs/architecture.md, tests/test_model_kinds.py).
CONTRACT = {
    "joint": ("crank_hinge", "rod_hinge", "rear_slide", "front_slide"),
    "body": ("rear_module", "front_module", "rod"),
    "site": ("rod_end",),
    "equality": ("rod_to_front",),
    "actuator": ("crank_motor",),
    "geom": ("rear_housing", "front_housing"),
}
HOUSINGS = CONTRACT["geom"]  # the modules' housings, rear first
MUJOCO_CLUTCHES = ("ratchet", "lock")  # the MuJoCo clutches a variant names (kinds' variants, --mujoco-clutch)

# the members a concrete kind must give (the class attributes, then the methods)
REQUIRED = ("name", "model", "mjcf", "free", "variants", "check", "takes", "settings", "build", "initial_state",
            "controller", "loop_options", "between_steps", "drawing", "replay")


class ModelKind(abc.ABC):
    """One MuJoCo model of the robot (module docstring). Abstract: a kind subclasses it and gives every required
    member (:data:`REQUIRED`); the members with a default below are the same for most kinds.

    Attributes
    ----------
    name : str
        Required. The kind's name (:data:`ipir_mujoco.engine.kinds.KINDS`' key; its folder's name with ``_`` for
        ``-``).
    model : str
        Required. The user's word for its MuJoCo model, ``simulate_mujoco``'s ``model`` (``--mujoco-model``); kinds
        of one word are told apart by :meth:`takes`.
    mjcf : str
        Required. Its MJCF template, a file in the package's ``mjcf/`` folder (:meth:`template`).
    free : str
        Required. What a module does while its clutch does not hold it, in the drawing's overlay ('slides').
    variants : tuple of dict
        Required. The registry's variants that run this kind: each the keyword arguments of
        :class:`ipir_mujoco.registry.Variant` but engine, geometry and model (MuJoCo, the exact linkage, this
        kind's ``model``); empty for a kind its parameters choose (the slides on finite grip).
    accuracy : str
        The accuracy monitor's mode where a run does not choose one ('stop' | 'warn').
    skid : bool
        Whether the energy audit books the grips' (or the contacts') work against skidding, ``skid_j``.
    """

    accuracy = "stop"
    skid = False

    def __init_subclass__(cls, abstract: bool = False, **options: Any) -> None:
        super().__init_subclass__(**options)
        if abstract:
            return
        missing = [member for member in REQUIRED
                   if not hasattr(cls, member) or getattr(getattr(cls, member), "__isabstractmethod__", False)]
        if missing:
            raise TypeError(f"model kind {cls.__name__} leaves out {', '.join(missing)}: a kind gives every member "
                            "of ModelKind's REQUIRED (or is declared abstract=True)")

    # ---- required: what the kind is ----
    @property
    @abc.abstractmethod
    def name(self) -> str: ...

    @property
    @abc.abstractmethod
    def model(self) -> str: ...

    @property
    @abc.abstractmethod
    def mjcf(self) -> str: ...

    @property
    @abc.abstractmethod
    def free(self) -> str: ...

    @property
    @abc.abstractmethod
    def variants(self) -> tuple[dict, ...]: ...

    def template(self) -> Path:
        """Its MJCF template's path (:attr:`mjcf` in the package's ``mjcf/`` folder)."""
        from ...resources import mjcf_dir

        return mjcf_dir() / self.mjcf

    # ---- required: a run of the kind ----
    @abc.abstractmethod
    def check(self, params: RobotParams, implementation: str, rule: str, route=None,
              until_steady: bool = False) -> RobotParams:
        """The parameters for a run (a route may set its incline), after refusing (ParameterError, one line)
        what this kind does not take.

        Parameters
        ----------
        params : RobotParams
        implementation : str
            The MuJoCo clutch: 'ratchet' | 'lock' | 'none'.
        rule : str
            The clutch rule: 'kinematic' | 'unilateral'.
        route : ipir_mujoco.core.route.Route or None
        until_steady : bool

        Returns
        -------
        RobotParams

        Raises
        ------
        ParameterError
        """

    @abc.abstractmethod
    def takes(self, params: RobotParams) -> bool:
        """Whether this kind is the one for ``params`` among the kinds of its ``model``
        (:func:`ipir_mujoco.engine.kinds.kind_for` asks the kinds in order)."""

    @abc.abstractmethod
    def settings(self, params: RobotParams, t_end: float, dt_out: float, servo=None,
                 implementation: str = "ratchet", route=None) -> tuple[SolverSettings, dict]:
        """The automatic settings of a run of ``t_end`` [s] sampled every ``dt_out`` [s] (along ``route``, for
        the kinds that take one), and why: (settings, {each limit [s]}); every run and ``registry.timestep`` ask
        this."""

    @abc.abstractmethod
    def build(self, params: RobotParams, settings: SolverSettings, *, mjcf=None, implementation: str = "ratchet",
              route=None, decorate=None) -> mujoco.MjModel:
        """The compiled model for ``params`` from ``mjcf`` (None: :meth:`template`); ``decorate(spec)`` adds what
        only drawing needs."""

    @abc.abstractmethod
    def initial_state(self, model: mujoco.MjModel, data: mujoco.MjData, params: RobotParams) -> None:
        """Set the run's initial state in ``data``."""

    @abc.abstractmethod
    def controller(self, model: mujoco.MjModel, data: mujoco.MjData, params: RobotParams, implementation: str,
                   rule: str = "unilateral"):
        """The run's clutch controller (:class:`ipir_mujoco.engine.loop.controller.ClutchController`), made after
        the initial state is set."""

    @abc.abstractmethod
    def loop_options(self, model: mujoco.MjModel, data: mujoco.MjData) -> dict:
        """:func:`ipir_mujoco.engine.loop.stepper.make_steps`' keyword arguments after ``mj_forward`` on the
        initial state: the crank, the drive's torque slope and torque, the dofs with friction (``friction_dofs``)
        and the work rates ``power(v)`` the loop counts after each step (the rows of the kind's resistances and,
        where it has any, of its grip or contacts against skidding)."""

    @abc.abstractmethod
    def between_steps(self, params: RobotParams, implementation: str, rule: str) -> list[str]:
        """What the kind's controller does to the model between MuJoCo's steps, one sentence each (the header of
        ``simulate --save-mjcf``'s file)."""

    # ---- required: drawing a run of the kind ----
    @abc.abstractmethod
    def drawing(self, params: RobotParams, route=None, facing=None) -> mujoco.MjSpec:
        """Its drawing model for ``render`` (an ``MjSpec``, not compiled): its model for ``params`` (along
        ``route``, for the kinds that take one) with what only drawing adds (:meth:`dress`); ``facing``: the
        camera's view direction (3,), or None."""

    @abc.abstractmethod
    def replay(self, model: mujoco.MjModel, run: RunResult):
        """The object that poses its drawing model ``model`` at any time of a recorded ``run``: ``pose(data,
        when)``, ``lookat(data)`` (:mod:`ipir_mujoco.replay`)."""

    # ---- defaults ----
    def dress(self, spec: mujoco.MjSpec, params: RobotParams, facing=None) -> None:
        """What a drawing adds to the kind's own model (``spec``, in place) beyond its build: nothing here (a kind
        whose build has no pipe draws one)."""

    def recorded_settings(self) -> dict:
        """What a run's ``RunResult.settings`` records of the kind beside the solver's settings."""
        return {}

    def columns(self, model: mujoco.MjModel, params: RobotParams, q: np.ndarray, scalars: dict,
                out: dict) -> dict[str, np.ndarray]:
        """The kind's series columns beyond the shared ones, from the samples' ``q`` (n, nq), the recorder's
        per-sample ``scalars`` (name: (n,)) and the shared columns ``out``: none here."""
        return {}

    def skid_rule(self, params: RobotParams):
        """The rule an automatically stepped run of ``params`` checks its skids by (its floor, figures and
        acceptance: :mod:`ipir_mujoco.engine.kinds.skid_check`): :data:`.skid_check.NO_SKIDS` here (no skids to
        check)."""
        from .skid_check import NO_SKIDS

        return NO_SKIDS

    def route_fit(self, route, params: RobotParams) -> dict:
        """The closed-form fit of a route's bends reported beside MuJoCo's outcome (``route_fit``: ``{"bends":
        [...], "predicted": one line}``), for the kinds that take a route (:meth:`check` refuses it elsewhere)."""
        raise NotImplementedError(f"the {self.name} model takes no route")

    def route_watch(self, route, model: mujoco.MjModel, recorder, params: RobotParams, dt_out: float):
        """What watches a run along ``route`` every block of its loop (where it is, why it stops; its
        series read along the route): :data:`NO_ROUTE` without a route, and for a kind that takes none
        (:meth:`check` refused it)."""
        return NO_ROUTE


class NoRoute:
    """The route watch of a run along no route: it never stops a run, leaves its series and records nothing
    (:class:`ipir_mujoco.engine.kinds.wheels.route_watch.RouteWatch`'s methods)."""

    def check(self, newest: int) -> None:
        return None

    def along_series(self, series: dict) -> dict:
        return series

    def record(self, t_end: float, stall) -> None:
        return None


NO_ROUTE = NoRoute()
