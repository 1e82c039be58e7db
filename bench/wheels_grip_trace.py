"""What a wheeled module's wheels hold while it skids back: one design of the agreement benchmark, traced.

Run on demand from the repository root (about a minute per simulated second on 2 busy cores):

    python bench/wheels_grip_trace.py --design 28 [--seed 1] [--module 1] [--work] [--smoke]

Draws the design as ``bench/wheels_agreement.py`` does (same seed and order), runs the wheeled MuJoCo model at its
automatic straight-pipe step with the hub ratchets, and at every 20th step where the module moves backward
(faster than 1 mm/s) sums over its wheels' contacts (``mj_contactForce``): the normal forces N, the friction
along the pipe (world x: the module's axis in a level straight pipe) and across it, against mu_wall N. Prints
the range of N over those samples and the means: what the wheels held along the pipe while the module skidded,
next to mu_wall F_n, the analytic model's grip. The numbers in mjcf/README.md on design 28 are this script's.

``--work``: where the wheels' contacts take the energy instead, every step: the work of each module's wheel
contacts' tangential forces on their slip (the sum the engine books as ``skid_work``), split into its part along
the pipe (x) and across it, while the module moves forward, is held (within 1 mm/s) or moves back. The numbers in
mjcf/README.md on design 99 are this script's.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import mujoco
import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import wheels_agreement  # noqa: E402  (the benchmark's design draw)

from ipir_mujoco.engine.builders.model import MOTOR, SolverSettings, drive_control  # noqa: E402
from ipir_mujoco.engine.builders.wheels_model import build_wheels_model, leg_names, set_wheels_state  # noqa: E402
from ipir_mujoco.engine.builders.wheels_model import wheels_timestep  # noqa: E402
from ipir_mujoco.engine.controllers.wheels import WheelRatchet  # noqa: E402

SLIDES = ("rear_slide", "front_slide")


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--design", type=int, required=True)
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--module", type=int, choices=(1, 2), default=1)
    parser.add_argument("--work", action="store_true", help="the contacts' work along and across the pipe, both modules")
    parser.add_argument("--smoke", action="store_true", help="0.02 s: the script runs")
    args = parser.parse_args(argv)
    rng = np.random.default_rng(args.seed)
    for _ in range(args.design + 1):
        params, t_end = wheels_agreement.design(rng)
    t_end = 0.02 if args.smoke else t_end
    i = args.module - 1
    dt = wheels_timestep()
    model = build_wheels_model(params, SolverSettings(timestep=dt))
    data = mujoco.MjData(model)
    set_wheels_state(model, data, params)
    data.ctrl[model.actuator(MOTOR).id] = drive_control(params)
    mujoco.mj_forward(model, data)
    ratchet = WheelRatchet(model, data, params)
    wheels = {model.geom(n + "_wheel").id for n in leg_names(params)[i]}
    dof = model.joint(SLIDES[i]).dofadr[0]
    if args.work:
        return contact_work(model, data, params, ratchet, t_end, dt, args.design)
    force, rows = np.zeros(6), []
    for step in range(int(round(t_end / dt))):
        ratchet.before_step()
        mujoco.mj_step(model, data)
        if step % 20 or data.qvel[dof] > -1e-3:
            continue
        normal = along = across = 0.0
        for c in range(data.ncon):
            contact = data.contact[c]
            if contact.geom1 not in wheels and contact.geom2 not in wheels:
                continue
            mujoco.mj_contactForce(model, data, c, force)
            frame = contact.frame.reshape(3, 3)
            tangential = frame.T @ force[:3] - force[0] * frame[0]
            normal += force[0]
            along += tangential[0]
            across += float(np.hypot(tangential[1], tangential[2]))
        rows.append((normal, along, across))
    F_n = (params.F_n1, params.F_n2)[i]
    print(f"design {args.design}: module {args.module} {(params.m1, params.m2)[i]:.2f} kg, F_n {F_n:.1f} N, mu_wall "
          f"{params.mu_wall:.3f}: grip mu_wall F_n {params.mu_wall * F_n:.2f} N; step {dt:g} s, {t_end:.2f} s")
    if not rows:
        print("  the module never moved backward")
        return 0
    N, along, across = (np.array(c) for c in zip(*rows))
    print(f"  {len(rows)} samples skidding back: wheels' normal forces {N.min():.1f}-{N.max():.1f} N (mean "
          f"{N.mean():.1f}); friction along the pipe mean {abs(along.mean()):.2f} N (mu_wall N: {params.mu_wall * N.mean():.2f}"
          f" N), across it {across.min():.1f}-{across.max():.1f} N (mean {across.mean():.2f})")
    return 0


def contact_work(model, data, params, ratchet, t_end: float, dt: float, design: int) -> int:
    """The ``--work`` mode (module docstring): steps the run and prints the contacts' work per module, motion and
    direction [J] (negative: taken from the robot)."""
    module_of = {model.geom(n + "_wheel").id: i for i in (0, 1) for n in leg_names(params)[i]}
    dofs = [model.joint(name).dofadr[0] for name in SLIDES]
    work = np.zeros((2, 3, 2))  # module, motion (forward, held, back), (along, across)
    for _ in range(int(round(t_end / dt))):
        ratchet.before_step()
        mujoco.mj_step(model, data)
        jv = np.zeros(data.nefc)
        mujoco.mj_mulJacVec(model, data, jv, data.qvel)  # the rows' speeds after the step, as the engine's sum
        for c in range(data.ncon):
            contact = data.contact[c]
            i = module_of.get(contact.geom1, module_of.get(contact.geom2))
            if i is None:
                continue
            v = data.qvel[dofs[i]]
            motion = 0 if v > 1e-3 else (2 if v < -1e-3 else 1)
            a, frame = contact.efc_address, contact.frame.reshape(3, 3)
            tangential = data.efc_force[a + 1] * frame[1] + data.efc_force[a + 2] * frame[2]
            slip = jv[a + 1] * frame[1] + jv[a + 2] * frame[2]
            work[i, motion] += dt * np.array([tangential[0] * slip[0], tangential[1:] @ slip[1:]])
    print(f"design {design}: the wheel contacts' work on their slip [J] over {t_end:.2f} s, step {dt:g} s "
          f"(total {work.sum():+.4f})")
    for i in (0, 1):
        for m, motion in enumerate(("forward", "held", "back")):
            print(f"  module {i + 1} {motion:8s} along the pipe {work[i, m, 0]:+.4f}  across it {work[i, m, 1]:+.4f}")
    print(f"  across the pipe in all {work[:, :, 1].sum():+.4f}, along it {work[:, :, 0].sum():+.4f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
