"""Benchmark: ways of taking the clutch logic out of the Python step loop, measured in one run.

Run on demand (not part of the test suite; needs a C compiler, ``cc``, for the callback prototype):

    python bench/step_options.py [--steps 10000] [--repeats 5] [--chunk 10] [--smoke]

The paper's case with the rigid ratchet at a given timestep of 1e-4 s, the
same compiled model and initial state for every variant; each steps
``--steps`` steps in chunks of ``--chunk`` (an output interval, no sampling
work), timed ``--repeats`` times interleaved, best kept, per step and as a
ratio to the plain step:

- plain mj_step: ``mujoco.mj_step(m, d, nstep=chunk)``, no clutch update (the
  bounds stay where they started);
- Python ratchet: the ratchet's bound update in Python before every
  ``mj_step`` (the core of the former loop, without its bookkeeping);
- control callback (C): a prototype compiled here with ``cc``: the bound
  update and the drive's work in ``mjcb_control``, installed as a ctypes
  handle (called without the GIL), and ``mj_step(m, d, nstep=chunk)``;
- compiled loop: the engine's stepper (``ipir_mujoco.engine.loop.stepper``),
  everything the engine does per step (bounds, excursion, drive work,
  friction work);
- native one-way damper: no per-step update at all: each slide's clutch
  actuator as a velocity damper clamped to push only (force = -kv v in
  [0, 1e10] N), ``mj_step(m, d, nstep=chunk)``.

Then what each does to the motion over the same steps, against the per-step
ratchet: revolutions, travel, and the worst backward slide of a module below
its furthest position (the monitor's excursion figure), for the control
callback (its bound acts a step late: mjcb_control runs after the constraint
rows are built) and for the one-way damper at several ``kv``.
"""

from __future__ import annotations

import argparse
import ctypes
import math
import os
import subprocess
import tempfile
import time

import mujoco
import numpy as np

from ipir_mujoco.analytic import RobotParams
from ipir_mujoco.engine.loop import stepper
from ipir_mujoco.engine.clutches import Ratchet
from ipir_mujoco.engine.kinds.slides.loop_rows import loop_options
from ipir_mujoco.engine.builders.model import (CRANK_HINGE, FRONT_CLUTCH, FRONT_SLIDE, MOTOR, REAR_CLUTCH, REAR_SLIDE,
                                      SolverSettings, build_model, dof_address, drive_control, qpos_address,
                                      set_closed_loop_state)

CALLBACK = r"""
#include <stdint.h>
typedef struct {
  double *qpos, *qvel, *range, *force;
  int64_t q0, q1, j0, j1, motor, crank_v, started;
  double margin0, margin1, bound0, bound1, excursion, motor_work, dt, gear;
} context_t;
static context_t ctx;
void *context(void) { return &ctx; }
/* runs inside mj_step after the constraint rows are built: the bound it writes acts from the next step */
void control(const void *m, void *d) {
  (void)m; (void)d;
  if (ctx.started) ctx.motor_work += ctx.gear * ctx.force[ctx.motor] * ctx.qvel[ctx.crank_v] * ctx.dt;
  ctx.started = 1;
  double x = ctx.qpos[ctx.q0];
  if (x > ctx.bound0) { ctx.bound0 = x; ctx.range[2 * ctx.j0] = x - ctx.margin0; }
  else if (ctx.bound0 - x > ctx.excursion) ctx.excursion = ctx.bound0 - x;
  x = ctx.qpos[ctx.q1];
  if (x > ctx.bound1) { ctx.bound1 = x; ctx.range[2 * ctx.j1] = x - ctx.margin1; }
  else if (ctx.bound1 - x > ctx.excursion) ctx.excursion = ctx.bound1 - x;
}
"""


class Context(ctypes.Structure):
    _fields_ = ([(n, ctypes.POINTER(ctypes.c_double)) for n in ("qpos", "qvel", "range", "force")]
                + [(n, ctypes.c_int64) for n in ("q0", "q1", "j0", "j1", "motor", "crank_v", "started")]
                + [(n, ctypes.c_double) for n in ("margin0", "margin1", "bound0", "bound1", "excursion",
                                                  "motor_work", "dt", "gear")])


