"""Build the wheeled MuJoCo model of the robot (``--mujoco-model wheels``) from a parameter set, through MjSpec.

The template ``mjcf/inchworm_wheels.xml`` holds the mechanism of ``inchworm.xml`` (crank on module 1, rod,
the loop closed on module 2 by an equality ``connect``) with each module free in the mechanism's plane
(slide x, slide y, hinge z), two walls (planes at y = +-D/2) and per module four wheels: at two stations
along x (aft and fore of the housing's centre, STATION_OFFSET either side), one on each wall at each station.
(The walls' forces on a pair at one station are collinear, so the preload makes no couple; two stations hold
the module's yaw; one station alone would leave it free to turn about that station.) Each wheel is a capsule (axis along z) on a hub hinge, on an arm that slides along the module's y axis, pressed on
its wall by a preloaded spring. :func:`build_wheels_model` writes the parameters in:

- the spring: stiffness k = (F_ni / WHEELS_PER_MODULE) / SPRING_TRAVEL with springref SPRING_TRAVEL, so that
  with the wheel on its wall (the arm slide at 0) it presses with F_ni / WHEELS_PER_MODULE: the module's
  wheels together press with F_ni (``F_n1``, ``F_n2``); a contact that sinks by p lowers that by p /
  SPRING_TRAVEL of it;
- the hub: ``frictionloss`` F_ri R / WHEELS_PER_MODULE [N m], so that the module's wheels rolling on the
  wall resist with F_ri (the rolling resistance, by construction); a limited hinge, the one-way clutch,
  whose lower bound the engine raises (:mod:`.wheels`);
- the contact: friction ``mu_wall`` (condim 3: sliding only; rolling is the hinge's), elliptic cone; with
  ``mu_wall`` unlimited the friction is MU_UNLIMITED, the parameter's upper bound: a grip of ten times the
  wall-press force, which no load of the robot comes near (a run reports it, ``peak_grip_use``, as the
  slide model does not);
- masses: the wheels and arms are part of their module's mass m_i (each ARM_SHARE and WHEEL_SHARE of it);
  a wheel is a disc, inertia m_w R^2 / 2 about its axis;
- geometry: walls at y = +-pipe_diameter / 2, wheel centres at +-(D / 2 - R) from the module's axis.

Element names beyond the slide model's (read by name, never by index) are the constants below.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import mujoco

from ipir_mujoco.core.errors import ParameterError
from ipir_mujoco.core.params import RobotParams
from ipir_mujoco.core.pipe import check_fit

from ..resources import mjcf_dir
from .model import (FRONT_SLIDE, LOOP, REAR_SLIDE, SolverSettings, _element, _write_drive, _write_gravity,
                    _write_mechanism, check_params, compile_spec, load_spec, write_step_options)

MODULES = ("rear", "front")
SIDES = ("top", "bottom")  # the wall at +D/2, the wall at -D/2
STATIONS = ("aft", "fore")  # the wheel stations along x, behind and ahead of the housing's centre
LATERALS = ("rear_lateral", "front_lateral")  # the modules' slides across the pipe (y)
YAWS = ("rear_yaw", "front_yaw")  # the modules' hinges about z
WALLS = ("wall_top", "wall_bottom")
# per module (rear first) its wheels' prefixes, MODULE_SIDE_STATION: + '_arm' (a body and its slide),
# '_hub' (the wheel's hinge), '_wheel' (the wheel's body and its capsule geom)
WHEEL_NAMES = tuple(tuple(f"{m}_{s}_{st}" for st in STATIONS for s in SIDES) for m in MODULES)
ARMS = tuple(f"{n}_arm" for names in WHEEL_NAMES for n in names)
HUBS = tuple(f"{n}_hub" for names in WHEEL_NAMES for n in names)
WHEELS = tuple(f"{n}_wheel" for names in WHEEL_NAMES for n in names)
WHEELS_PER_MODULE = 4
SPRING_TRAVEL = 1e-4  # m: the arm spring's compression at its preload (k = preload / SPRING_TRAVEL)
ARM_SHARE = 1e-3  # of the module's mass, per arm
WHEEL_SHARE = 1e-3  # of the module's mass, per wheel
HALF_WIDTH = 0.005  # m: the capsule's half-length along its axis (z), for drawing and contact
HOUSING_OFFSET = 0.035  # m: the housing's centre behind A (module 1) and ahead of C (module 2), as inchworm.xml
STATION_OFFSET = 0.025  # m: each wheel station's distance along x from its housing's centre
MU_UNLIMITED = 10.0  # the contact friction for mu_wall = unlimited: the parameter's upper bound
WALL_LENGTH = 3.0  # m: the walls' half-length as drawn (their planes are infinite for collisions)


def default_wheels_mjcf() -> Path:
    """The shipped template of the wheeled model."""
    return mjcf_dir() / "inchworm_wheels.xml"


@dataclass(frozen=True)
class ContactSettings:
    """The contact solver's settings of the wheeled model (``mjcf/README.md``, "Wheels in contact", has the
    convergence study): MuJoCo's friction cone ('elliptic' | 'pyramidal'), ``impratio`` (> 0: how much
    harder friction is than the normal direction) and ``noslip_iterations`` (>= 0: the post-pass that
    removes frictional creep)."""

    cone: str = "elliptic"
    impratio: float = 1.0
    noslip_iterations: int = 10

    def __post_init__(self) -> None:
        if self.cone not in ("elliptic", "pyramidal"):
            raise ParameterError(f"cone={self.cone!r} is unknown; allowed: elliptic, pyramidal")
        if not (math.isfinite(self.impratio) and self.impratio > 0):
            raise ParameterError(f"impratio={self.impratio} is out of range; allowed: impratio > 0")
        if not (isinstance(self.noslip_iterations, int) and 0 <= self.noslip_iterations <= 1000):
            raise ParameterError(f"noslip_iterations={self.noslip_iterations!r} is out of range; allowed: a whole "
                                 "number 0..1000")

    def as_dict(self) -> dict:
        return {"cone": self.cone, "impratio": self.impratio, "noslip_iterations": self.noslip_iterations}


def contact_friction(params: RobotParams) -> float:
    """The wheels' contact friction coefficient: ``mu_wall``, or MU_UNLIMITED for unlimited grip."""
    return MU_UNLIMITED if params.mu_wall is None else params.mu_wall


