"""Robot config loading: the shipped robots load, and each kind of mistake is named in one line.

Malformed configs are made by editing the text of a shipped file, so each test breaks exactly one
thing and the expected field comes from the edit itself.
"""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from gaitbot.gait.joints import PITCH_JOINTS
from gaitbot.robot.config import (
    ConfigError,
    RobotConfig,
    default_config_path,
    load_robot_config,
    resolve_config,
    shipped_config_names,
)
from gaitbot.servos.models import SERVO_MODELS

SHIPPED = ("xl430-biped", "sts3215-biped", "ax12a-biped")


def shipped_text(name: str) -> str:
    return resolve_config(name).read_text()


def joint_block(text: str, joint: str) -> tuple[int, int]:
    """Start and end offsets of the [joints.<joint>] table in a config's text."""
    start = text.index(f"[joints.{joint}]")
    nxt = text.find("\n[", start + 1)
    return start, (len(text) if nxt < 0 else nxt + 1)


def set_in_joint(text: str, joint: str, key: str, value: str) -> str:
    """Replace ``key = ...`` inside one joint's table."""
    a, b = joint_block(text, joint)
    block, n = re.subn(rf"(?m)^{key} = .*$", f"{key} = {value}", text[a:b])
    assert n == 1, f"{key} not found in joints.{joint}"
    return text[:a] + block + text[b:]


def set_top(text: str, key: str, value: str) -> str:
    """Replace the first ``key = ...`` line (keys outside the joint tables are unique)."""
    new, n = re.subn(rf"(?m)^{key} = [^#\n]*", f"{key} = {value}", text, count=1)
    assert n == 1, key
    return new


def load_text(tmp_path: Path, text: str) -> RobotConfig:
    path = tmp_path / "robot.toml"
    path.write_text(text)
    return load_robot_config(path)


def expect_error(tmp_path: Path, text: str, field: str, *words: str) -> ConfigError:
    with pytest.raises(ConfigError) as info:
        load_text(tmp_path, text)
    message = str(info.value)
    assert "\n" not in message
    assert message.startswith(f"{tmp_path / 'robot.toml'}: {field}: "), message
    for word in words:
        assert word in message, (word, message)
    return info.value


# --- the shipped robots --------------------------------------------------------------------------


@pytest.mark.parametrize("name", SHIPPED)
def test_shipped_config_loads_with_walking_joints_first(name):
    config = load_robot_config(resolve_config(name))
    assert config.name == name
    assert tuple(j.name for j in config.walking_joints) == PITCH_JOINTS
    assert all(j.hold_deg is None for j in config.walking_joints)
    assert all(j.hold_deg is not None for j in config.held_joints)
    assert len(set(config.ids)) == len(config.joints)


@pytest.mark.parametrize("name", SHIPPED)
def test_shipped_config_is_physically_plausible(name):
    """Numbers the brief fixes: legs of a small humanoid, steps within reach, limits that allow a
    flexion-positive gait, velocity limits below the servo's no-load speed."""
    config = load_robot_config(resolve_config(name))
    g = config.geometry
    assert 0.07 <= g.thigh_m <= 0.12 and 0.07 <= g.shank_m <= 0.12 and 0.08 <= g.foot_m <= 0.12
    assert config.gait.max_step_m <= 0.7 * (g.thigh_m + g.shank_m)
    assert 0.01 <= config.gait.clearance_m <= 0.015
    assert config.gait.rate_hz == 60 and config.bus.baudrate == 1_000_000
    for joint in config.walking_joints:
        kind = joint.name.split("_")[0]
        need = {"hip": (-45, 60), "knee": (0, 110), "ankle": (-45, 45)}[kind]
        assert joint.min_deg <= need[0] and joint.max_deg >= need[1], joint.name
        assert joint.max_velocity_dps < joint.model.no_load_speed_dps, joint.name
    assert any(j.direction == -1 for j in config.joints if j.name.endswith("_right"))


