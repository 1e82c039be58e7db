"""The video, the viewer loop and the mechanism diagram: they show what they claim."""

from __future__ import annotations

import ctypes.util
import math

import numpy as np
import pytest

from ipir_mujoco.analytic import RobotParams
from ipir_mujoco.cli import main
from ipir_mujoco.engine import simulate_mujoco
from ipir_mujoco.core.errors import ParameterError
from ipir_mujoco.video import RenderUnavailable, VideoSettings, frame_times, write_video


def _require_gl() -> None:
    """Skip, saying why, where this machine has no headless OpenGL (EGL or OSMesa) for MuJoCo's renderer."""
    from ipir_mujoco.video import _open_context

    try:
        _open_context(64, 64).free()
    except RenderUnavailable as exc:
        pytest.skip(f"no headless OpenGL here: {exc}")


@pytest.fixture(scope="module")
def short_run():
    # 0.05 s from rest: the crank has barely started; enough for a few frames
    return simulate_mujoco(RobotParams(), "unilateral", "ratchet", 0.05)


def test_frames_follow_the_playback_speed(short_run):
    settings = VideoSettings(width=96, height=64, fps=10.0, speed=0.1)  # a frame every 0.01 s simulated
    times = frame_times(short_run, settings)
    assert len(times) == 6 and times[0] == 0.0
    np.testing.assert_allclose(np.diff(times), 0.01, rtol=1e-12)
    assert len(frame_times(short_run, settings, t_end=0.02)) == 3


@pytest.mark.slow
def test_gif_has_the_promised_frames_size_and_clutch_colours(short_run, tmp_path):
    _require_gl()
    from PIL import Image

    path = tmp_path / "robot.gif"
    settings = VideoSettings(width=96, height=64, fps=10.0, speed=0.1)
    assert write_video(short_run, path, settings) == 6
    with Image.open(path) as gif:
        assert gif.n_frames == 6 and gif.size == (96, 64)
        assert gif.info["duration"] == 100  # ms per frame at 10 fps
        frames = []
        for i in range(gif.n_frames):
            gif.seek(i)
            frames.append(np.asarray(gif.convert("RGB"), dtype=int))
    # the robot moves between the first and the last frame
    assert np.abs(frames[-1] - frames[0]).sum() > 0
    # a held module is drawn green: from the first frame after t = 0 on, at least one clutch holds all
    # through this run (modes 0-2). At t = 0 no constraint force has been computed yet, and the ratchet's
    # bound sits one margin (1e-9 m) below the running maximum, so it engages within the first steps, once
    # the pushed-back module has moved back that far: before the first frame at 0.01 s
    first_frame = np.searchsorted(short_run.series["t"], 0.01)
    assert set(short_run.series["mode"][first_frame:].tolist()) <= {0, 1, 2}
    for frame in frames[1:]:
        r, g, b = frame[..., 0], frame[..., 1], frame[..., 2]
        assert np.count_nonzero((g > r + 50) & (g > b + 50)) > 10


@pytest.mark.slow
def test_render_command_writes_the_video(tmp_path, capsys):
    _require_gl()
    from PIL import Image

    out = tmp_path / "video" / "run.gif"
    assert main(["render", "--t-end", "0.03", "--fps", "10", "--width", "80", "--height", "64",
                 "--out", str(out)]) == 0
    with Image.open(out) as gif:
        assert gif.n_frames == 4 and gif.size == (80, 64)  # t = 0, 0.01, 0.02, 0.03 s
    printed = capsys.readouterr()
    assert "4 frames" in printed.out
    # progress on stderr while it works: the run, then the frames (a line per tenth in a log; all 4 here)
    assert printed.err.splitlines() == ["simulating 0.03 s in MuJoCo ...", *[f"rendered {k} / 4 frames"
                                                                            for k in range(1, 5)]]
    assert [p.name for p in out.parent.iterdir()] == ["run.gif"]  # no partial file left


