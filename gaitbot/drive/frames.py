"""The live drive's frame source: poll the input, plan the next step, check, convert to ticks, one frame a call.

``DriveFrames`` is an iterator of tick frames (one per 60 Hz period) that a walk session streams
(gaitbot.stream.session.walk_session takes an iterator). Each frame, never blocking:
1. the input source is polled (its ``now_s`` is the frame's time on the drive's clock, k * period: the
   drive is deterministic on the virtual clock); its messages are said once;
2. the command is clipped to the robot's ``[steer]`` limits (said once per drive);
3. while the walker has fewer than ``queue_steps`` steps planned that have not started, ONE step is
   planned from the latest command (gaitbot.gait.steer.planner: per-step limits and change limits, the
   soles' swept gap) and checked before the walker gets it (gaitbot.drive.step_check: the gap, the planned
   ZMP inside the support polygon, the legs' predicted angles, velocities and accelerations; a stage a
   frame); a step that fails is replaced by a stop and the drive stands until the command changes;
4. the balanced walker computes the frame; the FrameGuard checks it (limits, velocity, acceleration)
   before it is sent: a frame outside by a hair is brought inside, one that fails is replaced by the
   session's stop ramp and the drive ends;
5. the angles become ticks through the robot's calibration.
A still command with the feet side by side stops stepping: the walker closes its feet, lowers to the
standing pose and the drive holds standing until a command moves it again (a new walker, from standing).
An end (the source's stop entry, START, a UDP stop, a signal, --max-time) stops stepping the same way and
then ends: bounded frames (the queued steps, the close, the lowering).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from gaitbot.drive.guard import FrameGuard
from gaitbot.drive.step_check import StepCheck
from gaitbot.gait.joints import LEG_JOINTS
from gaitbot.gait.steer.command import STILL, TimedCommand, VelocityCommand
from gaitbot.gait.steer.planner import frame_of, leading_side
from gaitbot.robot.balanced_walk import balanced_gait_settings, balanced_walker
from gaitbot.robot.calibration import standing_ticks
from gaitbot.robot.steered_walk import footstep_planner
from gaitbot.robot.walk_settings import joint_limits_ticks
from gaitbot.stream.ramps import stop_ticks

QUEUE_STEPS = 1
"""Steps planned ahead that have not started: 1 is the least latency (a command shows in the next step that
starts after the one already planned); the walker previews beyond it the close-and-stand it would do."""


def command_limits(limits, step_s: float) -> tuple[VelocityCommand, VelocityCommand]:
    """(most forward/left/counter-clockwise, most backward/right/clockwise) command the [steer] limits allow,
    each axis alone (the planner's per-step displacement: dx = vx T, dy = 2 vy T, dtheta = 2 wz T)."""
    top = VelocityCommand(limits.max_forward_m / step_s, limits.max_side_m / (2 * step_s),
                          limits.max_turn_deg / (2 * step_s))
    bottom = VelocityCommand(-limits.max_backward_m / step_s, -top.vy_m_s, -top.wz_deg_s)
    return top, bottom


def clip_command(command: VelocityCommand, top: VelocityCommand, bottom: VelocityCommand) -> VelocityCommand:
    return VelocityCommand(*(min(max(getattr(command, a), getattr(bottom, a)), getattr(top, a))
                             for a in ("vx_m_s", "vy_m_s", "wz_deg_s")))


@dataclass
class DriveLog:
    """What the drive did: planned odometry (x, y m, heading rad of the walk frame), distance walked (m),
    steps, whether a command was clipped, why it ended, the commands received (each change, timed)."""

    x_m: float = 0.0
    y_m: float = 0.0
    heading_rad: float = 0.0
    distance_m: float = 0.0
    steps: int = 0
    clipped: bool = False
    refused: str | None = None
    step_refusals: int = 0
    ended_by_refusal: bool = False  # a refused frame, or a step whose stop would fail too, ended the drive
    commands: list[TimedCommand] = field(default_factory=list)
    latencies_s: list[float] = field(default_factory=list)  # from a new command to the start of its first step


class DriveFrames:
    """The live frame source (see the module docstring). ``say(text)``: how messages reach the user;
    ``on_command(TimedCommand)``: each command received as it changes (--record-commands)."""

    def __init__(self, config, source, *, queue_steps: int = QUEUE_STEPS, max_time_s: float | None = None,
                 say=print, on_command=None) -> None:
        self.config = config
        self.source = source
        self.gait = balanced_gait_settings(config)
        self.period_s = 1.0 / self.gait.rate_hz
        self.queue_steps = queue_steps
        self.max_time_s = max_time_s
        self.say = say
        self.on_command = on_command
        self.guard = FrameGuard(config, self.period_s)
        self.step_check = StepCheck(config, self.period_s)
        self.guard.reset(np.zeros(len(LEG_JOINTS)))
        self.stand = standing_ticks(config)
        self.velocity_ticks, self.accel_ticks = joint_limits_ticks(config)
        self.log = DriveLog()
        self.k = 0
        self.ending = False
        self.stop_requested = False
        self.command = STILL
        self._received: VelocityCommand | None = None
        self._refused_command: VelocityCommand | None = None  # a step under it was refused: stand until it changes
        self._changed_s: float | None = None
        self._walker_k0 = 0
        self._walker = None
        self._planner = None
        self._origin = None
        self._sent: list[np.ndarray] = [self.stand, self.stand]
        self._ramp: list[np.ndarray] | None = None
        self._body = None  # the walker's frame last handed out (None: standing or ramping), for body_pose
        self._new_walker()
        self.top, self.bottom = command_limits(config.steer, self._planner.step_s)
        self.start_root_m = tuple(float(v) for v in self._walker.rise_path[0][0])

    def __iter__(self):
        return self

    def _new_walker(self) -> None:
        """A walker standing where the drive stands (its own world; the odometry composes it)."""
        # The robot's own [balance], not the speed fit's: the fit is of a straight walk (it shortens the double
        # support to slow the knee), and over the steering envelope that makes sidesteps' hip roll faster (op3:
        # 261 of 240 deg/s in a ten-minute drive); each step is checked before it is walked (step_check) and
        # each frame before it is sent (guard). Passing it also keeps the fit's tens of ms out of any frame.
        self._walker = balanced_walker(self.config, self.gait, self.config.balance)
        self._next_step = None
        self._checking = None
        self._planner = footstep_planner(self.config, self.gait)
        self._before_check = self._planner
        self._origin = frame_of(self._walker.feet)
        self._started = False

    # --- per frame ---------------------------------------------------------------------------------
    def __next__(self) -> np.ndarray:
        t_s = self.k * self.period_s
        if self._ramp is not None:
            return self._from_ramp()
        self._read_input(t_s)
        walker = self._walker
        if not self._started:
            if self.ending:
                raise StopIteration
            if self.command.is_still:
                return self._hand_out(self.stand)
            walker.lead_with(leading_side(self.command))
            self._started = True
            self._walker_k0 = self.k
        if not self._plan_ahead():  # a frame that plans, checks or appends a step leaves the replan's share for the next
            walker.work()  # a share of the last append's replan (BalancedWalker.work)
        frame = walker.next_frame()
        if frame is None:  # the walker has closed its feet and lowered to standing
            self._close_walker()
            return self.__next__() if self.ending else self._hand_out(self.stand)
        clipped = self.guard.clipped
        goal, reason = self.guard.admit(frame[2])
        if reason is not None:
            self._refuse(f"frame at {t_s:.2f} s refused: {reason}")
            return self._from_ramp()
        if self.guard.clipped > clipped and clipped == 0:
            self.say(f"frame at {t_s:.2f} s brought inside a joint's limits by a hair (said once; --json counts them)")
        ticks = self._hand_out(self.config.calibration.angles_to_ticks(goal, LEG_JOINTS))
        self._body = frame
        return ticks

    def _hand_out(self, ticks: np.ndarray) -> np.ndarray:
        self._body = None
        self._sent = [self._sent[1], ticks]
        self.k += 1
        return ticks

    def _read_input(self, t_s: float) -> None:
        reading = self.source.poll(t_s)
        for message in reading.messages:
            self.say(message)
        if reading.command != self._received and not reading.end:
            self._received = reading.command
            self._record(TimedCommand(round(t_s, 6), reading.command))
        clipped = clip_command(reading.command, self.top, self.bottom)
        if clipped != reading.command and not self.log.clipped:
            self.log.clipped = True
            c = reading.command
            self.say(f"command ({c.vx_m_s:g} m/s, {c.vy_m_s:g} m/s, {c.wz_deg_s:g} deg/s) is beyond the robot's "
                     f"[steer] limits: clipped to ({clipped.vx_m_s:.3g}, {clipped.vy_m_s:.3g}, "
                     f"{clipped.wz_deg_s:.3g}) (said once)")
        end = reading.end or self.stop_requested or (self.max_time_s is not None and t_s >= self.max_time_s)
        if end and not self.ending:
            self.ending = True
            self._record(TimedCommand(round(t_s, 6), stop=True))
        if self._refused_command is not None and clipped != self._refused_command:
            self._refused_command = None
        command = STILL if self.ending or clipped == self._refused_command else clipped
        if command != self.command:
            self._changed_s = t_s
        self.command = command

    def _record(self, timed: TimedCommand) -> None:
        self.log.commands.append(timed)
        if self.on_command is not None:
            self.on_command(timed)

    def _plan_ahead(self) -> bool:
        """At most one piece of planning a frame, while fewer than queue_steps planned steps have not
        started: a step is planned in one frame, checked over the next step_check.STAGES frames (a stage a
        frame) and handed to the walker in the frame after (spreading the work). Returns whether this frame
        did a piece of that work (the walker's spread replan then waits for the next frame)."""
        walker, planner = self._walker, self._planner
        if self._next_step is not None:
            step, self._next_step = self._next_step, None
            if not (walker.finished or self.ending):
                self._append(step)
                return True
            return False
        if self._checking is not None:
            if walker.finished or self.ending:  # dropped: the planner forgets the step
                self._checking, self._planner = None, self._before_check
                return False
            try:
                next(self._checking)
            except StopIteration as done:
                self._checking = None
                if done.value is None:  # even slowing down would not pass: no more steps
                    self.ending = self.log.ended_by_refusal = True
                else:
                    self._next_step = done.value
            return True
        if walker.finished or self.ending:
            return False
        if self.command.is_still and planner.standing():
            return False
        now_s = walker._out / walker.rate_hz
        pending = sum(1 for s in walker.planned_steps[-self.queue_steps - 1:] if s.start_s >= now_s)
        if pending >= self.queue_steps:
            return False
        self._before_check = planner.copy()
        self._checking = self._checked_step(walker.next_swing_side, self.command)
        next(self._checking)
        return True

    def _checked_step(self, side: str, command: VelocityCommand):
        """A generator, one stage a frame: the planner's next step, then its check before the walker gets it
        (gaitbot.drive.step_check: the soles' swept gap, the planned ZMP inside the support polygon, the
        legs' angles, velocities and accelerations); returns the step. A step that fails is replaced by a
        stop: a slowing-down step (the still command, within the change limits) planned from the state
        before it, and the drive stands until the command changes; if that fails too, None (the walker
        closes the feet and the drive ends). The first refusal is said once."""
        for attempt in (command, STILL):
            step = self._planner.next_step(attempt, side)
            yield
            reason = yield from self.step_check.stages(self._walker, step)
            if reason is None:
                return step
            self.log.step_refusals += 1
            self._refused_command = command
            if self.log.refused is None:
                self.log.refused = f"a step at {self.k * self.period_s:.2f} s {reason}: replaced by a stop"
                self.say(self.log.refused + "; standing until the command changes (said once)")
            self._planner = self._before_check.copy()
        return None

    def _append(self, step) -> None:
        walker = self._walker
        walker.append_footstep(step.foothold, max(0.0, step.length_m), spread=True)
        if self._changed_s is not None:  # the first step planned since the command changed
            start_s = self._walker_k0 * self.period_s + walker.planned_steps[-1].start_s
            self.log.latencies_s.append(start_s - self._changed_s)
            self._changed_s = None
        self.log.steps += 1
        leading = step.side_m * (1 if step.foothold.side == "left" else -1) > 0
        self.log.distance_m += math.hypot(step.forward_m, step.side_m if leading else 0.0)

    def _close_walker(self) -> None:
        """The walker stands: add its displacement to the odometry and get a fresh one for the next command."""
        x, y, yaw = self.walk_pose()
        self.log.x_m, self.log.y_m, self.log.heading_rad = x, y, yaw
        self._new_walker()
        self.guard.reset(np.zeros(len(LEG_JOINTS)))

    def walk_pose(self) -> tuple[float, float, float]:
        """The planned pose now (x, y m, heading rad): the odometry so far and the current walker's feet."""
        here, origin = frame_of(self._planner.feet), self._origin
        dx, dy = here.x_m - origin.x_m, here.y_m - origin.y_m
        c, s = math.cos(self.log.heading_rad), math.sin(self.log.heading_rad)
        return (self.log.x_m + c * dx - s * dy, self.log.y_m + s * dx + c * dy,
                self.log.heading_rad + here.yaw_rad - origin.yaw_rad)

    def body_pose(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, float]:
        """The frame last handed out, for the view (gaitbot.view.drive_telemetry): its ticks, the planned body
        angles (LEG_JOINTS, rad; 0 while standing or ramping), the root (m) and the torso's yaw (rad), both
        in the drive's frame (the odometry composed as in walk_pose)."""
        if self._body is None:
            q, root, yaw = np.zeros(len(LEG_JOINTS)), self._walker.rise_path[0][0], 0.0
        else:
            q, root, yaw = self._body[1], self._body[3], self._walker.last_torso_yaw_rad()
        origin, heading = self._origin, self.log.heading_rad
        c, s = math.cos(heading), math.sin(heading)
        dx, dy = root[0] - origin.x_m, root[1] - origin.y_m
        world = np.array([self.log.x_m + c * dx - s * dy, self.log.y_m + s * dx + c * dy, root[2]])
        return self._sent[1], q, world, heading + yaw - origin.yaw_rad

    def _refuse(self, reason: str) -> None:
        self.log.ended_by_refusal = True
        if self.log.refused is None:
            self.log.refused = reason
            self.say(reason)
        previous, last = self._sent
        self._ramp = list(stop_ticks(previous, last, self.stand, self.velocity_ticks, self.accel_ticks, self.period_s))

    def _from_ramp(self) -> np.ndarray:
        if not self._ramp:
            raise StopIteration
        return self._hand_out(np.asarray(self._ramp.pop(0), dtype=np.int64))
