"""The footstep planner and the balanced walk in the plane of turned feet (docs/steering.md).

Checked against independent computations: the soles' gap from the legs' forward kinematics of the walk's
angles (not the planner's own footholds), the feet's yaw from forward kinematics, the commands' end pose
integrated apart from the planner, and the straight walk of the same steps through ``--steps``.
"""

import math

import numpy as np
import pytest

from gaitbot.app.cli import build_parser
from gaitbot.app.planned_walk import planned_walk
from gaitbot.app.steer_walk import commanded_pose, planned_pose
from gaitbot.gait.body import SIDE_SIGN
from gaitbot.gait.joints import SIDES
from gaitbot.gait.kinematics6 import foot_pose, sole_corners
from gaitbot.gait.steer.command import STILL, VelocityCommand
from gaitbot.gait.steer.planner import leading_side
from gaitbot.gait.steer.schedule import CommandSchedule, plan_footsteps
from gaitbot.robot.steered_walk import footstep_planner, plan_steered, steering_timing
from gaitbot.robot.balanced_walk import balanced_gait_settings
from helpers import config

OP3 = config("op3")
WALKS = {"turn": VelocityCommand(0.0, 0.0, 12.0), "side_left": VelocityCommand(0.0, 0.03, 0.0),
         "side_right": VelocityCommand(0.0, -0.03, 0.0), "backward": VelocityCommand(-0.04, 0.0, 0.0),
         "arc": VelocityCommand(0.04, 0.0, -8.0), "turn_and_side": VelocityCommand(0.02, 0.02, 10.0)}


@pytest.fixture(scope="module")
def walks():
    """Each walk (6 s of its command) planned once for op3: {name: (plan, footsteps)}."""
    return {name: plan_steered(OP3, CommandSchedule.steady(c, 6.0)) for name, c in WALKS.items()}


def args_for(*argv):
    return build_parser().parse_args(["generate", "--robot", "op3", *argv, "-o", "unused.csv"])


def test_a_straight_velocity_walk_is_the_steps_walk_of_the_same_steps():
    walk = planned_walk(args_for("--velocity", "0.07,0,0", "--duration", "3"))
    plan, trajectory = walk.plan, walk.planned
    lengths = [f.length_m for f in plan.footsteps]
    assert lengths[0] < lengths[1] and lengths[-1] == 0.0  # the ramp up, and the closing step
    straight = planned_walk(args_for("--steps", ",".join(repr(x) for x in lengths))).planned
    assert np.array_equal(trajectory.angles_rad, straight.angles_rad)
    assert np.array_equal(trajectory.root_m, straight.root_m)
    assert trajectory.torso_rpy_rad is None and trajectory.heel_strikes == straight.heel_strikes


def soles_from_angles(trajectory):
    """Each sole's corners (N, 4, 2) in the world from forward kinematics of the angles and the torso yaw."""
    g = OP3.body.geometry
    yaw = trajectory.torso_rpy_rad[:, 2] if trajectory.torso_rpy_rad is not None else np.zeros(len(trajectory.t_s))
    c, s = np.cos(yaw)[:, None], np.sin(yaw)[:, None]
    out = {}
    for i, side in enumerate(SIDES):
        local = sole_corners(g, side, trajectory.angles_rad[:, 6 * i:6 * i + 6])
        x = trajectory.root_m[:, None, 0] + c * local[..., 0] - s * local[..., 1]
        y = trajectory.root_m[:, None, 1] + s * local[..., 0] + c * local[..., 1]
        out[side] = np.stack([x, y], axis=-1)
    return out


def least_gap(a, b):
    """Least corner-to-edge distance between convex quadrilaterals a and b (N, 4, 2), vectorised (no overlap
    assumed: checked apart by the corners-inside test)."""
    best = np.full(len(a), np.inf)
    for p, q in ((a, b), (b, a)):
        for k in range(4):
            e0, e1 = q[:, k], q[:, (k + 1) % 4]
            d = e1 - e0
            for j in range(4):
                t = np.clip(np.einsum("ni,ni->n", p[:, j] - e0, d) / np.einsum("ni,ni->n", d, d), 0, 1)
                best = np.minimum(best, np.linalg.norm(e0 + t[:, None] * d - p[:, j], axis=1))
    return best


