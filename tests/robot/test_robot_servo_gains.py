"""Servo stiffness -> gain register values, checked against the datasheet formulas worked by hand.

Dynamixel X (e-Manual "Position PID Gain"): KPP = Position P Gain / 128 drives PWM, full at the PWM
Limit 885, so full output at 885 / KPP pulses; 4096 pulses a turn. AX-12A (e-Manual "Compliance
Slope"): steps 2, 4, ..., 128, full output beyond slope x 300/1023 deg. Feetech STS3215: P = 32 at the
X series' factory 12.4 deg (an assumption, written down in gaitbot/servos/models.py), P proportional to 1/error.
"""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from gaitbot.app.cli import main
from gaitbot.robot.config import ConfigError, load_robot_config
from gaitbot.robot.gains import GainError, gain_for_error, gain_plan
from gaitbot.servos.models import SERVO_MODELS
from helpers import CONFIG_DIR

XL430, XM430, AX12, STS = (SERVO_MODELS[n] for n in ("XL430-W250", "XM430-W350", "AX-12A", "STS3215"))


def x_gain_by_hand(error_deg: float) -> int:
    pulses = error_deg * 4096 / 360
    return round(885 / (pulses / 128))  # KPP = 885 / pulses; register = 128 x KPP


@pytest.mark.parametrize("error_deg, register", [(2.0, 4978), (1.0, 9956), (5.0, 1991), (12.0, 830), (0.61, 16322)])
def test_x_series_position_p_gain(error_deg, register):
    assert x_gain_by_hand(error_deg) == register  # the hand formula, worked once more
    for model in (XL430, XM430):
        setting = gain_for_error(model, error_deg)
        assert setting.value == register
        assert setting.writes == ((84, 2, register, "Position P Gain"),)
        assert setting.full_torque_error_deg == pytest.approx(885 * 128 / register * 360 / 4096)
        assert abs(setting.full_torque_error_deg - error_deg) < 0.5 / register * error_deg * 1.01  # rounding only


def test_x_series_factory_gains_are_the_e_manual_ones():
    # XM430-W350: Position P Gain 800 -> 141.6 pulses; XL430-W250: 640 -> 177 pulses.
    assert XM430.gain.full_torque_error_deg(800) == pytest.approx(141.6 * 360 / 4096)
    assert XL430.gain.full_torque_error_deg(640) == pytest.approx(177.0 * 360 / 4096)
    assert (XM430.gain.factory_value, XL430.gain.factory_value) == (800, 640)


@pytest.mark.parametrize("error_deg, slope", [(2.0, 4), (2.35, 8), (1.17, 2), (1.18, 4), (9.4, 32), (37.6, 128),
                                              (300.0, 128), (0.6, 2)])
def test_ax12a_compliance_slope_is_the_stiffer_step(error_deg, slope):
    setting = gain_for_error(AX12, error_deg)
    assert setting.value == slope
    assert setting.full_torque_error_deg == pytest.approx(slope * 300 / 1023)
    assert setting.full_torque_error_deg <= error_deg  # never softer than asked
    if slope < 128:
        assert 2 * slope * 300 / 1023 > error_deg  # and the next step would be
    assert setting.writes == ((28, 1, slope, "CW/CCW Compliance Slope"), (29, 1, slope, "CW/CCW Compliance Slope"))


@pytest.mark.parametrize("byte, representative", [(0, 2), (3, 2), (4, 4), (25, 16), (32, 32), (127, 64), (128, 128),
                                                  (254, 128), (255, 128)])
def test_ax12a_register_bytes_act_as_their_step(byte, representative):
    assert AX12.gain.full_torque_error_deg(byte) == pytest.approx(representative * 300 / 1023)


@pytest.mark.parametrize("error_deg, p", [(2.0, 199), (4.0, 100), (12.4453125, 32), (1.6, 249), (40.0, 10)])
def test_sts3215_p_coefficient_follows_the_stated_assumption(error_deg, p):
    x_factory_deg = 885 / (800 / 128) * 360 / 4096  # 12.445 deg: the X series at its factory gain
    assert round(32 * x_factory_deg / error_deg) == p
    setting = gain_for_error(STS, error_deg)
    assert setting.value == p
    assert setting.writes == ((55, 1, 1, "Lock"), (21, 1, p, "P coefficient"))  # lock on first: lasts until power-off
    assert STS.gain.assumed


@pytest.mark.parametrize("model, error_deg, allowed", [
    (XL430, 0.6, "0.608 to 9956 deg"),  # 16594 > 16383
    (XL430, 20000.0, "0.608 to 9956 deg"),  # rounds to 0
    (STS, 1.5, "1.562 to 398.2 deg"),  # 266 > 255
    (AX12, 0.5, "0.587 deg or more"),  # below slope 2
])
def test_a_register_that_cannot_hold_the_gain_is_refused_with_the_range(model, error_deg, allowed):
    with pytest.raises(GainError, match=re.escape(allowed)):
        gain_for_error(model, error_deg)