def test_shipped_servo_choices():
    xl = load_robot_config(resolve_config("xl430-biped"))
    assert {j.model.name for j in xl.joints} == {"XL430-W250"} and len(xl.joints) == 6
    assert xl.bus.backend == "dynamixel" and xl.bus.protocol == 2.0
    sts = load_robot_config(resolve_config("sts3215-biped"))
    assert {j.model.name for j in sts.joints} == {"STS3215"} and sts.bus.backend == "feetech"
    assert sts.bus.protocol == 1.0  # Feetech speaks one, Dynamixel-1.0-shaped protocol
    assert xl.models_by_id == {i: xl.joints[0].model for i in range(1, 7)}
    ax = load_robot_config(resolve_config("ax12a-biped"))
    assert {j.model.name for j in ax.joints} == {"AX-12A"} and ax.bus.protocol == 1.0


def test_default_is_xl430_and_names_resolve():
    assert default_config_path().name == "xl430-biped.toml"
    assert set(SHIPPED) <= set(shipped_config_names())
    assert resolve_config("ax12a-biped.toml") == resolve_config("ax12a-biped")


def test_resolve_prefers_existing_path_and_lists_shipped_names(tmp_path):
    path = tmp_path / "mine.toml"
    path.write_text(shipped_text("xl430-biped"))
    assert resolve_config(str(path)) == path
    with pytest.raises(ConfigError) as info:
        resolve_config("no-such-robot")
    assert "xl430-biped" in str(info.value) and "no-such-robot" in str(info.value)


def test_joint_lookup_and_held_joint_order():
    config = load_robot_config(resolve_config("ax12a-biped"))
    assert config.joint("knee_pitch_right").direction == -1
    assert [j.name for j in config.held_joints] == ["hip_roll_left", "hip_roll_right"]
    assert config.ids[:6] == (11, 13, 15, 12, 14, 16)  # PITCH_JOINTS order, not id order
    with pytest.raises(KeyError):
        config.joint("elbow")


def test_optional_fields_take_their_defaults(tmp_path):
    text = shipped_text("xl430-biped")
    text = re.sub(r"(?m)^ankle_height_m = .*\n", "", text)
    text = re.sub(r"(?m)^torque_off_on_exit = .*\n", "", text)
    config = load_text(tmp_path, text)
    assert config.geometry.ankle_height_m == 0.0
    assert config.bus.torque_off_on_exit is False


def test_config_is_frozen():
    config = load_robot_config(default_config_path())
    with pytest.raises(AttributeError):
        config.name = "other"  # type: ignore[misc]


# --- each mistake raises ConfigError naming the field ---------------------------------------------


def test_unreadable_file(tmp_path):
    missing = tmp_path / "nope.toml"
    with pytest.raises(ConfigError) as info:
        load_robot_config(missing)
    assert str(info.value).startswith(f"{missing}: file: cannot read")


def test_toml_syntax_error_gives_line(tmp_path):
    text = shipped_text("xl430-biped")
    lines = text.splitlines()
    n = next(i for i, line in enumerate(lines) if line.startswith("shank_m"))
    lines[n] = "shank_m 0.110"  # '=' missing
    expect_error(tmp_path, "\n".join(lines) + "\n", f"line {n + 1}", "TOML syntax error")


def test_missing_section(tmp_path):
    text = shipped_text("xl430-biped")
    a = text.index("[gait]")
    b = text.index("[bus]")
    expect_error(tmp_path, text[:a] + text[b:], "gait", "missing section")


def test_missing_field(tmp_path):
    text = re.sub(r"(?m)^thigh_m = .*\n", "", shipped_text("xl430-biped"))
    expect_error(tmp_path, text, "geometry.thigh_m", "missing")


def test_missing_joint_field(tmp_path):
    text = shipped_text("xl430-biped")
    a, b = joint_block(text, "ankle_pitch_right")
    block = re.sub(r"(?m)^zero_tick = .*\n", "", text[a:b])
    expect_error(tmp_path, text[:a] + block + text[b:], "joints.ankle_pitch_right.zero_tick", "missing")


