"""The balanced walker's own costs: a replan spread over frames walks (nearly) the frames of one done at once,
and a walk of any length holds bounded memory (the plan behind the output is dropped, frames unchanged)."""

from __future__ import annotations

import math

import numpy as np
import pytest

import gaitbot.gait.balance.lookahead as lookahead
from gaitbot.app.options import load_robot
from gaitbot.gait.steer.command import VelocityCommand
from gaitbot.robot.balanced_walk import balanced_gait_settings, balanced_walker
from gaitbot.robot.steered_walk import footstep_planner

OP3 = load_robot("op3")
GAIT = balanced_gait_settings(OP3)
COMMANDS = [VelocityCommand(0.05, 0.0, 0.0), VelocityCommand(0.0, 0.03, 0.0), VelocityCommand(0.03, 0.0, 15.0),
            VelocityCommand(-0.03, 0.0, 0.0), VelocityCommand(0.0, -0.03, -10.0)]
SPREAD_TOLERANCE_DEG = 0.1
"""The spread walk's angles against the at-once walk's: measured 0.05 deg at most (a sidestep), about half an
OP3 servo's tick (0.088 deg)."""


def steered_walk(spread: bool, steps: int, per_command: int = 4):
    """Frames of a steered OP3 walk, each step appended (as the drive does) once the one before has started."""
    walker = balanced_walker(OP3, GAIT)
    planner = footstep_planner(OP3, GAIT)
    walker.lead_with("left")
    frames, n = [], 0
    while True:
        now = walker._out / walker.rate_hz
        if n < steps and not any(s.start_s >= now for s in walker.planned_steps[-1:]):
            step = planner.next_step(COMMANDS[(n // per_command) % len(COMMANDS)], walker.next_swing_side)
            walker.append_footstep(step.foothold, max(0.0, step.length_m), spread=spread)
            n += 1
        elif spread:
            walker.work()
        frame = walker.next_frame()
        if frame is None:
            return walker, frames
        frames.append(frame)


def test_a_spread_replan_walks_the_frames_of_one_done_at_once():
    at_once, a = steered_walk(False, 20)
    spread, b = steered_walk(True, 20)
    assert spread.heel_strikes == at_once.heel_strikes  # the same footholds, exactly
    assert len(a) == len(b)
    q_a, q_b = np.array([f[1] for f in a]), np.array([f[1] for f in b])
    assert math.degrees(np.abs(q_a - q_b).max()) < SPREAD_TOLERANCE_DEG
    assert np.abs(np.array([f[3] for f in a]) - np.array([f[3] for f in b])).max() < 0.5e-3  # root, m
    assert np.abs(q_b).max() > 0.3  # it did walk


def test_dropping_the_plan_behind_the_output_changes_no_frame(monkeypatch):
    _, kept = steered_walk(True, 12, per_command=3)
    monkeypatch.setattr(lookahead, "STORED_FRAMES", 60)
    walker, trimmed = steered_walk(True, 12, per_command=3)
    assert walker.plan_start_frame > 300  # it did drop
    assert walker.stored_frames < 60 + 3 * walker.gains.horizon_frames
    for i in (1, 2, 3):
        assert np.array_equal(np.array([f[i] for f in kept]), np.array([f[i] for f in trimmed]))


@pytest.mark.slow
def test_five_minutes_of_walking_hold_bounded_memory():
    """A long walk without a stop, on the walker's own clock (no sleeping): its stores stay bounded. Five
    minutes drop the plan behind the output fifteen times (once STORED_FRAMES have gathered: about every 20 s)."""
    walker = balanced_walker(OP3, GAIT)
    planner = footstep_planner(OP3, GAIT)
    walker.lead_with("left")
    rng = np.random.default_rng(1)
    command, sizes = COMMANDS[0], []
    frames = round(5 * 60 * walker.rate_hz)
    for j in range(frames):
        if j % 180 == 0:
            command = COMMANDS[int(rng.integers(len(COMMANDS)))]
        now = walker._out / walker.rate_hz
        if not any(s.start_s >= now for s in walker.planned_steps[-1:]):
            step = planner.next_step(command, walker.next_swing_side)
            walker.append_footstep(step.foothold, max(0.0, step.length_m), spread=True)
        else:
            walker.work()
        assert walker.next_frame() is not None
        if j % 600 == 0:
            sizes.append(walker.stored_frames)
    bound = lookahead.STORED_FRAMES + lookahead.RESERVE_FRAMES + 3 * walker.gains.horizon_frames
    assert max(sizes) <= bound
    assert walker.plan_start_frame > frames - lookahead.STORED_FRAMES - walker.rise_frames



def walking_forward(steps: int):
    """A walker leading with the left foot with ``steps`` forward steps queued, and the planner that planned them."""
    walker = balanced_walker(OP3, GAIT)
    walker.lead_with("left")
    planner = footstep_planner(OP3, GAIT)
    for _ in range(steps):
        step = planner.next_step(COMMANDS[0], walker.next_swing_side)
        walker.append_footstep(step.foothold, step.length_m)
    return walker, planner


def test_a_step_taken_back_and_appended_elsewhere_plans_as_if_appended_there_at_once():
    """BalancedWalker.retract_last_step (a push felt after a step was queued, gaitbot.drive.stepping): the plan
    after taking back a queued step and appending another foothold is exactly the plan of a walker that was
    given that foothold in the first place (every per-frame array, the heel strikes and steps); a step that
    has started cannot be taken back."""
    from gaitbot.gait.balance.zmp_reference import FootPlacement

    def walked_to(first_side_offset_m: float, retract_to_m: float | None):
        walker, _ = walking_forward(3)
        for _ in range(walker.rise_frames + 30):
            walker.next_frame()
        stance = walker.feet["left" if walker.next_swing_side == "right" else "right"]
        side = walker.next_swing_side
        y = stance.y_m + (OP3.body.geometry.hip_width_m if side == "left" else -OP3.body.geometry.hip_width_m)
        walker.append_footstep(FootPlacement(side, stance.x_m + 0.04, y + first_side_offset_m, 0.0), 0.04)
        for _ in range(5):
            walker.next_frame()
        if retract_to_m is not None:
            assert walker.last_step_unstarted
            walker.retract_last_step()
            walker.append_footstep(FootPlacement(side, stance.x_m + 0.04, y + retract_to_m, 0.0), 0.04)
        return walker

    direct = walked_to(0.02, None)
    taken_back = walked_to(0.0, 0.02)
    assert taken_back.heel_strikes == direct.heel_strikes
    assert taken_back.planned_steps == direct.planned_steps
    assert taken_back.planned_frames == direct.planned_frames
    for key, a in direct.plan_arrays().items():
        np.testing.assert_array_equal(taken_back.plan_arrays()[key], a, err_msg=key)
    assert taken_back.heel_strikes != walked_to(0.0, None).heel_strikes  # the move did change the plan
    while taken_back.last_step_unstarted:
        taken_back.next_frame()
    with pytest.raises(RuntimeError):
        taken_back.retract_last_step()
    # both walk on to the end, stand, and the frames after the retraction converge on the direct walker's
    ends = []
    for walker in (direct, taken_back):
        frames = []
        while (frame := walker.next_frame()) is not None:
            frames.append(frame[1])
        ends.append(np.array(frames[-60:]))
    assert np.abs(ends[0] - ends[1]).max() < 1e-6


def test_a_step_previewed_in_place_of_the_queued_one_is_the_step_previewed_after_taking_that_one_back():
    """BalancedWalker.preview_step(replacing_last=True) (a moved step checked while the planned one stays
    queued, gaitbot.drive.stepping): the same arrays as a preview after retract_last_step, the walker
    unchanged; refused once the queued step has started."""
    import copy

    from gaitbot.gait.balance.zmp_reference import FootPlacement

    walker, _ = walking_forward(3)
    for _ in range(walker.rise_frames + 30):
        walker.next_frame()
    side = walker.next_swing_side
    stance = walker.feet["left" if side == "right" else "right"]
    y = stance.y_m + (OP3.body.geometry.hip_width_m if side == "left" else -OP3.body.geometry.hip_width_m)
    walker.append_footstep(FootPlacement(side, stance.x_m + 0.04, y, 0.0), 0.04)
    walker.next_frame()
    moved = FootPlacement(side, stance.x_m + 0.05, y + (0.02 if side == "left" else -0.02), 0.0)
    before = copy.deepcopy(walker.plan_arrays())
    arrays, first, end = walker.preview_step(moved, 0.05, before_frames=40, replacing_last=True)
    for key, a in before.items():  # the walker did not change
        np.testing.assert_array_equal(walker.plan_arrays()[key], a, err_msg=key)
    taken_back = copy.deepcopy(walker)
    taken_back.retract_last_step()
    expected, first_expected, end_expected = taken_back.preview_step(moved, 0.05, before_frames=40)
    assert (first, end) == (first_expected, end_expected)
    for key, a in expected.items():
        np.testing.assert_array_equal(arrays[key], a, err_msg=key)
    while walker.last_step_unstarted:
        walker.next_frame()
    with pytest.raises(RuntimeError):
        walker.preview_step(moved, 0.05, replacing_last=True)


def test_a_pause_stands_on_both_feet_with_the_zmp_between_them_and_the_next_step_shifts_its_weight_slowly():
    """BalancedWalker.append_pause (a push that lifting the next foot would make worse, gaitbot.drive.stepping):
    for its frames both feet stay where they stand and neither swings, the ZMP reference ends between the
    soles' centres and the weight half on each foot; the step after it takes a whole step's frames to move
    the ZMP onto its stance foot, as a walk's first step does, where one after a step takes the short
    double support."""
    from gaitbot.gait.balance.zmp_reference import standing_zmp

    def walker_after(pause_frames: int):
        walker, planner = walking_forward(2)
        before = walker.planned_frames
        feet = walker.feet
        if pause_frames:
            walker.append_pause(pause_frames)
        paused = walker.planned_frames
        step = planner.next_step(COMMANDS[0], walker.next_swing_side)
        walker.append_footstep(step.foothold, step.length_m)
        return walker, feet, before, paused

    walker, feet, before, paused = walker_after(48)
    a = walker.plan_arrays()
    assert paused - before == 48
    pause = slice(before, paused)
    assert not a["swinging"][pause].any()
    expected_ankles = [[feet[s].x_m, feet[s].y_m, OP3.body.geometry.ankle_height_m] for s in ("left", "right")]
    np.testing.assert_allclose(a["ankles"][pause], np.broadcast_to(expected_ankles, (48, 2, 3)))
    np.testing.assert_allclose(a["zmp"][paused - 1], standing_zmp(OP3.body.geometry, feet["left"], feet["right"]))
    assert a["share_left"][paused - 1] == pytest.approx(0.5)
    # the step after: double support (nothing swings) for a whole step's frames, then its swing
    after = a["swinging"][paused:]
    timing = walker.timing
    assert np.flatnonzero(after)[0] == timing.step_frames
    unpaused, _, before_b, _ = walker_after(0)
    assert np.flatnonzero(unpaused.plan_arrays()["swinging"][before_b:])[0] == timing.ds_frames
