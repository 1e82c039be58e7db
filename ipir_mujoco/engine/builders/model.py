"""Build the MuJoCo model of the robot from a parameter set, through MjSpec.

The shipped ``mjcf/inchworm.xml`` is the template: it names every element and
sets the structure (slides, crank hinge, rod hinge, the loop-closing
``connect``, clutch locks, drive). :func:`build_model` loads it with
``mujoco.MjSpec`` and writes every number of the parameter set into it (masses,
inertias, lengths, resistances, the drive's gain and bias, gravity) and the
solver settings, then compiles. No XML text is edited. Each physical effect is
written by one small function (``_write_*``), so a new one adds a function.

Element names used by the engine (read by name, never by index) are the
constants below. The solver settings (:class:`SolverSettings`, :data:`INTEGRATORS`, :func:`write_step_options`,
:func:`implicit_damping`) are :mod:`.solver_settings`'s, re-exported here.
"""

from __future__ import annotations

import functools
import math
from pathlib import Path

import mujoco
import numpy as np

from ipir_mujoco.core.errors import ParameterError
from ipir_mujoco.core.params import RobotParams

from ...resources import mjcf_dir
from . import RANGE_FAR  # the slides' range beyond any run: only the lower bound ever acts
from .grip_model import scale_grip_rows, write_grip
from .solver_settings import (IMPLICIT_INTEGRATORS, INTEGRATORS, SolverSettings, implicit_damping,  # noqa: F401
                              write_step_options)  # (re-exported: their home was here)

REAR_SLIDE, FRONT_SLIDE, CRANK_HINGE, ROD_HINGE = "rear_slide", "front_slide", "crank_hinge", "rod_hinge"
REAR_LOCK, FRONT_LOCK, LOOP = "rear_lock", "front_lock", "rod_to_front"
MOTOR, ROD_END = "crank_motor", "rod_end"
REAR_CLUTCH, FRONT_CLUTCH = "rear_clutch", "front_clutch"  # the compliant clutches' spring-damper actuators
SLIDES = (REAR_SLIDE, FRONT_SLIDE)  # the modules' slides, rear first
# Share of m1 carried by the crank body; the rest is the module body. Both
# translate with module 1, so the split changes nothing but must keep each > 0.
CRANK_MASS_SHARE = 0.01
# A clutch actuator's force range is [0, this] N: it never pulls; the upper bound is MuJoCo's largest
# state value (mjMAXVAL), far beyond any clutch force a run survives.
CLUTCH_FORCE_MAX = 1e10


def default_mjcf() -> Path:
    """The shipped MJCF template."""
    return mjcf_dir() / "inchworm.xml"


def check_params(params: RobotParams) -> None:
    """The parameters the MuJoCo model needs beyond the shared ranges (ParameterError, one line)."""
    if params.rod_mass <= 0:
        raise ParameterError(f"rod_mass={params.rod_mass} kg is out of range for the MuJoCo engine; allowed: "
                             "rod_mass > 0 (the rod is a body in the loop)")
    if params.rod_inertia_value <= 0:
        raise ParameterError(f"rod_inertia={params.rod_inertia_value} kg m^2 is out of range for the MuJoCo "
                             "engine; allowed: rod_inertia > 0")


@functools.lru_cache(maxsize=8)
def _parsed(path: str, mtime_ns: int, size: int) -> mujoco.MjSpec:
    """The file as parsed (keyed by its modification time and size too, so an edited file is read again)."""
    return mujoco.MjSpec.from_file(path)


def load_spec(mjcf: str | Path | None = None) -> mujoco.MjSpec:
    """Parse an MJCF file into an MjSpec (a copy of the file's parse, kept: a sweep builds hundreds of
    models from one file); a missing or broken file is a ParameterError."""
    path = Path(mjcf) if mjcf is not None else default_mjcf()
    if not path.is_file():
        raise ParameterError(f"MJCF file {str(path)!r} does not exist")
    stat = path.stat()
    try:
        return _parsed(str(path), stat.st_mtime_ns, stat.st_size).copy()
    except ValueError as exc:
        message = " ".join(str(exc).split())
        raise ParameterError(f"MJCF file {str(path)!r} is not a valid model: {message}") from None


def _element(getter, name: str, path_hint: str):
    element = getter(name)
    if element is None:
        raise ParameterError(f"MJCF {path_hint} has no element named {name!r}, which the engine needs")
    return element


