"""``python -m ipir_mujoco.view``: the robot in MuJoCo's interactive viewer, clutches working.

The one entry point beside the registry that steps the MuJoCo engine itself: the viewer needs the live
model and data between steps, which a finished run does not give.

The shipped MJCF alone does not crawl: its one-way clutches are not MJCF
elements but the engine's Python controllers (:mod:`ipir_mujoco.engine.kinds`),
which move a joint limit or switch a lock before every step. This command
builds the model from a parameter set exactly as ``simulate --engine mujoco``
does and steps it in a passive viewer loop with the engine's own stepping loop
(:mod:`ipir_mujoco.engine.loop.stepper`: the same controller, compiled where it can be), in
real time (or slower with ``--slow``), and starts the run again every
``--t-end`` seconds of simulated time (a constant torque accelerates the robot
without bound). A module's housing turns green while its clutch holds it; the
camera follows module 1 (drag to turn it, scroll to zoom). Needs a screen (on macOS, run it with ``mjpython``); without
one, use ``ipir-mujoco render`` for a video.

    python -m ipir_mujoco.view [--clutch unilateral|kinematic] [--mujoco-clutch ratchet|lock]
                               [--mujoco-model slides|wheels]
                               [--set NAME=VALUE]... [--config FILE.toml] [--slow FACTOR] [--t-end SECONDS]

With ``--mujoco-model wheels`` the robot on wheels in its pipe (walls and wheels drawn), its hub ratchets
stepped by the engine's Python loop.
"""

from __future__ import annotations

import os
import sys
import time
from typing import Sequence

import mujoco
import numpy as np

from ipir_mujoco import registry
from ipir_mujoco.core.control import SpeedController
from ipir_mujoco.core.errors import ParameterError
from ipir_mujoco.core.params import RobotParams

from ..engine.kinds import kind_for
from ..engine.builders.model import CRANK_HINGE, FRONT_SLIDE, REAR_SLIDE, SolverSettings
from ..engine.run.run_setup import RunSetup
from ..video import FREE_RGBA, HELD_RGBA, HOUSINGS, checker_floor, state_text
from .common import EXIT_BAD_INPUT, EXIT_OK, Parser, add_model_options, model_params


class ViewedRobot:
    """The model, its data and the engine's clutch controller, stepped by the engine's stepping loop.

    Refuses (ParameterError, one line) exactly the parameters and clutch choices ``simulate_mujoco``
    refuses (the model kind's :meth:`ipir_mujoco.engine.kinds.base.ModelKind.check`), and builds and starts the
    robot as a run does (:class:`ipir_mujoco.engine.run.run_setup.RunSetup`).
    """

    def __init__(self, params: RobotParams, clutch: str = "unilateral", implementation: str | None = None,
                 settings: SolverSettings | None = None, t_end: float = 4.0, model: str = "slides", route=None):
        self.clutch = clutch
        self.implementation = implementation or ("lock" if clutch == "kinematic" else "ratchet")
        kind = kind_for(model, params)
        params = kind.check(params, self.implementation, clutch, route)  # the route's incline
        self.params, self.free = params, kind.free  # the overlay's word
        if settings is None:  # the step the engine would choose for a run of t_end [s]
            settings, _ = kind.settings(params, t_end, 1e-3, None, self.implementation, route=route)
        self.settings = settings
        def decorate(spec):
            kind.dress(spec, params)  # the slide model in its pipe, whole and translucent: the viewer's camera turns
            checker_floor(spec)

        self.setup = RunSetup(kind, params, settings, implementation=self.implementation, rule=clutch, route=route,
                              decorate=decorate)
        self.model, self.data = self.setup.model, self.setup.data
        self.housings = [self.model.geom(name).id for name in HOUSINGS]
        self._qvel_before = np.empty((1, self.model.nv))  # the loop's sample buffer (the viewer takes no samples)
        self.reset()

    def reset(self) -> None:
        """Back to the start: the loop-consistent initial state, a fresh clutch controller."""
        speed = None
        if self.params.drive == "servo":  # the speed controller, its table computed as for a run
            speed = SpeedController(self.params, registry.feedforward_table(self.params))
        self.setup.start(speed)
        self.controller = self.setup.controller
        self.steps, _ = self.setup.steps(self._qvel_before, speed)
        self.held: tuple[bool, bool] | None = None
        self._colour()

    def step(self, n: int = 1) -> None:
        """``n`` MuJoCo steps with the clutch controller around each, by the engine's own loop; then the
        housings take the clutches' colours (rewritten only when a clutch's state changed)."""
        self.steps.run(n)
        self._colour()

    def overlay(self) -> tuple[str, str]:
        """The viewer's text, as render's: the time and the playback, then the crank's and the modules' state."""
        d, m = self.data, self.model
        crank, rear, front = (m.joint(n) for n in (CRANK_HINGE, REAR_SLIDE, FRONT_SLIDE))
        labels, values = state_text(d.time, float(d.qpos[crank.qposadr[0]]), self.params.phi0,
                                    float(d.qvel[crank.dofadr[0]]), float(d.qvel[rear.dofadr[0]]),
                                    float(d.qvel[front.dofadr[0]]), self.held or (False, False), self.free)
        return f"t = {d.time:.2f} s\n{labels}", f"\n{values}"

    def _colour(self) -> None:
        held = tuple(self.controller.reactions()[:2])
        if held != self.held:
            self.held = held
            for geom, on in zip(self.housings, held):
                self.model.geom_rgba[geom] = HELD_RGBA if on else FREE_RGBA


