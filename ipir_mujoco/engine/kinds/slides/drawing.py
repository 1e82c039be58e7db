"""How the slide model is drawn and replayed (``render``, the viewer): its round pipe, which its build has not
(:func:`in_pipe`), and a recorded run's pose at any time (:class:`SlideReplay`)."""

from __future__ import annotations

import mujoco
import numpy as np

from ipir_mujoco.core.params import RobotParams
from ipir_mujoco.core.results import RunResult

from ...builders.model import CRANK_HINGE, FRONT_SLIDE, REAR_SLIDE, ROD_HINGE, closed_loop_pose, qpos_address

PIPE_RGBA = (0.35, 0.45, 0.6, 0.55)  # the slide model's pipe, cut away: more opaque than a whole translucent tube


def in_pipe(spec, params: RobotParams, facing=None) -> None:
    """Draw the slide model's round pipe around it (drawing only, :func:`ipir_mujoco.engine.builders.pipe_drawing.draw_pipe`): with
    ``facing`` (the camera's view direction) its far half, the near half cut away; without, the whole tube,
    translucent. The floor moves under the pipe."""
    from ...builders.pipe_drawing import RGBA, draw_pipe
    from ...builders.pipe_walls import wall_pieces

    D = params.pipe_diameter
    draw_pipe(spec, wall_pieces(None, D, 0.0), D, facing=facing, rgba=RGBA if facing is None else PIPE_RGBA)
    floor = spec.geom("pipe_floor")
    floor.pos = [floor.pos[0], floor.pos[1], -0.5 * D - 0.01]


class SlideReplay:
    """The slide model's pose at a time of ``run`` (``model``: the drawing model, compiled from the run's
    parameters): module 1 at x1, module 2 at its start plus x2, the crank at phi, the rod closing the loop
    (:func:`ipir_mujoco.engine.builders.model.closed_loop_pose`: the modules stay on the pipe's axis)."""

    def __init__(self, model: mujoco.MjModel, run: RunResult):
        self.model, self.params, self.series = model, run.params, run.series
        self.address = {name: qpos_address(model, name) for name in (REAR_SLIDE, FRONT_SLIDE, CRANK_HINGE, ROD_HINGE)}
        self.front0 = closed_loop_pose(self.params, float(self.series["phi"][0]))[FRONT_SLIDE]

    def value(self, name: str, when: float) -> float:
        """Column ``name`` at time ``when`` [s], interpolated linearly between samples."""
        return float(np.interp(when, self.series["t"], self.series[name]))

    def pose(self, data: mujoco.MjData, when: float) -> None:
        """Set ``data``'s joints for time ``when`` [s] and compute its kinematics."""
        a, p = self.address, self.params
        phi = self.value("phi", when)
        x1, x2 = self.value("x1", when), self.value("x2", when)
        data.qpos[a[REAR_SLIDE]] = x1
        data.qpos[a[CRANK_HINGE]] = phi
        data.qpos[a[ROD_HINGE]] = closed_loop_pose(p, phi)[ROD_HINGE]
        data.qpos[a[FRONT_SLIDE]] = self.front0 + x2
        mujoco.mj_kinematics(self.model, data)
        self._travel = (x1, x2)

    def lookat(self, data: mujoco.MjData) -> list[float]:
        """Where the camera looks after :meth:`pose` [m, (3,)]: midway between A and C on the pipe's axis,
        below the plane."""
        x1, x2 = self._travel
        return [0.5 * (x1 + self.front0 + x2 + self.params.r + self.params.L), 0.0, -0.02]
