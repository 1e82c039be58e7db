"""A test rig for the wheels' side force (docs/model.md, "The wheels' side force"): one ring of the wheeled
model's legs (:func:`.model.add_leg`) rolled along a straight pipe at a fixed slip angle, and what the law says
of it. :mod:`ipir_mujoco.engine.builders.pipe_rig` is the pipe wall's own rig."""

from __future__ import annotations

import math
from dataclasses import dataclass

import mujoco
import numpy as np


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
    """One ring of the wheeled model's legs (:func:`.model.add_leg`: module 1's, its wheels steer-compliant
    or rigid as ``params`` says) on a carriage that a stiff velocity servo drives along a straight pipe on a slide
    (it cannot move across the pipe or turn), its axis turned by ``slip`` [rad] about z off the pipe's axis, so
    that each wheel rolls at a slip angle; gravity off, the model's contact and solver settings, step ``dt``
    [s]. Returns the compiled model: the side-force law's test bed (docs/model.md, "The wheels' side force")."""
    from ipir_mujoco.core.pipe import leg_direction

    from ...builders.model import INTEGRATORS
    from .model import NOSLIP_ITERATIONS, add_leg, leg_count, write_pipe_wall

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
    from .model import leg_count, steer_compliant

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

    from .model import cornering_stiffness, leg_count, steer_compliant

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
