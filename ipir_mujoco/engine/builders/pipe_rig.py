"""A test rig for the round pipe's wall (:mod:`.pipe_walls`): sprung wheels carried along the centreline.

A carriage (a mocap body: moved kinematically, each step, to the centreline point ``s`` = speed * t with the
pipe's frame) carries LEGS wheels evenly spaced about the pipe's axis (the first straight up), each a sphere of
WHEEL_RADIUS on a radial slide pressed outward by a linear spring: stiffness ``preload / travel``, its free
length ``travel`` beyond the wall, so a wheel on a round wall presses with ``preload``. The contacts are
frictionless (condim 1): the carriage's kinematic motion is no velocity in MuJoCo's dynamics, so a rolling
wheel's friction would brake it; the normal force is what the wall's construction shapes. :func:`roll` returns
each wheel's normal force per step: a perfectly round wall keeps it at the preload, but for the wheel's own
inertia in a bend (m v^2 / R along the bend's radius, which changes the press of a wheel that rides on the
bend's outer or inner wall), and the contact's settling.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass

import mujoco
import numpy as np

from .pipe_walls import PIPE_BIT, WallContact, add_pipe_walls

WHEEL_RADIUS = 0.015  # m
WHEEL_MASS = 0.02  # kg


@dataclass
class RigRun:
    """A rig's run: ``s`` [m] (n,) the carriage's centreline position per step, ``force`` [N] (n, legs) each
    wheel's normal force, ``us_per_step`` [us] the mean mj_step cost, ``contacts`` the most contacts per wheel."""

    s: np.ndarray
    force: np.ndarray
    us_per_step: float
    contacts: int


def build_rig(route, diameter: float = 0.16, legs: int = 3, preload: float = 10.0, travel: float = 0.003,
              solref: tuple[float, float] = (1e-3, 1.0), dt: float = 1e-4, wall: str = "pipe") -> mujoco.MjModel:
    """The rig (module docstring) in the pipe of ``route`` (None: straight), or with ``wall='plane'``: each
    wheel against a plane tangent to the round wall at its track in a straight pipe (the reference)."""
    spec = mujoco.MjSpec()
    spec.option.timestep = dt
    spec.option.gravity = [0.0, 0.0, 0.0]
    contact = WallContact(friction=0.0, solref=solref, condim=1)
    a = diameter / 2
    carriage = spec.worldbody.add_body(name="carriage", mocap=True)
    for k in range(legs):
        phi = math.pi / 2 + 2 * math.pi * k / legs
        e = [0.0, math.cos(phi), math.sin(phi)]  # the leg's direction in the carriage (x along the pipe)
        if wall == "plane":
            normal = [-v for v in e]
            spec.worldbody.add_geom(name=f"plane{k}", type=mujoco.mjtGeom.mjGEOM_PLANE, size=[0, 0, 1],
                                    pos=[a * v for v in e], zaxis=normal, contype=0, conaffinity=PIPE_BIT,
                                    priority=1, condim=1, solref=list(solref), solimp=list(contact.solimp))
        arm = carriage.add_body(name=f"arm{k}")
        arm.add_joint(name=f"slide{k}", type=mujoco.mjtJoint.mjJNT_SLIDE, axis=e, stiffness=[preload / travel, 0, 0],
                      springref=travel, damping=0.0)
        arm.add_geom(type=mujoco.mjtGeom.mjGEOM_SPHERE, name=f"wheel{k}", size=[WHEEL_RADIUS, 0, 0],
                     pos=[(a - WHEEL_RADIUS) * v for v in e], mass=WHEEL_MASS, contype=PIPE_BIT, conaffinity=0)
    if wall == "pipe":
        add_pipe_walls(spec, route, diameter, contact, robot_length=0.1, draw=False)
    return spec.compile()


