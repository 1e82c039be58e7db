"""The video, the viewer loop and the mechanism diagram: they show what they claim."""

from __future__ import annotations

import ctypes.util
import math

import numpy as np
import pytest

from ipir_mujoco.analytic import RobotParams
from ipir_mujoco.cli import main
from ipir_mujoco.engine import simulate_mujoco
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
    from ipir_mujoco.engine.model import build_model

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
