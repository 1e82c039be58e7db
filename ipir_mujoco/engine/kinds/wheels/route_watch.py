"""A wheeled run along a route (``--route``): where the robot is along it, and why the run stops.

:class:`RouteWatch` reads the recorded samples every block of the run loop (:mod:`.simulate`): the rear
module's point A (the crank's axis, :class:`ModulePoints`, in 3-D) projected on the route's centreline
(:meth:`ipir_mujoco.core.route.Route.along`) is the robot's distance along the route, ``route_s_m`` (the
furthest so far). At the run's end the series' x and v columns are read along the route
(:meth:`RouteWatch.along_series`), so the summary's travel and every figure of x and v are along the centreline.
The run stops, with one line in ``route_stop``, when

- the rear module reaches the route's end (``route_done`` true, ``route_time_s`` the time it did,
  interpolated between samples);
- the robot slid back out of the pipe behind the route's start (the walls reach LEAD_IN behind it);
- no progress: the distance along the route grew by less than PROGRESS_M in PROGRESS_S (the crank turns
  and the robot skids or rocks in place, or the crank stands: the message says which);
- or the run's own ends: t_end, a stall (the robot at rest for good), a failure.

A wheel that lost its wall (its spring pressing with less than LOST_SHARE of its preload, for WALL_LOSS_S
without a break) is reported (``route_wall_loss``, with how long wheels and whole modules were off their
walls) but does not stop the run: in tight bends the modules ride on two diagonal wheels, or float on the
linkage for a moment, and still get through (measured: R/D = 2, mjcf/README.md), so a lost wall alone is no
jam. A robot that no longer progresses is one, and its stop line says whether a wheel had lost its wall.

Every check reads recorded samples, so its times are good to one output interval.
"""

from __future__ import annotations

import math

import mujoco
import numpy as np

from ipir_mujoco.core.route import Route

from ...builders.model import CRANK_HINGE, FRONT_SLIDE, REAR_SLIDE, dof_address, qpos_address
from ...builders.pipe_walls import LEAD_IN

WALL_LOSS_S = 0.05  # s: a wheel off its wall this long without a break has lost it (a skid's bounces last < 1 ms)
LOST_SHARE = 0.1  # a wheel pressing with less than this share of its preload is off its wall
PROGRESS_M = 0.01  # m: the least progress along the route in PROGRESS_S (a tenth of a stroke, 2 r)
PROGRESS_S = 2.0  # s: (the default motor makes ~7 revolutions in it)
COCKED_DEG = 5.0  # deg: a module turned this far off the pipe's axis is cocked (its rings 0.1 m apart then reach
# 8.7 mm across: beyond the legs' 5 mm of travel to their free length), said in a stall's line
BACK_OUT = LEAD_IN - 0.1  # m: the rear module this far behind the start has its aft wheels (0.075 m back) at the
# walls' end


class ModulePoints:
    """Where the wheeled models' reference points are, in route coordinates (the world's): the rear module's point
    A (the crank's axis) and the front module's C, each its module body's place in the template plus its slides
    along x, y (``*_lateral``) and, in the round-pipe model, z (``*_vertical``; the planar model has none: z = 0),
    and their velocities (the slides' rates): ``positions(qpos) -> (A, C)``, ``velocities(qvel) -> (vA, vC)``,
    each (3,) [m], [m/s]. A module's tilt (a ball joint at its point) does not move the point."""

    def __init__(self, model):
        names = ((REAR_SLIDE, "rear_lateral", "rear_vertical"), (FRONT_SLIDE, "front_lateral", "front_vertical"))
        self.q, self.v, self.base = [], [], []
        for module, slides in zip(("rear_module", "front_module"), names):
            present = [mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, n) >= 0 for n in slides]
            self.q.append([qpos_address(model, n) if ok else None for n, ok in zip(slides, present)])
            self.v.append([dof_address(model, n) if ok else None for n, ok in zip(slides, present)])
            self.base.append(np.array(model.body(module).pos, dtype=float))

    @staticmethod
    def _read(values, addresses, base) -> np.ndarray:
        values = np.asarray(values, dtype=float)
        out = np.broadcast_to(base, values.shape[:-1] + (3,)).copy()
        for k, a in enumerate(addresses):
            if a is not None:
                out[..., k] += values[..., a]
        return out

    def positions(self, q) -> tuple[np.ndarray, np.ndarray]:
        """(A, C) [m] of the state ``q`` (nq,), each (3,), or of the rows of ``q`` (n, nq), each (n, 3)."""
        return self._read(q, self.q[0], self.base[0]), self._read(q, self.q[1], self.base[1])

    def velocities(self, v) -> tuple[np.ndarray, np.ndarray]:
        """(vA, vC) [m/s] of ``v`` (nv,) or of its rows (n, nv), as :meth:`positions`."""
        zero = np.zeros(3)
        return self._read(v, self.v[0], zero), self._read(v, self.v[1], zero)