def test_mp4_is_readable(short_run, tmp_path):
    imageio_ffmpeg = pytest.importorskip("imageio_ffmpeg", reason="MP4 needs the optional 'video' extra")
    _require_gl()
    path = tmp_path / "robot.mp4"
    assert write_video(short_run, path, VideoSettings(width=96, height=64, fps=10.0, speed=0.1)) == 6
    reader = imageio_ffmpeg.read_frames(str(path))
    meta = next(reader)
    assert tuple(meta["size"]) == (96, 64)
    assert sum(1 for _ in reader) == 6


def test_without_opengl_render_exits_2_with_one_line(tmp_path, capsys, monkeypatch):
    monkeypatch.delenv("MUJOCO_GL", raising=False)
    monkeypatch.delenv("PYOPENGL_PLATFORM", raising=False)
    monkeypatch.setattr(ctypes.util, "find_library", lambda name: None)
    out = tmp_path / "x.gif"
    assert main(["render", "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "EGL" in err and "OSMesa" in err
    assert not out.exists()


def test_render_refuses_bad_video_settings(tmp_path, capsys):
    assert main(["render", "--out", str(tmp_path / "x.avi")]) == 2
    assert ".avi" in capsys.readouterr().err
    assert main(["render", "--out", str(tmp_path / "x.gif"), "--width", "63"]) == 2
    assert "width=63" in capsys.readouterr().err


# a 90-degree bend of R/D 2.5 right after the first straight: in 0.6 s from rest the motor drives the front
# module into the bend, where it turns by ~29 degrees and moves ~33 mm across the first straight's axis
BEND = [dict(kind="straight", length=0.33), dict(kind="bend", radius=0.4, angle=90.0),
        dict(kind="straight", length=0.3)]


@pytest.fixture(scope="module")
def bend_run():
    from ipir_mujoco import registry
    from ipir_mujoco.core.route import route_from_tables

    route = route_from_tables(BEND, "bend.toml")
    run = registry.run("mujoco-wheels", RobotParams(drive="motor"), 0.6, route=route, accuracy="warn", dt_out=1e-3)
    return run, route


@pytest.mark.slow
def test_a_route_replay_poses_the_robot_as_recorded_among_the_runs_walls(bend_run):
    """Without OpenGL: the drawing model carries the walls the run's model had, and at every frame time (each a
    sample time here, so nothing is interpolated) each module stands at its recorded pose in the plane and the
    rod closes the loop as the run's did.

    Tolerances: the poses are the recorded joint values through MuJoCo's kinematics (a few additions and
    products of numbers of order 1 m): round-off, 1e-12 m and rad. The replayed rod points at module 2's pin,
    so its end misses it by | |BC| - L |, which the run's own gap |end - C| bounds (its rod has length L too).
    A module's turn goes through a quaternion and back to its rotation vector: 1e-9 rad.
    """
    import mujoco

    from ipir_mujoco.engine.builders.model import FRONT_SLIDE, ROD_END, closed_loop_pose
    from ipir_mujoco.engine.builders.wheels_model import build_wheels_model
    from ipir_mujoco.replay import WheeledReplay, replay_for
    from ipir_mujoco.video import _render_model

    run, route = bend_run
    settings = VideoSettings(width=96, height=64, fps=10.0, speed=0.1)  # a frame every 0.01 s: every 10th sample
    model = _render_model(run.params, settings, "wheels", route=route)
    ran = build_wheels_model(run.params, route=route)
    walls = [ran.geom(i).name for i in range(ran.ngeom) if ran.geom(i).name.startswith(("pipe_straight", "pipe_bend"))]
    assert {"pipe_straight1", "pipe_bend1"} <= set(walls)
    for name in walls:
        for field in ("pos", "quat", "size", "rgba"):
            np.testing.assert_array_equal(getattr(model.geom(name), field), getattr(ran.geom(name), field))
    replay = replay_for(model, run)
    assert isinstance(replay, WheeledReplay)
    data = mujoco.MjData(model)
    s = run.series
    rear, front = model.body("rear_module").id, model.body("front_module").id
    c0 = model.body_pos[front][0] + closed_loop_pose(run.params, run.params.phi0)[FRONT_SLIDE]  # C at the start
    assert s["x2_world"][0] == pytest.approx(c0, abs=1e-12) and s["x1_world"][0] == 0.0 and s["x1"][0] == 0.0
    pin = model.eq_data[model.equality("rod_to_front").id, 3:6]
    times = frame_times(run, settings)
    rows = np.searchsorted(s["t"], times - 1e-9)
    np.testing.assert_allclose(s["t"][rows], times, rtol=0, atol=1e-12)
    for i in rows:
        replay.pose(data, float(s["t"][i]))
        # along a route x1, x2 are read along its centreline; the world's x stays in x1_world, x2_world
        for body, x, k in ((rear, s["x1_world"][i], 1), (front, s["x2_world"][i], 2)):
            np.testing.assert_allclose(data.xpos[body], [x, s[f"y{k}"][i], s[f"z{k}"][i]], rtol=0, atol=1e-12)
            quat = np.zeros(4)
            mujoco.mju_mat2Quat(quat, data.xmat[body])
            quat *= 1.0 if quat[0] >= 0 else -1.0
            norm = np.linalg.norm(quat[1:])
            turn = quat[1:] * (2 * math.atan2(norm, quat[0]) / norm if norm > 0 else 2.0)
            np.testing.assert_allclose(turn, [s[f"{a}{k}"][i] for a in ("roll", "pitch", "yaw")], rtol=0, atol=1e-9)
        c = data.xpos[front] + data.xmat[front].reshape(3, 3) @ pin
        assert np.linalg.norm(data.site_xpos[model.site(ROD_END).id] - c) <= s["loop_gap"][i] + 1e-12
    # the poses checked include the front module turned and off the axis in the bend (its rings follow the
    # centreline, so its middle C sits inside it, and its wheels' sideways scrub pushes it about)
    assert math.degrees(s["yaw2"][rows[-1]]) > 2 and s["y2"][rows[-1]] > 2e-3


@pytest.mark.slow
def test_route_frames_draw_the_robot_turning_where_a_straight_replay_does_not(bend_run):
    """The frames follow the recorded pose: at t = 0 (on the axis, unturned) a frame is the frame of a replay with
    y and yaw zeroed, pixel for pixel; at 0.6 s, with the front module turned and off the axis in the bend, they
    differ in more than the housing's 25 pixels."""
    _require_gl()
    from dataclasses import replace

    from ipir_mujoco.video import render_frames

    run, route = bend_run
    settings = VideoSettings(width=96, height=64, fps=10.0, speed=3.0)  # a frame every 0.3 s: 0, 0.3, 0.6 s
    planar = ("y1", "y2", "yaw1", "yaw2")
    assert all(run.series[c][0] == 0.0 for c in planar)
    straight = replace(run, series={**run.series, **{c: np.zeros_like(run.series[c]) for c in planar}})
    turned = list(render_frames(run, settings, route=route))
    flat = list(render_frames(straight, settings, route=route))
    assert len(turned) == len(flat) == 3
    assert np.array_equal(turned[0], flat[0])
    assert np.count_nonzero(np.any(turned[-1] != flat[-1], axis=2)) > 25
    with pytest.raises(ParameterError, match="its route"):  # the walls are the run's: a route run needs its route
        next(render_frames(run, settings))


@pytest.mark.slow
def test_render_takes_a_route_for_the_wheeled_model_only(tmp_path, capsys):
    good = tmp_path / "bend.toml"
    good.write_text("".join("[[segment]]\n" + "".join(f"{k} = {v!r}\n".replace("'", '"') for k, v in seg.items())
                            for seg in BEND))
    out = tmp_path / "x.gif"
    for argv, word in ((["--route", str(good)], "--mujoco-model wheels"),
                       (["--mujoco-model", "wheels", "--route", str(tmp_path / "none.toml")], "does not exist")):
        assert main(["render", *argv, "--out", str(out)]) == 2
        err = capsys.readouterr().err.strip()
        assert len(err.splitlines()) == 1 and word in err
    assert not out.exists()
    _require_gl()
    from PIL import Image

    assert main(["render", "--mujoco-model", "wheels", "--route", str(good), "--drive", "motor", "--t-end", "0.3",
                 "--fps", "10", "--speed", "1", "--width", "80", "--height", "64", "--out", str(out)]) == 0
    with Image.open(out) as gif:
        assert gif.n_frames == 4 and gif.size == (80, 64)  # t = 0, 0.1, 0.2, 0.3 s
    printed = capsys.readouterr().out.splitlines()
    assert printed[0].startswith(f"wrote {out}: 4 frames")
    assert printed[1].startswith("route NOT done: t_end 0.3 s reached before the route's end")


def test_viewer_loop_steps_the_robot_as_the_engine_does():
    """The viewer runs the engine's own clutch controller: after the same steps, the same state.

    Both make the same MuJoCo calls in the same order (controller, mj_step, constraint forces); the
    engine's sampling reads the state and writes none, so they agree to round-off (1e-12 m here).
    """
    from ipir_mujoco.view import ViewedRobot

    params = RobotParams()
    robot = ViewedRobot(params, "unilateral")
    steps = round(0.1 / robot.settings.timestep)
    for _ in range(steps):
        robot.step()
    run = simulate_mujoco(params, "unilateral", "ratchet", steps * robot.settings.timestep,
                          dt_out=robot.settings.timestep, settings=robot.settings)
    model, data = robot.model, robot.data
    x1 = data.qpos[model.jnt_qposadr[model.joint("rear_slide").id]]
    phi = data.qpos[model.jnt_qposadr[model.joint("crank_hinge").id]]
    assert x1 == pytest.approx(run.series["x1"][-1], abs=1e-12)
    assert phi == pytest.approx(run.series["phi"][-1], abs=1e-12)
    assert x1 > 0.01  # and it crawls: module 1 has moved forward


def test_viewer_without_a_screen_exits_2(monkeypatch, capsys):
    from ipir_mujoco import view

    monkeypatch.setattr(view.sys, "platform", "linux")
    monkeypatch.delenv("DISPLAY", raising=False)
    monkeypatch.delenv("WAYLAND_DISPLAY", raising=False)
    assert view.main([]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "ipir-mujoco render" in err


@pytest.mark.slow
def test_mechanism_diagram_is_drawn_to_the_parameters(tmp_path):
    from PIL import Image

    from ipir_mujoco.report.diagram import figure_mechanism, write_mechanism_diagram

    path = write_mechanism_diagram(tmp_path / "m.png")
    with Image.open(path) as image:
        assert image.size == (900, 460)  # 9 x 4.6 in at 100 dpi
    # the drawn rod runs from B to C with the length L (scaled as r is): the geometry is the model's
    for L in (0.2, 0.1):
        fig = figure_mechanism(RobotParams(L=L), phi=math.radians(55))
        rod = [line for line in fig.axes[0].get_lines() if line.get_color() == "tab:blue"][0]
        (bx, cx), (by, cy) = rod.get_xdata(), rod.get_ydata()
        assert math.hypot(cx - bx, cy - by) == pytest.approx(L, rel=1e-12) and cy == 0.0


@pytest.mark.parametrize("params, clutch, implementation", [
    (RobotParams(clutch_stiffness=1e6), "kinematic", "lock"),
    (RobotParams(clutch_stiffness=1e6), "unilateral", "lock"),
    (RobotParams(clutch_damping=50.0), "unilateral", "ratchet"),
    (RobotParams(clutch_backlash=1e-3), "unilateral", "ratchet"),
    (RobotParams(), "kinematic", "ratchet"),
    (RobotParams(rod_mass=0.0), "unilateral", "ratchet"),
])
def test_the_viewer_refuses_what_the_engine_refuses(params, clutch, implementation):
    """One check for both: the same ParameterError, word for word, before anything is built."""
    from ipir_mujoco.analytic import ParameterError
    from ipir_mujoco.view import ViewedRobot

    with pytest.raises(ParameterError) as engine:
        simulate_mujoco(params, clutch, implementation, 0.01)
    with pytest.raises(ParameterError) as viewer:
        ViewedRobot(params, clutch, implementation)
    assert str(viewer.value) == str(engine.value) and "\n" not in str(engine.value)


def test_the_lock_controller_refuses_a_compliant_clutch():
    """The locks are rigid: given a finite stiffness the controller itself refuses, whoever calls it."""
    import mujoco

    from ipir_mujoco.analytic import ParameterError
    from ipir_mujoco.engine.clutches import clutch_controller
    from ipir_mujoco.engine.builders.model import build_model

    params = RobotParams(clutch_stiffness=1e6)
    model = build_model(params)
    for implementation in ("lock", "none"):
        with pytest.raises(ParameterError, match=r"clutch_stiffness=1000000.0 N/m with the MuJoCo '(lock|none)'"):
            clutch_controller(model, mujoco.MjData(model), params, implementation, "unilateral")


def test_the_viewer_colours_the_housings_by_the_clutches():
    """The viewer steps with the engine's loop (bit for bit the run's state) and writes the housings'
    colours when a clutch's state changes: after each frame they show the clutches' held state."""
    from ipir_mujoco.video import FREE_RGBA, HELD_RGBA
    from ipir_mujoco.view import ViewedRobot

    robot = ViewedRobot(RobotParams(), "unilateral")
    seen = set()
    for _ in range(160):  # 0.4 s in frames of 2.5 ms: the first contraction and the expansion after it
        robot.step(round(2.5e-3 / robot.settings.timestep))
        held = robot.controller.reactions()[:2]
        for geom, on in zip(robot.housings, held):
            expected = np.float32(HELD_RGBA if on else FREE_RGBA)  # MuJoCo stores colours in float32
            np.testing.assert_array_equal(robot.model.geom_rgba[geom], expected)
        seen.add(tuple(held))
    assert len(seen) >= 2  # the clutches did change state (contraction and expansion)
    run = simulate_mujoco(RobotParams(), "unilateral", "ratchet", robot.data.time, dt_out=2.5e-3,
                          settings=robot.settings)
    assert robot.data.qpos[robot.model.joint("crank_hinge").qposadr[0]] == run.series["phi"][-1]


def test_the_viewer_draws_the_checker_floor_and_says_time_and_speeds():
    """So that the robot is seen to advance with the camera following it, and the state is read as in render."""
    from ipir_mujoco.view import ViewedRobot

    robot = ViewedRobot(RobotParams())
    assert robot.model.ntex == 1 and robot.model.geom_matid[robot.model.geom("pipe_floor").id] >= 0
    robot.step(2000)
    labels, values = robot.overlay()
    assert labels.startswith("t = 0.") and "module 2 (front)" in labels
    assert values.count("m/s, clutch") == 2 and "rad/s" in values


def test_the_overlay_says_a_free_wheeled_module_rolls():
    """A module whose clutch does not hold slides on its slide, but rolls on its wheels: the overlay's word
    follows the model (render and the viewer share state_text)."""
    from ipir_mujoco.engine.kinds import drawn
    from ipir_mujoco.video import state_text

    _, slides = state_text(0.1, 1.0, 0.0, 20.0, 0.5, 0.0, (False, True))
    _, wheels = state_text(0.1, 1.0, 0.0, 20.0, 0.5, 0.0, (False, True), drawn("wheels").free)
    assert slides.splitlines()[1].endswith("clutch slides") and wheels.splitlines()[1].endswith("clutch free, rolls")
    assert slides.splitlines()[2] == wheels.splitlines()[2] == "0.00 m/s, clutch holds (green)"


def test_the_slide_model_is_drawn_in_its_pipe_cut_away_towards_the_camera():
    """Without OpenGL: the drawing model of a slide run carries the round pipe (a tube of the pipe's diameter
    about the x axis, colliding with nothing), only its far half as the camera looks (every vertex's outward
    direction has a non-negative component along the view: 1e-9 for round-off of unit vectors), and the floor
    below it."""
    from ipir_mujoco.video import SIDE_VIEW, _render_model, view_direction

    params = RobotParams()
    model = _render_model(params, VideoSettings(width=96, height=64))
    geom = model.geom("pipe_drawn1")
    assert model.geom_contype[geom.id] == 0 and model.geom_conaffinity[geom.id] == 0
    mesh = model.geom_dataid[geom.id]
    start, count = model.mesh_vertadr[mesh], model.mesh_vertnum[mesh]
    local = model.mesh_vert[start:start + count]
    rotation = np.zeros(9)
    import mujoco

    mujoco.mju_quat2Mat(rotation, geom.quat)
    world = local @ rotation.reshape(3, 3).T + geom.pos  # MuJoCo recentres a mesh: its frame is the geom's
    radius = np.hypot(world[:, 1], world[:, 2])
    np.testing.assert_allclose(radius, params.pipe_diameter / 2, rtol=1e-6)
    outward = np.column_stack([np.zeros(count), world[:, 1], world[:, 2]]) / radius[:, None]
    assert (outward @ view_direction(*SIDE_VIEW) > -1e-6).all()
    assert model.geom("pipe_floor").pos[2] < -params.pipe_diameter / 2


def test_the_camera_along_a_route_looks_square_to_its_plane():
    """A route in the horizontal plane is seen from straight above; one turning up into a riser (its points in
    the x-z plane) from its side, level, its start running to the frame's right."""
    from ipir_mujoco.core.route import route_from_tables
    from ipir_mujoco.video import route_view

    assert route_view(route_from_tables(BEND)) == (90.0, -90.0)
    up = route_from_tables([BEND[0], dict(BEND[1], plane=90.0), dict(kind="straight", length=0.3)])
    azimuth, elevation = route_view(up)  # from -y, looking along +y: +x to the right, +z up
    assert abs(azimuth - 90.0) < 1e-6 and abs(elevation) < 1e-6


def test_every_drawing_clips_nothing_near_the_camera():
    """Without OpenGL: MuJoCo clips what is nearer the camera than znear x extent and farther than zfar x extent.
    In every drawing model (render's and the viewer's, the slides and the wheels, without and along a route) the
    near plane stands within 2 cm of the camera, far inside the robot's 0.5 m and a route's 0.9 m view distance,
    and the far plane beyond 10 m. (The wheeled model's 2 km straight wall once made the extent 2000 m: its near
    plane stood 20 m out, and every frame without a route was black.)"""
    from ipir_mujoco.core.route import route_from_tables
    from ipir_mujoco.video import _render_model
    from ipir_mujoco.view import ViewedRobot

    route = route_from_tables(BEND, "bend.toml")
    models = [_render_model(RobotParams(), VideoSettings(width=96, height=64), model, route)
              for model, route in (("slides", None), ("wheels", None), ("wheels", route))]
    models += [ViewedRobot(RobotParams(), model=model).model for model in ("slides", "wheels")]
    for model in models:
        near, far = (float(model.vis.map.znear * model.stat.extent), float(model.vis.map.zfar * model.stat.extent))
        assert near <= 0.02 and far >= 10.0, (near, far)


@pytest.fixture(scope="module")
def wheels_run():
    from ipir_mujoco import registry

    # 0.04 s from rest of the wheeled model in its straight pipe, no route (the case once drawn black)
    return registry.run("mujoco-wheels", RobotParams(), 0.04, dt_out=1e-3)


def _pixel_of(point, lookat, distance: float, azimuth: float, elevation: float, fovy: float, size) -> tuple:
    """(row, column) of the pixel where a MuJoCo free camera (looking at ``lookat`` from ``distance`` [m] at
    ``azimuth``, ``elevation`` [deg], vertical field of view ``fovy`` [deg]) draws the world point ``point``, in a
    frame of ``size`` (height, width) px, top row first: a pinhole projection, z up."""
    from ipir_mujoco.video import view_direction

    forward = view_direction(azimuth, elevation)
    right = np.cross(forward, [0.0, 0.0, 1.0])
    right /= np.linalg.norm(right)
    up = np.cross(right, forward)
    d = np.asarray(point) - (np.asarray(lookat) - distance * forward)
    scale = 0.5 * size[0] / math.tan(math.radians(fovy) / 2)
    return (round(0.5 * size[0] - scale * (d @ up) / (d @ forward)),
            round(0.5 * size[1] + scale * (d @ right) / (d @ forward)))


@pytest.mark.slow
def test_a_wheeled_run_without_a_route_is_drawn_in_its_pipe(wheels_run):
    """The first frame of the wheeled robot in its straight pipe is a picture, not a black frame: nine tenths of
    its pixels are lit (the floor, the pipe, the robot; the frame once was all black but its text), and at each
    module's housing, where the camera's projection puts it, the pixel is the housing's colour (green where its
    clutch holds, grey-blue where not): the robot is where it is. 256 x 144 px: no text drawn over it."""
    _require_gl()
    import mujoco

    from ipir_mujoco.replay import replay_for
    from ipir_mujoco.video import HOUSINGS, SIDE_VIEW, _held, _render_model, render_frames

    settings = VideoSettings(width=256, height=144, fps=10.0, speed=0.1)
    frame = next(iter(render_frames(wheels_run, settings, t_end=0.0))).astype(int)
    lit = frame.sum(axis=2) > 3 * 40  # brighter than a dark grey in every channel on average
    assert lit.mean() > 0.9, lit.mean()
    model = _render_model(wheels_run.params, settings, "wheels")
    data = mujoco.MjData(model)
    replay = replay_for(model, wheels_run)
    replay.pose(data, 0.0)
    lookat = replay.lookat(data)
    for name, held in zip(HOUSINGS, _held(int(wheels_run.series["mode"][0]))):
        row, column = _pixel_of(data.geom_xpos[model.geom(name).id], lookat, 0.5, *SIDE_VIEW,
                                float(model.vis.global_.fovy), frame.shape[:2])
        r, g, b = frame[row, column]
        assert (g > r + 40 and g > b + 20) if held else (b > r + 20 and b > g), (name, held, (r, g, b))


@pytest.mark.slow
def test_the_reports_animation_shows_the_wheeled_robot_at_a_readable_size(wheels_run, tmp_path):
    """The validation report animates the ladder's last rung, the robot on wheels in its pipe, at 640 px or more
    (--quick; 768 px in full), and says so in its caption."""
    _require_gl()
    from PIL import Image

    from ipir_mujoco.report.validation import ANIMATION, _mechanism_section, write_animation
    from ipir_mujoco.studies.validate import LadderRun

    note, settings = write_animation(LadderRun("wheels in contact", "", wheels_run), tmp_path / "robot.gif", True)
    assert note is None and settings["model"] == "wheels" and ANIMATION["width"] >= 768
    with Image.open(tmp_path / "robot.gif") as gif:
        assert gif.size[0] >= 640
        gif.seek(gif.n_frames - 1)
        assert (np.asarray(gif.convert("RGB"), dtype=int).sum(axis=2) > 120).mean() > 0.9
    caption = _mechanism_section({"mechanism.png": "m.png", "robot.gif": "r.gif"}, None, settings)[-1].caption
    assert "on wheels in its pipe" in caption and "--mujoco-model wheels" in caption
