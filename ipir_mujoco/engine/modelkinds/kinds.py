"""MuJoCo's models of the robot, each one object: a *model kind* owns what differs between them.

A kind is chosen once per run (:func:`kind_for`, from ``simulate_mujoco``'s ``model`` and the parameter set)
and owns its checks (which clutches, options and parameters it takes), its settings (the automatic timestep,
the contact settings a run records), its build (MJCF template to ``MjModel``), its initial state, its clutch
controller (:mod:`.controller`'s protocol), its stepping loop's options, its extra series columns and energy
terms and its default accuracy mode. Everything else, the run loop (:mod:`.stepper`), the recorder, the
accuracy monitor, the run's setup (:mod:`.run_setup`), is shared and names no kind.

The kinds:

- ``slides`` (:data:`SLIDES`): the modules on two slides, the clutches a joint-limit ratchet (rigid or
  compliant, :mod:`.slide_clutches`, :mod:`.compliant`) or velocity-triggered locks; unlimited grip.
- ``slides`` with a finite ``mu_wall`` (:data:`GRIP_SLIDES`): a carriage per module on the wall, held by
  friction G_i, carries the clutch (:mod:`.grip_model`, :mod:`.grip`, :mod:`.compliant_grip`).
- ``wheels`` (:data:`WHEELS`): a 3-D robot on sprung wheel legs in a round pipe, a ratchet in every hub
  (:mod:`.wheels_model`, :mod:`.wheels`); routes of straights and bends (:mod:`.route_watch`).

Adding a kind: subclass :class:`ModelKind`, give it a ``name`` and the methods below that differ from the
base's, and list it in :data:`KINDS` (``docs/architecture.md``, "Adding a model kind").
"""

from __future__ import annotations

import mujoco
import numpy as np

from ipir_mujoco.core.errors import ParameterError
from ipir_mujoco.core.params import RobotParams
from ipir_mujoco.core.results import grip_use

from .common import check_clutch_options
from ..controllers.grip import GripRatchet
from ..controllers.compliant_grip import CompliantGrip
from ..builders.grip_model import SKIDS
from .loop_rows import loop_options
from ..builders.model import SolverSettings, build_model, qpos_address, set_closed_loop_state
from .route_watch import check_route, pipe_fit
from ..controllers.slide_clutches import slide_controller
from .timestep import choose_settings
from ..controllers.wheels import (WheelRatchet, link_columns, pose_columns, press_columns, refuse_clutches, wheel_loop_options, wheel_slip,
                     wheels_settings)
from ..builders.wheels_model import NOSLIP_ITERATIONS, ROW_TIMES, build_wheels_model, set_wheels_state


