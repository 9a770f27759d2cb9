"""A walk on the simulated robot, and what the plan promised it (``gaitbot walk --sim``).

The physics, the port and the meter (model.py, physics.py, port.py, metrics.py) know nothing of the
gait: the planned distance, the swing windows and the footholds are taken from the walker here and
handed down as a WalkPlan. The walk itself runs exactly as ``gaitbot walk`` runs it (preflight,
LimitGuard, walk_session, --record); only the bus is the simulated robot's and the clock virtual.
"""

from __future__ import annotations

import json
import sys

from collections.abc import Callable

from gaitbot.bus.base import Bus
from gaitbot.bus.log import BusRecorder
from gaitbot.gait.segments import CLEARANCE_WINDOW
from gaitbot.gait.trajectory import Trajectory
from gaitbot.gait.walker import OnlineWalker
from gaitbot.robot.config import RobotConfig
from gaitbot.sim.metrics import SimReport, SwingWindow, WalkMeter, WalkPlan


def swing_windows(walker: OnlineWalker) -> tuple[SwingWindow, ...]:
    """For every planned step: the swinging leg over the part of its swing where the gait keeps the
    sole the configured clearance above the floor (CLEARANCE_WINDOW of the time from toe-off, at
    toe_off_u of the step, to heel strike)."""
    ctx = walker.ctx
    windows = []
    for step in walker.planned_steps:
        toe_off_s = step.start_s + ctx.toe_off_u * (step.end_s - step.start_s)
        span = step.end_s - toe_off_s
        windows.append(SwingWindow(step.leg, toe_off_s + CLEARANCE_WINDOW[0] * span,
                                   toe_off_s + CLEARANCE_WINDOW[1] * span))
    return tuple(windows)


def walk_plan(walker: OnlineWalker, trajectory: Trajectory) -> WalkPlan:
    """The plan in the simulation's terms: hip displacement, swing windows, and the heel strikes
    in the simulated world, whose x origin is the hip's starting point."""
    origin = float(trajectory.root_m[0, 0])
    return WalkPlan(distance_m=float(trajectory.root_m[-1, 0]) - origin, swings=swing_windows(walker),
                    footholds=tuple((h.leg, float(h.x_m) - origin) for h in walker.heel_strikes))


class SimWalk:
    """The simulated robot of one walk, its measurements and, if asked, its video."""

    def __init__(self, config: RobotConfig, rate_hz: float, plan: WalkPlan, free_pitch: bool = False,
                 video: str | None = None) -> None:
        from gaitbot.sim.physics import SimRobot

        self.config = config
        self.plan = plan
        self.robot = SimRobot(config, rate_hz, free_pitch)
        self.meter = WalkMeter(self.robot)
        self.robot.observers.append(self.meter)
        self.video = None
        if video:
            from gaitbot.sim.video import VideoRecorder

            self.video = VideoRecorder(self.robot, video, plan.footholds)
            self.robot.observers.append(self.video)

    def make_bus(self, now: Callable[[], float], recorder: BusRecorder | None) -> Bus:
        """The robot's bus on the simulated chain, its physics following ``now()`` (the session's clock)."""
        from gaitbot.sim.port import make_sim_bus

        return make_sim_bus(self.config, self.robot, now, recorder)

    def report(self) -> SimReport:
        return self.meter.report(self.plan, self.robot.free_pitch)

    def print_report(self, as_json: bool, outcome: str, on_progress=None) -> SimReport:
        """The measurements: a summary paragraph, or (``as_json``) one JSON object on stdout; returned too.
        ``on_progress(k, n)`` follows the video's encoding, if there is one."""
        report = self.report()
        frames = self.video.save(on_progress) if self.video is not None else 0
        if as_json:
            print(json.dumps({"robot": self.config.name, "outcome": outcome, **report.to_dict(),
                              "video": str(self.video.path) if self.video is not None else None}, indent=2))
        else:
            print(report.summary())
        if self.video is not None:
            print(f"video: {self.video.path} ({frames} frames)", file=sys.stderr if as_json else sys.stdout)
        return report