def build_spec(params: RobotParams, settings: SolverSettings = SolverSettings(),
               mjcf: str | Path | None = None, ratchet: bool = False) -> mujoco.MjSpec:
    """The template with ``params`` and ``settings`` written in (not compiled).

    ``ratchet`` makes both slides limited (the joint-limit ratchet clutch); the
    engine raises their lower bounds as the modules advance. Only for rigid
    clutches: a compliant ratchet (finite ``clutch_stiffness``) holds its
    modules with its clutch actuators' springs, and its slides stay unlimited.
    A finite grip (``params.grip``) adds a carriage per module between the
    module and the wall (:mod:`.grip_model`); the ratchet then acts on the
    wheels' roll, a tendon, and the slides stay unlimited.
    """
    check_params(params)
    spec = load_spec(mjcf)
    hint = str(mjcf or default_mjcf())
    for write in (_write_mechanism, _write_drive, _write_gravity, _write_clutches):
        write(spec, params, hint)
    _write_solver(spec, settings, hint, ratchet and params.clutch_stiffness is None)
    if params.grip is not None:  # the wheels' finite grip: carriages and tendons (grip_model), rigid or compliant
        write_grip(spec, params, [settings.grip_rows, 1.0], [*settings.solimp, 0.5, 2.0], SLIDES,
                   (REAR_CLUTCH, FRONT_CLUTCH), settings.carriage_share)
    return spec


def _write_mechanism(spec: mujoco.MjSpec, params: RobotParams, hint: str) -> None:
    """Masses, inertias, lengths and resistances."""
    body = lambda name: _element(spec.body, name, hint)  # noqa: E731
    r, L = params.r, params.L
    rear, crank, rod, front = body("rear_module"), body("crank"), body("rod"), body("front_module")
    rear.mass = (1 - CRANK_MASS_SHARE) * params.m1
    crank.mass = CRANK_MASS_SHARE * params.m1
    crank.ipos = [0, 0, 0]
    crank.inertia = [params.J_A / 2, params.J_A / 2, params.J_A]  # a disc: J_A about the axis
    _element(spec.geom, "crank_arm", hint).fromto = [0, 0, 0, r, 0, 0]

    rod.pos = [r, 0, 0]
    rod.mass = params.rod_mass
    rod.ipos = [L / 2, 0, 0]
    i_rod = params.rod_inertia_value
    rod.inertia = [1e-3 * i_rod, i_rod, i_rod]  # slender: tiny about its own axis
    _element(spec.geom, "rod_bar", hint).fromto = [0, 0, 0, L, 0, 0]
    _element(spec.site, ROD_END, hint).pos = [L, 0, 0]

    front.pos = [r + L, 0, 0]  # reference pose (all joints 0): crank points at C, S = r + L
    front.mass = params.m2
    _element(spec.equality, LOOP, hint).data[0:3] = [L, 0, 0]  # C in the rod's frame

    _element(spec.joint, REAR_SLIDE, hint).frictionloss = params.F_r1
    _element(spec.joint, FRONT_SLIDE, hint).frictionloss = params.F_r2


def _write_drive(spec: mujoco.MjSpec, params: RobotParams, hint: str) -> None:
    """The crank actuator: torque = gainprm[0] ctrl + biasprm[0] + biasprm[1] phi + biasprm[2] omega (gear 1).

    MuJoCo's general actuator with fixed gain and affine bias (XML reference,
    actuator/general gaintype and biastype). ``drive='torque'``: gain 1, no bias,
    ctrl = M. ``drive='motor'``: gain M_stall, bias -(M_stall / omega_noload) omega,
    ctrl = 1 (full voltage), so the torque is M_stall (1 - omega / omega_noload) on
    both sides of the no-load speed, computed by MuJoCo itself every step (and
    integrated implicitly in omega by the implicit integrators). ``drive='servo'``: the
    same motor, ctrl = u in [-1, 1] written by the speed controller at its ticks
    (:mod:`.servo_drive`). See :func:`drive_control` for the ctrl value.
    """
    act = _element(spec.actuator, MOTOR, hint)
    act.gear[0] = 1.0
    act.gaintype = mujoco.mjtGain.mjGAIN_FIXED
    act.ctrllimited = mujoco.mjtLimited.mjLIMITED_FALSE
    act.dyntype = mujoco.mjtDyn.mjDYN_NONE
    act.gainprm[:] = 0.0
    act.biasprm[:] = 0.0
    if params.drive in ("motor", "servo"):
        act.gainprm[0] = params.M_stall
        act.biastype = mujoco.mjtBias.mjBIAS_AFFINE
        act.biasprm[2] = -params.M_stall / params.omega_noload
    else:
        act.gainprm[0] = 1.0
        act.biastype = mujoco.mjtBias.mjBIAS_NONE


def drive_torque_slope(model: mujoco.MjModel) -> float:
    """d(torque)/d(omega) [N m s/rad] of the crank actuator that the step integrates implicitly.

    MuJoCo's ``actuator_force`` is the drive's torque at the step's starting speed omega_n; the implicit
    integrators apply the velocity term at the final speed, so the torque applied over the step is
    actuator_force + slope (omega_{n+1} - omega_n) with slope = biasprm[2] (the motor's -M_stall /
    omega_noload; 0 for a constant torque). Euler applies actuator_force itself: slope 0. The
    builder writes gear 1, so the actuator's force is the crank torque. Serial and batched runs both
    count the drive's work with this slope.
    """
    if not implicit_damping(model):
        return 0.0
    return float(model.actuator_biasprm[model.actuator(MOTOR).id, 2])


