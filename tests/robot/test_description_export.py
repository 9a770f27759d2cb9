"""gaitbot robot export --urdf: every shipped robot, read back by a maintained URDF parser (yourdfpy).

Its forward kinematics (yourdfpy's own transform chain) must put every link where gaitbot's leg model does
(gaitbot.gait.kinematics6) at random poses within the joints' limits, to 1e-9 m; its masses must add up to
the config's, and the whole robot's centre of mass, summed here from yourdfpy's link frames and the URDF's
inertials, must be gaitbot's mass model's (gaitbot.gait.mass, a different computation: rotations of points).
The MJCF's twin test is tests/sim/test_description_mjcf.py.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from gaitbot.gait.body import LEG_LINKS
from gaitbot.gait.joints import LEG_JOINT_KINDS, SIDES
from gaitbot.gait.kinematics6 import leg_frames, sole_centre
from gaitbot.gait.mass import MassModel
from gaitbot.robot.config import load_robot_config, resolve_config, shipped_config_names
from gaitbot.robot.description.urdf_writer import urdf_text

yourdfpy = pytest.importorskip("yourdfpy")

POSES = 60
TOLERANCE_M = 1e-9


def random_leg_angles(config, rng) -> dict[str, float]:
    """Every walking joint at a random angle within its limits (rad); held joints at their hold angle."""
    angles = {j.name: rng.uniform(math.radians(j.min_deg), math.radians(j.max_deg)) for j in config.walking_joints}
    angles.update({j.name: math.radians(j.hold_deg) for j in config.held_joints})
    return angles


def leg_vector(angles: dict[str, float], side: str) -> np.ndarray:
    return np.array([angles.get(f"{kind}_{side}", 0.0) for kind in LEG_JOINT_KINDS])


def tilted_config(tmp_path):
    """The ax12a-biped with its held hip roll held at 4 deg instead of 0: a held joint turns the leg below it."""
    text = resolve_config("ax12a-biped").read_text()
    assert text.count("hold_deg = 0.0") == 2
    path = tmp_path / "tilted.toml"
    path.write_text(text.replace("hold_deg = 0.0", "hold_deg = 4.0"))
    return path


ROBOTS = shipped_config_names() + ["tilted"]


def load(tmp_path, name):
    config = load_robot_config(tilted_config(tmp_path) if name == "tilted" else resolve_config(name))
    path = tmp_path / f"{name}.urdf"
    path.write_text(urdf_text(config))
    return config, yourdfpy.URDF.load(str(path), load_meshes=False, build_scene_graph=True)


@pytest.mark.parametrize("name", ROBOTS)
def test_urdf_forward_kinematics_masses_and_centre_of_mass_are_the_configs(tmp_path, name):
    config, urdf = load(tmp_path, name)
    assert sorted(urdf.actuated_joint_names) == sorted(config.walking_joint_names)  # held joints are fixed
    mass_model = MassModel.of(config.body)
    inertials = {link.name: link.inertial for link in urdf.robot.links if link.inertial is not None}
    assert sum(i.mass for i in inertials.values()) == pytest.approx(config.body.total_kg, abs=1e-12)
    rng = np.random.default_rng(24)
    worst_m = 0.0
    for _ in range(POSES):
        angles = random_leg_angles(config, rng)
        urdf.update_cfg({n: angles[n] for n in urdf.actuated_joint_names})
        for side in SIDES:
            rotations, origins = leg_frames(config.body.geometry, side, leg_vector(angles, side))
            for k, link in enumerate(LEG_LINKS):
                t = urdf.get_transform(f"{link}_{side}", "base_link")
                worst_m = max(worst_m, np.abs(t[:3, 3] - origins[k]).max())
                assert np.allclose(t[:3, :3], rotations[k], atol=1e-12)
            sole = urdf.get_transform({"left": "l_sole", "right": "r_sole"}[side], "base_link")[:3, 3]
            assert np.abs(sole - sole_centre(config.body.geometry, side, leg_vector(angles, side))).max() < TOLERANCE_M
        com = sum(i.mass * (urdf.get_transform(n, "base_link") @ np.append(i.origin[:3, 3], 1.0))[:3]
                  for n, i in inertials.items()) / config.body.total_kg
        q12 = np.concatenate([leg_vector(angles, side) for side in SIDES])
        assert np.abs(com - mass_model.com_in_root(q12)).max() < TOLERANCE_M
    assert worst_m < TOLERANCE_M


def test_urdf_frames_for_other_tools_are_there(tmp_path):
    """REP-120's base_link and soles, PlaCo's trunk, feet and hips (docs/robot-description.md)."""
    _, urdf = load(tmp_path, "op3")
    for frame in ("base_link", "torso", "trunk", "l_sole", "r_sole", "left_foot", "right_foot", "left_hip_yaw",
                  "right_hip_yaw"):
        assert frame in urdf.link_map, frame
    assert np.allclose(urdf.get_transform("left_foot", "base_link"), urdf.get_transform("l_sole", "base_link"))


def test_urdf_limits_and_the_held_joint(tmp_path):
    config, urdf = load(tmp_path, "ax12a-biped")
    for joint in config.walking_joints:
        limit = urdf.joint_map[joint.name].limit
        assert (limit.lower, limit.upper) == pytest.approx((math.radians(joint.min_deg), math.radians(joint.max_deg)))
    held = config.held_joints[0]
    assert urdf.joint_map[held.name].type == "fixed"


def test_placo_reads_the_urdf_with_its_frames(tmp_path):
    """PlaCo (Rhoban's walking library, the benchmark extra) takes the exported URDF as a HumanoidRobot: its
    trunk-to-hip spacing and its mass are the config's."""
    placo = pytest.importorskip("placo")
    config, _ = load(tmp_path, "op3")
    robot = placo.HumanoidRobot(str(tmp_path / "op3.urdf"))
    hip = robot.get_T_a_b("trunk", "left_hip_yaw")[:3, 3]
    assert np.allclose(hip, config.body.geometry.hip_in_root("left"), atol=1e-12)
    assert robot.total_mass() == pytest.approx(config.body.total_kg, abs=1e-9)
