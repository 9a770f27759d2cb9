"""A walk on the simulated robot, and what the plan promised it (``gaitbot walk --sim``).

The physics, the port and the meter (model.py, model3d.py, physics.py, port.py, metrics.py) know nothing
of the gait: the planned distance, the swing windows, the heel strikes and the first pose are taken
from the walker here and handed down as a WalkPlan. The walk itself runs exactly as ``gaitbot walk``
runs it (preflight, LimitGuard, walk_session, --record); only the bus is the simulated robot's and the
clock virtual. ``--push`` is a Pusher observer: a sideways force on the torso for PUSH_DURATION_S,
starting in the middle of the swing of the step half-way through the walk.
"""

from __future__ import annotations

import json
import math
import sys
from collections.abc import Callable
from dataclasses import dataclass, replace

import numpy as np

from gaitbot.bus.base import Bus
from gaitbot.bus.recording import BusRecorder
from gaitbot.gait.walk_segments import CLEARANCE_WINDOW
from gaitbot.gait.trajectory import Trajectory
from gaitbot.robot.config import RobotConfig
from gaitbot.sim.metrics import PlannedStrike, SimReport, SwingWindow, WalkMeter, WalkPlan

PUSH_DURATION_S = 0.1


def swing_windows(walker) -> tuple[SwingWindow, ...]:
    """For every planned step: the swinging leg over the part of its swing where the gait keeps the
    sole the configured clearance above the floor (CLEARANCE_WINDOW of the time from toe-off to heel
    strike). Planar walker: toe-off at toe_off_u of the step; balanced walker: at the end of double support."""
    windows = []
    if hasattr(walker, "ctx"):
        for step in walker.planned_steps:
            toe_off_s = step.start_s + walker.ctx.toe_off_u * (step.end_s - step.start_s)
            span = step.end_s - toe_off_s
            windows.append(SwingWindow(step.leg, toe_off_s + CLEARANCE_WINDOW[0] * span,
                                       toe_off_s + CLEARANCE_WINDOW[1] * span))
        return tuple(windows)
    swinging, rate = walker.walk.swinging, 1.0 / (walker.walk.t_s[1] - walker.walk.t_s[0])
    edges = np.flatnonzero(np.diff(np.r_[0, swinging, 0]))
    for start, end in zip(edges[:-1], edges[1:]):
        if swinging[start]:
            # frame k holds the pose at k / rate: the swing spans (start - 1, end - 1] / rate
            begin, finish = (start - 1) / rate, (end - 1) / rate
            span = finish - begin
            leg = "left" if swinging[start] == 1 else "right"
            windows.append(SwingWindow(leg, begin + CLEARANCE_WINDOW[0] * span, begin + CLEARANCE_WINDOW[1] * span))
    return tuple(windows)


def walk_plan(walker, trajectory: Trajectory) -> WalkPlan:
    """The plan in the simulation's terms, in the plan's world, with the walk's first pose."""
    strikes = tuple(PlannedStrike(h.t_s, h.leg, float(h.x_m), h.y_m) for h in walker.heel_strikes)
    return WalkPlan(distance_m=float(trajectory.root_m[-1, 0] - trajectory.root_m[0, 0]),
                    swings=swing_windows(walker), footholds=tuple((h.leg, float(h.x_m)) for h in walker.heel_strikes),
                    heel_strikes=strikes, lateral_m=float(trajectory.root_m[-1, 1] - trajectory.root_m[0, 1]),
                    start_angles_rad=dict(zip(trajectory.joints, (float(a) for a in trajectory.angles_rad[0]))),
                    start_root_m=tuple(float(v) for v in trajectory.root_m[0]))


@dataclass(frozen=True)
class Push:
    """An impulse (N s) from start_s, in step ``step`` (its ``leg`` swinging), horizontal, ``direction_deg`` from
    forward (the walk's +x), counter-clockwise: 90 (the default) pushes to the left, and a negative
    impulse the opposite way. ``phase``: where in the step it came (mid_walk_push), None for mid-swing."""

    impulse_n_s: float
    start_s: float
    step: int
    leg: str
    direction_deg: float = 90.0
    phase: float | None = None

    @property
    def end_s(self) -> float:
        return self.start_s + PUSH_DURATION_S

    def to_dict(self) -> dict:
        return {"impulse_n_s": self.impulse_n_s, "direction_deg": self.direction_deg, "start_s": self.start_s,
                "end_s": self.end_s, "step": self.step, "leg": self.leg, "phase": self.phase}


def mid_walk_push(plan: WalkPlan, impulse_n_s: float, direction_deg: float = 90.0,
                  phase: float | None = None) -> Push:
    """The push of ``--push``, in the step half-way through the walk: at ``phase`` of it (``--push-phase``; 0
    as its foot lifts, 1 as the next foot lifts: its swing, then the double support after it), or without
    a phase in the middle of its swing."""
    if not plan.swings:
        raise ValueError("the walk has no steps to push in")
    index = len(plan.swings) // 2
    window = plan.swings[index]
    if phase is None:
        start_s = 0.5 * (window.start_s + window.end_s)
    else:
        after_s = plan.swings[min(index + 1, len(plan.swings) - 1)].start_s
        start_s = window.start_s + phase * max(after_s - window.start_s, 0.0)
    return Push(impulse_n_s, start_s, index + 1, window.leg, direction_deg, phase)