def test_wrong_type_string_for_number(tmp_path):
    text = set_top(shipped_text("xl430-biped"), "shank_m", '"0.110"')
    expect_error(tmp_path, text, "geometry.shank_m", "positive number", "string")


def test_wrong_type_boolean_is_not_a_number(tmp_path):
    text = set_in_joint(shipped_text("xl430-biped"), "knee_pitch_left", "id", "true")
    expect_error(tmp_path, text, "joints.knee_pitch_left.id", "integer", "boolean")


def test_wrong_type_float_id(tmp_path):
    text = set_in_joint(shipped_text("xl430-biped"), "knee_pitch_left", "id", "2.0")
    expect_error(tmp_path, text, "joints.knee_pitch_left.id", "integer")


def test_unknown_key_in_section_is_named_with_suggestion(tmp_path):
    text = shipped_text("xl430-biped").replace("foot_m = ", "foot_mm = ")
    expect_error(tmp_path, text, "geometry.foot_mm", "unknown key", "'foot_m'")


def test_unknown_key_in_joint(tmp_path):
    text = shipped_text("xl430-biped")
    a, b = joint_block(text, "hip_pitch_right")
    block = text[a:b].replace("max_velocity_dps", "max_velocity_dsp")
    expect_error(tmp_path, text[:a] + block + text[b:], "joints.hip_pitch_right.max_velocity_dsp",
                 "unknown key", "max_velocity_dps")


def test_unknown_top_level_section(tmp_path):
    text = shipped_text("xl430-biped") + "\n[gaits]\ncycle_s = 1.0\n"
    expect_error(tmp_path, text, "gaits", "unknown key", "'gait'")


def test_unknown_backend_lists_allowed(tmp_path):
    text = set_top(shipped_text("xl430-biped"), "backend", '"herkulex"')
    expect_error(tmp_path, text, "bus.backend", "herkulex", "dynamixel", "feetech")


def test_unknown_model_lists_allowed(tmp_path):
    text = set_in_joint(shipped_text("xl430-biped"), "ankle_pitch_left", "model", '"XL430-W350"')
    expect_error(tmp_path, text, "joints.ankle_pitch_left.model", "XL430-W350", *SERVO_MODELS)


def test_model_family_must_match_backend(tmp_path):
    text = set_in_joint(shipped_text("xl430-biped"), "hip_pitch_left", "model", '"STS3215"')
    expect_error(tmp_path, text, "joints.hip_pitch_left.model", "feetech", "dynamixel")


def test_duplicate_ids(tmp_path):
    text = set_in_joint(shipped_text("xl430-biped"), "knee_pitch_right", "id", "2")
    # knee_pitch_left has id 2 and comes first in joint order
    expect_error(tmp_path, text, "joints.knee_pitch_right.id", "id 2", "knee_pitch_left")


@pytest.mark.parametrize("name, bad_id, top", [("xl430-biped", 253, 252), ("sts3215-biped", 254, 253),
                                              ("xl430-biped", -1, 252)])
def test_id_out_of_range(tmp_path, name, bad_id, top):
    text = set_in_joint(shipped_text(name), "hip_pitch_left", "id", str(bad_id))
    expect_error(tmp_path, text, "joints.hip_pitch_left.id", f"0..{top}")


def test_highest_ids_are_allowed(tmp_path):
    text = set_in_joint(shipped_text("sts3215-biped"), "hip_pitch_left", "id", "253")
    assert load_text(tmp_path, text).joint("hip_pitch_left").id == 253


def test_min_above_max(tmp_path):
    text = set_in_joint(shipped_text("xl430-biped"), "knee_pitch_left", "min_deg", "120.0")
    expect_error(tmp_path, text, "joints.knee_pitch_left.min_deg", "120.0", "above max_deg 110.0")


