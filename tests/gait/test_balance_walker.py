"""The balanced walker's parts against invariants and against each other: leg IK inverts FK, the float
fast path equals the vectorised code, preview control online equals offline and tracks its reference,
the walker online equals offline, steps appended while walking are walked, the planned ZMP stays
inside the feet, the speed fit relaxes what the servos cannot follow."""

from __future__ import annotations

import math

import numpy as np
import pytest

from gaitbot.gait.balance.flat_foot_body import FlatFootBody
from gaitbot.gait.balance.preview import PreviewController, preview_gains, preview_offline
from gaitbot.gait.balance.speed_fit import candidates, fit_to_servo_speed
from gaitbot.gait.balance.walker import BalancedWalkError, generate_balanced_walk
from gaitbot.gait.joints import LEG_JOINTS, SIDES
from gaitbot.gait.kinematics6 import foot_pose, leg_ik, rot_y
from gaitbot.gait.mass import MassModel
from gaitbot.robot.balanced_walk import (balanced_gait_settings, balanced_walker, fitted_settings, leg_limits_rad,
                                         motion_measure, plan_balanced, servo_stiffness_nm_per_rad, velocity_limit_dps)
from gaitbot.robot.config import load_robot_config, resolve_config
from gaitbot.robot.motion_margin import PLANNED_SHARE

OP3 = load_robot_config(resolve_config("op3"))
GEOMETRY = OP3.body.geometry
STEPS = [0.03, 0.05, 0.04, 0.05, 0.02, 0.05, 0.05]


@pytest.fixture(scope="module")
def walk():
    return plan_balanced(OP3, STEPS).walk


def random_legs(side: str, n: int, seed: int) -> np.ndarray:
    lo, hi = leg_limits_rad(OP3)
    i = 0 if side == "left" else 6
    q = np.random.default_rng(seed).uniform(lo[i:i + 6], hi[i:i + 6], (n, 6))
    q[:, 3] = np.clip(q[:, 3], math.radians(2.0), None)  # the IK bends the knee forward
    return q


@pytest.mark.parametrize("side", SIDES)
def test_leg_ik_inverts_fk_to_1e_9(side):
    q = random_legs(side, 20000, 0)
    ankle, rot = foot_pose(GEOMETRY, side, q)
    back = leg_ik(GEOMETRY, side, ankle, rot)
    assert np.abs(back - q).max() < 1e-9
    ankle2, rot2 = foot_pose(GEOMETRY, side, back)
    assert np.abs(ankle2 - ankle).max() < 1e-9 and np.abs(rot2 - rot).max() < 1e-9


def test_the_planar_leg_is_the_special_case_yaw_and_roll_zero():
    from gaitbot.gait.geometry import LegGeometry
    from gaitbot.gait.geometry import leg_ik as planar_ik

    planar = LegGeometry(thigh=GEOMETRY.thigh_m, shank=GEOMETRY.shank_m, foot=GEOMETRY.foot_m,
                         hip_width=GEOMETRY.hip_width_m)
    rng = np.random.default_rng(5)
    x, z, pitch = rng.uniform(-0.06, 0.06, 500), rng.uniform(-0.205, -0.15, 500), rng.uniform(-0.4, 0.4, 500)
    hka = planar_ik(planar, np.column_stack([x, z]), pitch)
    for side in SIDES:
        ankle = GEOMETRY.hip_in_root(side) + np.column_stack([x, np.zeros_like(x), z])
        q = leg_ik(GEOMETRY, side, ankle, rot_y(-pitch))
        assert np.abs(q[:, [0, 1, 5]]).max() < 1e-12
        assert np.abs(q[:, 2:5] - hka).max() < 1e-12


def test_the_float_fast_path_equals_the_vectorised_kinematics_and_masses():
    flat, mass = FlatFootBody(OP3.body), MassModel.of(OP3.body)
    rng = np.random.default_rng(0)
    for _ in range(200):
        root = np.array([rng.uniform(-0.03, 0.03), rng.uniform(-0.03, 0.03), rng.uniform(0.22, 0.26)])
        ankles = np.array([[rng.uniform(-0.06, 0.06), 0.035 + rng.uniform(-0.01, 0.01), 0.0305 + rng.uniform(0, 0.03)],
                           [rng.uniform(-0.06, 0.06), -0.035 + rng.uniform(-0.01, 0.01), 0.0305]])
        q_fast = np.array(flat.legs(root, ankles))
        q_vec = np.concatenate([leg_ik(GEOMETRY, s, ankles[i] - root, np.eye(3)) for i, s in enumerate(SIDES)])
        assert np.abs(q_fast - q_vec).max() < 1e-12
        assert np.abs(np.array(flat.com_in_root(list(q_fast))) - mass.com_in_root(q_vec)).max() < 1e-12
        share, cops = rng.uniform(0, 1), rng.uniform(-0.05, 0.05, (2, 2))
        fast = np.array(flat.gravity_torques(list(q_fast), share, cops))
        cop3 = [np.array([[c[0], c[1], -root[2]]]) for c in cops]
        assert np.abs(fast - mass.gravity_torques(q_vec[None], np.array([share]), *cop3)[0]).max() < 1e-12


