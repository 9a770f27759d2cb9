"""``[feedback] attitude_roll_gain_by_servo_error`` and ``[fall] load_lost_*`` in a robot config: read as
written, bad ones refused in one line naming the field and what is allowed."""

from __future__ import annotations

import pytest

from gaitbot.fields import FieldError
from gaitbot.robot.config import load_robot_config
from helpers import REPO_ROOT as REPO

TABLE = "attitude_roll_gain_by_servo_error = [[6.0, 0.0], [10.0, 0.4]]"


def op3_with(tmp_path, replacement: str):
    text = (REPO / "config" / "op3.toml").read_text()
    assert TABLE in text
    path = tmp_path / "op3.toml"
    path.write_text(text.replace(TABLE, replacement))
    return load_robot_config(path)


def test_the_shipped_table_is_read_as_written():
    assert load_robot_config(REPO / "config" / "op3.toml").imu.attitude_roll_gain_by_servo_error == ((6.0, 0.0), (10.0, 0.4))


@pytest.mark.parametrize("replacement", [
    "attitude_roll_gain_by_servo_error = [[10.0, 0.5], [6.0, 0.0]]",   # errors not rising
    "attitude_roll_gain_by_servo_error = [[6.0, 3.0]]",                # gain beyond 2
    "attitude_roll_gain_by_servo_error = [[6.0]]",                     # not a pair
    "attitude_roll_gain_by_servo_error = 0.5",                         # not a list
    "attitude_roll_gain_by_servo_error = [[-1.0, 0.2]]",               # a negative error
    f"{TABLE}\nattitude_roll_gain = 0.3",                              # both ways at once
])
def test_a_bad_table_is_refused_naming_the_field(tmp_path, replacement):
    with pytest.raises(FieldError) as caught:
        op3_with(tmp_path, replacement)
    message = str(caught.value)
    assert "feedback.attitude_roll_gain" in message and "\n" not in message


def test_a_flat_gain_still_works_without_the_table(tmp_path):
    cfg = op3_with(tmp_path, "attitude_roll_gain = 0.3")
    assert cfg.imu.roll_gain(6.0) == cfg.imu.roll_gain(13.0) == 0.3


def op3_fall_with(tmp_path, old: str, new: str):
    text = (REPO / "config" / "op3.toml").read_text()
    assert text.count(old) == 1
    path = tmp_path / "op3.toml"
    path.write_text(text.replace(old, new))
    return load_robot_config(path)


def test_the_load_lost_thresholds_are_read_as_written(tmp_path):
    imu = op3_fall_with(tmp_path, "load_lost_g = 0.2\nload_lost_s = 0.05", "load_lost_g = 0.15\nload_lost_s = 0.1").imu
    assert (imu.fall_load_lost_g, imu.fall_load_lost_s) == (0.15, 0.1)


@pytest.mark.parametrize("old, new, field", [
    ("load_lost_g = 0.2", "load_lost_g = 1.5", "fall.load_lost_g"),     # over 1 g: a standing robot's reading
    ("load_lost_g = 0.2", "load_lost_g = 0.6", "fall.load_lost_g"),     # over 0.5 g: near a walk's own swings
    ("load_lost_g = 0.2", "load_lost_g = 0.0", "fall.load_lost_g"),     # no reading is under 0 g: 0.05 at least
    ("load_lost_s = 0.05", "load_lost_s = 5.0", "fall.load_lost_s"),    # 5 s of falling: the floor first
    ("load_lost_s = 0.05", 'load_lost_s = "soon"', "fall.load_lost_s"),
])
def test_a_bad_load_lost_threshold_is_refused_naming_the_field(tmp_path, old, new, field):
    with pytest.raises(FieldError) as caught:
        op3_fall_with(tmp_path, old, new)
    message = str(caught.value)
    assert field in message and "\n" not in message