def roll(model: mujoco.MjModel, route, speed: float, distance: float, settle: float = 0.05) -> RigRun:
    """Carry the rig at ``speed`` [m/s] from s = 0 over ``distance`` [m] after ``settle`` [s] at rest (the
    springs and contacts settle); returns every step's forces after the settling."""
    data = mujoco.MjData(model)
    dt = model.opt.timestep
    legs = sum(1 for j in range(model.njnt) if model.joint(j).name.startswith("slide"))
    wheels = [model.geom(f"wheel{k}").id for k in range(legs)]
    n_settle, n_run = int(round(settle / dt)), int(round(distance / speed / dt))
    force = np.zeros((n_run, legs))
    s_out = np.zeros(n_run)
    most, wrench, elapsed = 0, np.zeros(6), 0.0
    for i in range(n_settle + n_run):
        s = 0.0 if i < n_settle else speed * (i - n_settle) * dt
        if route is None:
            p, frame = np.array([s, 0.0, 0.0]), np.eye(3)
        else:
            p, _ = route.at3(s)
            frame = route.frame_at(s)
        data.mocap_pos[0] = p
        mujoco.mju_mat2Quat(data.mocap_quat[0], np.column_stack(frame).ravel())
        start = time.perf_counter()
        mujoco.mj_step(model, data)
        elapsed += time.perf_counter() - start if i >= n_settle else 0.0
        if i < n_settle:
            continue
        row = i - n_settle
        s_out[row] = s
        per = [0] * legs
        for c in range(data.ncon):
            g = data.contact.geom[c]
            for k, w in enumerate(wheels):
                if w in g:
                    mujoco.mj_contactForce(model, data, c, wrench)
                    force[row, k] += wrench[0]
                    per[k] += 1
        most = max(most, max(per))
    return RigRun(s_out, force, 1e6 * elapsed / max(n_run, 1), most)


def rolling_rig(diameter: float = 0.16, legs: int = 3, preload: float = 10.0, travel: float = 0.003,
                solref: tuple[float, float] = (1e-3, 1.0), dt: float = 1e-4, bend_radius: float | None = None,
                friction: float = 0.5, speed: float = 0.5) -> mujoco.MjModel:
    """The rig on joints, its wheels rolling: the carriage on a slide along the straight pipe's axis (or, with
    ``bend_radius`` [m], on a hinge about a half turn's axis, its centre on the bend's centreline), driven at
    ``speed`` [m/s] by a stiff velocity servo; each wheel on a hub hinge (its axis across its leg and the pipe)
    rolling on the wall with ``friction``; gravity off. The wheels' normal forces then carry what rolling adds to
    the wall's construction: the contacts' tangential forces and the wheels' spin."""
    spec = mujoco.MjSpec()
    spec.option.timestep = dt
    spec.option.gravity = [0.0, 0.0, 0.0]
    spec.option.cone = mujoco.mjtCone.mjCONE_ELLIPTIC
    spec.option.noslip_iterations = 10
    a = diameter / 2
    contact = WallContact(friction=friction, solref=solref, condim=3)
    if bend_radius is None:
        route = None
        carriage = spec.worldbody.add_body(name="carriage")
        carriage.add_joint(name="drive", type=mujoco.mjtJoint.mjJNT_SLIDE, axis=[1, 0, 0])
        gear = 1.0
    else:
        from ipir_mujoco.core.route import route_from_tables

        route = route_from_tables([dict(kind="straight", length=0.5), dict(kind="bend", radius=bend_radius,
                                                                        angle=180.0)])
        pivot = spec.worldbody.add_body(name="pivot", pos=[0.5, bend_radius, 0.0])
        pivot.add_joint(name="drive", type=mujoco.mjtJoint.mjJNT_HINGE, axis=[0, 0, 1])
        carriage = pivot.add_body(name="carriage", pos=[0.0, -bend_radius, 0.0])
        gear = bend_radius  # the hinge's rate times R: the carriage's speed along the centreline
    carriage.add_geom(type=mujoco.mjtGeom.mjGEOM_SPHERE, size=[0.01, 0, 0], mass=1.0, contype=0, conaffinity=0)
    for k in range(legs):
        phi = math.pi / 2 + 2 * math.pi * k / legs
        e = np.array([0.0, math.cos(phi), math.sin(phi)])
        arm = carriage.add_body(name=f"arm{k}")
        arm.add_joint(name=f"slide{k}", type=mujoco.mjtJoint.mjJNT_SLIDE, axis=e.tolist(),
                      stiffness=[preload / travel, 0, 0], springref=travel)
        arm.add_geom(type=mujoco.mjtGeom.mjGEOM_SPHERE, size=[0.002, 0, 0], mass=1e-3, contype=0, conaffinity=0)
        wheel = arm.add_body(name=f"hub{k}", pos=((a - WHEEL_RADIUS) * e).tolist())
        wheel.add_joint(name=f"hub{k}", type=mujoco.mjtJoint.mjJNT_HINGE, axis=np.cross([1.0, 0, 0], e).tolist())
        wheel.add_geom(type=mujoco.mjtGeom.mjGEOM_SPHERE, name=f"wheel{k}", size=[WHEEL_RADIUS, 0, 0],
                       mass=WHEEL_MASS, contype=PIPE_BIT, conaffinity=0)
    spec.add_actuator(name="drive", target="drive", trntype=mujoco.mjtTrn.mjTRN_JOINT,
                      gainprm=[200.0 * gear] + [0.0] * 9, biasprm=[0.0, 0.0, -200.0 * gear] + [0.0] * 7,
                      biastype=mujoco.mjtBias.mjBIAS_AFFINE, gaintype=mujoco.mjtGain.mjGAIN_FIXED)
    add_pipe_walls(spec, route, diameter, contact, robot_length=0.1, draw=False)
    model = spec.compile()
    model.actuator_ctrlrange[0] = [-1e3, 1e3]
    return model