def test_limit_outside_servo_range(tmp_path):
    # AX-12A, zero 512, 1023 ticks over 300 deg: +150 deg is tick 512 + 150 * 1023/300 = 1023.5,
    # +155 deg is 1040.5 -> beyond 1023.
    text = set_in_joint(shipped_text("ax12a-biped"), "knee_pitch_left", "max_deg", "155.0")
    expect_error(tmp_path, text, "joints.knee_pitch_left.max_deg", "outside", "0..1023")


def test_limit_outside_servo_range_mirrored(tmp_path):
    # direction -1: min_deg -155 maps to 512 + 155 * 3.41 = 1040.5, beyond 1023.
    text = set_in_joint(shipped_text("ax12a-biped"), "knee_pitch_right", "min_deg", "-155.0")
    expect_error(tmp_path, text, "joints.knee_pitch_right.min_deg", "outside", "0..1023")


def test_limit_past_wrap_seam(tmp_path):
    # XL430 zero 2048: +190 deg is 2048 + 190 * 4096/360 = 4209.8 > 4095 (past the seam).
    text = set_in_joint(shipped_text("xl430-biped"), "hip_pitch_left", "max_deg", "190.0")
    expect_error(tmp_path, text, "joints.hip_pitch_left.max_deg", "0..4095")


def test_zero_tick_outside_range(tmp_path):
    text = set_in_joint(shipped_text("ax12a-biped"), "ankle_pitch_left", "zero_tick", "1024")
    expect_error(tmp_path, text, "joints.ankle_pitch_left.zero_tick", "1024", "0..1023")


def test_missing_walking_joint_names_it_and_the_likely_typo(tmp_path):
    text = shipped_text("xl430-biped").replace("[joints.knee_pitch_left]", "[joints.knee_pitch_lft]")
    expect_error(tmp_path, text, "joints.knee_pitch_left", "missing walking joint", "knee_pitch_lft")


def test_protocol_not_spoken_by_ax12a(tmp_path):
    text = set_top(shipped_text("ax12a-biped"), "protocol", "2.0")
    expect_error(tmp_path, text, "bus.protocol", "AX-12A", "1.0")


def test_protocol_not_spoken_by_xl320(tmp_path):
    text = set_top(shipped_text("ax12a-biped"), "protocol", "1.0")
    text = set_in_joint(text, "hip_roll_left", "model", '"XL-320"')
    expect_error(tmp_path, text, "bus.protocol", "XL-320", "2.0")


def test_x_series_speaks_both_protocols(tmp_path):
    text = set_top(shipped_text("xl430-biped"), "protocol", "1.0")
    assert load_text(tmp_path, text).bus.protocol == 1.0


def test_unknown_protocol(tmp_path):
    text = set_top(shipped_text("xl430-biped"), "protocol", "3.0")
    expect_error(tmp_path, text, "bus.protocol", "1.0 or 2.0")


def test_dynamixel_needs_protocol(tmp_path):
    text = re.sub(r"(?m)^protocol = .*\n", "", shipped_text("xl430-biped"))
    expect_error(tmp_path, text, "bus.protocol", "missing")


def test_feetech_protocol_is_ignored(tmp_path):
    text = shipped_text("sts3215-biped").replace('backend = "feetech"', 'backend = "feetech"\nprotocol = 2.0')
    assert load_text(tmp_path, text).bus.protocol == 1.0


def test_mixed_feetech_byte_orders(tmp_path):
    # SCS0009 is big-endian, STS3215 little-endian. SCS0009 covers 300 deg over 1024 ticks: keep
    # the limits (-45..45 deg -> 358..666 ticks around 512) inside its range so only the byte order is wrong.
    text = set_in_joint(shipped_text("sts3215-biped"), "ankle_pitch_right", "model", '"SCS0009"')
    text = set_in_joint(text, "ankle_pitch_right", "zero_tick", "512")
    expect_error(tmp_path, text, "joints.ankle_pitch_right.model", "big-endian", "little-endian")


@pytest.mark.parametrize("field, value", [("thigh_m", "0.0"), ("hip_width_m", "-0.07"), ("cycle_s", "0"),
                                          ("max_step_m", "-0.1"), ("clearance_m", "0.0"), ("rate_hz", "0")])