def arm_slides(model) -> tuple[list[int], list[float]]:
    """The wheels' arm slides (joints named ``*_arm``, the rear module's first, as the models build them): their
    qpos addresses and their springs' free lengths [m] (``qpos_spring``: the slide where a spring is unloaded)."""
    joints = [j for j in range(model.njnt) if model.joint(j).name.endswith("_arm")]
    addresses = [int(model.jnt_qposadr[j]) for j in joints]
    return addresses, [float(model.qpos_spring[a]) for a in addresses]


class RouteWatch:
    """The route's checks on one run (module docstring); ``model`` the compiled wheeled model with the route's
    walls, ``recorder`` the run's :class:`.recorder.Recorder`, ``points`` where the modules' reference points
    are (default :class:`ModulePoints`)."""

    def __init__(self, route: Route, model, recorder, prediction: dict, dt_out: float, points=None,
                 unlimited_grip: bool = False, ring_reach: float = 0.0):
        self.route, self.rec, self.prediction = route, recorder, prediction
        # a stall with the robot in a bend says what unlimited grip does there; ring_reach [m]: how far a
        # module's wheels reach beyond its points A and C along the pipe
        self.unlimited_grip, self.ring_reach = unlimited_grip, ring_reach
        self.points = ModulePoints(model) if points is None else points
        self.s_front = 0.0
        self.crank = qpos_address(model, CRANK_HINGE)
        self.arms, free = arm_slides(model)
        self.free = np.array(free)  # the arm slides' springref: the springs' free lengths [m]
        self.arm_names = [model.joint(j).name for j in range(model.njnt) if model.joint(j).name.endswith("_arm")]
        self.fed = 0
        self.s_max = 0.0
        self.s_last = 0.0
        self.along: list[tuple[float, float]] = []  # (rear A's s, front C's s) [m] per sample fed
        self.progress_at = (0.0, 0.0, 0.0)  # (t, s, crank angle) when progress last passed PROGRESS_M
        self.off_since: list[float | None] = [None] * len(self.arms)
        self.done_at: float | None = None
        self.off_time = 0.0  # s: samples' time with some wheel off its wall (below LOST_SHARE of its preload)
        self.module_off_time = 0.0  # s: samples' time with every wheel of a module off its wall
        self.lost: str | None = None  # the first wheel off its wall for WALL_LOSS_S, in words
        self.reach = 0.0  # the largest arm slide over the spring's free length (1: a spring unloaded)
        self.dt = dt_out
        self.marks = [p.s0 for p in route.pieces] + [route.length]
        self.mark_times: list[float | None] = [None] * len(self.marks)
        self.stop: str | None = None
        found = [mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, n) for n in ("rear_tilt", "front_tilt")]
        self.tilts = [int(model.jnt_qposadr[j]) for j in found] if min(found) >= 0 else None  # the ball joints

    def check(self, newest: int) -> int | None:
        """Feed the samples up to row ``newest``; the row to end the run at, or None to go on. The block's points
        and wheel states are read from the samples at once (numpy), the checks run sample by sample."""
        rec = self.rec
        first = self.fed
        self.fed = newest + 1
        if newest < first:
            return None
        q, t = rec.qpos, rec.t
        block = np.asarray(q[first:newest + 1], dtype=float)
        rears, aheads = (points.tolist() for points in self.points.positions(block))
        arms = block[:, self.arms]
        reach = (arms / self.free).max(axis=1).tolist()
        off = (arms > (1.0 - LOST_SHARE) * self.free).tolist()
        times = np.asarray(t[first:newest + 1], dtype=float).tolist()
        length = self.route.length
        for j, ti in enumerate(times):
            i = first + j
            s = self.route.along(rears[j], self.s_last)
            t0 = float(t[i - 1]) if i > 0 else ti
            front = self.route.along(aheads[j], self.s_front)
            self.along.append((s, front))
            centre, before = 0.5 * (s + front), 0.5 * (self.s_last + self.s_front)
            self.s_front = front
            for k, mark in enumerate(self.marks):  # when the robot's centre first reached each piece's start
                if self.mark_times[k] is None and centre >= mark:
                    share = (mark - before) / (centre - before) if centre > before else 1.0
                    self.mark_times[k] = t0 + share * (ti - t0)
            if s >= length and self.done_at is None:
                share = (length - self.s_last) / (s - self.s_last) if s > self.s_last else 1.0
                self.done_at = t0 + share * (ti - t0)
                self.s_last = self.s_max = s
                self.stop = f"reached the route's end ({length:.3f} m) at t = {self.done_at:.4f} s"
                return i
            if s < -BACK_OUT:
                self.stop = (f"slid back out of the pipe: the rear module {-s:.3f} m behind the route's start at "
                             f"t = {ti:.4f} s (the walls end {LEAD_IN:g} m behind it)")
                return i
            self.s_last = s
            self.s_max = max(self.s_max, s)
            if self.s_max - self.progress_at[1] >= PROGRESS_M:
                self.progress_at = (ti, self.s_max, float(q[i, self.crank]))
            elif ti - self.progress_at[0] >= PROGRESS_S:
                turns = (float(q[i, self.crank]) - self.progress_at[2]) / (2 * math.pi)
                why = (f"the crank turned {turns:.2f} revolutions" if abs(turns) >= 0.05
                       else "the crank stood: the linkage bound, or the drive too weak")
                cocked = self.cocked(q[i], (s, front))
                if cocked:
                    why += f"; {cocked}"
                if self.lost is not None:
                    why += f"; {self.lost}"
                if self.unlimited_grip and self.in_bend(s, front):
                    why += ("; unlimited grip: the wheels are rigid then, and in a bend, rolling only along their "
                            "module's axis, they must also slide across the pipe, which mu_wall=unlimited holds them "
                            "from (give a finite mu_wall: the wheels then steer on their cornering compliance)")
                self.stop = (f"stalled: less than {PROGRESS_M * 1e3:g} mm of progress in {PROGRESS_S:g} s "
                             f"({why}), at {self.route.where(self.s_max)}, t = {ti:.4f} s")
                return i
            self._wheels(off[j], reach[j], ti)
        return None

    def in_bend(self, rear: float, front: float) -> bool:
        """Whether a bend lies between the rear module's wheels and the front module's (A at ``rear``, C at
        ``front`` [m] along the centreline, the wheels ring_reach beyond)."""
        lo, hi = rear - self.ring_reach, front + self.ring_reach
        return any(p.s0 < hi and p.s0 + p.length > lo for p in self.route.bends)

    def cocked(self, q, along: tuple[float, float]) -> str | None:
        """The modules turned more than COCKED_DEG off the centreline's direction at their points (``along``: A's
        and C's s [m]), in words, or None: a module cocked across its pipe rests on its legs' stops (its rings
        ``ring_spacing`` apart reach across the pipe by sin(angle) times that), where its wheels cannot roll it on."""
        if self.tilts is None:
            return None
        words = []
        for k, (adr, s) in enumerate(zip(self.tilts, along), start=1):
            quat = np.asarray(q[adr:adr + 4], dtype=float)
            axis = np.zeros(9)
            mujoco.mju_quat2Mat(axis, quat / np.linalg.norm(quat))
            _, direction = self.route.at3(s)
            angle = math.degrees(math.acos(min(1.0, abs(float(axis.reshape(3, 3)[:, 0] @ direction)))))
            if angle > COCKED_DEG:
                words.append(f"module {k} cocked {angle:.0f} deg off the pipe's axis")
        return ", ".join(words) or None

    def along_series(self, series: dict) -> dict:
        """The run's series read along the route: ``x1``, ``x2`` become the rear module's A and the front
        module's C distances along the centreline from where they started [m] (as x1, x2 are in a straight
        pipe), ``v1``, ``v2`` their velocities along it (the velocity's component along the centreline's
        direction there) [m/s] and ``a1``, ``a2`` the rates of those [m/s^2]; the world positions stay as
        ``x1_world``, ``y1_world``, ``z1_world`` (and 2) [m], and the centreline's curvature where each is,
        ``bend_x1``, ``bend_y1``, ``bend_z1`` (and 2) [1/m] in the world (1 / R towards a bend's centre, 0 in a
        straight: the lift-off and scrub checks' bends, :mod:`ipir_mujoco.core.route_loads`). Every figure and
        summary figure drawn from x and v then reads along the route."""
        n = len(series["t"])
        rec = self.rec
        out = dict(series)
        along = list(self.along[:n])
        world = np.concatenate(self.points.positions(np.asarray(rec.qpos[:n], dtype=float)), axis=1).reshape(n, 6)
        velocities = self.points.velocities(np.asarray(rec.qvel[:n], dtype=float))
        for i in range(len(along), n):  # samples after the last check (the run's end)
            before = along[-1] if along else (0.0, 0.0)
            along.append((self.route.along(world[i, :3], before[0]), self.route.along(world[i, 3:], before[1])))
        along = np.array(along).reshape(n, 2)
        for k, column in ((0, "1"), (1, "2")):
            s = along[:, k]
            out[f"x{column}_world"], out[f"y{column}_world"], out[f"z{column}_world"] = world[:, 3 * k:3 * k + 3].T
            out[f"x{column}"] = s - s[0]
            directions = np.array([self.route.direction_xyz(float(si)) for si in s]).reshape(n, 3)
            speed = np.einsum("ij,ij->i", velocities[k].reshape(n, 3), directions)
            out[f"v{column}"] = speed
            bend = np.array([self.route.curvature_xyz(float(si)) for si in s]).reshape(n, 3)
            out[f"bend_x{column}"], out[f"bend_y{column}"], out[f"bend_z{column}"] = bend.T.copy()
            out[f"a{column}"] = np.gradient(speed, series["t"]) if n > 1 else np.zeros(n)
        return out

    def _wheels(self, off: list[bool], reach: float, t: float) -> None:
        """Note which wheels press with less than LOST_SHARE of their preload at one sample: ``off`` per arm
        slide, whether it reaches beyond 1 - LOST_SHARE of its spring's free length (the spring presses with
        1 - q / free of its preload, the light arm's contact with as much but for the arm's inertia); ``reach``
        the sample's largest q / free."""
        self.reach = max(self.reach, reach)
        if any(off):
            self.off_time += self.dt
            half = len(off) // 2
            if all(off[:half]) or all(off[half:]):
                self.module_off_time += self.dt
        for k, wheel_off in enumerate(off):
            if not wheel_off:
                self.off_since[k] = None
                continue
            since = self.off_since[k]
            if since is None:
                self.off_since[k] = t
            elif self.lost is None and t - since >= WALL_LOSS_S:
                self.lost = (f"wheel {self.arm_names[k][:-4]} lost its wall (pressing with < {100 * LOST_SHARE:g} % of "
                             f"its preload for {WALL_LOSS_S:g} s) from t = {since:.4f} s, at "
                             f"{self.route.where(self.s_max)}")

    def record(self, t_end: float, stall: str | None) -> dict:
        """The summary's route keys: ``route_done``, ``route_time_s`` [s] or None, ``route_s_m`` [m] (the furthest the
        rear module got along the route), ``route_length_m``, ``route_stop`` (one line), ``route_wall_loss`` (the
        first wheel that lost its wall, in words, or None), ``route_wheel_off_s`` [s] (how long some wheel was off
        its wall), ``route_module_off_s`` [s] (every wheel of a module), ``route_arm_reach`` (the largest arm
        extension over the spring's free length: 1 unloads a spring), ``route_piece_times_s`` (when the robot's
        centre, midway along the route between the rear module's A and the front module's C, first reached each
        segment's start and the route's end [s], or None: it starts about L / 2 into the route), and ``route_fit``
        (the closed-form prediction, :func:`.route_walls.fit_prediction`)."""
        stop = self.stop
        if stop is None:
            where = self.route.where(self.s_max)
            if stall is not None:
                stop = f"stalled: {stall}, at {where}"
            else:
                stop = f"t_end {t_end:g} s reached before the route's end, at {where}"
        return {"route_done": self.done_at is not None, "route_time_s": self.done_at, "route_s_m": self.s_max,
                "route_length_m": self.route.length, "route_stop": stop, "route_fit": self.prediction,
                "route_wall_loss": self.lost, "route_wheel_off_s": self.off_time,
                "route_module_off_s": self.module_off_time, "route_arm_reach": self.reach,
                "route_piece_times_s": list(self.mark_times)}