def wheel_mass(params: RobotParams, module: int) -> float:
    """Mass [kg] of one wheel of module ``module`` (0 rear, 1 front)."""
    return WHEEL_SHARE * (params.m1, params.m2)[module]


def wheel_inertia(params: RobotParams, module: int) -> float:
    """A wheel's inertia about its axis [kg m^2]: a disc, m_w R^2 / 2."""
    return 0.5 * wheel_mass(params, module) * params.wheel_radius ** 2


def build_wheels_spec(params: RobotParams, settings: SolverSettings = SolverSettings(),
                      contact: ContactSettings = ContactSettings(), mjcf: str | Path | None = None) -> mujoco.MjSpec:
    """The template with ``params`` and the settings written in (not compiled); see the module docstring."""
    check_params(params)
    check_fit(params)
    spec = load_spec(mjcf if mjcf is not None else default_wheels_mjcf())
    hint = str(mjcf or default_wheels_mjcf())
    _write_mechanism(spec, params, hint)  # masses, inertias, lengths as the slide model's; resistances below
    _write_drive(spec, params, hint)
    _write_gravity(spec, params, hint)
    _write_wheels(spec, params, hint)
    _write_contact_solver(spec, settings, contact, hint)
    return spec


def _write_wheels(spec: mujoco.MjSpec, params: RobotParams, hint: str) -> None:
    """Walls, arms, springs, hubs, wheels and the modules' own masses (module docstring)."""
    R, half = params.wheel_radius, 0.5 * params.pipe_diameter
    mu = contact_friction(params)
    for k, name in enumerate(WALLS):
        wall = _element(spec.geom, name, hint)
        wall.pos = [0.0, half if k == 0 else -half, 0.0]
        wall.size = [WALL_LENGTH, 0.05, 0.01]
        wall.friction = [mu, 0.0, 0.0]
    masses = (params.m1, params.m2)
    normals = (params.F_n1, params.F_n2)
    resistances = (params.F_r1, params.F_r2)
    for i, module in enumerate(MODULES):
        direction = -1.0 if i == 0 else 1.0  # the housing sits behind A on module 1, ahead of C on module 2
        centre = direction * HOUSING_OFFSET
        preload = normals[i] / WHEELS_PER_MODULE
        m_arm, m_wheel, J = ARM_SHARE * masses[i], wheel_mass(params, i), wheel_inertia(params, i)
        for prefix in WHEEL_NAMES[i]:
            _, side, station = prefix.split("_")
            outward = 1.0 if side == "top" else -1.0
            arm = _element(spec.body, prefix + "_arm", hint)
            arm.pos = [centre + (STATION_OFFSET if station == "fore" else -STATION_OFFSET), 0.0, 0.0]
            arm.mass, arm.ipos, arm.inertia = m_arm, [0, 0, 0], [1e-8, 1e-8, 1e-8]
            slide = _element(spec.joint, prefix + "_arm", hint)
            slide.stiffness = [preload / SPRING_TRAVEL, 0.0, 0.0]  # a linear spring (MuJoCo 4: a triple)
            slide.springref = SPRING_TRAVEL
            wheel = _element(spec.body, prefix + "_wheel", hint)
            wheel.pos = [0.0, outward * (half - R), 0.0]
            across = J / 2 + m_wheel * HALF_WIDTH ** 2 / 3  # a disc of width 2 HALF_WIDTH, about a diameter
            wheel.mass, wheel.ipos, wheel.inertia = m_wheel, [0, 0, 0], [across, across, J]
            hub = _element(spec.joint, prefix + "_hub", hint)
            hub.frictionloss = resistances[i] * R / WHEELS_PER_MODULE
            hub.limited = mujoco.mjtLimited.mjLIMITED_TRUE
            hub.range = [-1e9, 1e9]  # the engine sets the lower bound before the first step
            geom = _element(spec.geom, prefix + "_wheel", hint)
            geom.size = [R, HALF_WIDTH, 0.0]
            geom.friction = [mu, 0.0, 0.0]
        body = _element(spec.body, f"{module}_module", hint)
        body.mass = body.mass - WHEELS_PER_MODULE * (m_arm + m_wheel)  # the module's mass m_i includes them
    for name in (REAR_SLIDE, FRONT_SLIDE):
        _element(spec.joint, name, hint).frictionloss = 0.0  # the resistance is the hubs'


