"""12-joint robots in the config: joint sets by name, the 3D geometry, the link mass table, and one
line naming the field for each malformed file (exit 2 through the command line, nothing sent)."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest

from gaitbot.app.cli import main
from gaitbot.gait.joints import LEG_JOINTS
from gaitbot.robot.config import ConfigError, load_robot_config, resolve_config

OP3_TEXT = resolve_config("op3").read_text()


def joint_block(text: str, name: str) -> tuple[int, int]:
    start = text.index(f"[joints.{name}]")
    nxt = re.search(r"(?m)^\[", text[start + 1:])
    return start, (start + 1 + nxt.start()) if nxt else len(text)


def without_joint(text: str, name: str) -> str:
    a, b = joint_block(text, name)
    return text[:a] + text[b:]


def set_in_joint(text: str, name: str, key: str, value: str) -> str:
    a, b = joint_block(text, name)
    block = re.sub(rf"(?m)^{key} = .*$", f"{key} = {value}", text[a:b])
    return text[:a] + block + text[b:]


def expect(tmp_path: Path, capsys, text: str, field: str, *words: str) -> str:
    path = tmp_path / "robot.toml"
    path.write_text(text)
    with pytest.raises(ConfigError) as info:
        load_robot_config(path)
    message = str(info.value)
    assert "\n" not in message and message.startswith(f"{path}: {field}: "), message
    for word in words:
        assert word in message, (word, message)
    # the command line says the same in one line, exit 2, before any port is opened or any packet sent
    record = tmp_path / "run.jsonl"
    assert main(["walk", "--dry-run", "--robot", str(path), "--steps", "0.02", "--record", str(record)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and field in err[0] and not record.exists()
    return message


def test_the_op3_lists_twelve_leg_joints_in_canonical_order_and_its_mass_adds_up():
    config = load_robot_config(resolve_config("op3"))
    assert config.walking_joint_names == LEG_JOINTS and config.is_3d and not config.boom
    # ROBOTIS's own ids: right odd, left even, hip yaw 7/8 ... ankle roll 17/18
    assert config.ids == (8, 10, 12, 14, 16, 18, 7, 9, 11, 13, 15, 17)
    links = dict(config.links)
    assert config.body.total_kg == pytest.approx(links["torso"].mass_kg + 2 * sum(
        links[n].mass_kg for n in ("hip_yaw", "hip_roll", "thigh", "shank", "ankle", "foot")))
    # the right leg's links are the left's mirror image
    right = config.body.leg_link("thigh", "right")
    assert right.com_m[1] == -links["thigh"].com_m[1]


def test_a_roll_joint_on_one_side_only(tmp_path, capsys):
    expect(tmp_path, capsys, without_joint(OP3_TEXT, "hip_roll_right"), "joints.hip_roll_right", "missing",
           "hip_roll_left", "mirror")


def test_an_unknown_joint_name(tmp_path, capsys):
    text = OP3_TEXT + ("\n[joints.ankle_rol_left]\nid = 30\nmodel = \"XM430-W350\"\nzero_tick = 2048\ndirection = 1\n"
                       "min_deg = -10.0\nmax_deg = 10.0\nmax_velocity_dps = 240.0\nmax_acceleration_dps2 = 20000.0\n")
    expect(tmp_path, capsys, text, "joints.ankle_rol_left", "unknown joint", "ankle_roll_left")


def test_roll_limits_that_cannot_hold_a_flat_foot(tmp_path, capsys):
    # ankle roll only down to -5 deg: with hip roll beyond 5 deg the left sole cannot stay flat
    text = set_in_joint(OP3_TEXT, "ankle_roll_left", "max_deg", "5.0")
    expect(tmp_path, capsys, text, "joints.ankle_roll_left.max_deg", "flat sole", "12.2")


def test_a_mass_table_that_does_not_add_up(tmp_path, capsys):
    text = re.sub(r"(?m)^total_kg = .*$", "total_kg = 3.5", OP3_TEXT)
    expect(tmp_path, capsys, text, "mass.total_kg", "does not add up", "3.147")


def test_an_inertia_no_rigid_body_has(tmp_path, capsys):
    a = OP3_TEXT.index("[links.thigh]")
    b = OP3_TEXT.index("inertia_kg_m2", a)
    end = OP3_TEXT.index("\n", b)
    text = OP3_TEXT[:b] + "inertia_kg_m2 = [1e-4, 1e-5, 1e-5, 0, 0, 0]" + OP3_TEXT[end:]
    expect(tmp_path, capsys, text, "links.thigh.inertia_kg_m2", "rigid body")


def test_a_3d_robot_needs_its_sole_width(tmp_path, capsys):
    text = re.sub(r"(?m)^foot_width_m = .*\n", "", OP3_TEXT)
    expect(tmp_path, capsys, text, "geometry.foot_width_m", "missing")


def test_a_held_joint_whose_mirror_walks(tmp_path, capsys):
    a, b = joint_block(OP3_TEXT, "hip_yaw_left")
    text = OP3_TEXT[:b].rstrip("\n") + "\nhold_deg = 0.0\n\n" + OP3_TEXT[b:]
    expect(tmp_path, capsys, text, "joints.hip_yaw_right.hold_deg", "missing", "held")


def test_link_masses_and_segment_masses_together_are_refused(tmp_path, capsys):
    text = OP3_TEXT.replace("[mass]\n", "[mass]\ntorso_kg = 1.0\n", 1)
    expect(tmp_path, capsys, text, "mass.torso_kg", "not both")


def test_a_planar_robot_with_a_total_mass_that_does_not_add_up(tmp_path, capsys):
    text = resolve_config("xl430-biped").read_text().replace("[mass]\n", "[mass]\ntotal_kg = 2.0\n", 1)
    expect(tmp_path, capsys, text, "mass.total_kg", "0.84")


def test_the_bioloid_is_a_twelve_joint_ax12a_robot_on_protocol_1():
    config = load_robot_config(resolve_config("bioloid"))
    assert config.is_3d and len(config.walking_joints) == 12
    assert {j.model.name for j in config.joints} == {"AX-12A"} and config.bus.protocol == 1.0
    assert config.body.total_kg == pytest.approx(1.539, abs=1e-3)
    # the dog-leg offsets: the servos' centre (512) is where our hip, knee and ankle stand at the link
    # offsets (10.94, 22.48, 11.54 deg), each 3.41 ticks per degree
    for name, offset_deg in (("hip_pitch_left", 10.94), ("knee_pitch_left", 22.48), ("ankle_pitch_left", 11.54)):
        joint = config.joint(name)
        at_offset = joint.zero_tick + joint.direction * offset_deg * 1023 / 300
        assert abs(at_offset - 512) <= 0.5
    assert np.isclose(config.geometry.thigh_m, np.hypot(0.075, 0.0145), atol=1e-4)
