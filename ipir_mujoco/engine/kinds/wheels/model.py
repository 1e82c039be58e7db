"""Build the wheeled MuJoCo model of the robot, a 3-D robot in a round pipe (``--mujoco-model wheels``), through MjSpec.

The template ``mjcf/inchworm_wheels.xml`` holds the mechanism of ``inchworm.xml`` (crank on module 1, rod, the loop
closed on module 2 by an equality ``connect``, a ball joint at C) with the rod on a universal joint at the crank pin
B (``rod_hinge`` about z and ``rod_tilt``, a cross pin about the rod's own y: in a bend module 2's C leaves module 1's
plane, and a rod hinged about z alone would hold it there, off the pipe's centreline by about L^2 / (2 R)) and each
module free in 3-D: slides along x (``rear_slide``,
``front_slide``: the travel every column reads), y (``*_lateral``) and z (``*_vertical``) and a ball joint
(``*_tilt``). x is the pipe's axis, z is up in a horizontal pipe, the crank turns about z. :func:`build_wheels_spec`
adds, per module, two rings (``aft``, ``fore``) of ``wheel_legs`` legs each, ``ring_spacing`` apart and centred
on the module's joint with the linkage (A on module 1, C on module 2: the linkage's forces there make no moment
about the rings' middle), the legs evenly spaced about the axis with leg 0 at the bottom. A leg:

- an arm, a slide along the leg's outward radial direction u, pressed outward by a linear spring of stiffness
  k = P / ``suspension_travel`` and free length ``suspension_travel`` beyond the wall, so that on the wall (slide
  at 0) it presses with its preload P = F_ni / (2 ``wheel_legs``): a module's legs press the wall with F_ni in
  all (``F_n1``, ``F_n2``). The arm stops at the spring's free length (slide +travel: a wheel off its wall
  presses nothing) and at STOP_COMPRESSION travels of compression (slide -(STOP_COMPRESSION - 1) travel);
- a wheel on a hub hinge about x cross u (forward rolling turns it positively): the one-way clutch (a limited
  hinge whose lower bound the engine raises, :mod:`.wheels`) and the rolling resistance (``frictionloss``
  F_ri R / (2 ``wheel_legs``), so that a module's wheels rolling on the wall resist with F_ri);
- the wheel's contact: a sphere of radius ``wheel_radius`` (one contact point on any wall), friction
  ``mu_wall`` (condim 3: sliding; the rolling is the hinge's), elliptic cone. With ``mu_wall`` unlimited the
  friction is MU_UNLIMITED; the engine reports a run whose grip use comes near it.

For symmetric legs on linear springs the sum of a ring's normal forces does not change as the module moves
across the pipe (the outward directions sum to zero), so the module's press stays F_ni while its weight sags it;
the arms' stops and a wheel off its wall end that (the closed-form check: :func:`ipir_mujoco.core.pipe.lift_check`).

Masses: each arm and each wheel ARM_SHARE and WHEEL_SHARE of its module's mass m_i (:mod:`ipir_mujoco.core.wheel_legs`,
which says why), inside m_i; the module's inertia is a solid cylinder of its mass, as long as its ring spacing, of
the radius inside its wheels. The pipe's wall: :func:`write_pipe_wall` (round and exact, :mod:`.pipe_walls`; flat
walls along each leg's track let a skidding module roll off them: a rolled wheel's normal on a plane has a moment
about the axis that rolls it on).
Every contact's and limit's time constant is a property of the model in seconds (:class:`RowTimes`), not a multiple
of the step; the loop's pin, a rigid joint, follows the step (2 steps, as the slide model's constraints).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import mujoco
import numpy as np

from ipir_mujoco.core.errors import ParameterError
from ipir_mujoco.core.params import RobotParams
from ipir_mujoco.core.pipe import ARM_SHARE, WHEEL_SHARE, check_fit, rigid_wheels, sprung_mass
from ipir_mujoco.core.pipe import leg_direction as core_leg_direction

from ....resources import mjcf_dir
from ..base import HOUSINGS
from ...builders.model import (CRANK_HINGE, FRONT_SLIDE, INTEGRATORS, LOOP, REAR_SLIDE, ROD_HINGE, SolverSettings, _element,
                    _write_drive, _write_gravity, _write_mechanism, check_params, compile_spec, dof_address,
                    load_spec, qpos_address, start_closed_loop)

MODULES = ("rear", "front")
RINGS = ("aft", "fore")
LATERALS = ("rear_lateral", "front_lateral")  # the modules' slides across the pipe (y)
VERTICALS = ("rear_vertical", "front_vertical")  # the modules' slides across the pipe (z)
TILTS = ("rear_tilt", "front_tilt")  # the modules' ball joints
ROD_TILT = "rod_tilt"  # the rod's cross pin at B (with rod_hinge a universal joint): the rod leaves the crank's plane
HALF_WIDTH = 0.005  # m: the drawn tyre's half-width along its hub (the contact is the sphere's)
SEAT = 1e-8  # m: how far the initial state sets each wheel into the wall (its contact then acts from the first step)
STOP_COMPRESSION = 4.0  # the arm's inner stop, in suspension travels of compression (4 x the preload)
# the contact friction for mu_wall = unlimited: a grip of 100 times the press, beyond any load the parameters'
# envelope puts on a module (its largest demand, a 5 kg module on a riser under a 2 N m motor through a 0.02 m
# crank, is 30 times a 5 N press); mu 10 let such a module skid
MU_UNLIMITED = 100.0
NOSLIP_ITERATIONS = 0  # MuJoCo's no-slip pass: off (a held robot creeps ~3e-6 m/s without it; it doubles the cost)
TRAIL_SHARE = 0.25  # the steer-compliant wheel's trail over its radius (mjcf/README.md, "The wheels' side force")
STEER_STOP = 1.0  # rad: the steer hinge's stops either way, beyond any slip angle the side-force law is used at
IMPEDANCE = (0.9999, 0.9999, 0.001, 0.5, 2.0)  # every row's solimp: MuJoCo's largest impedance, as the slides'


@dataclass(frozen=True)
class RowTimes:
    """The time constants [s] of the model's soft rows (MuJoCo's solref, damping ratio 1), properties of the
    model and not of the step (mjcf/README.md, "The round pipe: convergence"): ``contact`` (wheel and housing
    against the wall), ``limit`` (the hubs' ratchets and friction, the arms' stops). MuJoCo needs each >= 2 steps;
    :func:`wheels_timestep` picks the step from them. The loop's pin (the rod on module 2) is no such row: it is
    a rigid joint, its softness numerical only, so it follows the step as the slide model's constraints do
    (:attr:`ipir_mujoco.engine.builders.solver_settings.SolverSettings.time_constant`, 2 steps:
    :func:`build_wheels_spec`)."""

    contact: float = 2e-4
    limit: float = 2e-4

    def shortest(self) -> float:
        return min(self.contact, self.limit)


ROW_TIMES = RowTimes()
STEPS_PER_TIME_CONSTANT = 2  # the default step: the shortest time constant over this (convergence study)
# along a route with bends: every wheel of a rolling module slides across the pipe in a bend (its scrub), and a
# sliding soft contact's push-off (about 2 mu v tau) converges at first order in step / tau: at tau / 2 a R/D 5
# bend's revolutions came out 0.5 % short, at tau / 4 within 0.13 % of tau / 32 (mjcf/README.md, "The round pipe:
# convergence")
STEPS_PER_TIME_CONSTANT_BENDS = 4


def wheels_timestep(times: RowTimes = ROW_TIMES, bends: bool = False) -> float:
    """The default step [s] of the round-pipe model: its shortest row time constant / STEPS_PER_TIME_CONSTANT, or
    / STEPS_PER_TIME_CONSTANT_BENDS along a route with ``bends``."""
    return times.shortest() / (STEPS_PER_TIME_CONSTANT_BENDS if bends else STEPS_PER_TIME_CONSTANT)


def default_wheels_mjcf() -> Path:
    """The shipped template of the round-pipe model."""
    return mjcf_dir() / "inchworm_wheels.xml"


def leg_count(params: RobotParams) -> int:
    return int(params.wheel_legs)


def leg_names(params: RobotParams) -> tuple[tuple[str, ...], tuple[str, ...]]:
    """Per module (rear first) its legs' prefixes MODULE_RING_legK, aft ring first: + '_arm' (the arm's body and
    slide), '_hub' (the wheel's hinge), '_wheel' (the wheel's body and sphere), '_tyre' (the drawn tyre)."""
    n = leg_count(params)
    return tuple(tuple(f"{m}_{ring}_leg{k}" for ring in RINGS for k in range(n)) for m in MODULES)


def leg_direction(k: int, n: int) -> np.ndarray:
    """Leg k's outward unit vector (of n evenly spaced, leg 0 pointing down, -z), shape (3,)
    (:func:`ipir_mujoco.core.wheel_legs.leg_direction`, the lift-off check's)."""
    return np.array(core_leg_direction(k, n))


def hub_axis(u: np.ndarray) -> np.ndarray:
    """The hub's axis x cross u for a leg pointing along u: a wheel rolling forward (+x) on the wall at u turns
    positively about it."""
    return np.cross([1.0, 0.0, 0.0], u)


def contact_friction(params: RobotParams) -> float:
    """The wheels' contact friction coefficient: ``mu_wall``, or MU_UNLIMITED for unlimited grip."""
    return MU_UNLIMITED if params.mu_wall is None else params.mu_wall


def leg_preload(params: RobotParams, module: int) -> float:
    """One leg's spring preload P [N] on the wall: F_ni / (2 wheel_legs)."""
    return (params.F_n1, params.F_n2)[module] / (2 * leg_count(params))


def leg_stiffness(params: RobotParams, module: int) -> float:
    """One leg's spring stiffness [N/m]: preload / suspension_travel."""
    return leg_preload(params, module) / params.suspension_travel


def wheel_mass(params: RobotParams, module: int) -> float:
    return WHEEL_SHARE * (params.m1, params.m2)[module]


def steer_compliant(params: RobotParams) -> bool:
    """Whether the wheels steer on their hinges (a finite ``cornering_coefficient`` and a finite ``mu_wall``,
    :func:`ipir_mujoco.core.wheel_legs.rigid_wheels`): unlimited grip asks a held wheel to take any load along the pipe,
    and a steer-compliant wheel pushed back harder than its cornering stiffness C [N/rad] swings off its axis (its
    trail's lever beats its spring), so with unlimited grip the wheels are rigid."""
    return not rigid_wheels(params)


def trail(params: RobotParams) -> float:
    """The steer-compliant wheel's trail e [m]: how far its centre (and contact) follows its steer axis along the
    module, TRAIL_SHARE of ``wheel_radius``."""
    return TRAIL_SHARE * params.wheel_radius


def cornering_stiffness(params: RobotParams, module: int) -> float:
    """One wheel's cornering stiffness C [N/rad]: ``cornering_coefficient`` times its leg's preload."""
    return params.cornering_coefficient * leg_preload(params, module)


def steer_stiffness(params: RobotParams, module: int) -> float:
    """The steer hinge's spring [N m/rad], C e: a rolling wheel steered by its slip angle alpha to its path holds
    it with the contact's side force C alpha at the trail e."""
    return cornering_stiffness(params, module) * trail(params)


def wheel_inertias(params: RobotParams, module: int) -> tuple[float, float]:
    """A wheel's inertias [kg m^2] about its hub's axis, a disc's m R^2 / 2, and across it, a disc's about a
    diameter with the drawn tyre's half-width."""
    m, R = wheel_mass(params, module), params.wheel_radius
    return 0.5 * m * R * R, 0.25 * m * R * R + m * HALF_WIDTH ** 2 / 3


def housing_radius(params: RobotParams) -> float:
    """The housing's radius [m]: inside the wheels' ring, D/2 - 2 R."""
    return 0.5 * params.pipe_diameter - 2.0 * params.wheel_radius


def check_wheels_params(params: RobotParams) -> None:
    """The parameters the round-pipe model needs beyond the shared ranges (ParameterError, one line)."""
    check_params(params)
    check_fit(params)
    for name in ("F_n1", "F_n2"):
        if not getattr(params, name) > 0:
            raise ParameterError(f"{name}={getattr(params, name)!r} N with the wheeled MuJoCo model: its legs' springs "
                                 f"press the wheels on with it; allowed: 0 < {name} <= 1e+06 N")
    if not params.suspension_travel < 0.25 * params.pipe_diameter / STOP_COMPRESSION:
        raise ParameterError(f"suspension_travel={params.suspension_travel:g} m with pipe_diameter="
                             f"{params.pipe_diameter:g} m: the arm's travel to its stop must fit in the pipe; allowed: "
                             f"suspension_travel < pipe_diameter / {4 * STOP_COMPRESSION:g}")


def build_wheels_spec(params: RobotParams, settings: SolverSettings | None = None, times: RowTimes = ROW_TIMES,
                    mjcf: str | Path | None = None, route=None) -> mujoco.MjSpec:
    """The template with ``params`` written in, the legs added and the pipe's wall (:func:`write_pipe_wall`, a
    straight pipe or along ``route``, a :class:`ipir_mujoco.core.route.Route`), not compiled. ``settings``: the
    step and integrator (default :func:`wheels_timestep`, implicitfast); the rows' softness is ``times``."""
    check_wheels_params(params)
    settings = settings or SolverSettings(timestep=wheels_timestep(times))
    if settings.timestep > 0.5 * times.shortest() * (1 + 1e-12):
        raise ParameterError(f"timestep={settings.timestep:g} s with the wheeled model: its rows' shortest time "
                             f"constant is {times.shortest():g} s; allowed: timestep <= {0.5 * times.shortest():g} s")
    spec = load_spec(mjcf if mjcf is not None else default_wheels_mjcf())
    hint = str(mjcf or default_wheels_mjcf())
    _write_mechanism(spec, params, hint)  # masses, inertias, lengths as the slide model's; resistances below
    _write_drive(spec, params, hint)
    _write_gravity(spec, params, hint)
    for name in (REAR_SLIDE, FRONT_SLIDE):
        _element(spec.joint, name, hint).frictionloss = 0.0  # the resistance is the hubs'
    _write_legs(spec, params, times, hint)
    write_pipe_wall(spec, params, route, times)
    spec.option.timestep = settings.timestep
    spec.option.integrator = INTEGRATORS[settings.integrator]
    spec.option.cone = mujoco.mjtCone.mjCONE_ELLIPTIC
    spec.option.impratio = 1.0
    spec.option.noslip_iterations = NOSLIP_ITERATIONS
    eq = _element(spec.equality, LOOP, hint)
    # the loop's pin is rigid: its soft row at 2 steps (the slide model's), stiffer as the step shrinks. Held at the
    # contacts' 2e-4 s it gained energy where the step is finer and the crank fast (the constant-torque runaway of
    # 5 s at the defaults, at its automatic 1.1e-5 s: a residual of -2.5 % of the drive's work, -6.6 J, halving
    # with the step; at 2 steps -4.4e-4: mjcf/README.md, "The round pipe: energy")
    eq.solref, eq.solimp = [settings.time_constant, 1.0], list(IMPEDANCE)
    for name in HOUSINGS:
        g = _element(spec.geom, name, hint)
        g.solref, g.solimp = [times.contact, 1.0], list(IMPEDANCE)
        g.friction = [contact_friction(params), 0.0, 0.0]
    return spec


def add_leg(body, prefix: str, u: np.ndarray, x: float, params: RobotParams, module: int,
            times: RowTimes = ROW_TIMES) -> None:
    """One wheel leg of module ``module`` (0 rear, 1 front) on ``body`` (an MjSpec body), pointing along the unit
    ``u`` (3,) across the pipe, ``x`` [m] along the body's axis from its origin, its names ``prefix`` + '_arm',
    '_steer', '_hub', '_wheel', '_strut', '_tyre' (module docstring): the arm on its sprung slide, the wheel on
    its steer hinge (steer-compliant wheels, ``cornering_coefficient`` finite: about u through the point the
    trail e ahead of the wheel's centre, its spring C e, undamped: mjcf/README.md) and its hub hinge, the sphere
    touching the wall."""
    R, travel, n = params.wheel_radius, params.suspension_travel, leg_count(params)
    reach = 0.5 * params.pipe_diameter - R  # the wheel's centre from the axis, the arm at 0
    limit = [times.limit, 1.0]
    arm = body.add_body(name=prefix + "_arm", pos=[x, 0.0, 0.0])
    arm.mass, arm.ipos, arm.inertia = ARM_SHARE * (params.m1, params.m2)[module], [0, 0, 0], [1e-8, 1e-8, 1e-8]
    arm.explicitinertial = True
    slide = arm.add_joint(name=prefix + "_arm", type=mujoco.mjtJoint.mjJNT_SLIDE, axis=u.tolist())
    slide.stiffness = [leg_stiffness(params, module), 0.0, 0.0]
    slide.springref = travel
    slide.limited = mujoco.mjtLimited.mjLIMITED_TRUE
    slide.range = [-(STOP_COMPRESSION - 1.0) * travel, travel]
    slide.solref_limit, slide.solimp_limit = limit, list(IMPEDANCE)
    arm.add_geom(name=prefix + "_strut", type=mujoco.mjtGeom.mjGEOM_CAPSULE, contype=0, conaffinity=0,
                 group=1, size=[0.003, 0, 0], fromto=[0, 0, 0, *(0.9 * reach * u)], rgba=[0.4, 0.4, 0.45, 1])
    wheel = arm.add_body(name=prefix + "_wheel", pos=(reach * u).tolist())
    J, across = wheel_inertias(params, module)
    a = hub_axis(u)
    wheel.mass, wheel.ipos = wheel_mass(params, module), [0, 0, 0]
    wheel.fullinertia = (J * np.outer(a, a) + across * (np.eye(3) - np.outer(a, a)))[[0, 1, 2, 0, 0, 1],
                                                                                      [0, 1, 2, 1, 2, 2]]
    wheel.explicitinertial = True
    if steer_compliant(params):  # the steer hinge first: it turns the hub's axis
        # its axis meets the wall the trail ahead of the contact: a leg tilted off the wall's normal (a cocked
        # module) then leaves the trail as it is (an axis through the wheel's centre would move it by R tilt)
        steer = wheel.add_joint(name=prefix + "_steer", type=mujoco.mjtJoint.mjJNT_HINGE, axis=u.tolist(),
                                pos=(trail(params) * np.array([1.0, 0.0, 0.0]) + R * u).tolist())
        steer.stiffness = [steer_stiffness(params, module), 0.0, 0.0]  # undamped (mjcf/README.md)
        steer.limited = mujoco.mjtLimited.mjLIMITED_TRUE
        steer.range = [-STEER_STOP, STEER_STOP]
        steer.solref_limit, steer.solimp_limit = limit, list(IMPEDANCE)
    hub = wheel.add_joint(name=prefix + "_hub", type=mujoco.mjtJoint.mjJNT_HINGE, axis=a.tolist())
    hub.frictionloss = (params.F_r1, params.F_r2)[module] * R / (2 * n)
    hub.limited = mujoco.mjtLimited.mjLIMITED_TRUE
    hub.range = [-1e9, 1e9]  # the engine sets the lower bound before the first step
    hub.margin = 1e-9
    hub.solref_limit, hub.solimp_limit = limit, list(IMPEDANCE)
    hub.solref_friction, hub.solimp_friction = limit, list(IMPEDANCE)
    wheel.add_geom(name=prefix + "_wheel", type=mujoco.mjtGeom.mjGEOM_SPHERE, size=[R, 0, 0], contype=1,
                   conaffinity=0, condim=3, friction=[contact_friction(params), 0.0, 0.0], group=3,
                   rgba=[0.25, 0.25, 0.25, 1], solref=[times.contact, 1.0], solimp=list(IMPEDANCE))
    wheel.add_geom(name=prefix + "_tyre", type=mujoco.mjtGeom.mjGEOM_CYLINDER, contype=0, conaffinity=0,
                   group=1, size=[R, 0, 0], fromto=[*(-HALF_WIDTH * a), *(HALF_WIDTH * a)],
                   rgba=[0.2, 0.2, 0.2, 1])


def _write_legs(spec: mujoco.MjSpec, params: RobotParams, times: RowTimes, hint: str) -> None:
    """The modules' masses and inertias, their rings of legs (module docstring)."""
    n = leg_count(params)
    masses = (params.m1, params.m2)
    rho, s = housing_radius(params), params.ring_spacing
    for i, module in enumerate(MODULES):
        body = _element(spec.body, f"{module}_module", hint)
        m_arm, m_wheel = ARM_SHARE * masses[i], wheel_mass(params, i)
        for prefix in leg_names(params)[i]:
            ring, leg = prefix.split("_")[1], int(prefix.split("_leg")[1])
            add_leg(body, prefix, leg_direction(leg, n), (-0.5 if ring == "aft" else 0.5) * s, params, i, times)
        carried = 2 * n * (m_arm + m_wheel)
        own = body.mass - carried  # the module's mass m_i includes its legs
        body.mass = own
        body.ipos = [0, 0, 0]
        body.inertia = [0.5 * own * rho * rho, own * (3 * rho * rho + s * s) / 12, own * (3 * rho * rho + s * s) / 12]
        body.explicitinertial = True
        housing = _element(spec.geom, HOUSINGS[i], hint)
        housing.size = [rho, 0, 0]
        housing.fromto = [-0.5 * s, 0, 0, 0.5 * s, 0, 0]
        housing.contype, housing.conaffinity, housing.condim = 1, 0, 3


def write_pipe_wall(spec: mujoco.MjSpec, params: RobotParams, route=None, times: RowTimes = ROW_TIMES) -> list[str]:
    """The pipe's round wall (:func:`.pipe_walls.add_pipe_walls`: exact contacts with the wheels' spheres and the
    housings' capsules, no seams or facets), a straight pipe along x or along ``route``, with the wheels'
    friction (:func:`contact_friction`), the contact time constant and the rows' impedance; returns its geoms'
    names."""
    from ...builders.pipe_walls import WallContact, add_pipe_walls

    reach = params.r + params.L + 0.5 * params.ring_spacing + 2.0 * params.wheel_radius
    return add_pipe_walls(spec, route, params.pipe_diameter,
                          WallContact(contact_friction(params), (times.contact, 1.0), IMPEDANCE), robot_length=reach)


def build_wheels_model(params: RobotParams, settings: SolverSettings | None = None, times: RowTimes = ROW_TIMES,
                     mjcf: str | Path | None = None, route=None, decorate=None) -> mujoco.MjModel:
    """Compile the round-pipe robot for ``params`` (:func:`build_wheels_spec`); ``decorate(spec)`` as for
    :func:`.model.build_model`."""
    return compile_spec(build_wheels_spec(params, settings, times, mjcf, route), decorate, "wheeled MuJoCo model")


def sag(params: RobotParams, module: int) -> float:
    """How far [m] module ``module``'s weight sags it across the pipe on its legs' springs, closed form: the two
    rings' n legs each stiffen it by n k / 2, so delta = m g cos(incline) / (n k), m the mass its springs carry
    (:func:`~ipir_mujoco.core.wheel_legs.sprung_mass`: m_i less its legs), while no wheel lifts."""
    weight = sprung_mass(params, module) * params.g * math.cos(math.radians(params.incline))
    return weight / (leg_count(params) * leg_stiffness(params, module))


def set_wheels_state(model: mujoco.MjModel, data: mujoco.MjData, params: RobotParams) -> None:
    """The loop closed at ``phi0`` with module 1 at 0, each module sagged by its own weight on its springs
    (:func:`sag`, at most to its lower legs' stops: a module heavier than its press rests on them, and a larger
    drop would start its housing inside the wall), every wheel on its round wall (its arm's reach exact, not the
    sag's component along the leg alone: that set the upper wheels into the wall), at rest or with the crank at
    ``omega0`` (the slide model's rule, :func:`.model.start_closed_loop`). Where the two sags differ the rod
    leaves the crank's plane on its cross pin (``rod_tilt``) by asin((delta2 - delta1) / L) and the loop closes
    in the plane on the rod's projection, L cos of that: started at a common height, the module with the
    larger sag dropped from it at the first step and bounced on its springs by the difference (up to a few
    millimetres, a lift of its upper wheels where its weight leaves its press little margin)."""
    cap = (STOP_COMPRESSION - 1.0) * params.suspension_travel
    drops = [min(sag(params, i), cap) for i in (0, 1)]
    tilt = math.asin(max(-1.0, min(1.0, (drops[1] - drops[0]) / params.L)))
    projected = params.L * math.cos(tilt)
    planar = params if projected == params.L else params.replace(L=projected)
    freed = start_closed_loop(model, data, planar)
    # module 2's slide is measured from the model's reference pose at x = r + L (the rod's own length)
    data.qpos[qpos_address(model, FRONT_SLIDE)] += projected - params.L
    data.qpos[qpos_address(model, ROD_TILT)] = tilt
    n = leg_count(params)
    reach = 0.5 * params.pipe_diameter - params.wheel_radius  # a wheel's centre from the axis, its arm at 0
    for i in (0, 1):
        data.qpos[qpos_address(model, VERTICALS[i])] = -drops[i]
        for prefix in leg_names(params)[i]:
            u = leg_direction(int(prefix.split("_leg")[1]), n)
            # the arm reaches what the module left, and SEAT into the wall: a contact at a distance of exactly 0
            # is left out of MuJoCo's first step, and the module would drop until its wheels meet the wall. The
            # wall is round: a module dropped by delta moves a leg's wheel delta u_y along the wall as well, so
            # the arm reaches delta u_z + sqrt(reach^2 - (delta u_y)^2) - reach (delta u_z alone would set the
            # upper wheels (delta u_y)^2 / (2 reach) into the wall, 0.3 mm at a 7 mm sag, and their contacts would
            # kick the arms off at the first steps, sliding the wheels a millimetre or more across the wall)
            reached = drops[i] * u[2] + math.sqrt((reach + SEAT) ** 2 - (drops[i] * u[1]) ** 2) - reach
            lo, hi = model.jnt_range[model.joint(prefix + "_arm").id]
            data.qpos[qpos_address(model, prefix + "_arm")] = min(max(reached, lo), hi)
    if freed is not None:  # the wheels of the moving module roll with it
        target, speed = freed
        for prefix in leg_names(params)[0 if target == REAR_SLIDE else 1]:
            data.qvel[dof_address(model, prefix + "_hub")] = speed / params.wheel_radius
    mujoco.mj_forward(model, data)
