"""The drive's frame source in process: poses against the commands, clipping said once, bounded stops."""

from __future__ import annotations

import math

import numpy as np
import pytest

from gaitbot.app.options import load_robot
from gaitbot.app.steer_walk import commanded_pose
from gaitbot.drive.frames import DriveFrames
from gaitbot.drive.guard import FrameGuard
from gaitbot.gait.steer.command import TimedCommand, VelocityCommand
from gaitbot.gait.steer.schedule import CommandSchedule
from gaitbot.inputs.scripted import ScriptedSource
from gaitbot.robot.calibration import standing_ticks

CASES = {"forward": (0.05, 0.0, 0.0), "turn in place": (0.0, 0.0, 10.0), "sidestep": (0.0, 0.02, 0.0),
         "backwards": (-0.04, 0.0, 0.0), "arc": (0.04, 0.0, 8.0)}


def drive(robot: str, commands, **options):
    said = []
    frames = DriveFrames(load_robot(robot), ScriptedSource(commands), say=said.append, **options)
    out = np.array(list(frames))
    return frames, out, said


@pytest.mark.parametrize("case", CASES)
def test_the_planned_pose_follows_the_commands_within_25_percent(case):
    """The commands integrated on their own (steer_walk.commanded_pose, a plain Euler sum of the velocities)
    against the drive's planned odometry; the drive starts stepping after the rise and ramps speed within the
    change limits, which the 25% allows for."""
    vx, vy, wz = CASES[case]
    commands = [TimedCommand(0.0, VelocityCommand(vx, vy, wz)), TimedCommand(8.0, stop=True)]
    frames, ticks, said = drive("op3", commands)
    x, y, heading = frames.walk_pose()
    cx, cy, ch = commanded_pose(CommandSchedule.of(commands, "test"))
    size = math.hypot(cx, cy)
    if size > 0.01:
        assert math.hypot(x - cx, y - cy) <= 0.25 * size
    else:
        assert math.hypot(x, y) <= 0.01
    assert abs(math.degrees(heading) - ch) <= 0.25 * abs(ch) + 0.5
    assert frames.log.refused is None and not said
    stand = standing_ticks(load_robot("op3"))
    assert np.array_equal(ticks[0], stand) and np.array_equal(ticks[-1], stand)  # starts and ends standing


def test_a_command_beyond_the_limits_is_clipped_and_said_once():
    commands = [TimedCommand(0.0, VelocityCommand(0.5, 0.0, 0.0)), TimedCommand(2.0, VelocityCommand(0.0, 0.0, 90.0)),
                TimedCommand(4.0, stop=True)]
    frames, _, said = drive("op3", commands)
    limits = load_robot("op3").steer
    assert frames.log.clipped
    assert len([s for s in said if "clipped" in s]) == 1
    # the clipped command asks exactly the step limit per step (dx = vx T)
    assert frames.top.vx_m_s * frames._planner.step_s == pytest.approx(limits.max_forward_m)


def test_an_end_stops_stepping_within_bounded_frames_and_stands():
    """A stop requested mid-walk (a signal) closes the feet and lowers: bounded by the queued step, the close
    and the lowering (a few steps' frames), not by the command still in force."""
    commands = [TimedCommand(0.0, VelocityCommand(0.06, 0.0, 5.0))]  # no stop entry: it would go on for ever
    frames = DriveFrames(load_robot("op3"), ScriptedSource(commands), say=lambda s: None)
    for k, _ in enumerate(frames):
        if k == 150:
            frames.stop_requested = True
        assert k < 150 + 5 * 60, "the stop took more than 5 s"
    assert frames.log.commands[-1].stop
    assert frames.walk_pose()[0] > 0.0


def test_still_commands_stand_and_a_later_command_walks_again():
    commands = [TimedCommand(0.0, VelocityCommand(0.05, 0.0, 0.0)), TimedCommand(3.0, VelocityCommand()),
                TimedCommand(10.0, VelocityCommand(0.05, 0.0, 0.0)), TimedCommand(13.0, stop=True)]
    frames, ticks, _ = drive("op3", commands)
    stand = standing_ticks(load_robot("op3"))
    standing = np.all(ticks == stand, axis=1)
    assert standing[round(9.5 * 60)]  # stood between the two walks (the stop: slow down, close, settle, lower)
    assert not standing[round(12.0 * 60)]  # and walked again
    assert frames.walk_pose()[0] > 0.15


def test_the_guard_refuses_a_frame_past_a_limit_or_too_fast():
    config = load_robot("op3")
    guard = FrameGuard(config, 1 / 60)
    guard.reset(np.zeros(12))
    assert guard.check(np.zeros(12)) is None
    jump = np.zeros(12)
    jump[3] = 0.5  # 0.5 rad in one frame: 30 rad/s, far over any servo
    assert "deg/s" in guard.check(jump)
    beyond = np.radians(np.full(12, 400.0))
    assert "outside" in guard.check(beyond)


def test_two_identical_drives_give_identical_frames():
    commands = [TimedCommand(0.0, VelocityCommand(0.04, 0.01, 6.0)), TimedCommand(3.0, stop=True)]
    _, a, _ = drive("bioloid", commands)
    _, b, _ = drive("bioloid", commands)
    assert np.array_equal(a, b)
