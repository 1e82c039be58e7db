"""One run setup: a model kind's model, data, clutch controller, drive and stepping loop, as every stepper uses.

A serial run (:mod:`.simulate`), the viewer (``python -m ipir_mujoco.view``) and anything else that steps the
engine itself build through :class:`RunSetup`, so that they step the same model from the same initial state with
the same controller and loop. (Batched runs, :mod:`.batch`, step many slide models at once with their own
vectorized ratchet; they build and start each through the same kind.)
"""

from __future__ import annotations

import mujoco

from ipir_mujoco.core.params import RobotParams

from ..kinds import ModelKind
from ..builders.model import CRANK_HINGE, MOTOR, SolverSettings, drive_control
from ..loop.servo_drive import TickedDrive
from ..loop.stepper import PythonSteps, make_steps


class RunSetup:
    """The model of ``kind`` for ``params`` built with ``settings``, and its data.

    Parameters
    ----------
    kind : ModelKind
        The model kind (:func:`.kinds.kind_for`); its checks are the caller's to have run.
    params : RobotParams
    settings : SolverSettings
    implementation : str
        The MuJoCo clutch: 'ratchet' | 'lock' | 'none'.
    rule : str
        The clutch rule: 'kinematic' | 'unilateral'.
    mjcf : str or os.PathLike or None
        The MJCF template (None: the kind's shipped one).
    route : ipir_mujoco.core.route.Route or None
        The walls along a route (the kinds that take one).
    servo : CrankServo or None
        A crank servo in place of the drive.
    decorate : callable or None
        ``decorate(spec)`` adds what only drawing needs before compiling (the viewer's floor).

    Attributes
    ----------
    model : mujoco.MjModel
    data : mujoco.MjData
    controller : ClutchController
        Made by :meth:`start` (:mod:`.controller`).
    loop : dict
        The stepping loop's options (:meth:`.kinds.ModelKind.loop_options`), made by :meth:`start`.
    """

    def __init__(self, kind: ModelKind, params: RobotParams, settings: SolverSettings, *, implementation: str,
                 rule: str, mjcf=None, route=None, servo=None, decorate=None):
        self.kind, self.params, self.settings = kind, params, settings
        self.implementation, self.rule, self.servo = implementation, rule, servo
        self.model = kind.build(params, settings, mjcf=mjcf, implementation=implementation, route=route,
                                decorate=decorate)
        self.data = mujoco.MjData(self.model)
        self.controller = None
        self.loop: dict = {}

    def start(self, speed=None) -> None:
        """Set the initial state, make a fresh clutch controller, set the drive (the crank servo's or the speed
        controller's first tick, ``speed``: a :class:`ipir_mujoco.core.control.SpeedController`) and run
        ``mj_forward``; then the loop's options."""
        m, d, p = self.model, self.data, self.params
        self.kind.initial_state(m, d, p)
        self.controller = self.kind.controller(m, d, p, self.implementation, self.rule)
        motor, crank = m.actuator(MOTOR).id, m.joint(CRANK_HINGE)
        d.ctrl[motor] = drive_control(p) if self.servo is None else self.servo.torque(
            0.0, d.qpos[crank.qposadr[0]], d.qvel[crank.dofadr[0]])
        if speed is not None:  # the speed controller's tick at t = 0
            d.ctrl[motor] = speed.tick(float(d.qpos[crank.qposadr[0]]), float(d.qvel[crank.dofadr[0]]))
        mujoco.mj_forward(m, d)
        self.loop = self.kind.loop_options(m, d)

    def steps(self, qvel_before, speed=None) -> tuple[PythonSteps, TickedDrive | None]:
        """The stepping loop (compiled where it can be, :func:`.stepper.make_steps`) writing the velocities
        before each sample's step into ``qvel_before`` (n, nv), and the speed controller's ticks on it (None
        without ``speed``)."""
        m, d = self.model, self.data
        steps = make_steps(m, d, self.controller, qvel_before, servo=self.servo, **self.loop)
        ticked = None
        if speed is not None:
            ticked = TickedDrive(steps, speed, d, motor=self.loop["motor"], crank_q=self.loop["crank_q"],
                                 crank_v=self.loop["crank_v"], dt=m.opt.timestep)
        return steps, ticked