@pytest.mark.parametrize("name", sorted(WALKS))
def test_the_soles_keep_their_gap_over_every_frame(walks, name):
    plan, _ = walks[name]
    soles = soles_from_angles(plan.walk.trajectory())
    gap = least_gap(soles["left"], soles["right"])
    # no corner of one sole inside the other (each sole's corners on the outer side of some edge of the other)
    assert gap.min() >= OP3.steer.min_gap_m - 1e-3, f"{name}: soles {1e3 * gap.min():.1f} mm apart"


@pytest.mark.parametrize("name", sorted(WALKS))
def test_every_step_keeps_the_limits(walks, name):
    lim = OP3.steer
    steps = walks[name][1]
    prev = (0.0, 0.0, 0.0)
    for f in steps:
        assert -lim.max_backward_m - 1e-12 <= f.forward_m <= lim.max_forward_m + 1e-12
        assert abs(f.side_m) <= lim.max_side_m + 1e-12 and abs(f.turn_deg) <= lim.max_turn_deg + 1e-9
        assert abs(f.forward_m - prev[0]) <= lim.max_change_forward_m + 1e-12
        assert abs(f.side_m - prev[1]) <= lim.max_change_side_m + 1e-12
        assert abs(f.turn_deg - prev[2]) <= lim.max_change_turn_deg + 1e-9
        prev = (f.forward_m, f.side_m, f.turn_deg)


@pytest.mark.parametrize("name, first", [("turn", "left"), ("side_left", "left"), ("side_right", "right"),
                                         ("arc", "right")])
def test_a_turn_or_sidestep_leads_with_the_foot_on_its_side(walks, name, first):
    steps = walks[name][1]
    assert steps[0].foothold.side == first
    for f in steps[:-2]:
        if f.foothold.side != first:  # the other foot follows: it closes parallel, never opens or crosses
            assert abs(f.dtheta_deg) < 1e-9
            assert SIDE_SIGN[f.foothold.side] * f.dy_m >= OP3.body.geometry.hip_width_m - 1e-9
        else:  # the leading foot opens outward
            assert f.dtheta_deg * SIDE_SIGN[first] >= 0.0


@pytest.mark.parametrize("name", sorted(WALKS))
def test_a_stop_brings_the_feet_side_by_side_with_the_weight_between(walks, name):
    plan, _ = walks[name]
    walk, g = plan.walk, OP3.body.geometry
    left, right = walk.ankles_m[-1, 0], walk.ankles_m[-1, 1]
    assert walk.feet_yaw_rad[-1, 0] == pytest.approx(walk.feet_yaw_rad[-1, 1], abs=1e-12)
    assert np.hypot(*(left[:2] - right[:2])) == pytest.approx(g.hip_width_m, abs=1e-9)
    heading = walk.feet_yaw_rad[-1, 0]
    across = np.array([-math.sin(heading), math.cos(heading)])
    assert np.dot(left[:2] - right[:2], across) == pytest.approx(g.hip_width_m, abs=1e-9)  # left on the left
    assert np.allclose(walk.zmp_ref_m[-1], 0.5 * (left[:2] + right[:2]) + (g.foot_m / 2 - g.heel_back_m) *
                       np.array([math.cos(heading), math.sin(heading)]), atol=1e-9)


