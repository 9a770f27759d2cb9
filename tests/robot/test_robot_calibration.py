"""Calibration: angles <-> ticks. Expected ticks are worked out by hand from the datasheet scales:
X series / STS3215: 4096 ticks per 360 deg, so 90 deg = 1024 ticks exactly;
AX-12A: 1023 ticks per 300 deg, so 30 deg = 102.3 ticks.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from gaitbot.robot.calibration import angles_to_ticks, standing_ticks, ticks_to_angles
from gaitbot.robot.config import load_robot_config, resolve_config


@pytest.fixture(scope="module")
def xl430():
    return load_robot_config(resolve_config("xl430-biped"))


@pytest.fixture(scope="module")
def ax12a():
    return load_robot_config(resolve_config("ax12a-biped"))


def test_quarter_turn_on_xl430_and_its_mirror(xl430):
    # hip_pitch_left direction +1, hip_pitch_right direction -1, both zero 2048.
    angles = np.radians([[90.0, 0, 0, 90.0, 0, 0]])
    ticks = angles_to_ticks(xl430, angles)
    assert ticks.dtype == np.int64 and ticks.shape == (1, 6)
    assert ticks[0, 0] == 2048 + 1024
    assert ticks[0, 3] == 2048 - 1024


def test_direction_minus_one_mirrors_about_zero_tick(xl430):
    rng = np.random.default_rng(1)
    left = rng.uniform(-0.7, 0.7, size=(50, 3))
    ticks = angles_to_ticks(xl430, np.hstack([left, left]))
    # same angle on the mirrored right side lands as far below 2048 as the left lands above it
    np.testing.assert_array_equal(ticks[:, :3] - 2048, 2048 - ticks[:, 3:])


def test_ax12a_thirty_degrees_rounds_to_nearest_tick(ax12a):
    angles = np.radians([30.0, 30.0, -30.0, 30.0, 0.0, 0.0])
    ticks = angles_to_ticks(ax12a, angles)
    # 30 deg = 102.3 ticks -> 102; knee_pitch_right direction -1 but at 0 -> 512.
    assert ticks.shape == (8,)
    assert list(ticks[:6]) == [512 + 102, 512 + 102, 512 - 102, 512 - 102, 512, 512]


def test_held_joints_sit_at_hold_deg(ax12a):
    ticks = angles_to_ticks(ax12a, np.zeros((4, 6)))
    assert ticks.shape == (4, 8)
    assert np.all(ticks[:, 6:] == 512)  # hip roll held at 0 deg


def test_held_joint_at_a_non_zero_hold(tmp_path):
    text = resolve_config("ax12a-biped").read_text()
    i = text.index("[joints.hip_roll_right]")
    text = text[:i] + text[i:].replace("hold_deg = 0.0", "hold_deg = 15.0", 1)
    path = tmp_path / "robot.toml"
    path.write_text(text)
    config = load_robot_config(path)
    # hip_roll_right: direction -1, 15 deg = 51.15 ticks -> 512 - 51 = 461
    assert standing_ticks(config)[7] == 461
    assert angles_to_ticks(config, np.zeros(6))[7] == 461


def test_standing_ticks_are_the_zero_ticks(xl430, ax12a):
    assert list(standing_ticks(xl430)) == [2048] * 6
    assert list(standing_ticks(ax12a)) == [512] * 8


@pytest.mark.parametrize("name", ["xl430-biped", "sts3215-biped", "ax12a-biped"])
def test_round_trip_within_half_a_tick(name):
    config = load_robot_config(resolve_config(name))
    rng = np.random.default_rng(7)
    angles = rng.uniform(-math.radians(44), math.radians(44), size=(1000, 6))
    back = ticks_to_angles(config, angles_to_ticks(config, angles))
    assert back.shape == (1000, len(config.joints))
    half_tick_rad = np.array([0.5 / j.model.ticks_per_rad for j in config.walking_joints])
    assert np.all(np.abs(back[:, :6] - angles) <= half_tick_rad + 1e-12)


def test_ticks_to_angles_by_hand(xl430):
    ticks = np.array([3072, 2048, 2048, 1024, 2048, 2048])
    angles = ticks_to_angles(xl430, ticks)
    np.testing.assert_allclose(np.degrees(angles), [90, 0, 0, 90, 0, 0], atol=1e-9)


def test_full_joint_angles_are_accepted(ax12a):
    angles = np.zeros((2, 8))
    angles[:, 6] = math.radians(-30.0)  # hip_roll_left, direction +1
    ticks = angles_to_ticks(ax12a, angles)
    assert list(ticks[0, 6:]) == [512 - 102, 512]


def test_wrong_width_is_refused(xl430):
    with pytest.raises(ValueError):
        angles_to_ticks(xl430, np.zeros((3, 5)))
    with pytest.raises(ValueError):
        ticks_to_angles(xl430, np.zeros((3, 7), dtype=int))
