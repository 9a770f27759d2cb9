"""Issue 26 item 11: every number of a robot config has a physical range, refused in one line naming the field."""

from __future__ import annotations

import re

import pytest

from gaitbot.robot.config import ConfigError, load_robot_config
from helpers import CONFIG_DIR, gaitbot

OP3 = (CONFIG_DIR / "op3.toml").read_text()
TORSO_COM = "com_m = [-0.00581498, 0.000115708, 0.0725197]"
TORSO_INERTIA = "inertia_kg_m2 = [0.0142998, 0.00682604, 0.0112527, 6.50859e-06, -7.92052e-05, -4.55023e-06]"


def refused(tmp_path, text: str, field: str) -> str:
    path = tmp_path / "robot.toml"
    path.write_text(text)
    with pytest.raises(ConfigError) as caught:
        load_robot_config(path)
    message = str(caught.value)
    assert f"{field}:" in message and "\n" not in message, message
    return message


@pytest.mark.parametrize("com", ["[1e300, 0, 0]", "[0, 0, 5.0]", "[-1e308, 1e308, 1e308]"])
def test_a_centre_of_mass_beyond_the_robots_reach_is_refused_naming_the_field(tmp_path, com):
    assert TORSO_COM in OP3
    message = refused(tmp_path, OP3.replace(TORSO_COM, f"com_m = {com}"), "links.torso.com_m")
    assert "reach" in message


@pytest.mark.parametrize("inertia, field", [
    ("[1e300, 1e300, 1e300, 0, 0, 0]", "links.torso.inertia_kg_m2[0]"),  # more than 1.96 kg within reach can have
    ("[0.3, 0.2, 0.2, 0, 0, 0]", "links.torso.inertia_kg_m2[0]"),        # 0.3 > 1.96 kg x (0.347 m)^2 = 0.236
    ("[0.01, 0.01, 0.0, 0, 0, 0]", "links.torso.inertia_kg_m2"),          # not positive-definite: a massive rod
])
def test_an_inertia_a_link_cannot_have_is_refused_naming_the_field(tmp_path, inertia, field):
    refused(tmp_path, OP3.replace(TORSO_INERTIA, f"inertia_kg_m2 = {inertia}"), field)


def test_the_shipped_robots_inertias_are_well_inside_the_range():
    """An independent bound: a link's moments are at most mass x (its distance to the far end)^2, which the
    reach bounds; the shipped OP3 (ROBOTIS' own mass table) sits far inside it."""
    config = load_robot_config(CONFIG_DIR / "op3.toml")
    reach_m = config.geometry.thigh_m + config.geometry.shank_m + config.geometry.foot_m
    for name, link in config.links:
        assert abs(link.inertia_kg_m2).max() <= 0.1 * max(link.mass_kg, 1e-9) * reach_m ** 2, name


def test_a_baud_rate_the_servo_model_cannot_be_set_to_is_refused(tmp_path):
    """The AX-12A's fastest is 1 Mbaud (ROBOTIS e-Manual, AX-12A, Baud Rate(4): 2,000,000 / (value + 1), value
    1 = 1 Mbps the fastest listed); the Dynamixel SDK itself would set 2 Mbaud."""
    bioloid = (CONFIG_DIR / "bioloid.toml").read_text()
    assert re.search(r"^baudrate = 1000000", bioloid, re.M)
    message = refused(tmp_path, re.sub(r"^baudrate = 1000000", "baudrate = 2000000", bioloid, flags=re.M),
                      "bus.baudrate")
    assert "AX-12A" in message and "cannot run at 2,000,000 baud" in message and "1000000" in message


def test_the_command_line_refuses_them_in_one_line_exit_2(tmp_path):
    path = tmp_path / "r.toml"
    path.write_text(OP3.replace(TORSO_COM, "com_m = [1e300, 0, 0]"))
    proc = gaitbot("walk", "--dry-run", "--robot", str(path), "--distance", "0.1")
    assert proc.returncode == 2 and "links.torso.com_m" in proc.stderr
    assert "Traceback" not in proc.stderr and len(proc.stderr.strip().splitlines()) == 1, proc.stderr


def test_each_tables_keys_are_its_data_class_fields_and_the_module_is_short():
    """Issue 21: the allowed keys were tuples kept by hand beside the fields; now derived, written once."""
    from dataclasses import fields

    from gaitbot.robot import config as module
    from gaitbot.robot.config_types import GaitSettings, Geometry, JointConfig

    assert module._GEOMETRY_KEYS == tuple(f.name for f in fields(Geometry))
    assert module._GAIT_KEYS == tuple(f.name for f in fields(GaitSettings))
    assert set(module._JOINT_KEYS) == {f.name for f in fields(JointConfig)} - {"name"}
    assert len(open(module.__file__).read().splitlines()) < 600
