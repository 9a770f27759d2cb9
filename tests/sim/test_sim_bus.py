"""The simulation bus against the bus interface: the real backend and SDK on a port whose servos are
the simulated joints. Expected ticks are computed here from the config's calibration numbers
(zero_tick + direction * angle * ticks per radian)."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from gaitbot.sim import SimUnavailable, import_mujoco  # noqa: E402  (picks the offscreen GL first)

try:
    import_mujoco()
except SimUnavailable:
    pytest.skip("the sim extra (MuJoCo) is not installed", allow_module_level=True)

from gaitbot.sim.physics import SimRobot  # noqa: E402
from gaitbot.sim.port import SimPort, make_sim_bus  # noqa: E402
from gaitbot.app.cli import main  # noqa: E402
from gaitbot.stream.clock import VirtualClock  # noqa: E402
from gaitbot.robot.config import load_robot_config, resolve_config  # noqa: E402
from helpers import float_in_air  # noqa: E402

ROBOTS = ("xl430-biped", "sts3215-biped", "ax12a-biped")


def ticks_of(joint, angle_rad: float) -> int:
    return round(joint.zero_tick + joint.direction * angle_rad * joint.model.ticks_per_rad)


def sim_bus(name: str):
    config = load_robot_config(resolve_config(name))
    robot = SimRobot(config, 60.0)
    clock = VirtualClock()
    return config, robot, clock, make_sim_bus(config, robot, clock.now)


@pytest.mark.parametrize("name", ROBOTS)
def test_every_configured_servo_answers_and_reads_the_standing_pose(name):
    config, _, _, bus = sim_bus(name)
    with bus:
        assert bus.scan(range(0, 30)) == sorted(config.ids)
        present = bus.read_present_ticks(config.ids)
    for joint in config.walking_joints:
        assert present[joint.id] == ticks_of(joint, 0.0)
    assert isinstance(bus.port, SimPort)


@pytest.mark.parametrize("name", ROBOTS)
def test_reads_are_the_simulated_joint_angles_through_the_calibration(name):
    config, robot, _, bus = sim_bus(name)
    angles = np.radians([20.0, 35.0, -10.0, -15.0, 50.0, 12.0])
    robot.data.qpos[robot.qpos_index] = angles
    robot.mujoco.mj_forward(robot.model, robot.data)
    with bus:
        present = bus.read_present_ticks(config.ids)
    for joint, angle in zip(config.walking_joints, angles):
        assert present[joint.id] == ticks_of(joint, angle)


@pytest.mark.parametrize("name", ROBOTS)
def test_goals_drive_the_joints_once_torque_is_on_and_time_passes(name):
    config, robot, clock, bus = sim_bus(name)
    float_in_air(robot)
    goals_deg = [10.0, 30.0, -5.0, 5.0, 20.0, 8.0]
    goals = {j.id: ticks_of(j, math.radians(a)) for j, a in zip(config.walking_joints, goals_deg)}
    for joint in config.held_joints:
        goals[joint.id] = ticks_of(joint, math.radians(joint.hold_deg + 3.0))
    with bus:
        bus.write_goal_ticks(goals)
        clock.advance(0.5)
        assert bus.read_present_ticks(config.ids) != goals  # torque off: the servos do not move
        bus.set_torque(config.ids, True)
        assert robot.torque_on.all()
        clock.advance(1.0)
        present = bus.read_present_ticks(config.ids)
        assert robot.time_s == pytest.approx(1.5)
        bus.set_torque(config.ids, False)
        assert not robot.torque_on.any()
    for servo_id, goal in goals.items():
        assert abs(present[servo_id] - goal) <= 1, (servo_id, present[servo_id], goal)


def test_physics_follows_the_clock_and_nothing_else():
    _, robot, clock, bus = sim_bus("xl430-biped")
    with bus:
        bus.ping(1)
        bus.ping(1)
        assert robot.time_s == 0.0
        clock.advance(0.25)
        bus.ping(1)
        assert robot.time_s == pytest.approx(0.25)


def recorded_packets(path) -> list[tuple[float, str]]:
    lines = [json.loads(line) for line in path.read_text().splitlines()[1:]]
    return [(line["t"], line["hex"]) for line in lines if line["dir"] == "tx"]


@pytest.mark.parametrize("name", ROBOTS)
def test_a_sim_recording_sends_what_a_dry_run_sends_and_passes_gaitbot_check(name, tmp_path, capsys):
    sim, dry = tmp_path / "sim.jsonl", tmp_path / "dry.jsonl"
    assert main(["walk", "--robot", name, "--steps", "0.03,0.03", "--sim", "--boom", "--record", str(sim)]) == 0
    assert main(["walk", "--robot", name, "--steps", "0.03,0.03", "--dry-run", "--record", str(dry)]) == 0
    assert recorded_packets(sim) == recorded_packets(dry)
    capsys.readouterr()
    assert main(["check", str(sim)]) == 0
    assert "OK (0 errors" in capsys.readouterr().out
