"""What the wheels of a module rolling through a bend push sideways: MuJoCo's contact rows, traced.

Run on demand from the repository root (a minute or a few per case on 2 busy cores):

    python bench/wheels_bend_forces.py [--ratios 5,20,50] [--arc 0.5] [--set NAME=VALUE]... [--free-side]
                                       [--timestep S] [--smoke]

Each case is the wheeled MuJoCo model (the motor, mu_wall 0.8 unless --set gives one) along a 0.45 m straight, a
horizontal bend of R/D from ``--ratios`` whose arc is ``--arc`` metres, and a 0.3 m straight, stepped in Python
with the hub ratchets (:class:`ipir_mujoco.engine.controllers.wheels.WheelRatchet`) at the route's automatic step.
Every 10th step where a module is wholly inside the bend and rolls forward (faster than 0.05 m/s), for each of its
wheels in contact (``mj_contactForce`` and the contact rows' slip speeds, ``mj_mulJacVec``): its side force, the
tangential force along its axle (the wheel's sideways direction: it rolls perpendicular to it), over mu_wall
times its normal force (1: the wheel slides sideways at the friction limit); its sideways slip speed over the
module's speed; and its slip angle, atan(sideways slip / rolling speed). The closed form of a rigid module
tangent to the bend at its middle, rings b = ring_spacing / 2 either side: each ring's slip angle b / R. Beside
them each module's yaw off the centreline's direction at its point, and how long some wheel pressed with less
than a tenth of its preload (off its wall) while either module's point was in the bend.

``--free-side`` is a test edit: each wheel gets a frictionless slide along its axle (+-20 mm, a centring spring of
1 % of its preload per 5 mm), so that the wall's friction can hold it only along its rolling direction; the
module is then held across the pipe by its legs' springs alone. ``--smoke``: one case, 0.02 s.
"""

from __future__ import annotations

import argparse
import math
import sys

import mujoco
import numpy as np

from ipir_mujoco.core.params import RobotParams, parse_overrides
from ipir_mujoco.core.route import route_from_tables
from ipir_mujoco.engine.builders.model import MOTOR, SolverSettings, drive_control
from ipir_mujoco.engine.builders.wheels_model import (build_wheels_model, leg_names, leg_preload, set_wheels_state,
                                                      wheels_timestep)
from ipir_mujoco.engine.controllers.wheels import WheelRatchet

LEAD, EXIT = 0.45, 0.3  # m: the straights before and after the bend
EVERY = 10  # steps between samples
ROLLING = 0.05  # m/s: a module rolls forward faster than this
OFF = 0.1  # share of the preload below which a wheel is off its wall
FREE_RANGE = 0.02  # m: --free-side's slide range either way


def free_side(params: RobotParams):
    """The --free-side test edit, ``decorate(spec)``: a frictionless slide along each wheel's axle."""
    def decorate(spec: mujoco.MjSpec) -> None:
        for i, module in enumerate(leg_names(params)):
            k = 0.01 * leg_preload(params, i) / 0.005
            for prefix in module:
                wheel = spec.body(prefix + "_wheel")
                hub = spec.joint(prefix + "_hub")
                slide = wheel.add_joint(name=prefix + "_side", type=mujoco.mjtJoint.mjJNT_SLIDE,
                                        axis=list(hub.axis))
                slide.stiffness = [k, 0.0, 0.0]
                slide.limited = mujoco.mjtLimited.mjLIMITED_TRUE
                slide.range = [-FREE_RANGE, FREE_RANGE]  # along the hub's axis: its rotation leaves it in place
    return decorate


