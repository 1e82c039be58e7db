"""A recorded run of the wheeled model posed again in its drawing model at any time (``render``): each module at its
recorded place and turn, the crank at phi, the rod closing the loop between the modules as they stand, the wheels
turned by their travel (:mod:`ipir_mujoco.replay`)."""

from __future__ import annotations

import math

import mujoco
import numpy as np

from ipir_mujoco.core.errors import ParameterError
from ipir_mujoco.core.results import RunResult

from ...builders.model import CRANK_HINGE, FRONT_SLIDE, LOOP, REAR_SLIDE, ROD_END, ROD_HINGE, qpos_address
from ..slides.drawing import SlideReplay

SLIDES_ACROSS = ("y1", "y2", "z1", "z2")  # the wheeled model's columns beside x1, x2: its modules' slides
TURNS = ("roll", "pitch", "yaw")  # and their ball joints' rotation vectors, roll1 ... yaw2


class WheeledReplay(SlideReplay):
    """The wheeled model's pose at a time of ``run``: each module at its recorded place and turn, the crank at phi,
    the rod closing the loop between the modules as they stand, the wheels turned by their travel (module
    docstring). ParameterError if the run lacks the pose columns (not a wheeled MuJoCo run)."""

    def __init__(self, model: mujoco.MjModel, run: RunResult):
        from .model import LATERALS, ROD_TILT, TILTS, VERTICALS, leg_names

        columns = SLIDES_ACROSS + tuple(f"{turn}{k}" for k in (1, 2) for turn in TURNS)
        missing = [c for c in columns if c not in run.series]
        if missing:
            raise ParameterError(f"the run's series lacks {', '.join(missing)}; allowed: a run of the wheeled MuJoCo "
                                 "model (mujoco-wheels), which records each module's pose in the pipe")
        super().__init__(model, run)
        self.address.update({name: qpos_address(model, joint) for name, joint in
                             zip(SLIDES_ACROSS, (LATERALS[0], LATERALS[1], VERTICALS[0], VERTICALS[1]))})
        self.tilts = [qpos_address(model, joint) for joint in TILTS]
        self.hubs = [[qpos_address(model, n + "_hub") for n in names] for names in leg_names(run.params)]
        s = self.series
        # the x slides' values: a run along a route reads x1, x2 along the route and keeps the modules' world
        # positions (x1_world, x2_world: the module body's place in the template plus its slide)
        if "x1_world" in s:
            self.slides = [s[f"x{k}_world"] - float(model.body(name).pos[0])
                           for k, name in ((1, "rear_module"), (2, "front_module"))]
        else:
            self.slides = [s["x1"], self.front0 + s["x2"]]
        self.travel = [_axial_travel(x, s[f"y{k}"], s[f"yaw{k}"]) for k, x in zip((1, 2), self.slides)]
        self.rear, self.rod = model.body("rear_module").id, model.body("rod").id
        self.front, self.end = model.body("front_module").id, model.site(ROD_END).id
        self.pin = model.eq_data[model.equality(LOOP).id, 3:6].copy()  # C in module 2's frame
        tilt = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, ROD_TILT)
        self.tilt = int(model.jnt_qposadr[tilt]) if tilt >= 0 else None  # the rod's cross pin (wheels template)

    def pose(self, data: mujoco.MjData, when: float) -> None:
        a, m = self.address, self.model
        t = self.series["t"]
        data.qpos[a[REAR_SLIDE]] = float(np.interp(when, t, self.slides[0]))
        data.qpos[a[FRONT_SLIDE]] = float(np.interp(when, t, self.slides[1]))
        for name in SLIDES_ACROSS:
            data.qpos[a[name]] = self.value(name, when)
        for k, adr in enumerate(self.tilts, start=1):
            turn = np.array([self.value(f"{name}{k}", when) for name in TURNS])
            angle = float(np.linalg.norm(turn))
            quat = np.array([1.0, 0.0, 0.0, 0.0])
            if angle > 0:
                mujoco.mju_axisAngle2Quat(quat, turn / angle, angle)
            data.qpos[adr:adr + 4] = quat
        data.qpos[a[CRANK_HINGE]] = self.value("phi", when)
        data.qpos[a[ROD_HINGE]] = 0.0
        for travel, module in zip(self.travel, self.hubs):
            data.qpos[module] = float(np.interp(when, self.series["t"], travel)) / self.params.wheel_radius
        mujoco.mj_kinematics(m, data)
        # the rod along the crank (hinge 0) now; turn it in module 1's plane to point from B at C
        frame = data.xmat[self.rear].reshape(3, 3)
        b, tip = data.xpos[self.rod], data.site_xpos[self.end]
        c = data.xpos[self.front] + data.xmat[self.front].reshape(3, 3) @ self.pin
        to_c, to_tip = frame.T @ (c - b), frame.T @ (tip - b)
        turn = math.atan2(to_c[1], to_c[0]) - math.atan2(to_tip[1], to_tip[0])
        data.qpos[a[ROD_HINGE]] = math.remainder(turn, 2 * math.pi)
        if self.tilt is not None:  # and out of it about the universal joint's cross pin (a turn about y lowers +x)
            data.qpos[self.tilt] = -math.atan2(to_c[2], math.hypot(to_c[0], to_c[1]))
        mujoco.mj_kinematics(m, data)

    def lookat(self, data: mujoco.MjData) -> list[float]:
        """Midway between the modules' frames (A and C)."""
        rear, front = data.xpos[self.rear], data.xpos[self.front]
        return [0.5 * float(rear[0] + front[0]), 0.5 * float(rear[1] + front[1]), 0.5 * float(rear[2] + front[2])]


def _axial_travel(x: np.ndarray, y: np.ndarray, yaw: np.ndarray) -> np.ndarray:
    """A module's cumulative travel along its own axis [m], shape (n,): each sample's step (dx, dy) on its
    heading, midway between the samples' yaws [rad]."""
    heading = 0.5 * (yaw[1:] + yaw[:-1])
    steps = np.diff(x) * np.cos(heading) + np.diff(y) * np.sin(heading)
    return np.concatenate([[0.0], np.cumsum(steps)])