def drive_control(params: RobotParams) -> float:
    """The ctrl value of the crank actuator: M [N m] for a constant torque, 1 (full voltage) for the motor;
    for the servo 0 until its controller's first tick sets u (:mod:`.servo_drive`)."""
    if params.drive == "servo":
        return 0.0
    return 1.0 if params.drive == "motor" else params.M


def _write_gravity(spec: mujoco.MjSpec, params: RobotParams, hint: str) -> None:
    """Gravity in the robot's frame: x along the pipe axis, the mechanism in the x-y plane.

    The pipe axis rises ``incline`` degrees above the horizontal, so gravity has
    -g sin(incline) along x and -g cos(incline) along z, across the pipe and
    normal to the mechanism's plane: a z force has no component along a slide
    (x) and no moment about a hinge (z), so it only loads bearings (the crank is
    balanced, its centre of mass on the hinge axis).
    """
    angle = math.radians(params.incline)
    spec.option.gravity = [-params.g * math.sin(angle), 0.0, -params.g * math.cos(angle)]


def _write_clutches(spec: mujoco.MjSpec, params: RobotParams, hint: str) -> None:
    """The compliant clutches: per module a spring k [N/m] and damper c [N s/m] from an anchor to the module.

    Each is a general actuator on the module's slide, a position servo with the
    anchor position [m] as its target ``ctrl``: force = k ctrl - k x - c v =
    k (anchor - x) - c v (gainprm[0] = k, biasprm = [0, -k, -c]), clamped by
    its force range to [0, 1e10] N, so it pushes and never pulls. Being an
    actuator force, k is a physical stiffness in N/m whatever the configuration
    (unlike a soft constraint's solref, which scales with the row's effective
    mass). The engine's controller (:class:`.compliant.CompliantClutches`)
    moves the anchor and switches the damper off inside the backlash. With
    rigid clutches (``clutch_stiffness`` None) both stay at zero: no force.
    """
    k = params.clutch_stiffness
    for name in (REAR_CLUTCH, FRONT_CLUTCH):
        act = _element(spec.actuator, name, hint)
        act.gear[0] = 1.0
        act.gaintype = mujoco.mjtGain.mjGAIN_FIXED
        act.biastype = mujoco.mjtBias.mjBIAS_AFFINE
        act.dyntype = mujoco.mjtDyn.mjDYN_NONE
        act.ctrllimited = mujoco.mjtLimited.mjLIMITED_FALSE
        act.forcelimited = mujoco.mjtLimited.mjLIMITED_TRUE
        act.forcerange = [0.0, CLUTCH_FORCE_MAX]
        act.gainprm[:] = 0.0
        act.biasprm[:] = 0.0
        if k is not None:
            act.gainprm[0] = k
            act.biasprm[1] = -k
            act.biasprm[2] = -params.clutch_damping


def compile_spec(spec: mujoco.MjSpec, decorate, what: str) -> mujoco.MjModel:
    """``spec`` compiled, after ``decorate(spec)`` if given (what only drawing needs: a floor texture, a
    route's walls); a compiler error is a one-line ParameterError naming ``what`` was built."""
    if decorate is not None:
        decorate(spec)
    try:
        return spec.compile()
    except ValueError as exc:
        message = " ".join(str(exc).split())
        raise ParameterError(f"the {what} does not compile for these parameters: {message}") from None


def _write_solver(spec: mujoco.MjSpec, settings: SolverSettings, hint: str, ratchet: bool) -> None:
    """Timestep, integrator and the soft-constraint parameters of every constraint row."""
    joint = lambda name: _element(spec.joint, name, hint)  # noqa: E731
    solref, solimp = write_step_options(spec, settings)
    for name in (REAR_SLIDE, FRONT_SLIDE):
        j = joint(name)
        if ratchet:
            j.limited = mujoco.mjtLimited.mjLIMITED_TRUE
            j.range = [-RANGE_FAR, RANGE_FAR]  # the engine sets the lower bound before the first step
        j.solref_limit, j.solimp_limit = solref, solimp
        j.solref_friction, j.solimp_friction = solref, solimp
    for name in (LOOP, REAR_LOCK, FRONT_LOCK):
        eq = _element(spec.equality, name, hint)
        eq.solref, eq.solimp = solref, solimp


