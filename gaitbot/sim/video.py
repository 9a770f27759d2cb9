"""A three-quarter view of the simulated walk, rendered offscreen, written as GIF (Pillow) or MP4 (imageio-ffmpeg).

The camera looks at the robot from ahead of its right side and a little above (azimuth 120 deg,
elevation -20 deg), so the legs' roll and the weight shift show as well as the steps, and follows the
root; the near (right) leg is orange, the far (left) one grey. The planned heel strikes are drawn
on the floor as thin bars under each foot's track (green: left, red: right), so a foot landing
short or long shows. Rendering uses MuJoCo's offscreen
context: EGL by default (MUJOCO_GL=osmesa for pure software rendering).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from gaitbot.sim import SIM_EXTRA_HINT, SimUnavailable, VideoError
from gaitbot.sim.physics import SimRobot

FORMATS = {".gif": 20.0, ".mp4": 20.0}  # frames per second of each format
SIZE = {".gif": (480, 320), ".mp4": (640, 352)}  # width, height (MP4: multiples of 16)
MARKER_RGBA = {"left": (0.1, 0.65, 0.2, 1.0), "right": (0.85, 0.15, 0.15, 1.0)}


def check_video_path(path: str | Path) -> Path:
    """The path, if it names a format we write and its dependency is installed; VideoError otherwise."""
    path = Path(path)
    if path.suffix.lower() not in FORMATS:
        raise VideoError(f"--video {path}: the file must end in .gif or .mp4")
    module = "PIL" if path.suffix.lower() == ".gif" else "imageio_ffmpeg"
    try:
        __import__(module)
    except ImportError:
        raise SimUnavailable(f"--video {path.suffix} needs {module}, which is not installed: {SIM_EXTRA_HINT}") from None
    return path


class VideoRecorder:
    """An observer of a SimRobot that renders a frame every 1/fps simulated seconds while torque is on.

    footholds: planned heel strikes as (leg, heel x in the plan's world, metres); x_origin_m: the plan's x
    at the simulated world's origin."""

    def __init__(self, robot: SimRobot, path: str | Path, footholds: tuple[tuple[str, float], ...] = (),
                 x_origin_m: float = 0.0) -> None:
        self.path = check_video_path(path)
        suffix = self.path.suffix.lower()
        self.fps = FORMATS[suffix]
        self.width, self.height = SIZE[suffix]
        self.footholds = tuple((leg, x - x_origin_m) for leg, x in footholds)
        self.frames: list[np.ndarray] = []
        self._next_s = 0.0
        mujoco = robot.mujoco
        try:
            self.renderer = mujoco.Renderer(robot.model, self.height, self.width)
        except Exception as exc:  # noqa: BLE001 - any GL failure: say what to try
            raise VideoError(f"--video {self.path}: offscreen rendering is not available ({exc}); "
                             f"try MUJOCO_GL=osmesa or MUJOCO_GL=egl") from None
        self.camera = mujoco.MjvCamera()
        self.camera.type = mujoco.mjtCamera.mjCAMERA_FREE
        # three-quarter view: from the robot's front right, a little above (forward is to the picture's right)
        self.camera.azimuth, self.camera.elevation = 120.0, -20.0
        leg = robot.config.geometry.thigh_m + robot.config.geometry.shank_m
        self.camera.distance = 3.6 * leg
        self._marker_size = np.array([0.003, 0.35 * robot.config.geometry.hip_width_m, 0.0005])
        self._marker_y = {"left": robot.config.geometry.hip_width_m / 2, "right": -robot.config.geometry.hip_width_m / 2}

    def __call__(self, robot: SimRobot) -> None:
        if not robot.torque_on.all() or robot.time_s + 1e-9 < self._next_s:
            return
        self._next_s += 1.0 / self.fps
        root = robot.torso_xyz_m()
        self.camera.lookat[:] = (root[0], root[1], 0.55 * root[2])
        self.renderer.update_scene(robot.data, self.camera)
        flags, names = self.renderer.scene.flags, robot.mujoco.mjtRndFlag
        flags[names.mjRND_SHADOW] = flags[names.mjRND_REFLECTION] = False  # shadows: 10x the rest in software GL
        self._draw_footholds(robot)
        self.frames.append(self.renderer.render().copy())

    def _draw_footholds(self, robot: SimRobot) -> None:
        mujoco, scene = robot.mujoco, self.renderer.scene
        for leg, x in self.footholds:
            if scene.ngeom >= scene.maxgeom:
                return
            mujoco.mjv_initGeom(scene.geoms[scene.ngeom], mujoco.mjtGeom.mjGEOM_BOX, self._marker_size,
                                np.array([x, self._marker_y[leg], 0.0005]), np.eye(3).ravel(), np.array(MARKER_RGBA[leg], dtype=np.float32))
            scene.ngeom += 1

    def save(self, on_progress=None) -> int:
        """Write the file; return the number of frames. ``on_progress(k, n)`` is told as frames are encoded."""
        if not self.frames:
            raise VideoError(f"--video {self.path}: nothing was rendered (the walk never started)")
        report = on_progress or (lambda k, n: None)
        n = len(self.frames)
        if self.path.suffix.lower() == ".gif":
            from PIL import Image

            def rest():  # Pillow encodes the frames as it takes them from here
                for k, frame in enumerate(self.frames[1:], start=2):
                    yield Image.fromarray(frame)
                    report(k, n)

            Image.fromarray(self.frames[0]).save(self.path, save_all=True, append_images=rest(),
                                                 duration=round(1000 / self.fps), loop=0, optimize=False)
        else:
            import imageio_ffmpeg

            writer = imageio_ffmpeg.write_frames(str(self.path), (self.width, self.height), fps=self.fps,
                                                 codec="libx264", pix_fmt_out="yuv420p", quality=7)
            writer.send(None)
            for k, frame in enumerate(self.frames, start=1):
                writer.send(np.ascontiguousarray(frame))
                report(k, n)
            writer.close()
        self.renderer.close()
        return len(self.frames)
