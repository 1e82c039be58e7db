"""The wheeled model's kind: a 3-D robot on sprung wheel legs in a round pipe, a ratchet in every hub; routes of
straights and bends.

Its builder :mod:`.model` (from ``mjcf/inchworm_wheels.xml``: the legs, the pipe's wall, the rows' time constants),
its hub ratchets and their columns :mod:`.ratchet` (compiled: :mod:`.compiled`, ``_clutch_wheels.c``), its skid rule
:mod:`.skids`, a route's watch :mod:`.route_watch` and the closed-form fit of a route's bends :mod:`.route_walls`,
its replay :mod:`.drawing`.
"""

from __future__ import annotations

from ..base import NO_ROUTE, ModelKind

RATCHETS = "ipir_mujoco.engine.kinds.wheels.ratchet"  # where the header of a saved MJCF file sends a reader


class WheelsKind(ModelKind):
    """A 3-D robot on sprung wheel legs in a round pipe, a ratchet in every hub (module docstring)."""

    name = "wheels"
    model = "wheels"
    mjcf = "inchworm_wheels.xml"
    free = "free, rolls"
    variants = (dict(name="mujoco-wheels", rule="unilateral", clutch="ratchet", label="MuJoCo wheels in contact",
                     clutches="one-way ratchets in the wheels' hubs", mechanism="wheels, hub ratchets", routes=True),)
    # 'warn': the residual is recorded and shown rather than stopping the run. In a straight pipe it closes (the
    # loop's pin at 2 steps: mjcf/README.md, "The round pipe: energy"); along a route the wheels' scrub takes work
    # the contacts' rows measure only to the step's accuracy
    accuracy = "warn"
    skid = True

    def takes(self, params):
        return True  # unlimited or finite grip alike: the contacts' friction is mu_wall

    def check(self, params, implementation, rule, route=None, until_steady=False):
        from ..common import check_clutch_options
        from .ratchet import refuse_clutches
        from .route_watch import check_route

        refuse_clutches(params, implementation)
        params = check_route(route, self.model, params, until_steady)
        check_clutch_options(params, rule, implementation)
        return params

    def settings(self, params, t_end, dt_out, servo=None, implementation="ratchet", route=None):
        """The slide model's automatic step (:func:`ipir_mujoco.engine.kinds.timestep.choose_settings`) capped by
        the model's own (:func:`.ratchet.wheels_settings`)."""
        from ..timestep import choose_settings
        from .ratchet import wheels_settings

        chosen, why = choose_settings(params, t_end, dt_out, servo, implementation)
        return wheels_settings(chosen, why, dt_out, route)

    def recorded_settings(self):
        from .model import NOSLIP_ITERATIONS, ROW_TIMES

        return {"mujoco_model": self.model, "cone": "elliptic", "impratio": 1.0,
                "noslip_iterations": NOSLIP_ITERATIONS, "contact_time_constant_s": ROW_TIMES.contact,
                "limit_time_constant_s": ROW_TIMES.limit}

    def build(self, params, settings, *, mjcf=None, implementation="ratchet", route=None, decorate=None):
        from .model import build_wheels_model

        return build_wheels_model(params, settings, mjcf=self.template() if mjcf is None else mjcf, route=route,
                                  decorate=decorate)

    def initial_state(self, model, data, params):
        from .model import set_wheels_state

        set_wheels_state(model, data, params)

    def route_fit(self, route, params):
        from .route_watch import pipe_fit

        return pipe_fit(route, params)

    def route_watch(self, route, model, recorder, params, dt_out):
        """:class:`.route_watch.RouteWatch` along ``route`` (:data:`~ipir_mujoco.engine.kinds.base.NO_ROUTE`
        without one)."""
        from .route_watch import route_watch

        if route is None:
            return NO_ROUTE
        return route_watch(route, model, recorder, params, dt_out, self.route_fit)

    def controller(self, model, data, params, implementation, rule="unilateral"):
        from .ratchet import WheelRatchet

        return WheelRatchet(model, data, params)

    def between_steps(self, params, implementation, rule):
        return ["Before every mj_step a ratchet in every wheel hub raises the hub's lower joint limit to the "
                f"running maximum of its angle ({RATCHETS}.WheelRatchet): a wheel rolls "
                "forward and never back. MuJoCo alone keeps the limits this file holds."]

    def loop_options(self, model, data):
        from .ratchet import wheel_loop_options

        return wheel_loop_options(model, data)

    def columns(self, model, params, q, scalars, out):
        """slip1/2 [m], each module's backward steps (:func:`.ratchet.wheel_slip`); grip_use1/2
        (:func:`~ipir_mujoco.core.summary.grip_use`) with finite grip; the contacts' cumulative work skid_work [J],
        the wheels' states wheels1/2; the legs' press press1/2 [N] and wheels_off (:func:`.ratchet.press_columns`);
        the modules' pose across the pipe y1/2, z1/2 [m], roll1/2, pitch1/2, yaw1/2 [rad]
        (:func:`.ratchet.pose_columns`), which with x1, x2, phi pose the robot for a replay; slid1/2 [m], how far
        each module's wheels slid sideways on the wall (:func:`.ratchet.slide_columns`); the linkage's forces on each
        module across the pipe link_y1/2, link_z1/2 [N] (:func:`.ratchet.link_columns`)."""
        from ipir_mujoco.core.results import grip_use

        from .ratchet import link_columns, pose_columns, press_columns, slide_columns, wheel_slip

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
        cols.update(slide_columns(model, params, q))
        cols.update(link_columns(scalars, cols))
        return cols

    def skid_rule(self, params):
        """The wheeled model's rule (:data:`.skids.WHEELS_RULE`): a run whose wheels skid is rerun at half its step
        until its figures are within the model's accuracy (a sliding soft contact converges at first order in the
        step: mjcf/README.md, "The round pipe: convergence")."""
        from .skids import WHEELS_RULE

        return WHEELS_RULE

    def drawing(self, params, route=None, facing=None):
        """Its model as its build makes it (the pipe's walls and the wheels; along ``route``, built as the run
        built them), whatever the camera."""
        from .model import build_wheels_spec

        return build_wheels_spec(params, mjcf=self.template(), route=route)

    def replay(self, model, run):
        from .drawing import WheeledReplay

        return WheeledReplay(model, run)


KIND = WheelsKind()
