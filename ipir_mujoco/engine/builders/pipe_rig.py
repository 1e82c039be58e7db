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