@pytest.mark.parametrize("name", sorted(WALKS))
def test_footholds_land_exactly_where_planned_and_the_swing_turns_smoothly(walks, name):
    plan, steps = walks[name]
    walk = plan.walk
    swinging = walk.swinging
    landings = [k for k in range(1, len(swinging)) if swinging[k - 1] and not swinging[k]]
    assert len(landings) == len(steps)
    for k, f in zip(landings, steps):
        i = SIDES.index(f.foothold.side)
        assert walk.ankles_m[k - 1, i, 0] == f.foothold.x_m and walk.ankles_m[k - 1, i, 1] == f.foothold.y_m
        assert walk.feet_yaw_rad[k - 1, i] == f.foothold.yaw_rad
        start = k - 1
        while swinging[start - 1]:
            start -= 1
        rate = np.diff(walk.feet_yaw_rad[start - 1:k, i])
        if np.abs(rate).max() > 1e-6:  # a turning swing: at rest in yaw where it lifts off and touches down
            assert abs(rate[0]) < 0.01 * np.abs(rate).max() and abs(rate[-1]) < 0.01 * np.abs(rate).max()


def test_the_hip_yaw_joints_turn_the_feet_and_the_torso_follows_their_mean(walks):
    plan, _ = walks["turn_and_side"]
    trajectory = plan.walk.trajectory()
    torso = trajectory.torso_rpy_rad[:, 2]
    feet = []
    for i, side in enumerate(SIDES):
        _, rot = foot_pose(OP3.body.geometry, side, trajectory.angles_rad[:, 6 * i:6 * i + 6])
        feet.append(torso + np.arctan2(rot[:, 1, 0], rot[:, 0, 0]))  # flat feet: yaw from the x axis
    feet = np.stack(feet, axis=1)
    assert np.allclose(feet, plan.walk.yaw_rad, atol=1e-9)
    assert np.allclose(torso, feet.mean(axis=1), atol=1e-9)
    assert np.abs(trajectory.angles_rad[:, [0, 6]]).max() > math.radians(2)  # the hip yaw joints do it


@pytest.mark.parametrize("name", sorted(WALKS))
def test_the_plan_is_within_a_quarter_of_the_command(walks, name):
    plan, _ = walks[name]
    schedule = CommandSchedule.steady(WALKS[name], 6.0)
    cx, cy, ch = commanded_pose(schedule)
    steered = type("P", (), {"walk": plan.walk})
    px, py, ph = planned_pose(steered)
    assert math.hypot(px - cx, py - cy) <= 0.25 * math.hypot(cx, cy) + 0.01
    assert abs(ph - ch) <= 0.25 * abs(ch) + 1.0


def test_the_commands_end_pose_is_integrated_apart_from_the_planner():
    # a quarter turn at 10 deg/s while walking 0.05 m/s: a quarter circle of radius v / w
    cx, cy, ch = commanded_pose(CommandSchedule.steady(VelocityCommand(0.05, 0.0, 10.0), 9.0))
    r = 0.05 / math.radians(10.0)
    assert (cx, cy, ch) == pytest.approx((r, r, 90.0), abs=2e-4)


def test_the_planner_is_incremental_and_a_copy_replans_alone():
    gait = balanced_gait_settings(OP3)
    planner = footstep_planner(OP3, gait)
    go = VelocityCommand(0.07, 0.0, 10.0)
    first = [planner.next_step(go, side) for side in ("left", "right", "left")]
    ahead = planner.copy()
    planned_ahead = [ahead.next_step(go, side) for side in ("right", "left")]  # a look-ahead under the command
    replanned = [planner.next_step(STILL, side) for side in ("right", "left", "right", "left")]  # it changed
    assert planned_ahead[0].foothold != replanned[0].foothold  # the copy did not move the planner
    assert replanned[0].forward_m == pytest.approx(first[-1].forward_m - OP3.steer.max_change_forward_m)
    assert planner.standing() and len(first) == 3


def test_the_walk_ends_once_the_stop_has_closed_the_feet():
    gait = balanced_gait_settings(OP3)
    t = steering_timing(OP3, gait)
    steps = plan_footsteps(footstep_planner(OP3, gait), CommandSchedule.steady(VelocityCommand(0, 0, 0), 1.0),
                           2 * t.step_frames / t.rate_hz, t.step_frames / t.rate_hz, 100)
    assert steps == [] or all(f.forward_m == 0 and f.side_m == 0 and f.turn_deg == 0 for f in steps)
    assert leading_side(VelocityCommand(0, -0.01, 5)) == "right"