def build_parser() -> Parser:
    parser = Parser(prog="python -m ipir_mujoco.view",
                    description="Open the robot in MuJoCo's interactive viewer with its one-way clutches working "
                                "(the engine's own clutch controller runs in the viewer loop).")
    parser.add_argument("--clutch", choices=("unilateral", "kinematic"), default="unilateral",
                        help="unilateral: one-way clutches (default); kinematic: the paper's rule")
    parser.add_argument("--mujoco-clutch", choices=registry.MUJOCO_CLUTCHES, default=None,
                        help="ratchet (default with unilateral) or lock (default with kinematic)")
    parser.add_argument("--mujoco-model", choices=("slides", "wheels"), default="slides",
                        help="slides: the modules on slide joints (default); wheels: on wheels in the pipe")
    parser.add_argument("--route", metavar="FILE.toml", default=None,
                        help="with --mujoco-model wheels: the pipe along a route of straights and bends (docs/cli.md)")
    parser.add_argument("--slow", type=float, default=1.0, metavar="FACTOR",
                        help="play FACTOR times slower than real time (default 1; the crank reaches ~10 rev/s "
                             "within a second)")
    parser.add_argument("--t-end", type=float, default=4.0, metavar="SECONDS",
                        help="start again after this much simulated time (default 4 s)")
    add_model_options(parser)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    args = build_parser().parse_args(argv)
    try:
        if not (1.0 <= args.slow <= 1000.0):
            raise ParameterError(f"--slow {args.slow} is out of range; allowed: 1 <= FACTOR <= 1000")
        if not (0.0 < args.t_end <= 60.0):
            raise ParameterError(f"--t-end {args.t_end} is out of range; allowed: 0 < SECONDS <= 60")
        route = None
        if args.route is not None:
            from ipir_mujoco.core.route import read_route

            from .common import check_input_file

            check_input_file("--route", args.route)
            route = read_route(args.route)
        robot = ViewedRobot(model_params(args), args.clutch, args.mujoco_clutch, t_end=args.t_end,
                            model=args.mujoco_model, route=route)
        if sys.platform.startswith("linux") and not (os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY")):
            raise ParameterError("the viewer needs a screen and none is set (no DISPLAY); "
                                 "write a video instead: ipir-mujoco render")
    except ParameterError as exc:
        print(f"python -m ipir_mujoco.view: error: {exc}", file=sys.stderr)
        return EXIT_BAD_INPUT
    import mujoco.viewer

    frame = 1.0 / 60.0  # wall-clock seconds between two viewer updates
    print("python -m ipir_mujoco.view: drag to turn the camera, right-drag to move it, scroll to zoom; Space "
          "pauses, Tab and Shift+Tab show the panels, Esc or closing the window ends it", file=sys.stderr)
    # the panels start hidden so the robot has the window (Tab and Shift+Tab show them)
    with mujoco.viewer.launch_passive(robot.model, robot.data, show_left_ui=False,
                                      show_right_ui=False) as viewer:
        with viewer.lock():  # a camera that follows module 1, close enough to see the crank turn
            viewer.cam.type = mujoco.mjtCamera.mjCAMERA_TRACKING
            viewer.cam.trackbodyid = robot.model.body("rear_module").id
            viewer.cam.distance, viewer.cam.azimuth, viewer.cam.elevation = 0.6, 90.0, -45.0
        while viewer.is_running():
            started = time.perf_counter()
            with viewer.lock():
                # a frame's steps at once: as fast as real time allows, slower if the machine cannot
                robot.step(max(1, round(frame / args.slow / robot.settings.timestep)))
                if robot.data.time >= args.t_end:
                    robot.reset()
            viewer.set_texts((mujoco.mjtFontScale.mjFONTSCALE_150, mujoco.mjtGridPos.mjGRID_BOTTOMLEFT,
                              *robot.overlay()))
            viewer.sync()
            time.sleep(max(0.0, frame - (time.perf_counter() - started)))
    return EXIT_OK


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