class Pusher:
    """An observer that applies a Push: the force is set at frame ends, so it acts on whole frames."""

    def __init__(self, push: Push, frame_s: float) -> None:
        self.push = push
        frames = max(1, round(PUSH_DURATION_S / frame_s))
        self.force_n = push.impulse_n_s / (frames * frame_s)
        angle = math.radians(push.direction_deg)
        self.force_xy_n = (self.force_n * math.cos(angle), self.force_n * math.sin(angle))
        self.frames_left = frames

    def __call__(self, robot) -> None:
        on = self.frames_left > 0 and robot.time_s + 1e-9 >= self.push.start_s
        if on:
            self.frames_left -= 1
        robot.push(self.force_xy_n[1] if on else 0.0, self.force_xy_n[0] if on else 0.0)


class SimWalk:
    """The simulated robot of one walk, its measurements and, if asked, its video and push."""

    def __init__(self, config: RobotConfig, rate_hz: float, plan: WalkPlan, support: str = "free",
                 video: str | None = None, push_n_s: float | None = None, push_direction_deg: float = 90.0,
                 foreign: tuple | None = None, imu_seed: int = 0, imu_fault: str | None = None,
                 push_phase: float | None = None) -> None:
        """``foreign``: (model file, SimMap) of another author's model (gaitbot.sim.foreign), else gaitbot's own."""
        from gaitbot.sim.physics import SimRobot

        self.config = config
        self.plan = plan
        self.imu_seed, self.imu_fault = imu_seed, imu_fault
        self.extra: dict = {}  # more for the JSON object (the feedback mode, the fall the IMU noticed)
        if foreign is not None:
            from gaitbot.sim.foreign import ForeignRobot

            self.robot = ForeignRobot(config, rate_hz, *foreign)
        else:
            self.robot = SimRobot(config, rate_hz, support=support)
        if self.robot.planar:  # today's planar model starts standing straight, its hip at x = 0
            self.plan = plan = replace(plan, x_origin_m=plan.start_root_m[0] if plan.start_root_m else 0.0)
        elif plan.start_angles_rad is not None:  # the 3D model stands in the walk's first pose, in its world
            self.robot.place(plan.start_angles_rad, plan.start_root_m)
        self.meter = WalkMeter(self.robot, plan)
        self.robot.observers.append(self.meter)
        self.push = None
        if push_n_s:
            self.push = mid_walk_push(plan, push_n_s, push_direction_deg, push_phase)
            self.robot.observers.append(Pusher(self.push, self.robot.frame_s))
        self.video = None
        if video:
            from gaitbot.sim.video import VideoRecorder

            self.video = VideoRecorder(self.robot, video, plan.footholds, plan.x_origin_m)
            self.robot.observers.append(self.video)

    def make_bus(self, now: Callable[[], float], recorder: BusRecorder | None) -> Bus:
        """The robot's bus on the simulated chain, its physics following ``now()`` (the session's clock)."""
        from gaitbot.sim.port import make_sim_bus

        return make_sim_bus(self.config, self.robot, now, recorder, self.imu_seed, self.imu_fault)

    def tilt_crossed_s(self, threshold_deg: float) -> float | None:
        """When the torso's true tilt (the angle between its z axis and the world's up, the measure of the
        IMU estimate's tilt_deg; not the hypot of roll and pitch, which overstates a tilt both ways at once)
        first passed ``threshold_deg`` (frame ends), or None: the yardstick of how soon a fall is noticed."""
        for t_s, tilt_deg in zip(self.meter.times_s, self.meter.tilt_deg):
            if tilt_deg > threshold_deg:
                return float(t_s)
        return None

    def report(self) -> SimReport:
        return self.meter.report(self.plan, self.robot.free_pitch,
                                 self.push.to_dict() if self.push is not None else None)

    def print_report(self, as_json: bool, outcome: str, on_progress=None) -> SimReport:
        """The measurements: a summary paragraph, or (``as_json``) one JSON object on stdout; returned too.
        ``on_progress(k, n)`` follows the video's encoding, if there is one."""
        report = self.report()
        frames = self.video.save(on_progress) if self.video is not None else 0
        if as_json:
            print(json.dumps({"robot": self.config.name, "outcome": outcome, **report.to_dict(), **self.extra,
                              "video": str(self.video.path) if self.video is not None else None}, indent=2))
        else:
            print(report.summary())
        if self.video is not None:
            print(f"video: {self.video.path} ({frames} frames)", file=sys.stderr if as_json else sys.stdout)
        return report