def test_non_positive_settings(tmp_path, field, value):
    section = "geometry" if field.endswith("_m") and field not in ("max_step_m", "clearance_m") else "gait"
    text = set_top(shipped_text("xl430-biped"), field, value)
    expect_error(tmp_path, text, f"{section}.{field}", "positive")


@pytest.mark.parametrize("key, value", [("max_velocity_dps", "0.0"), ("max_acceleration_dps2", "-6000.0")])
def test_non_positive_joint_rates(tmp_path, key, value):
    text = set_in_joint(shipped_text("xl430-biped"), "hip_pitch_right", key, value)
    expect_error(tmp_path, text, f"joints.hip_pitch_right.{key}", "positive")


def test_negative_ankle_height(tmp_path):
    text = set_top(shipped_text("xl430-biped"), "ankle_height_m", "-0.01")
    expect_error(tmp_path, text, "geometry.ankle_height_m", ">= 0")


@pytest.mark.parametrize("value", ["nan", "inf", "-inf"])
def test_non_finite_numbers(tmp_path, value):
    text = set_in_joint(shipped_text("xl430-biped"), "ankle_pitch_left", "max_deg", value)
    expect_error(tmp_path, text, "joints.ankle_pitch_left.max_deg", "finite")


def test_non_finite_length(tmp_path):
    text = set_top(shipped_text("xl430-biped"), "foot_m", "inf")
    expect_error(tmp_path, text, "geometry.foot_m", "finite")


@pytest.mark.parametrize("value", ["0", "-115200"])
def test_baudrate_not_positive(tmp_path, value):
    text = set_top(shipped_text("xl430-biped"), "baudrate", value)
    expect_error(tmp_path, text, "bus.baudrate", "positive")


def test_direction_must_be_plus_or_minus_one(tmp_path):
    text = set_in_joint(shipped_text("xl430-biped"), "hip_pitch_right", "direction", "0")
    expect_error(tmp_path, text, "joints.hip_pitch_right.direction", "1 or -1")


def test_torque_off_on_exit_must_be_boolean(tmp_path):
    text = set_top(shipped_text("xl430-biped"), "torque_off_on_exit", '"yes"')
    expect_error(tmp_path, text, "bus.torque_off_on_exit", "true or false")


def test_empty_port(tmp_path):
    text = set_top(shipped_text("xl430-biped"), "port", '""')
    expect_error(tmp_path, text, "bus.port", "serial port")


def test_held_joint_needs_hold_deg(tmp_path):
    text = re.sub(r"(?m)^hold_deg = .*\n", "", shipped_text("ax12a-biped"), count=1)
    expect_error(tmp_path, text, "joints.hip_roll_left.hold_deg", "missing")


def test_hold_deg_within_limits(tmp_path):
    text = set_in_joint(shipped_text("ax12a-biped"), "hip_roll_right", "hold_deg", "35.0")
    expect_error(tmp_path, text, "joints.hip_roll_right.hold_deg", "35.0", "-30.0..30.0")


def test_walking_joint_cannot_be_held(tmp_path):
    text = shipped_text("xl430-biped")
    a, b = joint_block(text, "hip_pitch_left")
    text = text[:a] + text[a:b].rstrip("\n") + "\nhold_deg = 0.0\n\n" + text[b:]
    expect_error(tmp_path, text, "joints.hip_pitch_left.hold_deg", "non-walking")


def test_section_of_wrong_shape(tmp_path):
    """The whole [robot] table becomes a string. The table is cut out to the next section: since the humanoid
    work it holds more than its name (``boom = true`` on the pitch-only robots), which would otherwise be left
    behind as an unknown top-level key and named first."""
    text, count = re.subn(r'(?ms)^\[robot\]\n.*?(?=^\[)', 'robot = "xl430-biped"\n\n', shipped_text("xl430-biped"),
                          count=1)
    assert count == 1
    expect_error(tmp_path, text, "robot", "table")


