"""See the robot move: a MuJoCo run replayed through MuJoCo's offscreen renderer, headless.

A run's recorded state (crank angle and module positions, from any engine's
series; a wheeled run's modules also at their recorded pose in the plane) is
put back into the MuJoCo model frame by frame (:mod:`ipir_mujoco.replay`: the
rod's angle closes the loop), drawn with MuJoCo's own renderer and written as
a GIF (Pillow) or an MP4 (the optional ``video`` extra, imageio-ffmpeg). A
wheeled run along a route is drawn among the route's walls, built as the run
built them, seen from above by a camera that follows the robot. Each frame
shows the modules, crank and rod, each module's clutch state by its colour
(green: the clutch holds the module; grey-blue: the module moves), and the
time, playback speed and speeds as text (in frames at least 320 px wide; in
narrower ones the text would hide the robot).

Rendering needs an OpenGL library that works without a screen: EGL (Debian:
libegl1) or OSMesa (libosmesa6). ``MUJOCO_GL=egl`` or ``osmesa`` picks one;
otherwise EGL is tried, then OSMesa. Where neither exists,
:class:`RenderUnavailable` (a ParameterError: exit status 2 on the command
line) names the missing piece in one line.
"""

from __future__ import annotations

import ctypes.util
import math
import os
from dataclasses import dataclass
from pathlib import Path
from typing import Callable

import numpy as np

from ipir_mujoco.core.errors import ParameterError
from ipir_mujoco.core.params import RobotParams
from ipir_mujoco.core.results import Mode, RunResult

from .engine.kinds.base import HOUSINGS  # the modules' housings, coloured by their clutches (every kind's model)
from .labels import fixed

HELD_RGBA = (0.15, 0.7, 0.3, 1.0)  # the clutch holds the module to the pipe
FREE_RGBA = (0.6, 0.68, 0.85, 1.0)  # the module slides forward (grey-blue)
OVERLAY_MIN_WIDTH = 320  # px: narrower frames show the robot without the text
ROUTE_VIEW_DISTANCE = 0.9  # m: the camera above the plane along a route (fovy 45 deg: 0.75 m of it in a frame's
# height, 0.41 m between the texts: the robot, 0.4 m long, and its pipe, 0.16 m wide by default, fit there)
SIDE_VIEW = (90.0, -50.0)  # deg: the camera's azimuth and elevation without a route
DRAWN_EXTENT = 1.0  # m: the drawing model's extent, MuJoCo's scale for its clipping planes (checker_floor)
LIBRARIES = {"egl": ("EGL", "EGL (Debian: apt-get install libegl1)"),
             "osmesa": ("OSMesa", "OSMesa (Debian: apt-get install libosmesa6)")}


class RenderUnavailable(ParameterError):
    """No headless OpenGL (or no video writer) on this machine: one line naming the missing piece."""


def gl_backend() -> str:
    """The headless OpenGL backend to use: 'egl' or 'osmesa' (RenderUnavailable if neither is installed)."""
    wanted = os.environ.get("MUJOCO_GL", "").strip().lower()
    platform = os.environ.get("PYOPENGL_PLATFORM", "").strip().lower()
    candidates = [wanted] if wanted in LIBRARIES else [platform] if platform in LIBRARIES else list(LIBRARIES)
    for name in candidates:
        if ctypes.util.find_library(LIBRARIES[name][0]):
            return name
    missing = " or ".join(LIBRARIES[name][1] for name in candidates)
    raise RenderUnavailable(f"rendering needs a headless OpenGL library and none was found: install {missing}")


def view_direction(azimuth: float, elevation: float) -> np.ndarray:
    """The unit direction a MuJoCo free camera looks along (3,), from its azimuth and elevation [deg]."""
    az, el = math.radians(azimuth), math.radians(elevation)
    return np.array([math.cos(el) * math.cos(az), math.cos(el) * math.sin(az), math.sin(el)])


def route_view(route) -> tuple[float, float]:
    """(azimuth, elevation) [deg] of a camera square to the plane a route lies in (the normal of least spread of
    its centreline's points), from the side where the route starts towards the frame's right (and, for a plane
    near the horizontal, from above): a route in the horizontal plane is seen from straight above (+x right, +y
    up), one that turns up into a riser from its side."""
    if route.planar:
        return 90.0, -90.0
    points = np.array([route.at3(route.length * i / 100)[0] for i in range(101)])
    normal = np.linalg.svd(points - points.mean(axis=0))[2][2]
    d = normal if normal[2] <= 0 else -normal  # the view direction, downward or level
    if abs(d[2]) < 0.99 and float(np.cross(d, [0.0, 0.0, 1.0]) @ route.pieces[0].frame[0]) < 0:
        d = -d  # the route's start runs to the right of the frame, as it does seen from above
    return math.degrees(math.atan2(d[1], d[0])), math.degrees(math.asin(max(-1.0, min(1.0, d[2]))))