def check_route(route, model: str, params, until_steady: bool, reach: float | None = None):
    """``params`` for a run along ``route`` (None: as they are): its incline the route's first straight's;
    ParameterError (one line) for a route on the slide model, with --until-steady, with an incline set apart
    from the route's, or whose first straight is shorter than the robot (it starts in it: ``reach`` [m], how far
    the robot reaches ahead of its rear module's point A; the round-pipe model's by default). The round pipe's walls
    (:mod:`.pipe_walls`) take any route: at most MAX_SEGMENTS + 2 pieces."""
    from ipir_mujoco.core.errors import ParameterError, ParameterTypeError

    if route is None:
        return params
    if not isinstance(route, Route):
        raise ParameterTypeError(f"route={route!r} is not a Route; allowed: a Route "
                                 "(ipir_mujoco.core.route.read_route), or None")
    if model != "wheels":
        raise ParameterError("--route applies only to the wheeled model; allowed: --mujoco-model wheels")
    if until_steady:
        raise ParameterError("--until-steady with --route: a run along a route ends at the route's end; "
                             "allowed: one of them")
    if params.incline != 0.0 and params.incline != route.incline:
        raise ParameterError(f"incline={params.incline:g} deg with --route: the route's first straight sets the "
                             "incline; allowed: incline=0 (give it in the route)")
    route.check_pipe(params.pipe_diameter)
    if reach is None:  # the round-pipe model's: A to its front ring's wheels
        reach = params.L + params.r + 0.5 * params.ring_spacing + params.wheel_radius
    first = route.pieces[0]
    if first.length < reach:
        raise ParameterError(f"{route.source}: segment 1: length={first.length:g} m; the robot starts in it and "
                             f"reaches L + r + {reach - params.L - params.r:g} m ahead of its rear module; allowed: "
                             f"length >= {reach:g} m")
    return params.replace(incline=route.incline)


def pipe_fit(route: Route, params) -> dict:
    """The round-pipe model's closed-form fit of the route's bends (:func:`.route_walls.fit_prediction`): its rings
    ``ring_spacing`` / 2 either side of a module's middle, its legs' springs reaching ``suspension_travel`` beyond
    their preload, its housing as wide as the ring inside its wheels and as long as its ring spacing."""
    from .route_walls import fit_prediction
    from .model import housing_radius

    return fit_prediction(route, params, 0.5 * params.ring_spacing, params.suspension_travel,
                          housing=(2 * housing_radius(params), params.ring_spacing))


def route_watch(route: Route | None, model, recorder, params, dt_out: float, fit=pipe_fit) -> RouteWatch | None:
    """The run's RouteWatch (None without a route), with the closed-form fit of the route's bends for this model's
    geometry, ``fit(route, params) -> {"bends": [...], "predicted": one line}`` (the model kind's ``route_fit``)."""
    if route is None:
        return None
    return RouteWatch(route, model, recorder, fit(route, params), dt_out, unlimited_grip=params.mu_wall is None,
                      ring_reach=0.5 * params.ring_spacing + params.wheel_radius)