# --- the bus frame budget, checked on load with the vendor facts (no bus code) ---------------------


def test_config_module_does_not_import_the_bus_room():
    import gaitbot.robot.config as module

    source = Path(module.__file__).read_text()
    assert "gaitbot.bus" not in re.sub(r'(?s)""".*?"""', "", source)


@pytest.mark.parametrize("name", SHIPPED)
def test_shipped_configs_fit_the_bus_frame_budget_on_load(tmp_path, name):
    """Every shipped robot carries 60 Hz with read-back at its baud rate, and none can at 57600 baud
    (8 servos x ~14 bytes x 10 bits > 0.7 x 16.7 ms): refused on load, naming gait.rate_hz."""
    load_robot_config(resolve_config(name))
    slow = re.sub(r"(?m)^baudrate = \d+", "baudrate = 57600", shipped_text(name))
    path = tmp_path / "slow.toml"
    path.write_text(slow)
    with pytest.raises(ConfigError, match=r"gait\.rate_hz: .* too fast for .* at 57600 baud"):
        load_robot_config(path)


# --- the simulated robot's tables: [mass], [servo], heel_back_m -----------------------------------


def test_mass_and_servo_tables_are_optional_with_a_15_kg_default(tmp_path):
    text = shipped_text("xl430-biped")
    a, b = text.index("[mass]"), text.index("[bus]")
    text = re.sub(r"(?m)^heel_back_m = .*\n", "", text[:a] + text[b:])
    config = load_text(tmp_path, text)
    assert config.mass.total_kg == pytest.approx(1.5)
    assert (config.servo.stall_torque_nm, config.servo.no_load_speed_rpm, config.servo.full_torque_error_deg) == \
        (None, None, None)
    assert config.geometry.heel_back_m == 0.0


def test_mass_and_servo_values_are_read(tmp_path):
    text = set_top(shipped_text("xl430-biped"), "torso_kg", "0.55")
    text = text.replace("[servo]\nfull_torque_error_deg = 2.0\n", "[servo]\nstall_torque_nm = 1.5\nfull_torque_error_deg = 3.0\n")
    text = re.sub(r"(?m)^heel_back_m = .*$", "heel_back_m = 0.03", text, count=1)
    config = load_text(tmp_path, text)
    assert config.mass.torso_kg == 0.55 and config.mass.foot_kg == 0.04
    assert config.servo.stall_torque_nm == 1.5 and config.servo.full_torque_error_deg == 3.0
    assert config.servo.no_load_speed_rpm is None
    assert config.geometry.heel_back_m == 0.03


@pytest.mark.parametrize("edit, field, words", [
    (lambda t: set_top(t, "thigh_kg", "0"), "mass.thigh_kg", ("positive",)),
    (lambda t: set_top(t, "foot_kg", '"light"'), "mass.foot_kg", ("positive number", "string")),
    (lambda t: t.replace("[mass]\n", "[mass]\ntorso_g = 400\n"), "mass.torso_g", ("unknown key", "torso_kg")),
    (lambda t: t.replace("[servo]\n", "[servo]\nstall_torque_nm = -1.0\n"), "servo.stall_torque_nm", ("positive",)),
    (lambda t: t.replace("[servo]\n", "[servo]\nfull_torque_deg = 3.0\n"), "servo.full_torque_deg",
     ("unknown key", "full_torque_error_deg")),
    (lambda t: re.sub(r"(?m)^heel_back_m = .*$", "heel_back_m = 0.2", t, count=1),
     "geometry.heel_back_m", ("shorter than foot_m",)),
])
def test_bad_mass_servo_or_heel_is_named(tmp_path, edit, field, words):
    expect_error(tmp_path, edit(shipped_text("xl430-biped")), field, *words)


def test_every_servo_model_has_drive_figures():
    for model in SERVO_MODELS.values():
        assert model.stall_torque_nm > 0 and model.full_torque_error_deg > 0 and model.no_load_speed_rpm > 0
