"""The telemetry of a live drive: each frame's record made on the view's worker thread, not in the 60 Hz loop.

A drive has no plan to precompute (gaitbot.view.walk_frames does that for a planned walk): each step is
planned as the commands come. So the loop hands over only what it has (a :class:`DriveSample`: the ticks sent,
the planned body angles, the root and the torso's yaw, the command; a few copies), and
:class:`DriveTelemetry`, called on gaitbot.view.publisher's worker thread, turns it into a
:class:`~gaitbot.view.telemetry.FrameTelemetry`: the goals from the ticks through the calibration (what the
servos were sent, rounding included), and the centre of mass, the ZMP, the soles and the support polygon
from gaitbot.check.balance, as the preflight check computes them, over the last three frames (the ZMP needs
the CoM's acceleration: a central difference, so it is that of the frame before, 1/60 s late).
"""

from __future__ import annotations

from collections import deque
from dataclasses import dataclass

import numpy as np

from gaitbot.check.balance import balance_trace
from gaitbot.check.preflight import robot_angles_deg
from gaitbot.gait.joints import LEG_JOINTS, SIDES
from gaitbot.gait.trajectory import Trajectory
from gaitbot.robot.calibration import ticks_to_angles
from gaitbot.robot.config import RobotConfig
from gaitbot.view.telemetry import FrameTelemetry, ServoHealth
from gaitbot.view.walk_frames import sole_poses

WINDOW_FRAMES = 3  # the fewest a second difference needs


@dataclass(frozen=True)
class DriveSample:
    """What the drive's loop knows of frame ``t_s``: ticks sent (config joints), planned body angles (rad,
    LEG_JOINTS), root (m) and torso yaw (rad) in the drive's frame, the command (vx m/s, vy m/s, wz rad/s)
    and the servos' health (summarised in the loop: the monitor is the loop's)."""

    t_s: float
    ticks: np.ndarray
    body_rad: np.ndarray
    root_m: np.ndarray
    yaw_rad: float
    command: tuple[float, float, float]
    health: ServoHealth | None = None
    felt: object | None = None  # gaitbot.view.felt.FeltSample: the sensors' readings, made telemetry on the worker


class DriveTelemetry:
    """A Telemetry observer of DriveSamples (on the worker thread) over a TelemetryPublisher."""

    def __init__(self, config: RobotConfig, publisher) -> None:
        self.config = config
        self.publisher = publisher
        self.joints = tuple(config.joint_names)
        self._window: deque[DriveSample] = deque(maxlen=WINDOW_FRAMES)

    @property
    def notes(self) -> list[str]:
        return self.publisher.notes

    def frame(self, sample: DriveSample) -> FrameTelemetry:
        """The record of ``sample``, with the CoM, ZMP, soles and support of the window ending at it."""
        window = self._window
        if window and sample.t_s <= window[-1].t_s:  # a clock that did not move: start the window again
            window.clear()
        window.append(sample)
        rows = list(window)
        rpy = np.zeros((len(rows), 3))
        rpy[:, 2] = [r.yaw_rad for r in rows]
        body = Trajectory(np.array([r.t_s for r in rows]), np.array([r.body_rad for r in rows]),
                          np.array([r.root_m for r in rows]), joints=LEG_JOINTS, torso_rpy_rad=rpy)
        trace = balance_trace(self.config, body, robot_angles_deg(self.config, body))
        soles = {side: tuple(a[0] for a in sole_poses(trace.soles[side][-1:])) for side in SIDES}
        return FrameTelemetry(t_s=sample.t_s, joints=self.joints, goals_rad=ticks_to_angles(self.config, sample.ticks),
                              root_m=sample.root_m, root_rpy_rad=rpy[-1], com_m=trace.com_m[-1], zmp_m=trace.zmp_m[-1],
                              soles_m=soles, support_m=trace.support[-1], health=sample.health,
                              command=sample.command, felt=sample.felt)

    def on_frame(self, sample: DriveSample) -> None:
        self.publisher.on_frame(self.frame(sample))

    def close(self) -> None:
        self.publisher.close()