class ModelKind:
    """One MuJoCo model of the robot: its checks, settings, build, initial state, controller, loop options,
    extra columns and energy terms, default accuracy mode. The base is the slide model's; a kind overrides
    what differs.

    Attributes
    ----------
    name : str
        The kind's name (:data:`KINDS`' key).
    model : str
        The user's word for its MuJoCo model, ``simulate_mujoco``'s ``model`` ('slides' | 'wheels').
    accuracy : str
        The accuracy monitor's mode where a run does not choose one ('stop' | 'warn').
    skid : bool
        Whether the energy audit books the grips' (or the contacts') work against skidding, ``skid_j``.
    skid_rule : str or None
        Where an automatically stepped run whose modules skidded is checked at half its step
        (:func:`ipir_mujoco.engine.run.skid_check.verify_skids`), the name of the rule it is checked by (its
        floor, figures and acceptance; ``simulate.SKID_RULES``: 'slides', 'wheels'); None: not checked.
    pipe_built : bool
        Whether its build puts the pipe's walls in the model (else a viewer draws the slide model in a pipe).
    """

    name = "slides"
    model = "slides"
    accuracy = "stop"
    skid = False
    skid_rule = None
    pipe_built = False

    @property
    def verifies_skids(self) -> bool:
        """Whether an automatically stepped run whose modules skidded is checked at half its step."""
        return self.skid_rule is not None

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
        if route is not None:
            raise ParameterError("--route applies only to the wheeled model; allowed: --mujoco-model wheels")
        check_clutch_options(params, rule, implementation)
        return params

    def takes(self, params: RobotParams) -> bool:
        """Whether this kind is the one for ``params`` among the kinds of its ``model`` (:func:`kind_for` asks
        the kinds of :data:`KINDS` in order): the slides with unlimited grip."""
        return params.grip is None

    def settings(self, params: RobotParams, t_end: float, dt_out: float, servo=None,
                 implementation: str = "ratchet", route=None) -> tuple[SolverSettings, dict]:
        """The automatic settings of a run of ``t_end`` [s] sampled every ``dt_out`` [s] (along ``route``, for
        the kinds that take one), and why: (settings, {each limit [s]}) (:func:`.timestep.choose_settings`);
        every run and ``registry.timestep`` ask this."""
        return choose_settings(params, t_end, dt_out, servo, implementation)

    def recorded_settings(self) -> dict:
        """What a run's ``RunResult.settings`` records of the kind beside the solver's settings."""
        return {}

    def build(self, params: RobotParams, settings: SolverSettings, *, mjcf=None, implementation: str = "ratchet",
              route=None, decorate=None) -> mujoco.MjModel:
        """The compiled model for ``params``; ``decorate(spec)`` adds what only drawing needs."""
        return build_model(params, settings, mjcf, ratchet=implementation == "ratchet", decorate=decorate)

    def initial_state(self, model: mujoco.MjModel, data: mujoco.MjData, params: RobotParams) -> None:
        """The run's initial state (the loop closed at ``phi0``, at rest or at ``omega0``)."""
        set_closed_loop_state(model, data, params)

    def controller(self, model: mujoco.MjModel, data: mujoco.MjData, params: RobotParams, implementation: str,
                   rule: str = "unilateral"):
        """The run's clutch controller (:class:`.controller.ClutchController`), after the initial state."""
        return slide_controller(model, data, params, implementation, rule)

    def loop_options(self, model: mujoco.MjModel, data: mujoco.MjData) -> dict:
        """:func:`.stepper.make_steps`' keyword arguments after ``mj_forward`` on the initial state."""
        return loop_options(model, data)

    def columns(self, model: mujoco.MjModel, params: RobotParams, q: np.ndarray, scalars: dict,
                out: dict) -> dict[str, np.ndarray]:
        """The kind's series columns beyond the shared ones, from the samples' ``q`` (n, nq), the recorder's
        per-sample ``scalars`` (name: (n,)) and the shared columns ``out``."""
        return {}

    def route_fit(self, route, params: RobotParams) -> dict:
        """The closed-form fit of a route's bends reported beside MuJoCo's outcome (``route_fit``: ``{"bends":
        [...], "predicted": one line}``), for the kinds that take a route (:meth:`check` refuses it here)."""
        raise NotImplementedError(f"the {self.name} model takes no route")

    def between_steps(self, params: RobotParams, implementation: str, rule: str) -> list[str]:
        """What the kind's controller does to the model between MuJoCo's steps, one sentence each (the header of
        ``simulate --save-mjcf``'s file, :mod:`.export`)."""
        controllers = "ipir_mujoco.engine.controllers"
        if implementation == "ratchet" and params.clutch_stiffness is not None:
            return ["Before every mj_step each module's clutch anchor is ratcheted: its slide's lower limit is raised "
                    f"to the anchor's running maximum ({controllers}.compliant); the spring, damper and play between "
                    "anchor and module are MuJoCo's own, in this file."]
        if implementation == "ratchet":
            return ["Before every mj_step a ratchet raises each module's slide lower limit to the module's running "
                    f"maximum ({controllers}.slide_clutches): a module moves forward and never back. MuJoCo alone "
                    "keeps the limits this file holds."]
        if implementation == "lock":
            return ["Before every mj_step velocity-triggered locks fix a module's slide (both limits at its "
                    f"position) when it would move back, and release it by the clutch rule '{rule}' "
                    f"({controllers}.slide_clutches)."]
        return ["No clutch: nothing changes the model between steps but the drive below."]