def compile_callback(folder: str) -> ctypes.CDLL:
    source, library = os.path.join(folder, "callback.c"), os.path.join(folder, "callback.so")
    with open(source, "w") as f:
        f.write(CALLBACK)
    subprocess.run(["cc", "-O2", "-ffp-contract=off", "-shared", "-fPIC", source, "-o", library], check=True)
    lib = ctypes.CDLL(library)
    lib.context.restype = ctypes.c_void_p
    return lib


def fresh(params, timestep, ratchet=True):
    model = build_model(params, SolverSettings(timestep=timestep), ratchet=ratchet)
    data = mujoco.MjData(model)
    set_closed_loop_state(model, data, params)
    data.ctrl[model.actuator(MOTOR).id] = drive_control(params)
    mujoco.mj_forward(model, data)
    return model, data


class Tracker:
    """Worst backward slide of a module below its running maximum, sampled every chunk (the ratchet's own
    figure, ``excursion``, is checked before every step)."""

    def __init__(self, model, data):
        self.adr = [qpos_address(model, n) for n in (REAR_SLIDE, FRONT_SLIDE)]
        self.data, self.best = data, [float(data.qpos[a]) for a in self.adr]
        self.start = list(self.best)
        self.worst = 0.0

    def see(self):
        for i, a in enumerate(self.adr):
            x = float(self.data.qpos[a])
            self.best[i] = max(self.best[i], x)
            self.worst = max(self.worst, self.best[i] - x)

    def figures(self, model):
        q = self.data.qpos
        travel = 0.5 * sum(float(q[a]) - s for a, s in zip(self.adr, self.start))
        return float(q[qpos_address(model, CRANK_HINGE)]) / (2 * math.pi), travel, self.worst


