"""The simulated robot's model checked from outside: geometry, masses, servo behaviour, contacts.

Expected values come from the robot configs and the servo datasheet figures (gaitbot.servos.models), not
from the model builder: sole corners from the leg lengths, speeds from the no-load rpm, deflections
from stall torque over full-torque error.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from gaitbot.sim import SimUnavailable, import_mujoco  # noqa: E402  (picks the offscreen GL first)

try:
    import_mujoco()
except SimUnavailable:
    pytest.skip("the sim extra (MuJoCo) is not installed", allow_module_level=True)

from gaitbot.sim.physics import SimRobot  # noqa: E402
from gaitbot.robot.config import load_robot_config, resolve_config  # noqa: E402
from helpers import float_in_air  # noqa: E402

ROBOTS = ("xl430-biped", "sts3215-biped", "ax12a-biped")
KNEE_LEFT = 1  # walking-joint index of knee_pitch_left


def robot_of(name: str, **kwargs) -> SimRobot:
    return SimRobot(load_robot_config(resolve_config(name)), 60.0, **kwargs)


def sole_corners(robot: SimRobot, side: int) -> dict[str, np.ndarray]:
    """World positions of the sole's bottom heel and toe edges (mid-width)."""
    geom = robot.sole_geoms[side]
    centre, rot = robot.data.geom_xpos[geom], robot.data.geom_xmat[geom].reshape(3, 3)
    half = robot.model.geom_size[geom]
    return {"heel": centre + rot @ np.array([-half[0], 0.0, -half[2]]),
            "toe": centre + rot @ np.array([half[0], 0.0, -half[2]])}


@pytest.mark.parametrize("name", ROBOTS)
def test_standing_soles_lie_on_the_floor_where_the_config_puts_them(name):
    robot = robot_of(name)
    g = robot.config.geometry
    for side in (0, 1):
        corners = sole_corners(robot, side)
        # ankle straight below the hip at x = 0; heel heel_back_m behind it, toe foot_m ahead of the heel
        assert corners["heel"][0] == pytest.approx(-g.heel_back_m, abs=1e-9)
        assert corners["toe"][0] == pytest.approx(g.foot_m - g.heel_back_m, abs=1e-9)
        assert corners["heel"][2] == pytest.approx(0.0, abs=1e-9)
        assert corners["toe"][2] == pytest.approx(0.0, abs=1e-9)
    hip = robot.torso_position_m()
    assert hip[1] == pytest.approx(g.thigh_m + g.shank_m + g.ankle_height_m, abs=1e-9)


@pytest.mark.parametrize("name", ROBOTS)
def test_masses_and_joint_ranges_are_the_configs(name):
    robot = robot_of(name)
    config = robot.config
    assert float(np.sum(robot.model.body_mass)) == pytest.approx(config.mass.total_kg, rel=1e-9)
    for joint in config.walking_joints:
        lo, hi = robot.model.joint(joint.name).range
        assert (math.degrees(lo), math.degrees(hi)) == pytest.approx((joint.min_deg, joint.max_deg))


def test_flexion_positive_axes_match_the_gait_convention():
    """Hip flexion swings the knee forward, knee flexion the ankle back, ankle flexion lifts the toe."""
    robot = robot_of("xl430-biped")
    data, model = robot.data, robot.model
    for joint, body, forward in (("hip_pitch_left", "shank_left", True), ("knee_pitch_left", "foot_left", False)):
        data.qpos[:] = 0.0
        data.qpos[model.joint(joint).qposadr[0]] = 0.3
        robot.mujoco.mj_forward(model, data)
        assert (data.xpos[model.body(body).id][0] > 0) == forward
    data.qpos[:] = 0.0
    data.qpos[model.joint("ankle_pitch_left").qposadr[0]] = 0.3
    robot.mujoco.mj_forward(model, data)
    corners = sole_corners(robot, 0)
    assert corners["toe"][2] > corners["heel"][2]


