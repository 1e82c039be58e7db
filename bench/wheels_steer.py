"""How the steer-compliant wheels' steer hinges move in the default cruise, and what a damper on them would take.

Run on demand from the repository root (a minute on 2 busy cores):

    python bench/wheels_steer.py [--t-end 3] [--set NAME=VALUE]... [--smoke]

The wheeled MuJoCo model (the motor, mu_wall 0.5 unless --set gives one) in a straight pipe at the default step,
stepped in Python with the hub ratchets. Prints each module's steer angles' range and rms rate, the three strongest
frequencies of module 1's leg-0 steer rate (from 0.5 s on), the steer's free frequency sqrt(k_s / I) (its spring
over the wheel's inertia about its steer axis), and what critical damping of that free swing, c = 2 sqrt(k_s I),
would dissipate over the run, c delta_dot^2 summed, against the motor's work (the rates of this undamped run: an
estimate of the energy a damper would take that the energy audit does not book).
"""

from __future__ import annotations

import argparse
import math
import sys

import mujoco
import numpy as np

from ipir_mujoco.core.params import RobotParams, parse_overrides
from ipir_mujoco.engine.builders.model import CRANK_HINGE, MOTOR, SolverSettings, drive_control
from ipir_mujoco.engine.builders.wheels_model import (build_wheels_model, leg_names, set_wheels_state, trail,
                                                      wheel_inertias, wheel_mass, wheels_timestep)
from ipir_mujoco.engine.controllers.wheels import WheelRatchet


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--t-end", type=float, default=3.0)
    parser.add_argument("--set", action="append", default=[], metavar="NAME=VALUE")
    parser.add_argument("--smoke", action="store_true", help="0.05 s: the script runs")
    args = parser.parse_args(argv)
    p = RobotParams(**{"drive": "motor", "mu_wall": 0.5, **parse_overrides(args.set)})
    t_end = 0.05 if args.smoke else args.t_end
    dt = wheels_timestep()
    model = build_wheels_model(p, SolverSettings(timestep=dt))
    data = mujoco.MjData(model)
    set_wheels_state(model, data, p)
    data.ctrl[model.actuator(MOTOR).id] = drive_control(p)
    mujoco.mj_forward(model, data)
    ratchet = WheelRatchet(model, data, p)
    names = [n for module in leg_names(p) for n in module]
    dofs = np.array([model.joint(n + "_steer").dofadr[0] for n in names])
    adrs = np.array([model.joint(n + "_steer").qposadr[0] for n in names])
    per = len(names) // 2
    inertia = np.array([wheel_inertias(p, k // per)[1] + wheel_mass(p, k // per) * trail(p) ** 2
                        for k in range(len(names))])
    stiffness = model.jnt_stiffness[model.dof_jntid[dofs]]
    critical = 2.0 * np.sqrt(stiffness * inertia)
    motor, crank = model.actuator(MOTOR).id, model.joint(CRANK_HINGE).dofadr[0]
    steps, start = int(round(t_end / dt)), int(round(min(0.5, t_end / 2) / dt))
    rates, angles, work, damped = [], [], 0.0, 0.0
    for i in range(steps):
        ratchet.before_step()
        mujoco.mj_step(model, data)
        v = data.qvel[dofs]
        work += float(data.actuator_force[motor] * data.qvel[crank]) * dt
        damped += float(critical @ (v * v)) * dt
        if i >= start:
            rates.append(v.copy())
            angles.append(data.qpos[adrs].copy())
    rates, angles = np.array(rates), np.array(angles)
    print(f"mu_wall {p.mu_wall:g}, cornering_coefficient {p.cornering_coefficient:g} /rad, trail {trail(p) * 1e3:.3g} mm, "
          f"step {dt:g} s, {t_end:g} s")
    for i in (0, 1):
        block = slice(i * per, (i + 1) * per)
        print(f"  module {i + 1}: steer angles {math.degrees(angles[:, block].min()):+.2f} to "
              f"{math.degrees(angles[:, block].max()):+.2f} deg, rms rate {np.sqrt((rates[:, block] ** 2).mean()):.3f} "
              f"rad/s")
    spectrum = np.abs(np.fft.rfft(rates[:, 0] - rates[:, 0].mean()))
    freqs = np.fft.rfftfreq(len(rates), dt)
    top = sorted(freqs[np.argsort(spectrum)[-3:]])
    print(f"  module 1 leg 0's steer rate: strongest at {', '.join(f'{f:.1f}' for f in top)} Hz; the steer's free "
          f"frequency {math.sqrt(stiffness[0] / inertia[0]) / (2 * math.pi):.0f} Hz")
    print(f"  critical damping ({critical[0]:.3g} N m s/rad) would dissipate {damped:.4g} J of the motor's "
          f"{work:.4g} J ({damped / work:.2e})")
    return 0


if __name__ == "__main__":
    sys.exit(main())