def run_plain(params, timestep, steps, chunk):
    model, data = fresh(params, timestep)
    Ratchet(model, data)
    started = time.perf_counter()
    for _ in range(steps // chunk):
        mujoco.mj_step(model, data, nstep=chunk)
    return (time.perf_counter() - started) / steps, None


def run_python(params, timestep, steps, chunk):
    model, data = fresh(params, timestep)
    ratchet, tracker = Ratchet(model, data), Tracker(model, data)
    started = time.perf_counter()
    for _ in range(steps // chunk):
        for _ in range(chunk):
            ratchet.before_step()
            mujoco.mj_step(model, data)
        tracker.see()
    elapsed = (time.perf_counter() - started) / steps
    revolutions, travel, _ = tracker.figures(model)
    return elapsed, (revolutions, travel, ratchet.excursion)


def run_callback(library, params, timestep, steps, chunk):
    model, data = fresh(params, timestep)
    ratchet = Ratchet(model, data)  # sets the initial bounds
    ctx = Context.from_address(library.context())
    as_double = lambda a: a.ctypes.data_as(ctypes.POINTER(ctypes.c_double))  # noqa: E731
    ctx.qpos, ctx.qvel, ctx.range, ctx.force = (as_double(a) for a in (data.qpos, data.qvel, model.jnt_range,
                                                                     data.actuator_force))
    ctx.q0, ctx.q1 = ratchet.qpos_adr
    ctx.j0, ctx.j1 = ratchet.joint_ids
    ctx.motor, ctx.crank_v, ctx.started = model.actuator(MOTOR).id, dof_address(model, CRANK_HINGE), 0
    ctx.margin0, ctx.margin1 = ratchet.margins
    ctx.bound0, ctx.bound1 = ratchet.bounds
    ctx.excursion, ctx.motor_work, ctx.dt = 0.0, 0.0, model.opt.timestep
    ctx.gear = float(model.actuator_gear[model.actuator(MOTOR).id, 0])
    tracker = Tracker(model, data)
    mujoco.set_mjcb_control(library.control)
    try:
        started = time.perf_counter()
        for _ in range(steps // chunk):
            mujoco.mj_step(model, data, nstep=chunk)
            tracker.see()
        elapsed = (time.perf_counter() - started) / steps
    finally:
        mujoco.set_mjcb_control(None)
    revolutions, travel, _ = tracker.figures(model)
    return elapsed, (revolutions, travel, ctx.excursion)


def run_compiled(params, timestep, steps, chunk):
    model, data = fresh(params, timestep)
    ratchet = Ratchet(model, data)
    loop = stepper.CompiledSteps(model, data, ratchet, np.zeros((1, model.nv)), **loop_options(model, data))
    tracker = Tracker(model, data)
    started = time.perf_counter()
    for _ in range(steps // chunk):
        loop.run(chunk)
        tracker.see()
    elapsed = (time.perf_counter() - started) / steps
    revolutions, travel, _ = tracker.figures(model)
    return elapsed, (revolutions, travel, ratchet.excursion)


def run_damper(params, timestep, steps, chunk, kv):
    model, data = fresh(params, timestep, ratchet=False)
    for name in (REAR_CLUTCH, FRONT_CLUTCH):  # force = -kv v, clamped by the force range [0, 1e10] N
        model.actuator_biasprm[model.actuator(name).id, 2] = -kv
    tracker = Tracker(model, data)
    started = time.perf_counter()
    for _ in range(steps // chunk):
        mujoco.mj_step(model, data, nstep=chunk)
        tracker.see()
    elapsed = (time.perf_counter() - started) / steps
    return elapsed, tracker.figures(model)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--steps", type=int, default=10000, help="steps per timing (default 10000 = 1 s)")
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--chunk", type=int, default=10, help="steps between two returns to Python (default 10)")
    parser.add_argument("--smoke", action="store_true", help="every code path once, in seconds (not a measurement)")
    args = parser.parse_args()
    if args.smoke:
        args.steps, args.repeats = 200, 1
    params, timestep, kv_timed = RobotParams(), 1e-4, 1e5
    with tempfile.TemporaryDirectory() as folder:
        library = compile_callback(folder)
        variants = {
            "plain mj_step": lambda: run_plain(params, timestep, args.steps, args.chunk),
            "Python ratchet": lambda: run_python(params, timestep, args.steps, args.chunk),
            "control callback (C)": lambda: run_callback(library, params, timestep, args.steps, args.chunk),
            "compiled loop": lambda: run_compiled(params, timestep, args.steps, args.chunk),
            f"one-way damper {kv_timed:g}": lambda: run_damper(params, timestep, args.steps, args.chunk, kv_timed),
        }
        best, motion = dict.fromkeys(variants, float("inf")), {}
        for _ in range(args.repeats):
            for name, timed in variants.items():
                seconds, figures = timed()
                best[name], motion[name] = min(best[name], seconds), figures
        load = os.getloadavg()
        print(f"mujoco {mujoco.__version__}; load average {load[0]:.2f}; {args.steps} steps of {timestep:g} s in "
              f"chunks of {args.chunk}; best of {args.repeats}")
        plain = best["plain mj_step"]
        for name, seconds in best.items():
            print(f"  {name:26s} {seconds * 1e6:7.3f} us/step  {seconds / plain:5.2f} x plain")
        reference = motion["Python ratchet"]
        print(f"\nmotion over {args.steps * timestep:g} s against the per-step ratchet (revolutions "
              f"{reference[0]:.6f}, travel {reference[1]:.6f} m, worst backward slide {reference[2]:.3g} m):")
        rows = [("control callback (C)", motion["control callback (C)"]),
                ("compiled loop", motion["compiled loop"])]
        for kv in (1e2, 1e3, 1e4, 1e5, 1e6, 1e7):
            rows.append((f"one-way damper kv={kv:g} N s/m", run_damper(params, timestep, args.steps, args.chunk,
                                                                        kv)[1]))
        for name, (revolutions, travel, worst) in rows:
            print(f"  {name:32s} revolutions {revolutions / reference[0] - 1:+.2e}, travel "
                  f"{travel / reference[1] - 1:+.2e}, worst backward slide {worst:.3g} m")


if __name__ == "__main__":
    main()