@pytest.mark.parametrize("name", ROBOTS)
def test_a_servo_at_full_effort_runs_at_its_no_load_speed_and_no_faster(name):
    robot = robot_of(name)
    float_in_air(robot)
    robot.set_torque(KNEE_LEFT, True)
    robot.set_goal(KNEE_LEFT, math.radians(robot.config.walking_joints[KNEE_LEFT].max_deg))  # far: full effort
    dof = robot.model.joint("knee_pitch_left").dofadr[0]
    speeds = []
    for k in range(1, 25):
        robot.advance_to(k * 0.01)
        speeds.append(robot.data.qvel[dof])
    no_load = robot.config.walking_joints[KNEE_LEFT].model.no_load_speed_rpm * 2 * math.pi / 60
    assert max(speeds) <= no_load * 1.001
    assert max(speeds) >= 0.95 * no_load


@pytest.mark.parametrize("name", ROBOTS)
def test_a_servo_yields_to_a_load_by_load_over_its_stiffness_and_gives_way_beyond_stall(name):
    robot = robot_of(name)
    float_in_air(robot)
    for i in range(6):
        robot.set_torque(i, True)
    model = robot.config.walking_joints[KNEE_LEFT].model
    dof = robot.model.joint("knee_pitch_left").dofadr[0]
    load = 0.5 * model.stall_torque_nm
    robot.data.qfrc_applied[dof] = load
    robot.advance_to(2.0)
    deflection_deg = math.degrees(robot.joint_angles_rad()[KNEE_LEFT])
    # a proportional loop: full (stall) torque at full_torque_error_deg, so half of it at half the error
    assert deflection_deg == pytest.approx(0.5 * model.full_torque_error_deg, rel=0.02)
    robot.data.qfrc_applied[dof] = 1.2 * model.stall_torque_nm
    robot.advance_to(2.5)
    assert math.degrees(robot.joint_angles_rad()[KNEE_LEFT]) > 2 * model.full_torque_error_deg


def test_a_servo_with_torque_off_does_not_hold():
    robot = robot_of("xl430-biped")
    float_in_air(robot)
    robot.set_torque(KNEE_LEFT, False)
    robot.set_goal(KNEE_LEFT, 1.0)
    robot.advance_to(0.5)
    assert abs(robot.joint_angles_rad()[KNEE_LEFT]) < 1e-9


@pytest.mark.parametrize("name", ("xl430-biped", "ax12a-biped"))
def test_stiff_contacts_neither_sink_nor_creep(name):
    """Standing on both soles, then pushed forward with 0.3 m g (under the 1.0 friction) for 2 s: the soles
    sink less than 0.05 mm and creep less than 0.1 mm (MuJoCo's soft defaults: 0.2 mm and 1.5 mm)."""
    robot = robot_of(name)
    for i in range(6):
        robot.set_torque(i, True)
    robot.advance_to(1.0)
    before = sole_corners(robot, 0)["heel"]
    assert -before[2] < 5e-5
    robot.data.xfrc_applied[robot.torso_body, 0] = 0.3 * robot.config.mass.total_kg * 9.81
    robot.advance_to(3.0)
    after = sole_corners(robot, 0)["heel"]
    assert abs(after[0] - before[0]) < 1e-4


def test_free_pitch_adds_the_pitch_joint_and_held_pitch_has_none():
    assert robot_of("xl430-biped").model.njnt == 2 + 6
    free = robot_of("xl430-biped", free_pitch=True)
    assert free.model.njnt == 3 + 6
    assert free.torso_pitch_rad() == 0.0


def test_time_advances_in_whole_frames_and_observers_see_every_frame_end():
    robot = robot_of("ax12a-biped")
    seen = []
    robot.observers.append(lambda r: seen.append(r.time_s))
    robot.advance_to(10 / 60)
    assert seen == pytest.approx([k / 60 for k in range(1, 11)], abs=1e-12)
    robot.advance_to(10 / 60)  # no time passed: no step, no call
    assert len(seen) == 10