@pytest.mark.parametrize("name", ["XL-320", "SCS0009"])
def test_a_model_without_a_known_gain_register_is_refused(name):
    with pytest.raises(GainError, match=f"cannot set the stiffness of the {name}"):
        gain_for_error(SERVO_MODELS[name], 2.0)


def test_each_model_factory_stiffness_is_its_factory_register_value():
    for model in SERVO_MODELS.values():
        if model.gain is not None:
            assert model.gain.full_torque_error_deg(model.gain.factory_value) == pytest.approx(model.full_torque_error_deg)


def test_a_p_gain_of_zero_gives_no_stiffness_and_more_gain_is_stiffer():
    assert XL430.gain.full_torque_error_deg(0) == float("inf")
    errors = [XL430.gain.full_torque_error_deg(v) for v in (100, 640, 4978, 16383)]
    assert errors == sorted(errors, reverse=True)


# --- the robot config: the setting, checked at load --------------------------------------------------

def write_config(tmp_path: Path, text: str) -> Path:
    path = tmp_path / "robot.toml"
    path.write_text(text)
    return path


def with_error(name: str, error_deg: str) -> str:
    text = (CONFIG_DIR / f"{name}.toml").read_text()
    new = re.sub(r"(?m)^full_torque_error_deg = .*$", f"full_torque_error_deg = {error_deg}", text)
    assert new != text or f"full_torque_error_deg = {error_deg}" in text
    return new


def scs0009_robot() -> str:
    text = with_error("sts3215-biped", "2.0").replace('"STS3215"', '"SCS0009"')
    return text.replace("zero_tick = 2048", "zero_tick = 512")


def xl320_ankle() -> str:
    text = with_error("xl430-biped", "2.0")
    start = text.index("[joints.ankle_pitch_right]")
    joint = text[start:].replace('"XL430-W250"', '"XL-320"', 1).replace("zero_tick = 2048", "zero_tick = 512", 1)
    return text[:start] + joint


@pytest.mark.parametrize("text, words", [
    (with_error("xl430-biped", "0.5"), ("joints.hip_pitch_left (XL430-W250)", "allowed: 0.608 to 9956 deg")),
    (with_error("sts3215-biped", "1.0"), ("STS3215", "allowed: 1.562 to 398.2 deg")),
    (with_error("ax12a-biped", "0.3"), ("AX-12A", "allowed: 0.587 deg or more")),
    (scs0009_robot(), ("joints.hip_pitch_left (SCS0009)", "cannot set the stiffness")),
    (xl320_ankle(), ("joints.ankle_pitch_right (XL-320)", "cannot set the stiffness")),
    (with_error("xl430-biped", "-2.0"), ("positive",)),
])
def test_a_stiffness_no_servo_can_take_is_refused_at_load(tmp_path, text, words):
    path = write_config(tmp_path, text)
    with pytest.raises(ConfigError) as info:
        load_robot_config(path)
    message = str(info.value)
    assert message.startswith(f"{path}: servo.full_torque_error_deg: ")
    assert all(w in message for w in words), message
    assert "\n" not in message


def test_a_walk_with_such_a_config_exits_2_with_one_line_and_sends_nothing(tmp_path, capsys):
    path = write_config(tmp_path, with_error("xl430-biped", "0.5"))
    record = tmp_path / "run.jsonl"
    assert main(["walk", "--robot", str(path), "--steps", "0.03", "--dry-run", "--record", str(record)]) == 2
    err = capsys.readouterr().err.strip()
    assert "servo.full_torque_error_deg" in err and str(path) in err and "\n" not in err
    assert not record.exists()


def test_the_plan_covers_every_servo_held_joints_too():
    config = load_robot_config(CONFIG_DIR / "ax12a-biped.toml")
    ((setting, ids),) = gain_plan(config)
    assert sorted(ids) == sorted(config.ids) and len(ids) == 8
    assert setting.value == 4


def test_without_the_setting_the_plan_is_empty(tmp_path):
    text = re.sub(r"(?m)^\[servo\]\nfull_torque_error_deg = .*\n", "", (CONFIG_DIR / "xl430-biped.toml").read_text())
    assert gain_plan(load_robot_config(write_config(tmp_path, text))) == ()


def test_the_sag_feedforward_uses_the_stiffness_the_register_will_hold():
    """The balanced walk's sag feedforward divides the gravity torque by the servo's stiffness: it must be
    the stiffness of the gain value written (decoded by the register's own law), not the one asked for
    (an AX-12A's compliance slope has seven steps; asked for 2 deg it holds 1.17)."""
    from gaitbot.robot.balanced_walk import full_torque_error_deg
    from gaitbot.robot.config import load_robot_config, resolve_config
    from gaitbot.robot.gains import gain_writes

    for name in ("op3", "bioloid"):
        config = load_robot_config(resolve_config(name))
        writes = gain_writes(config)
        for joint in config.joints:
            if joint.hold_deg is not None:
                continue
            gain = joint.model.gain
            values = [w.value for w in writes if joint.id in w.ids and w.address in gain.addresses]
            assert values, (name, joint.name)
            held = max(gain.full_torque_error_deg(v) for v in values)
            assert full_torque_error_deg(config, joint.name) == pytest.approx(held, rel=1e-12), (name, joint.name)
