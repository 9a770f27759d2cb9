"""Every planned step checked before the walker gets it: a step that would touch, tip or break a limit is
replaced by a stop (said once), the drive stands until the command changes, and what it sends stays standing
or walking within the limits; the planner's last resort is gap-checked too."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from gaitbot.app.options import load_robot
from gaitbot.drive.frames import DriveFrames
from gaitbot.drive.step_check import STAGES, StepCheck
from gaitbot.gait.balance.zmp_reference import FootPlacement
from gaitbot.gait.steer.command import TimedCommand, VelocityCommand
from gaitbot.gait.steer.planner import FootstepPlanner
from gaitbot.gait.steer.schedule import CommandError, CommandSchedule, plan_footsteps
from gaitbot.gait.steer.soles import swept_gap_m
from gaitbot.inputs.scripted import ScriptedSource
from gaitbot.robot.balanced_walk import balanced_walker
from gaitbot.robot.calibration import standing_ticks
from gaitbot.robot.steered_walk import footstep_planner

FORWARD = [TimedCommand(0.0, VelocityCommand(0.04, 0.0, 0.0)), TimedCommand(6.0, stop=True)]


def drive(config, commands):
    said = []
    frames = DriveFrames(config, ScriptedSource(commands), say=said.append)
    return frames, np.array(list(frames)), said


def inject(monkeypatch, step_number: int, move):
    """The planner's ``step_number``-th step (1-based, every call counts) replaced by ``move(planner, step)``."""
    original = FootstepPlanner.next_step
    calls = {"n": 0}

    def next_step(self, command, side):
        stance = self.feet["right" if side == "left" else "left"]
        old = self.feet[side]
        step = original(self, command, side)
        calls["n"] += 1
        if calls["n"] != step_number:
            return step
        foothold = move(stance, step.foothold)
        self.feet[side] = foothold
        return dataclasses.replace(step, foothold=foothold, gap_m=swept_gap_m(self.geometry, stance, old, foothold))

    monkeypatch.setattr(FootstepPlanner, "next_step", next_step)
    return calls


def frames_within_limits(config, ticks) -> None:
    """Every frame sent keeps its joints inside their position and velocity limits (one tick's rounding)."""
    angles = config.calibration.ticks_to_angles(ticks)
    tick = np.array([1.0 / j.model.ticks_per_rad for j in config.joints])
    low = np.radians([j.min_deg for j in config.joints]) - tick
    high = np.radians([j.max_deg for j in config.joints]) + tick
    assert ((angles >= low) & (angles <= high)).all()
    speed = np.abs(np.diff(angles, axis=0)) * 60
    assert (speed <= np.radians([j.max_velocity_dps for j in config.joints]) + 2 * tick * 60).all()


def test_a_step_onto_the_stance_foot_is_replaced_by_a_stop_said_once(monkeypatch):
    """The 4th step lands on the stance foot's sole: refused before the walker gets it; the drive slows to a
    stop and stands until the command changes (it never does here), then ends standing."""
    config = load_robot("op3")
    inject(monkeypatch, 4, lambda stance, f: FootPlacement(f.side, stance.x_m + 0.01, stance.y_m, stance.yaw_rad))
    frames, ticks, said = drive(config, FORWARD)
    assert frames.log.step_refusals >= 1
    refusals = [s for s in said if "replaced by a stop" in s]
    assert len(refusals) == 1 and "soles" in refusals[0] and "standing until the command changes" in refusals[0]
    assert frames.log.steps <= 6  # stopped: a slowing step, the close; no more steps under the refused command
    assert not frames.log.ended_by_refusal  # the stop in its place passed: no failure (exit 0)
    stand = standing_ticks(config)
    assert np.array_equal(ticks[0], stand) and np.array_equal(ticks[-1], stand)


def test_after_a_refusal_a_new_command_walks_again(monkeypatch):
    config = load_robot("op3")
    inject(monkeypatch, 4, lambda stance, f: FootPlacement(f.side, stance.x_m + 0.01, stance.y_m, stance.yaw_rad))
    commands = [TimedCommand(0.0, VelocityCommand(0.04, 0.0, 0.0)), TimedCommand(6.0, VelocityCommand(0.03, 0.0, 0.0)),
                TimedCommand(10.0, stop=True)]
    frames = DriveFrames(config, ScriptedSource(commands), say=lambda text: None)
    poses = [frames.walk_pose() for _ in frames]
    assert frames.log.step_refusals == 1
    assert poses[5 * 60] == poses[6 * 60]  # stood still until the command changed
    assert poses[-1][0] > poses[6 * 60][0] + 0.05  # then walked on under the new one