def _open_context(width: int, height: int):
    """A current offscreen OpenGL context of the chosen backend."""
    backend = gl_backend()
    try:
        if backend == "egl":
            from mujoco.egl import GLContext
        else:
            from mujoco.osmesa import GLContext
        context = GLContext(width, height)
        context.make_current()
    except Exception as exc:  # a library present but unusable: report it in one line, not a traceback
        message = " ".join(str(exc).split()) or type(exc).__name__
        raise RenderUnavailable(f"MUJOCO_GL={backend}: the OpenGL context cannot be created ({message[:200]})") \
            from None
    return context


@dataclass(frozen=True)
class VideoSettings:
    """Frame size [px], frames per second of the video, and playback speed (video s per simulated s: 0.1 = 10x slow)."""

    width: int = 640
    height: int = 360
    fps: float = 25.0
    speed: float = 0.1

    def __post_init__(self) -> None:
        for name, low, high in (("width", 64, 1920), ("height", 64, 1080)):
            value = getattr(self, name)
            if not (isinstance(value, int) and low <= value <= high and value % 2 == 0):
                raise ParameterError(f"{name}={value!r} px is out of range; allowed: an even number, {low}..{high}")
        if not (math.isfinite(self.fps) and 1 <= self.fps <= 60):
            raise ParameterError(f"fps={self.fps!r} is out of range; allowed: 1 <= fps <= 60")
        if not (math.isfinite(self.speed) and 1e-3 <= self.speed <= 10):
            raise ParameterError(f"speed={self.speed!r} is out of range; allowed: 0.001 <= speed <= 10 "
                                 "(video seconds per simulated second)")

    @property
    def frame_interval(self) -> float:
        """Simulated time between two frames [s]."""
        return self.speed / self.fps


def frame_times(run: RunResult, settings: VideoSettings, t_end: float | None = None) -> np.ndarray:
    """Simulated times of the frames [s], shape (n,): from the run's start every frame interval to ``t_end``."""
    t = run.series["t"]
    last = min(float(t[-1]), t_end if t_end is not None else float(t[-1]))
    count = int(math.floor((last - t[0]) / settings.frame_interval + 1e-9)) + 1
    return t[0] + settings.frame_interval * np.arange(count)


def checker_floor(spec) -> None:
    """Give the pipe's floor 5 cm checker squares (and a softer light), so that the eye sees the robot advance
    when the camera follows it: drawing only, for render and the viewer (an ``mujoco.MjSpec``, in place)."""
    import mujoco

    spec.add_texture(name="grid", type=mujoco.mjtTexture.mjTEXTURE_2D, builtin=mujoco.mjtBuiltin.mjBUILTIN_CHECKER,
                     width=64, height=64, rgb1=[0.92, 0.92, 0.88], rgb2=[0.78, 0.78, 0.74])
    material = spec.add_material(name="grid", texrepeat=[10, 10], texuniform=True)  # 10 per metre: 5 cm squares
    material.textures[mujoco.mjtTextureRole.mjTEXROLE_RGB] = "grid"
    floor = spec.geom("pipe_floor")
    floor.material, floor.rgba = "grid", [1, 1, 1, 1]
    # far beyond any run, and wider than the view; a route's floor (under it all) stays as large
    floor.size = [max(100.0, floor.size[0]), max(1.0, floor.size[1]), 0.01]
    spec.visual.headlight.ambient = [0.45, 0.45, 0.45]
    spec.visual.headlight.diffuse = [0.6, 0.6, 0.6]
    # the drawing's scale: MuJoCo clips what is nearer the camera than 0.01 extent and farther than 50 extent,
    # the extent it would compute from every geom. The wheeled model's straight wall (a contact cylinder 2 km
    # long, drawn nowhere) made it 2000 m, so the near plane stood 20 m out and every frame was black (the slide
    # model's 100 m floor made it 20 m: 0.2 m). At DRAWN_EXTENT the near plane is 1 cm from the camera and the far
    # 50 m: the robot, its pipe and a route's bends in view, and the viewer's zoom in steps of the robot's size
    spec.stat.extent = DRAWN_EXTENT


