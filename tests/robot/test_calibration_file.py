"""Calibration files: written, read back, applied on top of a config, found beside it, and refused for other
servos or for values a servo cannot hold (one line naming the file and the field, exit 2)."""

from __future__ import annotations

import shutil
from pathlib import Path

import numpy as np
import pytest

from gaitbot.robot.calibration import angles_to_ticks
from gaitbot.robot.calibration_file import (CalibrationError, JointCalibration, apply_calibration, calibration_path_for,
                                            load_robot_with_calibration, read_calibration, write_calibration)
from helpers import CONFIG_DIR, config, gaitbot


def joints_of(robot, zero=2000, direction=-1):
    return [JointCalibration(j.name, j.id, j.model.name, zero + k, direction, 30.0) for k, j in enumerate(robot.joints)]


def test_round_trip_and_application(tmp_path):
    robot = config("xl430-biped")
    path = tmp_path / "cal.toml"
    write_calibration(path, robot.name, joints_of(robot), comment="test")
    calibrated = apply_calibration(robot, read_calibration(path))
    assert [j.zero_tick for j in calibrated.joints] == [2000 + k for k in range(6)]
    assert [j.direction for j in calibrated.joints] == [-1] * 6
    assert calibrated.calibration_file == path
    # the calibration is what angles become: 10 deg of hip flexion is 2000 - 10 deg of ticks
    ticks = angles_to_ticks(calibrated, np.radians([10, 0, 0, 0, 0, 0]))
    assert ticks[0] == 2000 - round(10 * 4096 / 360)


def test_found_beside_the_config_by_name_and_given_explicitly(tmp_path):
    shutil.copy(CONFIG_DIR / "xl430-biped.toml", tmp_path / "bot.toml")
    robot = config("xl430-biped")
    assert load_robot_with_calibration(tmp_path / "bot.toml").calibration_file is None
    write_calibration(calibration_path_for(tmp_path / "bot.toml"), robot.name, joints_of(robot, 2010))
    assert calibration_path_for(tmp_path / "bot.toml").name == "bot.calibration.toml"
    found = load_robot_with_calibration(tmp_path / "bot.toml")
    assert found.joints[0].zero_tick == 2010
    write_calibration(tmp_path / "other.toml", robot.name, joints_of(robot, 2020))
    assert load_robot_with_calibration(tmp_path / "bot.toml", tmp_path / "other.toml").joints[0].zero_tick == 2020


@pytest.mark.parametrize("change, words", [
    (lambda j: JointCalibration(j.name, j.id + 10, j.model, j.zero_tick, j.direction), "taken on servo 11"),
    (lambda j: JointCalibration(j.name, j.id, "XM430-W350", j.zero_tick, j.direction), "(XM430-W350)"),
    (lambda j: JointCalibration("elbow_left", j.id, j.model, j.zero_tick, j.direction), "no such joint"),
    (lambda j: JointCalibration(j.name, j.id, j.model, 5000, j.direction), "outside the XL430-W250's tick range 0..4095"),
    (lambda j: JointCalibration(j.name, j.id, j.model, 300, j.direction), "allowed angles are"),
])
def test_refused_for_other_servos_and_for_values_a_servo_cannot_hold(tmp_path, change, words):
    robot = config("xl430-biped")
    joints = joints_of(robot, 2048, 1)
    joints[0] = change(joints[0])
    write_calibration(tmp_path / "cal.toml", robot.name, joints)
    with pytest.raises(CalibrationError, match="joints.") as caught:
        apply_calibration(robot, read_calibration(tmp_path / "cal.toml"))
    assert words in str(caught.value) and "\n" not in str(caught.value)


def test_every_command_refuses_a_calibration_for_other_servos_in_one_line(tmp_path):
    robot = config("ax12a-biped")
    path = tmp_path / "wrong.toml"
    write_calibration(path, "xl430-biped", joints_of(config("xl430-biped")))  # ids 1..6, XL430s: not the AX biped
    for argv in (["plan", "--robot", "ax12a-biped", "--steps", "0.03"],
                 ["walk", "--robot", "ax12a-biped", "--dry-run", "--record", str(tmp_path / "r.jsonl")],
                 ["scan", "--robot", "ax12a-biped", "--dry-run"]):
        proc = gaitbot(*argv, "--calibration", str(path))
        assert proc.returncode == 2, proc.stderr
        assert proc.stderr.count("\n") == 1 and "a calibration belongs to the servos it was taken on" in proc.stderr
        assert "Traceback" not in proc.stderr
    assert not (tmp_path / "r.jsonl").exists()  # refused before the bus was made: nothing sent
    assert robot.name == "ax12a-biped"


def test_a_file_that_is_not_a_calibration_is_refused(tmp_path):
    (tmp_path / "x.toml").write_text('[calibration]\nformat = "something"\nversion = 1\nrobot = "r"\n')
    with pytest.raises(CalibrationError, match="calibration.format"):
        read_calibration(tmp_path / "x.toml")
    (tmp_path / "y.toml").write_text('[calibration]\nformat = "gaitbot-calibration"\nversion = 1\nrobot = "r"\n'
                                     '[joints.a]\nid = 1\nmodel = "AX-12A"\nzero_tick = 512\ndirection = 0\n')
    with pytest.raises(CalibrationError, match="joints.a.direction: must be 1 or -1"):
        read_calibration(tmp_path / "y.toml")
    assert Path(tmp_path / "y.toml").exists()