def test_a_step_beyond_the_legs_reach_is_refused_before_its_first_frame(monkeypatch):
    """A foothold 0.3 m ahead (the OP3's legs reach about half of it): refused, and no frame beyond a limit is
    ever sent (without the step check the walker would stretch a leg towards it)."""
    config = load_robot("op3")
    inject(monkeypatch, 3, lambda stance, f: FootPlacement(f.side, stance.x_m + 0.3, f.y_m, f.yaw_rad))
    frames, ticks, said = drive(config, FORWARD)
    refusal = next(s for s in said if "replaced by a stop" in s)
    assert "reach" in refusal or "limit" in refusal
    frames_within_limits(config, ticks)
    assert np.array_equal(ticks[-1], standing_ticks(config))


def test_a_step_that_would_tip_is_refused(monkeypatch):
    """A robot whose ZMP reference sits beyond its toes (balance zmp_forward_m past the sole): every step would
    put the planned ZMP outside the support polygon, so none is taken: the walker that had crouched to start
    stands up again, and as even a still step would fail the drive ends there, standing."""
    config = load_robot("op3")
    tipping = dataclasses.replace(config, balance=dataclasses.replace(config.balance, zmp_forward_m=0.1))
    frames, ticks, said = drive(tipping, FORWARD)
    refusals = [s for s in said if "replaced by a stop" in s]
    assert len(refusals) == 1 and "ZMP" in refusals[0]
    assert frames.log.steps == 0 and len(ticks) < 6 * 60 and frames.log.ended_by_refusal  # exit 1
    assert np.array_equal(ticks[-1], standing_ticks(config))


def test_an_ordinary_step_passes_and_the_check_leaves_the_walker_unchanged():
    config = load_robot("op3")
    walker = balanced_walker(config)
    planner = footstep_planner(config)
    walker.lead_with("right")
    step = planner.next_step(VelocityCommand(0.04, 0.0, 5.0), "right")
    before = {k: v.copy() for k, v in walker.plan_arrays().items()}
    feet = walker.feet
    check = StepCheck(config, walker.period_s)
    stages = check.stages(walker, step)
    for _ in range(STAGES):
        next(stages)
    with pytest.raises(StopIteration) as done:
        next(stages)
    assert done.value.value is None
    assert all(np.array_equal(before[k], v) for k, v in walker.plan_arrays().items())
    assert walker.feet == feet and not walker.planned_steps


def test_the_planners_last_resort_is_gap_checked():
    """Feet standing crossed (the left foot right of the right one): no push or halving keeps the soles apart,
    so the planner's last resort says how close it comes, and offline planning refuses it in one line."""
    config = load_robot("op3")
    g = config.body.geometry
    feet = {"left": FootPlacement("left", 0.0, -0.01, 0.0), "right": FootPlacement("right", 0.0, 0.01, 0.0)}
    planner = FootstepPlanner(g, config.steer, 0.3, feet)
    step = planner.next_step(VelocityCommand(0.04, 0.0, 0.0), "left")
    assert step.gap_m < config.steer.min_gap_m
    planner = FootstepPlanner(g, config.steer, 0.3, feet)
    schedule = CommandSchedule.of([TimedCommand(0.0, VelocityCommand(0.04, 0.0, 0.0)), TimedCommand(2.0, stop=True)],
                                  "test")
    with pytest.raises(CommandError, match="soles .* apart"):
        plan_footsteps(planner, schedule, 0.4, 0.3, 100)


def test_ordinary_steps_carry_their_gap():
    config = load_robot("op3")
    planner = footstep_planner(config)
    for side in ("left", "right", "left", "right"):
        step = planner.next_step(VelocityCommand(0.0, 0.02, 10.0), side)
        assert config.steer.min_gap_m <= step.gap_m < math.inf


def test_a_frame_beyond_a_limit_by_a_hair_is_brought_inside_and_more_is_refused():
    """The frame guard's window: a velocity 0.5% over the limit (the walker's rounding at a limit) is clipped to
    the limit and counted; 5% over is refused."""
    from gaitbot.drive.guard import FrameGuard

    config = load_robot("bioloid")
    guard = FrameGuard(config, 1 / 60)
    guard.reset(np.zeros(12))
    step = guard.max_velocity[3] / 60
    hair = np.zeros(12)
    hair[3] = 1.005 * step * 0.1  # a gentle start first (inside the acceleration limit)
    sent, reason = guard.admit(hair)
    assert reason is None and guard.clipped == 0
    guard.reset(np.zeros(12))
    guard.max_accel[:] = np.inf  # velocity alone
    over = np.zeros(12)
    over[3] = 1.005 * step
    sent, reason = guard.admit(over)
    assert reason is None and guard.clipped == 1 and abs(sent[3]) <= step
    guard.reset(np.zeros(12))
    over[3] = 1.05 * step
    sent, reason = guard.admit(over)
    assert sent is None and "deg/s" in reason