def state_text(t: float, phi: float, phi0: float, omega: float, v1: float, v2: float,
               held: tuple[bool, bool], free: str = "slides") -> tuple[str, str]:
    """The overlay's (labels, values) of the robot's state: crank speed and turns, each module's speed and
    whether its clutch holds (times [s], angles [rad], speeds [rad/s, m/s]); ``free``: what a module not held
    does, the drawing's word (the model kind's ``free``: it slides on its slide, or rolls on its wheels)."""
    words = ("holds (green)", free)
    values = (f"{fixed(omega, 1)} rad/s, {fixed((phi - phi0) / (2 * math.pi), 2)} rev\n"
              f"{fixed(v1, 2)} m/s, clutch {words[0] if held[0] else words[1]}\n"
              f"{fixed(v2, 2)} m/s, clutch {words[0] if held[1] else words[1]}")
    return "crank\nmodule 1 (rear)\nmodule 2 (front)", values


def _render_model(params: RobotParams, settings: VideoSettings, model: str = "slides", route=None):
    """The robot's MuJoCo model for drawing only: a 5 cm checker floor, an offscreen buffer of the frame size;
    ``model``: the MuJoCo model drawn (its model kind's drawing, :meth:`ModelKind.drawing
    <ipir_mujoco.engine.kinds.base.ModelKind.drawing>`: the slide model in its pipe, seen from the side, the near
    half cut away; the wheeled model's pipe walls and wheels); ``route``: its walls along the route, built as the
    run built them."""
    from .engine.kinds import drawn

    spec = drawn(model).drawing(params, route, view_direction(*SIDE_VIEW))
    checker_floor(spec)
    spec.visual.global_.offwidth = settings.width
    spec.visual.global_.offheight = settings.height
    return spec.compile()


def _held(mode: int) -> tuple[bool, bool]:
    """(rear held, front held) for a Mode value."""
    return (mode in (Mode.BOTH_LOCKED, Mode.EXPANSION), mode in (Mode.BOTH_LOCKED, Mode.CONTRACTION))


def check_route_run(run: RunResult, route) -> None:
    """ParameterError (one line) unless ``route`` (a :class:`ipir_mujoco.core.route.Route`, or None) is the one
    ``run`` ran along: a route for a run of the wheeled model along one, of its length; none for any other run."""
    ran = run.route
    if route is None and ran is not None:
        raise ParameterError(f"the run went along a route of {ran['route_length_m']:.6g} m; allowed: its route "
                             "(route=...), so that its walls are drawn")
    if route is not None and (ran is None or abs(route.length - ran["route_length_m"]) > 1e-12 * route.length):
        went = "along no route" if ran is None else f"along a route of {ran['route_length_m']:.6g} m"
        raise ParameterError(f"route {route.source} ({route.length:.6g} m): the run went {went}; allowed: the "
                             "route the run ran along")


def render_frames(run: RunResult, settings: VideoSettings = VideoSettings(), t_end: float | None = None,
                  title: str | None = None, route=None):
    """Yield the frames of ``run`` as uint8 arrays of shape (height, width, 3), one per frame time; ``route``:
    the route a wheeled run ran along (:func:`check_route_run`), its walls drawn and the camera above the
    plane, following the robot through the bends."""
    import mujoco

    from .replay import replay_for

    check_route_run(run, route)
    context = _open_context(settings.width, settings.height)
    params, s = run.params, run.series
    from .engine.kinds import drawn as drawn_kind

    drawn = run.settings.get("mujoco_model", "slides")  # the slide model's drawing for runs that record none
    model = _render_model(params, settings, drawn, route)
    data = mujoco.MjData(model)
    replay = replay_for(model, run)
    housings = [model.geom(name).id for name in HOUSINGS]
    scene = mujoco.MjvScene(model, maxgeom=200 if route is None else model.ngeom + 200)  # a bend: ~200-500 boxes
    camera = mujoco.MjvCamera()
    camera.type = mujoco.mjtCamera.mjCAMERA_FREE
    if route is None:
        camera.distance, (camera.azimuth, camera.elevation) = 0.5, SIDE_VIEW
    else:  # square to the route's plane: a route's near wall would hide the robot seen along it
        camera.distance, (camera.azimuth, camera.elevation) = ROUTE_VIEW_DISTANCE, route_view(route)
    option, perturb = mujoco.MjvOption(), mujoco.MjvPerturb()
    font = mujoco.mjtFontScale.mjFONTSCALE_150 if settings.width >= 600 else mujoco.mjtFontScale.mjFONTSCALE_100
    renderer = mujoco.MjrContext(model, font)
    mujoco.mjr_setBuffer(mujoco.mjtFramebuffer.mjFB_OFFSCREEN, renderer)
    viewport = mujoco.MjrRect(0, 0, settings.width, settings.height)
    t = s["t"]
    title = title or f"{run.engine}, {run.clutch} clutches"
    along = "" if route is None else f" along {Path(route.source).name}"
    try:
        for when in frame_times(run, settings, t_end):
            i = max(0, int(np.searchsorted(t, when, side="right")) - 1)  # the sample in force at this time
            phi = float(np.interp(when, t, s["phi"]))
            replay.pose(data, when)
            held = _held(int(s["mode"][i]))
            for geom, on in zip(housings, held):
                model.geom_rgba[geom] = HELD_RGBA if on else FREE_RGBA
            camera.lookat[:] = replay.lookat(data)
            mujoco.mjv_updateScene(model, data, option, perturb, camera, mujoco.mjtCatBit.mjCAT_ALL, scene)
            mujoco.mjr_render(viewport, scene, renderer)
            if settings.width < OVERLAY_MIN_WIDTH:  # the text would cover the robot
                yield _read_frame(settings, viewport, renderer)
                continue
            _overlay(mujoco.mjtGridPos.mjGRID_TOPLEFT, viewport, f"{title}\nt = {when:.3f} s{along}",
                     f"\n{settings.speed:g}x real time", renderer)
            labels, values = state_text(when, phi, float(s["phi"][0]), float(np.interp(when, t, s["omega"])),
                                        float(np.interp(when, t, s["v1"])), float(np.interp(when, t, s["v2"])), held,
                                        drawn_kind(drawn).free)
            _overlay(mujoco.mjtGridPos.mjGRID_BOTTOMLEFT, viewport, labels, values, renderer)
            yield _read_frame(settings, viewport, renderer)
    finally:
        renderer.free()
        context.free()