def refuse_grip(params: RobotParams, implementation: str) -> None:
    """ParameterError (one line) for a finite ``mu_wall`` with a clutch that has no grip: the locks (an equality
    holds whatever the load) and no clutch. (Wheel normal forces given with unlimited grip are refused for
    every engine by :func:`ipir_mujoco.core.params.refuse_idle_parameters`.)"""
    if params.mu_wall is not None and implementation != "ratchet":
        raise ParameterError(f"mu_wall={params.mu_wall!r} with the MuJoCo {implementation!r} clutch: only the ratchet "
                             "is modelled on wheels of finite grip (a lock holds whatever the load); allowed: "
                             "--mujoco-clutch ratchet, or mu_wall=unlimited")


class GripSlidesKind(ModelKind):
    """The slide model on wheels of finite grip: a carriage per module on the wall, held by friction G_i."""

    name = "slides-grip"
    skid = True
    skid_rule = "slides"

    def takes(self, params):
        return params.grip is not None

    def check(self, params, implementation, rule, route=None, until_steady=False):
        params = super().check(params, implementation, rule, route, until_steady)
        refuse_grip(params, implementation)
        return params

    def between_steps(self, params, implementation, rule):
        return [*super().between_steps(params, implementation, rule),
                f"Finite grip (mu_wall {params.mu_wall:g}): each module's carriage is ratcheted the same way "
                "(ipir_mujoco.engine.controllers.grip)."]

    def controller(self, model, data, params, implementation, rule="unilateral"):
        refuse_grip(params, implementation)
        if params.clutch_stiffness is None:
            return GripRatchet(model, data, params)
        return CompliantGrip(model, data, params)

    def columns(self, model, params, q, scalars, out):
        """slip1/2 [m], each carriage's backward travel below its start (its running minimum over the samples:
        the carriage only skids back, its limit holds it from going forward), grip_use1/2
        (:func:`~ipir_mujoco.core.results.grip_use`), the grips' cumulative work skid_work [J] and the wheels'
        states wheels1/2."""
        cols = {}
        for k, (name, G) in enumerate(zip(SKIDS, params.grip), start=1):
            adr = qpos_address(model, name)
            wheels = scalars[f"wheels{k}"]
            cols[f"slip{k}"] = q[0, adr] - np.minimum.accumulate(q[:, adr])
            cols[f"grip_use{k}"] = grip_use(out[f"lambda{k}"], wheels, G)
            cols[f"wheels{k}"] = wheels.copy()
        cols["skid_work"] = scalars["skid_work"].copy()
        return cols