def roll_on_joints(model: mujoco.MjModel, speed: float, duration: float, settle: float = 0.3) -> RigRun:
    """Drive :func:`rolling_rig` at ``speed`` [m/s] along the centreline for ``settle`` [s] (the wheels spin
    up), then record every step's normal forces over ``duration`` [s]; ``s`` is the centreline position."""
    data = mujoco.MjData(model)
    dt = model.opt.timestep
    legs = sum(1 for j in range(model.njnt) if model.joint(j).name.startswith("slide"))
    wheels = [model.geom(f"wheel{k}").id for k in range(legs)]
    drive = model.joint("drive")
    radius = 1.0 if drive.type[0] == mujoco.mjtJoint.mjJNT_SLIDE else float(-model.body("carriage").pos[1])
    data.ctrl[0] = speed / radius
    n_settle, n_run = int(round(settle / dt)), int(round(duration / dt))
    force, s_out, wrench, most, elapsed = np.zeros((n_run, legs)), np.zeros(n_run), np.zeros(6), 0, 0.0
    for i in range(n_settle + n_run):
        start = time.perf_counter()
        mujoco.mj_step(model, data)
        if i < n_settle:
            continue
        elapsed += time.perf_counter() - start
        row = i - n_settle
        s_out[row] = float(data.qpos[drive.qposadr[0]]) * radius
        per = [0] * legs
        for c in range(data.ncon):
            for k, w in enumerate(wheels):
                if w in data.contact.geom[c]:
                    mujoco.mj_contactForce(model, data, c, wrench)
                    force[row, k] += wrench[0]
                    per[k] += 1
        most = max(most, max(per))
    return RigRun(s_out, force, 1e6 * elapsed / max(n_run, 1), most)


def ripple(run: RigRun) -> float:
    """The largest wheel's normal-force ripple: its standard deviation over its mean, over the run."""
    return float(max(np.std(run.force[:, k]) / np.mean(run.force[:, k]) for k in range(run.force.shape[1])))