def _overlay(corner, viewport, left: str, right: str, renderer) -> None:
    """Text in a corner of the frame (MuJoCo's two columns), on the box MuJoCo draws behind it, as small as the
    text: drawn twice, so that the box is dark enough (half black, then three quarters) for the grey labels to
    read over the light floor, and covers no more of the robot than the text itself."""
    import mujoco

    for _ in range(2):
        mujoco.mjr_overlay(mujoco.mjtFont.mjFONT_NORMAL, corner, viewport, left, right, renderer)


def _counted(frames, total: int, progress: Callable[[int, int], None]):
    """``frames``, calling ``progress(done, total)`` after each."""
    for done, frame in enumerate(frames, start=1):
        yield frame
        progress(done, total)


def _read_frame(settings: VideoSettings, viewport, renderer) -> np.ndarray:
    """The rendered frame as uint8 (height, width, 3), top row first."""
    import mujoco

    pixels = np.empty((settings.height, settings.width, 3), dtype=np.uint8)
    mujoco.mjr_readPixels(pixels, None, viewport, renderer)
    return np.flipud(pixels)


def check_writer(path: str | Path) -> str:
    """The video format for ``path`` ('gif' or 'mp4'); RenderUnavailable if its writer is not installed."""
    suffix = Path(path).suffix.lower()
    if suffix == ".gif":
        return "gif"
    if suffix == ".mp4":
        try:
            import imageio_ffmpeg  # noqa: F401
        except ImportError:
            raise RenderUnavailable(f"writing {Path(path).name} needs the MP4 writer: "
                                    "pip install 'ipir-mujoco[video]' (or write a .gif)") from None
        return "mp4"
    raise ParameterError(f"video file {str(path)!r} has the suffix {suffix or '(none)'!r}; allowed: .gif, .mp4")


def write_video(run: RunResult, path: str | Path, settings: VideoSettings = VideoSettings(),
                t_end: float | None = None, title: str | None = None,
                progress: Callable[[int, int], None] | None = None, route=None) -> int:
    """Render ``run`` up to ``t_end`` [s] into ``path`` (.gif or .mp4); returns the number of frames.
    ``progress(done, total)`` is called with the frames rendered so far, after each frame; ``route``: the route
    the run ran along (:func:`render_frames`)."""
    path = Path(path)
    kind = check_writer(path)
    check_route_run(run, route)  # before the file is opened
    frames = render_frames(run, settings, t_end, title, route)
    if progress is not None:
        frames = _counted(frames, len(frame_times(run, settings, t_end)), progress)
    if kind == "gif":
        from PIL import Image

        images = [Image.fromarray(frame).quantize(colors=64, method=Image.Quantize.MEDIANCUT) for frame in frames]
        images[0].save(path, save_all=True, append_images=images[1:], duration=round(1000 / settings.fps), loop=0,
                       optimize=True)
        return len(images)
    import imageio_ffmpeg

    writer = imageio_ffmpeg.write_frames(str(path), (settings.width, settings.height), fps=settings.fps,
                                         codec="libx264", pix_fmt_out="yuv420p", macro_block_size=2,
                                         ffmpeg_log_level="error")
    writer.send(None)
    count = 0
    for frame in frames:
        writer.send(np.ascontiguousarray(frame))
        count += 1
    writer.close()
    return count