def _write_contact_solver(spec: mujoco.MjSpec, settings: SolverSettings, contact: ContactSettings,
                          hint: str) -> None:
    """Timestep, integrator, cone, impratio, noslip and every row's solref and solimp (the slide model's)."""
    solref, solimp = write_step_options(spec, settings)
    spec.option.cone = (mujoco.mjtCone.mjCONE_ELLIPTIC if contact.cone == "elliptic"
                        else mujoco.mjtCone.mjCONE_PYRAMIDAL)
    spec.option.impratio = contact.impratio
    spec.option.noslip_iterations = contact.noslip_iterations
    for name in HUBS:
        j = _element(spec.joint, name, hint)
        j.solref_limit, j.solimp_limit = solref, solimp
        j.solref_friction, j.solimp_friction = solref, solimp
    for name in WHEELS + WALLS:
        g = _element(spec.geom, name, hint)
        g.solref, g.solimp = solref, solimp
    eq = _element(spec.equality, LOOP, hint)
    eq.solref, eq.solimp = solref, solimp


def build_wheels_model(params: RobotParams, settings: SolverSettings = SolverSettings(),
                       contact: ContactSettings = ContactSettings(), mjcf: str | Path | None = None,
                       decorate=None) -> mujoco.MjModel:
    """Compile the wheeled robot for ``params`` (:func:`build_wheels_spec`); ``decorate(spec)`` as for
    :func:`.model.build_model`."""
    return compile_spec(build_wheels_spec(params, settings, contact, mjcf), decorate, "wheeled MuJoCo model")


def is_wheeled(model: mujoco.MjModel) -> bool:
    """Whether ``model`` is the wheeled model (it has the hubs)."""
    return mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, HUBS[0]) >= 0


def set_wheels_state(model: mujoco.MjModel, data: mujoco.MjData, params: RobotParams) -> None:
    """The loop closed at ``phi0`` with module 1 at 0, both modules on the pipe's axis, every wheel on its wall
    (arm slides at 0), at rest or with the crank at ``omega0`` (the slide model's rule: the gap rate goes to
    the module the paper's clutch rule frees, :func:`.model.set_closed_loop_state`)."""
    from .model import dof_address, start_closed_loop

    freed = start_closed_loop(model, data, params)
    if freed is not None:  # the wheels of the moving module roll with it
        target, speed = freed
        for prefix in WHEEL_NAMES[0 if target == REAR_SLIDE else 1]:
            data.qvel[dof_address(model, prefix + "_hub")] = speed / params.wheel_radius
    mujoco.mj_forward(model, data)