@dataclass
class CorneringRun:
    """A cornering rig's steady roll (:func:`corner`), means over its last ``window`` [s]: per wheel (n,) its
    slip angle ``slip`` [rad] (the carriage's path off the wheel's rolling direction, in the wall's tangent
    plane), ``side`` [N] the wall's force on it across its rolling direction (along its steered axle),
    ``normal`` [N], ``steer`` [rad] its steer hinge's angle, and ``sideways`` [m/s] its contact's slip speed
    across its rolling direction; ``drive`` [N] the force that keeps the carriage at its speed along the pipe."""

    slip: np.ndarray
    side: np.ndarray
    normal: np.ndarray
    steer: np.ndarray
    sideways: np.ndarray
    drive: float


def cornering_rig(params, slip: float, dt: float = 5e-5):
    """One ring of the wheeled model's legs (:func:`.wheels_model.add_leg`: module 1's, its wheels steer-compliant
    or rigid as ``params`` says) on a carriage that a stiff velocity servo drives along a straight pipe on a slide
    (it cannot move across the pipe or turn), its axis turned by ``slip`` [rad] about z off the pipe's axis, so
    that each wheel rolls at a slip angle; gravity off, the model's contact and solver settings, step ``dt``
    [s]. Returns the compiled model: the side-force law's test bed (docs/model.md, "The wheels' side force")."""
    from ipir_mujoco.core.pipe import leg_direction

    from .model import INTEGRATORS
    from .wheels_model import NOSLIP_ITERATIONS, add_leg, leg_count, write_pipe_wall

    spec = mujoco.MjSpec()
    spec.compiler.degree = False  # the steer's stops in radians, as the model's template has them
    spec.option.timestep = dt
    spec.option.integrator = INTEGRATORS["implicitfast"]
    spec.option.cone = mujoco.mjtCone.mjCONE_ELLIPTIC
    spec.option.impratio = 1.0
    spec.option.noslip_iterations = NOSLIP_ITERATIONS
    spec.option.tolerance, spec.option.iterations = 1e-12, 100
    spec.option.gravity = [0.0, 0.0, 0.0]
    carriage = spec.worldbody.add_body(name="carriage", quat=[math.cos(slip / 2), 0.0, 0.0, math.sin(slip / 2)])
    carriage.add_joint(name="drive", type=mujoco.mjtJoint.mjJNT_SLIDE,
                       axis=[math.cos(slip), -math.sin(slip), 0.0])  # the pipe's axis, in the carriage's frame
    carriage.add_geom(type=mujoco.mjtGeom.mjGEOM_SPHERE, size=[0.01, 0, 0], mass=1.0, contype=0, conaffinity=0)
    n = leg_count(params)
    for k in range(n):
        add_leg(carriage, f"leg{k}", np.array(leg_direction(k, n)), 0.0, params, 0)
    spec.add_actuator(name="drive", target="drive", trntype=mujoco.mjtTrn.mjTRN_JOINT,
                      gainprm=[1e4] + [0.0] * 9, biasprm=[0.0, 0.0, -1e4] + [0.0] * 7,
                      biastype=mujoco.mjtBias.mjBIAS_AFFINE, gaintype=mujoco.mjtGain.mjGAIN_FIXED)
    write_pipe_wall(spec, params)
    model = spec.compile()
    model.actuator_ctrlrange[0] = [-1e3, 1e3]
    return model