class WheelsKind(ModelKind):
    """A 3-D robot on sprung wheel legs in a round pipe, a ratchet in every hub."""

    name = "wheels"
    model = "wheels"
    # 'warn': the residual is recorded and shown rather than stopping the run. In a straight pipe it closes (the
    # loop's pin at 2 steps: mjcf/README.md, "The round pipe: energy"); along a route the wheels' scrub takes work
    # the contacts' rows measure only to the step's accuracy
    accuracy = "warn"
    skid = True
    # a run whose wheels skid is rerun at half its step until its figures are within the model's accuracy (a
    # sliding soft contact converges at first order in the step: mjcf/README.md, "The round pipe: convergence")
    skid_rule = "wheels"
    pipe_built = True

    def takes(self, params):
        return True  # unlimited or finite grip alike: the contacts' friction is mu_wall

    def check(self, params, implementation, rule, route=None, until_steady=False):
        refuse_clutches(params, implementation)
        params = check_route(route, self.model, params, until_steady)
        check_clutch_options(params, rule, implementation)
        return params

    def settings(self, params, t_end, dt_out, servo=None, implementation="ratchet", route=None):
        chosen, why = super().settings(params, t_end, dt_out, servo, implementation)
        return wheels_settings(chosen, why, dt_out, route)

    def recorded_settings(self):
        return {"mujoco_model": self.model, "cone": "elliptic", "impratio": 1.0,
                "noslip_iterations": NOSLIP_ITERATIONS, "contact_time_constant_s": ROW_TIMES.contact,
                "limit_time_constant_s": ROW_TIMES.limit}

    def build(self, params, settings, *, mjcf=None, implementation="ratchet", route=None, decorate=None):
        return build_wheels_model(params, settings, mjcf=mjcf, route=route, decorate=decorate)

    def initial_state(self, model, data, params):
        set_wheels_state(model, data, params)

    def route_fit(self, route, params):
        return pipe_fit(route, params)

    def controller(self, model, data, params, implementation, rule="unilateral"):
        return WheelRatchet(model, data, params)

    def between_steps(self, params, implementation, rule):
        return ["Before every mj_step a ratchet in every wheel hub raises the hub's lower joint limit to the "
                "running maximum of its angle (ipir_mujoco.engine.controllers.wheels.WheelRatchet): a wheel rolls "
                "forward and never back. MuJoCo alone keeps the limits this file holds."]

    def loop_options(self, model, data):
        return wheel_loop_options(model, data)

    def columns(self, model, params, q, scalars, out):
        """slip1/2 [m], each module's backward steps (:func:`.wheels.wheel_slip`); grip_use1/2
        (:func:`~ipir_mujoco.core.results.grip_use`) with finite grip; the contacts' cumulative work skid_work [J],
        the wheels' states wheels1/2; the legs' press press1/2 [N] and wheels_off (:func:`.wheels.press_columns`);
        the modules' pose across the pipe y1/2, z1/2 [m], roll1/2, pitch1/2, yaw1/2 [rad]
        (:func:`.wheels.pose_columns`), which with x1, x2, phi pose the robot for a replay; the linkage's forces
        on each module across the pipe link_y1/2, link_z1/2 [N] (:func:`.wheels.link_columns`)."""
        cols = {}
        for k in (1, 2):
            wheels = scalars[f"wheels{k}"]
            cols[f"slip{k}"] = wheel_slip(out[f"x{k}"])
            if params.grip is not None:
                G = params.grip[k - 1]
                cols[f"grip_use{k}"] = grip_use(out[f"lambda{k}"], wheels, G)
            cols[f"wheels{k}"] = wheels.copy()
        cols["skid_work"] = scalars["skid_work"].copy()
        cols.update(press_columns(model, params, q))
        cols.update(pose_columns(model, q))
        cols.update(link_columns(params, scalars, out, cols))
        return cols


SLIDES, GRIP_SLIDES, WHEELS = ModelKind(), GripSlidesKind(), WheelsKind()
KINDS = {kind.name: kind for kind in (SLIDES, GRIP_SLIDES, WHEELS)}  # kind_for asks them in this order
MODELS = tuple(dict.fromkeys(kind.model for kind in KINDS.values()))  # the words a user names them by


def kind_for(model: str, params: RobotParams) -> ModelKind:
    """The model kind of a run of MuJoCo's model ``model`` ('slides' | 'wheels') on ``params``: on the slides a
    finite ``mu_wall`` chooses the carriages' model.

    Parameters
    ----------
    model : str
    params : RobotParams

    Returns
    -------
    ModelKind

    Raises
    ------
    ParameterError
        For an unknown ``model``.
    """
    for kind in KINDS.values():
        if kind.model == model and kind.takes(params):
            return kind
    raise ParameterError(f"mujoco model {model!r} is unknown; allowed: {', '.join(MODELS)}")


def clutch_controller(model: mujoco.MjModel, data: mujoco.MjData, params: RobotParams, implementation: str,
                      rule: str = "unilateral"):
    """The slide model's clutch controller of a run (the slide kinds' :meth:`ModelKind.controller`): kept for
    scripts that built the slide model themselves."""
    return kind_for("slides", params).controller(model, data, params, implementation, rule)
