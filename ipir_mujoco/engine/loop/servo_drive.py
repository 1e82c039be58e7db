"""``drive = servo`` in MuJoCo: the speed controller (:mod:`ipir_mujoco.core.control`) writes the crank
actuator's ctrl at its ticks.

The motor is MuJoCo's: the crank actuator with gain M_stall and affine bias -M_stall / omega_noload * omega
(:func:`.model._write_drive`, as ``drive = motor``), so the torque M_stall (ctrl - omega / omega_noload)
is computed by MuJoCo every step, its velocity term integrated implicitly; only ctrl = u comes from the
controller. Tick k (at k / control_rate) is applied at the start of the first step at or after its time
(:func:`ipir_mujoco.core.control.tick_step`: the tick itself when the timestep divides the controller's
period, as the automatic timestep does where the output interval is a multiple of it), and u is held
until the next.

The run's steps go in chunks from one tick to the next through the loop's own ``run`` (compiled or Python,
:mod:`.stepper`); the samples are then recorded by the Python form of ``record``
(:meth:`.stepper.PythonSteps.record`, which the compiled loop equals bit for bit), so the default drives'
loop is untouched.
"""

from __future__ import annotations

import types

import numpy as np

from ipir_mujoco.core.control import FeedforwardTable, SpeedController, tick_step
from ipir_mujoco.core.errors import ParameterError
from ipir_mujoco.core.params import RobotParams

from .stepper import PythonSteps


def controller_for(params: RobotParams, feedforward) -> SpeedController | None:
    """A fresh speed controller for one run (drive = servo), else None; a table without the servo is refused."""
    if params.drive != "servo":
        if feedforward is not None:
            raise ParameterError(f"a feedforward table with drive={params.drive!r}; allowed: drive='servo'")
        return None
    if feedforward is not None and not isinstance(feedforward, FeedforwardTable):
        raise ParameterError(f"feedforward={feedforward!r} is not a FeedforwardTable; allowed: a table from "
                             "ipir_mujoco.registry.feedforward_table, or None")
    return SpeedController(params, feedforward)


class TickedDrive:
    """Steps a run's loop from tick to tick, writing ctrl = u at each (see the module docstring).

    ``steps``: the run's loop (:func:`.stepper.make_steps`), whose ``run`` and ``record`` this replaces;
    the controller has taken its tick at t = 0 (the run's setup). ``log`` holds each tick's
    (step at whose start it applies, u).
    """

    def __init__(self, steps: PythonSteps, controller: SpeedController, data, *, motor: int, crank_q: int,
                 crank_v: int, dt: float):
        self.steps, self.controller, self.data = steps, controller, data
        self.motor, self.crank_q, self.crank_v, self.dt = motor, crank_q, crank_v, dt
        self.inner = steps.run
        self.done = 0  # steps taken
        self.log_steps, self.log_u = [0], [controller.u]
        self.next_step = tick_step(controller.ticks, controller.period, dt)
        steps.run = self.run
        steps.record = types.MethodType(PythonSteps.record, steps)

    def run(self, nstep: int, row: int = -1) -> None:
        d, ctl = self.data, self.controller
        while nstep > 0:
            while self.done >= self.next_step:  # a tick is due at this step's start (the timestep <= the period)
                u = ctl.tick(d.qpos.item(self.crank_q), d.qvel.item(self.crank_v))
                d.ctrl[self.motor] = u
                self.log_steps.append(self.next_step)
                self.log_u.append(u)
                self.next_step = tick_step(ctl.ticks, ctl.period, self.dt)
            n = min(nstep, self.next_step - self.done)
            self.inner(n, row if n == nstep else -1)
            self.done += n
            nstep -= n

    def saturated_since(self, since: float) -> bool:
        """Whether every u applied from time ``since`` [s] on was full voltage, 1: a robot at rest since then is
        stalled for good (at rest the error is the whole target, and none is integrated into the clip)."""
        first = np.searchsorted(np.asarray(self.log_steps), since / self.dt - 1e-9, side="right") - 1
        return bool(np.all(np.asarray(self.log_u[max(first, 0):]) >= 1.0))

    def u_column(self, t: np.ndarray) -> np.ndarray:
        """u [-] over the step that ended at each sample time ``t`` (n,) [s] (at t = 0: the first tick's)."""
        steps = np.rint(np.asarray(t, dtype=float) / self.dt).astype(np.int64)
        index = np.searchsorted(np.asarray(self.log_steps), np.maximum(steps - 1, 0), side="right") - 1
        return np.asarray(self.log_u)[index]