def build_model(params: RobotParams, settings: SolverSettings = SolverSettings(),
                mjcf: str | Path | None = None, ratchet: bool = False, decorate=None) -> mujoco.MjModel:
    """Compile the robot for ``params`` (see :func:`build_spec`); ``decorate(spec)``, if given, adds what only
    drawing needs (the viewer's floor texture) before compiling."""
    model = compile_spec(build_spec(params, settings, mjcf, ratchet), decorate, "MuJoCo model")
    if params.grip is not None:
        scale_grip_rows(model, SLIDES)
    return model


def closed_loop_pose(params: RobotParams, phi: float) -> dict[str, float]:
    """Joint positions that close the loop at crank angle ``phi`` with module 1 at 0.

    Plane geometry of the MuJoCo model itself: the rod leaves B = r (cos phi,
    sin phi) and ends at C on the x axis, so its absolute angle is
    beta = asin(-r sin(phi) / L); the rod hinge holds beta - phi, and module 2's
    slide, measured from the reference pose at x = r + L, holds C_x - (r + L).
    """
    r, L = params.r, params.L
    beta = math.asin(-r * math.sin(phi) / L)
    c_x = r * math.cos(phi) + L * math.cos(beta)
    return {REAR_SLIDE: 0.0, CRANK_HINGE: phi, ROD_HINGE: beta - phi, FRONT_SLIDE: c_x - (r + L)}


def qpos_address(model: mujoco.MjModel, joint_name: str) -> int:
    return int(model.jnt_qposadr[model.joint(joint_name).id])


def dof_address(model: mujoco.MjModel, joint_name: str) -> int:
    return int(model.jnt_dofadr[model.joint(joint_name).id])


def set_closed_loop_state(model: mujoco.MjModel, data: mujoco.MjData, params: RobotParams) -> None:
    """Loop-consistent pose and velocities for (phi0, omega0) from rest or motion.

    Velocities: the crank turns at omega0, the rod hinge follows from the
    loop, and the gap rate that motion implies goes to the module the paper's
    clutch rule would free (module 1 if the gap shrinks, module 2 if it grows);
    the gap rate is read from MuJoCo's own kinematics (the rod end's velocity).
    """
    start_closed_loop(model, data, params)
    mujoco.mj_forward(model, data)


def start_closed_loop(model: mujoco.MjModel, data: mujoco.MjData, params: RobotParams) -> tuple[str, float] | None:
    """Reset ``data`` to the loop-consistent pose at phi0 and, with omega0 != 0, the crank, rod and freed
    module's velocities (:func:`set_closed_loop_state`; the slide and the wheeled models share it). Returns
    (the freed module's slide, its speed [m/s]) where omega0 != 0, else None; ``data`` is left before its
    final ``mj_forward``."""
    mujoco.mj_resetData(model, data)
    for name, value in closed_loop_pose(params, params.phi0).items():
        data.qpos[qpos_address(model, name)] = value
    if params.omega0 == 0.0:
        return None
    r, L, phi = params.r, params.L, params.phi0
    beta = math.asin(-r * math.sin(phi) / L)
    beta_rate = -r * math.cos(phi) * params.omega0 / (L * math.cos(beta))
    data.qvel[dof_address(model, CRANK_HINGE)] = params.omega0
    data.qvel[dof_address(model, ROD_HINGE)] = beta_rate - params.omega0
    mujoco.mj_forward(model, data)
    gap_rate = site_velocity_x(model, data, ROD_END)  # module 1 at rest: C's speed is the gap rate
    target = REAR_SLIDE if gap_rate < 0 else FRONT_SLIDE
    # freeing module 1 at -gap_rate carries A forward and leaves C (module 2) at rest
    data.qvel[dof_address(model, target)] = abs(gap_rate)
    return target, abs(gap_rate)


def pin_offset(model: mujoco.MjModel, data: mujoco.MjData | None = None) -> tuple[int, int, np.ndarray]:
    """(rod-end site id, front module body id, module 2's pin relative to that body in the world [m], (3,)).

    The loop gap is |site_xpos[site] - xpos[front] - offset|: the pin is fixed in module 2's frame and that
    body only slides, so its world offset is the same in every state: read from ``data`` (after its
    kinematics), or computed at qpos0.
    """
    if data is None:
        data = mujoco.MjData(model)
        mujoco.mj_kinematics(model, data)
    front = model.body("front_module").id
    offset = data.xmat[front].reshape(3, 3) @ model.eq_data[model.equality(LOOP).id, 3:6]
    return model.site(ROD_END).id, front, offset


def site_velocity_x(model: mujoco.MjModel, data: mujoco.MjData, site: str) -> float:
    """World-frame x velocity of a site [m/s] (needs mj_forward or a step first)."""
    velocity = np.zeros(6)
    mujoco.mj_objectVelocity(model, data, mujoco.mjtObj.mjOBJ_SITE, model.site(site).id, velocity, 0)
    return float(velocity[3])