def run_case(params: RobotParams, ratio: float, arc: float, t_end: float, timestep: float | None, free: bool):
    radius = ratio * params.pipe_diameter
    angle = math.degrees(arc / radius)
    route = route_from_tables([dict(kind="straight", length=LEAD),
                               dict(kind="bend", radius=radius, angle=angle, plane=0.0),
                               dict(kind="straight", length=EXIT)], "bend")
    dt = timestep or wheels_timestep(bends=True)
    decorate = free_side(params) if free else None
    model = build_wheels_model(params, SolverSettings(timestep=dt), route=route, decorate=decorate)
    data = mujoco.MjData(model)
    set_wheels_state(model, data, params)
    data.ctrl[model.actuator(MOTOR).id] = drive_control(params)
    mujoco.mj_forward(model, data)
    ratchet = WheelRatchet(model, data, params)
    legs = leg_names(params)
    wheel_geom = [[model.geom(p + "_wheel").id for p in module] for module in legs]
    wheel_body = [[model.body(p + "_wheel").id for p in module] for module in legs]
    hub_axis = [[np.array(model.jnt_axis[model.joint(p + "_hub").id]) for p in module] for module in legs]
    arms = [[model.joint(p + "_arm").qposadr[0] for p in module] for module in legs]
    free_len = float(params.suspension_travel)
    modules = [model.body(n).id for n in ("rear_module", "front_module")]
    bend = route.pieces[1]
    b = 0.5 * params.ring_spacing
    force = np.zeros(6)
    stats = {i: {"use": [], "slip": [], "angle": [], "yaw": [], "side_n": []} for i in (0, 1)}
    off_time, s_prev = 0.0, [0.0, 0.0]
    steps = int(round(t_end / dt))
    for step in range(steps):
        ratchet.before_step()
        mujoco.mj_step(model, data)
        if step % EVERY:
            continue
        in_bend = any(bend.s0 < route.along(data.xpos[modules[i]], s_prev[i]) < bend.s0 + bend.length for i in (0, 1))
        if in_bend and any(data.qpos[a] > (1 - OFF) * free_len for module in arms for a in module):
            off_time += EVERY * dt
        jv = np.zeros(data.nefc)
        mujoco.mj_mulJacVec(model, data, jv, data.qvel)
        by_geom = {}
        for c in range(data.ncon):
            con = data.contact[c]
            by_geom[con.geom1] = c
            by_geom[con.geom2] = c
        for i in (0, 1):
            p = data.xpos[modules[i]]
            s = route.along(p, s_prev[i])
            s_prev[i] = s
            axis = data.xmat[modules[i]].reshape(3, 3)[:, 0]
            _, direction = route.at3(s)
            inside = bend.s0 + b + 0.02 < s < bend.s0 + bend.length - b - 0.02
            speed = float(data.qvel[model.joint(("rear_slide", "front_slide")[i]).dofadr[0]])
            if not inside or speed < ROLLING:
                continue
            stats[i]["yaw"].append(math.degrees(math.acos(min(1.0, abs(float(axis @ direction))))))
            for k, g in enumerate(wheel_geom[i]):
                c = by_geom.get(g)
                if c is None:
                    continue
                con = data.contact[c]
                mujoco.mj_contactForce(model, data, c, force)
                if force[0] <= 0:
                    continue
                frame = con.frame.reshape(3, 3)
                a = data.xmat[wheel_body[i][k]].reshape(3, 3) @ hub_axis[i][k]
                n = frame[0]
                lateral = a - (a @ n) * n
                lateral /= np.linalg.norm(lateral)
                heading = np.cross(lateral, n)
                tangential = force[1] * frame[1] + force[2] * frame[2]
                adr = con.efc_address
                slip = jv[adr + 1] * frame[1] + jv[adr + 2] * frame[2]
                side = float(tangential @ lateral)
                stats[i]["use"].append(abs(side) / (params.mu_wall * force[0]))
                stats[i]["side_n"].append(abs(side))
                stats[i]["slip"].append(abs(float(slip @ lateral)) / speed)
                stats[i]["angle"].append(math.degrees(math.atan2(abs(float(slip @ lateral)),
                                                                 abs(float(slip @ heading)) + speed)))
    return route, stats, off_time, dt


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--ratios", default="5,20,50")
    parser.add_argument("--arc", type=float, default=0.5, help="the bend's arc length [m]")
    parser.add_argument("--t-end", type=float, default=None, help="default: long enough for the route at 0.3 m/s")
    parser.add_argument("--set", action="append", default=[], metavar="NAME=VALUE")
    parser.add_argument("--timestep", type=float, default=None)
    parser.add_argument("--free-side", action="store_true")
    parser.add_argument("--smoke", action="store_true")
    args = parser.parse_args(argv)
    params = RobotParams(**{"drive": "motor", "mu_wall": 0.8, **parse_overrides(args.set)})
    ratios = [float(r) for r in args.ratios.split(",")]
    t_end = args.t_end or (LEAD + args.arc + 0.1) / 0.3
    if args.smoke:
        ratios, t_end = ratios[:1], 0.02
    b = 0.5 * params.ring_spacing
    print(f"mu_wall {params.mu_wall:g}, F_n {params.F_n1:g}/{params.F_n2:g} N, arc {args.arc:g} m"
          f"{', free sideways (test edit)' if args.free_side else ''} ({', '.join(args.set) or 'defaults'})")
    for ratio in ratios:
        route, stats, off, dt = run_case(params, ratio, args.arc, t_end, args.timestep, args.free_side)
        R = ratio * params.pipe_diameter
        print(f"R/D {ratio:g} (R {R:g} m, step {dt:g} s, {t_end:.2f} s): closed-form ring slip angle b/R = "
              f"{math.degrees(b / R):.3f} deg; some wheel off its wall {off:.3f} s in the bend")
        for i in (0, 1):
            st = stats[i]
            if not st["use"]:
                print(f"  module {i + 1}: no sample rolling inside the bend")
                continue
            use, slip, ang, yaw, side = (np.array(st[k]) for k in ("use", "slip", "angle", "yaw", "side_n"))
            print(f"  module {i + 1}: {len(yaw)} samples; side force / (mu_wall N) median {np.median(use):.3f}, "
                  f"mean {use.mean():.3f}; side force mean {side.mean():.2f} N (mu_wall P "
                  f"{params.mu_wall * (params.F_n1, params.F_n2)[i] / (2 * params.wheel_legs):.2f} N); "
                  f"sideways slip / speed median {np.median(slip):.4f} (b/R {b / R:.4f}); slip angle median "
                  f"{np.median(ang):.3f} deg; yaw off the centreline mean {yaw.mean():.2f} deg, most {yaw.max():.2f}",
                  flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