def test_preview_online_equals_offline_and_the_zmp_tracks_its_reference():
    gains = preview_gains(0.25, 1 / 60, 60)
    assert preview_gains(0.25, 1 / 60, 60) is gains  # computed once per height and rate
    reference = np.zeros((400, 2))
    reference[100:, 0] = np.linspace(0, 0.3, 300)
    reference[100:250, 1] = 0.04
    offline = preview_offline(gains, reference)
    controller = PreviewController(gains, reference[0])
    padded = np.concatenate([reference, np.repeat(reference[-1:], 61, 0)])
    zmp = []
    for k in range(len(reference)):
        assert np.abs(controller.state[0] - offline[k]).max() < 1e-9
        zmp.append(gains.c @ controller.state)
        controller.step(reference[k], padded[k + 1:k + 61])
    zmp = np.array(zmp)
    assert np.abs(zmp[300:] - reference[300:]).max() < 1e-3  # on a steady ramp the ZMP is on its reference


def test_a_one_second_horizon_keeps_nearly_all_of_the_preview():
    """docs/balance.md: of a 2 s horizon's preview weight, the first 1.0 s carries over 99.5%."""
    long = preview_gains(0.244, 1 / 60, 120)
    assert long.weight_share_within(60) > 0.995
    assert long.weight_share_within(30) < 0.995  # and half a second would lose more


def test_the_walk_places_the_whole_body_centre_of_mass_on_the_plan(walk):
    assert walk.residual_m < 1e-9


def test_the_planned_zmp_stays_inside_the_feet(walk):
    """The plan's multibody ZMP (every link a point mass) stays over the support polygon by 1 cm."""
    from scipy.spatial import ConvexHull

    g = GEOMETRY
    margins = []
    for k in range(len(walk.t_s)):
        corners = []
        for i, side in enumerate(SIDES):
            if walk.swinging[k] == i + 1:
                continue
            s = 1 if side == "left" else -1
            cx = walk.ankles_m[k, i, 0] + g.foot_m / 2 - g.heel_back_m
            cy = walk.ankles_m[k, i, 1] + s * g.sole_outward_m
            corners += [(cx + a * g.foot_m / 2, cy + b * g.foot_width_m / 2) for a in (-1, 1) for b in (-1, 1)]
        hull = ConvexHull(np.array(corners))
        margins.append((-(hull.equations[:, :2] @ walk.zmp_plan_m[k] + hull.equations[:, 2])).min())
    assert min(margins) > 0.01


def test_online_equals_offline(walk):
    fit = plan_balanced(OP3, STEPS).fit  # the settings the offline walk was fitted to (the servos' limits)
    walker = balanced_walker(OP3, fit.gait, fit.balance)
    for length in STEPS:
        walker.append_step(length)
    frames = []
    while (frame := walker.next_frame()) is not None:
        frames.append(frame)
    assert [f[0] for f in frames] == pytest.approx(walk.t_s, abs=1e-12)
    for i, array in ((1, walk.q_rad), (2, walk.goals_rad), (3, walk.root_m)):
        assert np.abs(np.array([f[i] for f in frames]) - array).max() < 1e-6
    assert walker.heel_strikes == list(walk.heel_strikes)


def test_steps_appended_while_walking_are_walked_to_their_footholds():
    walker = balanced_walker(OP3)
    walker.append_step(0.05)
    frames, queued = [], 1
    while (frame := walker.next_frame()) is not None:
        frames.append(frame)
        if len(frames) % 20 == 0 and queued < 8:  # a step every third of a second, late on purpose
            walker.append_step(0.05)
            queued += 1
    assert queued == 8
    assert [h.x_m for h in walker.heel_strikes] == pytest.approx([0.05 * (i + 1) for i in range(8)] + [0.40])
    root = np.array([f[3] for f in frames])
    assert abs(root[-1, 0] - (0.40 + GEOMETRY.heel_back_m)) < 1e-9  # ends standing straight over its feet
    assert np.abs(frames[-1][1]).max() == 0.0


def test_a_walker_whose_queue_runs_dry_closes_its_feet_and_stands():
    walker = balanced_walker(OP3)
    walker.append_step(0.04)
    n = sum(1 for _ in iter(walker.next_frame, None))
    assert walker.finished and n > 200
    assert walker.heel_strikes[-1].x_m == pytest.approx(0.04)