def corner(model, params, speed: float = 0.3, duration: float = 0.4, window: float = 0.1) -> CorneringRun:
    """Drive :func:`cornering_rig` at ``speed`` [m/s] from rest for ``duration`` [s]; the means over its last
    ``window`` [s] (:class:`CorneringRun`)."""
    from .wheels_model import leg_count, steer_compliant

    data = mujoco.MjData(model)
    n, dt = leg_count(params), model.opt.timestep
    wheels = [model.geom(f"leg{k}_wheel").id for k in range(n)]
    bodies = [model.body(f"leg{k}_wheel").id for k in range(n)]
    hubs = [model.joint(f"leg{k}_hub").id for k in range(n)]
    steers = [model.joint(f"leg{k}_steer").qposadr[0] if steer_compliant(params) else None for k in range(n)]
    data.ctrl[0] = speed
    steps, last = int(round(duration / dt)), int(round(window / dt))
    sums = np.zeros((5, n))
    drive, wrench = 0.0, np.zeros(6)
    for i in range(steps):
        mujoco.mj_step(model, data)
        if i < steps - last:
            continue
        jv = np.zeros(data.nefc)
        mujoco.mj_mulJacVec(model, data, jv, data.qvel)
        drive += float(data.actuator_force[0])
        for c in range(data.ncon):
            g = data.contact.geom[c]
            for k, w in enumerate(wheels):
                if w not in g:
                    continue
                con = data.contact[c]
                mujoco.mj_contactForce(model, data, c, wrench)
                frame = con.frame.reshape(3, 3)
                normal = frame[0] * (1.0 if con.geom2 == w else -1.0)  # into the wheel: the wall's push on it
                axle = data.xaxis[hubs[k]] - (data.xaxis[hubs[k]] @ normal) * normal
                axle /= np.linalg.norm(axle)
                sign = 1.0 if con.geom2 == w else -1.0
                tangential = sign * (wrench[1] * frame[1] + wrench[2] * frame[2])
                a = con.efc_address
                slip_velocity = sign * (jv[a + 1] * frame[1] + jv[a + 2] * frame[2])
                across = np.cross(normal, [1.0, 0.0, 0.0])  # round the pipe, unit in a straight pipe
                path = np.array([speed, 0.0, 0.0])
                heading = np.cross(data.xmat[bodies[k]].reshape(3, 3) @ model.jnt_axis[hubs[k]], normal)
                sums[0, k] += math.atan2(float(heading @ across), float(heading @ path) / speed)
                sums[1, k] += float(tangential @ axle)
                sums[2, k] += wrench[0]
                sums[3, k] += 0.0 if steers[k] is None else float(data.qpos[steers[k]])
                sums[4, k] += float(slip_velocity @ axle)
    mean = sums / last
    return CorneringRun(*mean, drive / last)


def cornering_law(params, slip: float, normal) -> tuple[list[float], list[float], float]:
    """What the side-force law (docs/model.md, "The wheels' side force") says of :func:`cornering_rig` at ``slip``
    [rad], its wheels pressing with ``normal`` [N] (n,): per wheel its slip angle alpha_k = atan(tan(slip) e_k . y)
    [rad] and its side force min(C |alpha_k|, mu_wall N_k) [N], and the carriage's drive [N]: each wheel's rolling
    resistance along its path, and for a wheel that slides mu_wall N_k sin(|alpha_k| - mu_wall N_k / C) (its
    scrub's power over the speed; rigid wheels: C infinite)."""
    from ipir_mujoco.core.pipe import hub_tangent, leg_direction

    from .wheels_model import cornering_stiffness, leg_count, steer_compliant

    n = leg_count(params)
    mu, C = params.mu_wall, cornering_stiffness(params, 0) if steer_compliant(params) else math.inf
    roll = params.F_r1 / (2 * n)  # each hub's rolling resistance at the wall [N]
    angles, forces, drive = [], [], 0.0
    for k in range(n):
        along_y = hub_tangent(leg_direction(k, n))[0]
        alpha = math.atan(math.tan(slip) * along_y)
        grip = mu * float(normal[k])
        sliding = C * abs(alpha) > grip
        angles.append(alpha)
        forces.append(grip if sliding else C * abs(alpha))
        beyond = abs(alpha) - (grip / C if math.isfinite(C) else 0.0)
        drive += roll * math.cos(beyond) + grip * math.sin(beyond) if sliding else roll
    return angles, forces, drive
