"""A recorded MuJoCo run put back into a drawing model, at any time of its series (for ``render``).

The series holds what poses the robot: the crank angle ``phi`` and the modules' travel ``x1``, ``x2``; the
wheeled model's runs (``mujoco-wheels``) also each module's pose across the pipe, ``y1/2``, ``z1/2`` and its
turn ``roll1/2``, ``pitch1/2``, ``yaw1/2`` (:func:`ipir_mujoco.engine.kinds.wheels.ratchet.pose_columns`). Values between
samples are interpolated linearly. What the series does not hold follows from it:

- the rod's hinge closes the loop: the rod points from its pin on the crank (B) at module 2's pin (C),
  as MuJoCo's loop constraint holds it to within the run's ``loop_gap`` (a few micrometres: far below a pixel);
- the wheeled model's wheels turn by their module's travel along its own axis over the wheel radius (the
  run records no hub angles), and their arms stand at the springs' preload (arm slide 0: a module's sag on its
  springs, a few millimetres, is drawn by its recorded place; its legs stay at their preload length).
"""

from __future__ import annotations

import mujoco

from ipir_mujoco.core.results import RunResult

from .engine.kinds import drawn
from .engine.kinds.slides.drawing import SlideReplay  # noqa: F401  (older names: the kinds' replays)
from .engine.kinds.wheels.drawing import SLIDES_ACROSS, TURNS, WheeledReplay  # noqa: F401


def replay_for(model: mujoco.MjModel, run: RunResult):
    """The replay of ``run`` on its drawing model: its model kind's (:meth:`ModelKind.replay
    <ipir_mujoco.engine.kinds.base.ModelKind.replay>`; the slide model's for runs that record no MuJoCo model:
    the slides, the analytic engines)."""
    return drawn(run.settings.get("mujoco_model", "slides")).replay(model, run)
