"""Capture-point stepping: the DCM's error from the tilt (checked against the rigid body's exact geometry), the
next foothold moved toward the push and never beyond a [steer] limit or the soles' gap (checked from the sole
rectangles directly), and the stepping frame source walking the plan when nothing is felt."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from gaitbot.feel.capture import CapturePoint, dcm_error_m
from gaitbot.gait.balance.zmp_reference import FootPlacement
from helpers import Felt, config, op3_stepping_plan

G = 9.81


def test_the_dcm_error_is_the_tipped_com_and_its_velocity_over_omega():
    # a rigid body tipped about its support by theta at rate theta_dot: the CoM, h above it, moves h sin(theta)
    # at h cos(theta) theta_dot; its DCM moves by that plus the velocity over omega = sqrt(g / h)
    h, theta, rate = 0.24, math.radians(3.0), math.radians(40.0)
    omega = math.sqrt(G / h)
    exact = h * math.sin(theta) + h * math.cos(theta) * rate / omega
    x, y = dcm_error_m(0.0, 3.0, 0.0, 40.0, h)  # leaning and tipping forward
    assert x == pytest.approx(exact, rel=0.01) and y == 0.0
    x, y = dcm_error_m(-3.0, 0.0, -40.0, 0.0, h)  # roll negative: leaning left, the CoM goes to +y
    assert y == pytest.approx(exact, rel=0.01) and x == 0.0


def straight_feet(cfg, swing_side: str):
    half = cfg.body.geometry.hip_width_m / 2
    stance_side = "left" if swing_side == "right" else "right"
    sign = {"left": 1.0, "right": -1.0}
    stance = FootPlacement(stance_side, 0.0, sign[stance_side] * half)
    swing_from = FootPlacement(swing_side, -0.05, sign[swing_side] * half)
    planned = FootPlacement(swing_side, 0.05, sign[swing_side] * half)
    return stance, swing_from, planned


def boxes_gap(cfg, a: FootPlacement, b: FootPlacement) -> float:
    """The gap of two unturned soles, from their rectangles (the body's geometry), by the axes' overlaps."""
    g = cfg.body.geometry
    def box(f):
        x0 = f.x_m - g.heel_back_m
        y0 = f.y_m + (1 if f.side == "left" else -1) * g.sole_outward_m
        return x0, x0 + g.foot_m, y0 - g.foot_width_m / 2, y0 + g.foot_width_m / 2
    ax0, ax1, ay0, ay1 = box(a)
    bx0, bx1, by0, by1 = box(b)
    dx = max(bx0 - ax1, ax0 - bx1, 0.0)
    dy = max(by0 - ay1, ay0 - by1, 0.0)
    return math.hypot(dx, dy)


@settings(max_examples=200, deadline=None)
@given(st.floats(-0.15, 0.15), st.floats(-0.15, 0.15), st.sampled_from(["left", "right"]))
def test_the_moved_foothold_goes_toward_the_push_inside_the_limits_and_the_gap(ex, ey, side):
    cfg = config("op3")
    lim = cfg.steer
    capture = CapturePoint(cfg.body.geometry, lim)
    stance, swing_from, planned = straight_feet(cfg, side)
    step = capture.decide((ex, ey), stance, swing_from, planned)
    dx, dy = step.foothold.x_m - planned.x_m, step.foothold.y_m - planned.y_m
    if not step.beyond:
        assert (dx, dy) == (0.0, 0.0)
        return
    # toward the push: each axis moves the error's way or not at all, and the move is not against it
    assert dx * ex >= -1e-12 and dy * ey >= -1e-12
    assert dx * ex + dy * ey >= -1e-12
    # the [steer] limits: the move per axis, and the foot's place ahead of the stance foot
    assert -lim.max_backward_m - 1e-12 <= dx <= lim.max_forward_m + 1e-12
    assert abs(dy) <= lim.max_side_m + 1e-12
    ahead = step.foothold.x_m - stance.x_m
    assert -lim.max_backward_m - 1e-12 <= ahead <= planned.x_m - stance.x_m + lim.max_forward_m + 1e-12
    # the soles keep their gap where the foot lands (and never cross: the swing foot stays on its side)
    assert boxes_gap(cfg, stance, step.foothold) >= lim.min_gap_m - 1e-9
    assert (step.foothold.y_m - stance.y_m) * (1 if side == "left" else -1) > 0


def test_a_push_the_ankles_hold_moves_nothing_and_a_big_one_moves_the_step_to_its_side():
    cfg = config("op3")
    capture = CapturePoint(cfg.body.geometry, cfg.steer)
    stance, swing_from, planned = straight_feet(cfg, "left")
    assert capture.decide((0.002, 0.002), stance, swing_from, planned).foothold == planned
    pushed_left = capture.decide((0.0, 0.06), stance, swing_from, planned)
    assert pushed_left.beyond and pushed_left.foothold.y_m - planned.y_m == pytest.approx(cfg.steer.max_side_m)
    pushed_back = capture.decide((-0.06, 0.0), stance, swing_from, planned)
    assert pushed_back.foothold.x_m < planned.x_m


@pytest.fixture(scope="module")
def op3_plan():
    return op3_stepping_plan()


def test_nothing_felt_walks_the_plan_and_a_felt_push_left_moves_a_foothold_left(op3_plan):
    from gaitbot.drive.stepping import SteppingFrames
    from gaitbot.robot.calibration import trajectory_ticks

    cfg, plan = op3_plan
    planned = trajectory_ticks(cfg, plan.walk.trajectory(goals=True))
    quiet = SteppingFrames(cfg, plan, Felt(started=False))
    frames = np.array(list(quiet))
    assert frames.shape == planned.shape and not quiet.log.moved
    # the same steps, planned one at a time: within a few ticks of the offline plan (the preview sees one step
    # ahead, not the whole walk)
    assert np.abs(frames - planned).max() <= 0.01 * 4096
    leaning_left = SteppingFrames(cfg, plan, Felt(roll_deg=-4.0, rates=(-30.0, 0.0, 0.0)))
    walked = walked_moves(leaning_left)
    assert leaning_left.log.moved
    for _, step, _ in leaning_left.log.moved:
        assert step.moved_m[1] >= 0.0 and step.error_m[1] > 0
    # the moves are walked: steps start at footholds left of the plan's (after the pauses a lean toward the
    # lifting foot asks first, and at the part of the move the knee's speed allows from standing)
    assert any(dy > 0.005 for _, dy in walked) and all(dy >= 0.0 for _, dy in walked)


def walked_moves(frames, each=lambda: None) -> list[tuple[float, float]]:
    """Walk ``frames`` (a SteppingFrames) to its end, calling ``each()`` after every frame; for each step as it
    starts: its foothold's move from the plan's (dx, dy; m), read from the walker's queue, not from the log."""
    walked, seen = [], None
    for _ in frames:
        each()
        queued = frames._queued
        if queued is not None and queued is not seen and not frames.walker.last_step_unstarted:
            seen = queued
            walked.append((queued.foothold.x_m - queued.planned.x_m, queued.foothold.y_m - queued.planned.y_m))
    return walked


class FeltFrom(Felt):
    """Nothing felt until frame ``frame`` of the walk, then a lean backward (a push felt mid-walk; a lean toward
    a foot about to lift would pause the walk instead: the next test)."""

    def __init__(self, frame):
        super().__init__()
        self.frame, self.frames = frame, 0

    def tick(self):
        self.frames += 1
        if self.frames >= self.frame:
            self.pitch_deg, self.rates_dps = -6.0, np.array([0.0, -45.0, 0.0])


def test_a_push_felt_after_a_step_was_queued_moves_that_step_before_it_starts(op3_plan):
    """The step queued next, not started when the push is felt, is taken back and moved (requeued) once its
    check has passed, a stage a frame, rather than the push waiting for the next step to be queued."""
    from gaitbot.drive.step_check import STAGES
    from gaitbot.drive.stepping import CHECK_TRIES, SteppingFrames

    cfg, plan = op3_plan
    quiet = SteppingFrames(cfg, plan, Felt(started=False))
    queued_at = []  # the frames (after the first steps) at which a queued step has not started
    for n, _ in enumerate(quiet, start=1):
        if quiet.walker.last_step_unstarted and quiet.walker._k > 60:
            queued_at.append(n)
    felt_frame = queued_at[len(queued_at) // 2]
    felt = FeltFrom(felt_frame)
    pushed = SteppingFrames(cfg, plan, felt)
    walked = walked_moves(pushed, felt.tick)
    after = [(t, step, again) for t, step, again in pushed.log.moved if t >= (felt_frame - 1) / pushed.rate_hz]
    t_s, step, again = after[0]
    assert again, "the first move after the push was felt waited for a new step"
    assert t_s <= (felt_frame + 2 + STAGES * CHECK_TRIES) / pushed.rate_hz  # the check's frames, then queued
    assert step.moved_m[0] < -0.005 and step.error_m[0] < 0  # backward, where the push went
    assert any(dx < -0.005 for dx, _ in walked)  # and walked there


def test_a_lean_toward_the_foot_about_to_lift_pauses_on_both_feet_and_one_away_does_not(op3_plan):
    """A lean left (the DCM's error to the left) takes back a queued step of the left foot and stands on both
    feet for PAUSE_FRAMES instead, at most MAX_PAUSES in a row; the walk is then that much longer. A lean
    right pauses only before right steps, never before left ones."""
    from gaitbot.drive.stepping import MAX_PAUSES, PAUSE_FRAMES, SteppingFrames

    cfg, plan = op3_plan
    quiet = SteppingFrames(cfg, plan, Felt(started=False))
    n_quiet = len(list(quiet))
    assert not quiet.log.paused_s
    for roll_deg, side in ((-4.0, "left"), (4.0, "right")):
        leaning = SteppingFrames(cfg, plan, Felt(roll_deg=roll_deg, rates=(roll_deg * 7.5, 0.0, 0.0)))
        frames = list(leaning)
        pauses = leaning.log.paused_s
        assert pauses
        assert len(frames) >= n_quiet + PAUSE_FRAMES * len(pauses)  # (and the slower weight shift after one)
        steps = leaning.walker.planned_steps
        for t_s in pauses:  # the step that starts next after each pause lifts the foot the lean is toward
            assert next(s for s in steps if s.start_s > t_s).leg == side
        in_a_row = [sum(1 for u in pauses if t_s <= u < t_s + (MAX_PAUSES + 1) * PAUSE_FRAMES / 60) for t_s in pauses]
        assert max(in_a_row) <= MAX_PAUSES


@pytest.mark.parametrize("argv, words", [
    (("drive", "--robot", "op3", "--sim", "--feedback", "step"), "--feedback step: the live drive"),
    (("walk", "--robot", "op3", "--dry-run", "--feedback", "step", "--velocity", "0.05,0,0", "--duration", "2"),
     "--feedback step: only a balanced walk"),
])
def test_stepping_where_it_cannot_move_footholds_is_refused_in_one_line(capsys, argv, words):
    from helpers import run_cli

    code, out, err = run_cli(capsys, *argv)
    assert code == 2 and words in err and len(err.strip().splitlines()) == 1 and out == ""