def test_a_step_longer_than_the_walk_allows_is_refused():
    walker = balanced_walker(OP3)
    with pytest.raises(BalancedWalkError, match="step length"):
        walker.append_step(OP3.gait.max_step_m * 1.5)


def test_step_lengths_are_exact_heel_to_heel(walk):
    xs = [h.x_m for h in walk.heel_strikes]
    assert np.diff([0.0] + xs[:len(STEPS)]) == pytest.approx(STEPS, abs=1e-12)
    assert [h.leg for h in walk.heel_strikes[:4]] == ["right", "left", "right", "left"]  # right foot first


def test_sag_feedforward_is_gravity_torque_over_stiffness(walk):
    """Goal - plan = the pose's gravity torque / kp; largest at the stance knee, a few degrees at most."""
    kp = servo_stiffness_nm_per_rad(OP3)
    # XM430-W350 stall torque over the written 6 deg, within the register's whole step (Position P Gain 1659
    # holds 6.0014 deg; tests/robot/test_robot_servo_gains.py holds the exact value)
    assert kp == pytest.approx(4.1 / math.radians(6.0), rel=1e-3)
    offset = np.degrees(walk.goals_rad - walk.q_rad)
    assert 0.5 < np.abs(offset).max() < 3.0
    knees = [LEG_JOINTS.index("knee_pitch_left"), LEG_JOINTS.index("knee_pitch_right")]
    assert np.abs(offset).max() == pytest.approx(np.abs(offset[:, knees]).max())


def test_the_speed_fit_relaxes_a_walk_the_servos_cannot_follow():
    gait = balanced_gait_settings(OP3, cycle_s=0.8, max_step_m=0.08)
    fit = fit_to_servo_speed(OP3.body, gait, OP3.balance, 240.0)
    assert fit.relaxed > 0 and fit.balance.double_support_share < OP3.balance.double_support_share
    nominal = fit_to_servo_speed(OP3.body, balanced_gait_settings(OP3), OP3.balance, 240.0)
    assert nominal.relaxed == 0 and nominal.fits


def test_the_speed_fit_leaves_the_foot_moving_until_it_lands_for_last():
    """A foot still moving forward when it lands lands short (docs/walk-faster.md), so the candidates whose
    progression ends with the swing come last, and among candidates asking the same least share the fit keeps
    the earlier. The 0.15 m/s push walk (cycle 0.8 s, 6 cm), which no candidate fits within the margin, is then
    walked with its progression done before the swing ends; no later candidate asks less."""
    gait = balanced_gait_settings(OP3, cycle_s=0.8, max_step_m=0.06)
    fit = fitted_settings(OP3, gait)
    assert not fit.fits and fit.balance.progression_end < 1.0
    found = candidates(gait, OP3.balance)
    assert [b.progression_end >= 1.0 for b, _ in found] == sorted(b.progression_end >= 1.0 for b, _ in found)
    options = dict(measure=motion_measure(OP3), share=PLANNED_SHARE, limits_rad=leg_limits_rad(OP3),
                   kp_nm_per_rad=servo_stiffness_nm_per_rad(OP3))
    for first in range(fit.relaxed + 1, len(found)):
        later = fit_to_servo_speed(OP3.body, gait, OP3.balance, velocity_limit_dps(OP3), first=first, **options)
        assert later.peak_share >= fit.peak_share


def test_the_speed_fit_lowers_the_robots_own_clearance_and_never_an_asked_one():
    """The fallbacks lower the robot's clearance (op3: 5 mm) to 3 mm; a clearance the user asked for
    (``--clearance``) is the user's: every candidate keeps it, and only the rest is relaxed."""
    own = candidates(balanced_gait_settings(OP3, cycle_s=0.8, max_step_m=0.06), OP3.balance)
    assert OP3.gait.clearance_m > 0.003 and {g.clearance_m for _, g in own} == {OP3.gait.clearance_m, 0.003}
    asked = candidates(balanced_gait_settings(OP3, cycle_s=0.8, max_step_m=0.06, clearance_m=0.008,
                                              clearance_asked=True), OP3.balance)
    assert {g.clearance_m for _, g in asked} == {0.008}
    assert [b for b, _ in asked] == [b for b, _ in own]  # the other relaxations are the same


def test_generate_without_feedforward_sends_the_planned_angles():
    gait = balanced_gait_settings(OP3)
    walk = generate_balanced_walk(OP3.body, [0.05, 0.05], gait, OP3.balance)
    assert np.array_equal(walk.goals_rad, walk.q_rad)
