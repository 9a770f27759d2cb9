"""The /tf and /tf_static transforms against gaitbot's own leg kinematics (gaitbot.gait.kinematics6), computed
another way: there the link rotations are products of explicit axis rotations in the root frame; here each
joint is an offset and a quaternion about its axis, composed down the tree as a URDF's robot_state_publisher
does, the fixed joints from /tf_static."""

import numpy as np
import pytest

from gaitbot.check.balance import rotation_rpy
from gaitbot.gait.joints import LEG_JOINTS, SIDES
from gaitbot.gait.kinematics6 import leg_frames, sole_centre
from gaitbot.robot.description.frames import joint_frames
from gaitbot.view.link_frames import BASE_LINK, WORLD_FRAME, LinkTransforms, rotation_xyzw
from helpers import config


def quaternion_matrix(q) -> np.ndarray:
    x, y, z, w = q
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                     [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                     [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]])


def world_poses(transforms) -> dict:
    """Each frame's (rotation, origin) in the first transform's parent frame, composing parent -> child."""
    poses = {transforms[0].parent: (np.eye(3), np.zeros(3))}
    pending = list(transforms)
    while pending:  # parents before children, whatever the order given
        t = next(t for t in pending if t.parent in poses)
        pending.remove(t)
        rotation, origin = poses[t.parent]
        poses[t.child] = (rotation @ quaternion_matrix(t.rotation_xyzw), origin + rotation @ np.array(t.translation))
    return poses


@pytest.mark.parametrize("robot", ["op3", "xl430-biped"])
def test_links_match_the_leg_kinematics_at_random_poses(robot):
    cfg = config(robot)
    geometry = cfg.body.geometry
    links = LinkTransforms(cfg)
    child = {row.name: row.child for row in joint_frames(cfg)}  # a held joint's link too
    fixed = {row.name: row.angle_rad for row in joint_frames(cfg)}  # a held joint at its hold angle, a missing one at 0
    rng = np.random.default_rng(24)
    for _ in range(50):
        q = rng.uniform(-0.8, 0.8, len(LEG_JOINTS))
        q = np.array([a if j in cfg.walking_joint_names else fixed[j] for j, a in zip(LEG_JOINTS, q)])
        root, rpy = rng.uniform(-1, 1, 3), rng.uniform(-0.4, 0.4, 3)
        poses = world_poses(links.transforms(LEG_JOINTS, q, root, rpy) + list(links.static))
        torso = rotation_rpy(rpy[None, :])[0]
        assert np.allclose(poses[BASE_LINK][0], torso, atol=1e-12)
        for i, side in enumerate(SIDES):
            rotations, origins = leg_frames(geometry, side, q[6 * i:6 * i + 6])
            for k, joint in enumerate(LEG_JOINTS[6 * i:6 * i + 6]):
                rotation, origin = poses[child[joint]]
                assert np.allclose(rotation, torso @ rotations[k], atol=1e-12), joint
                assert np.allclose(origin, root + torso @ origins[k], atol=1e-12), joint
            # the sole centre, from the foot link and the body's sole offset, as kinematics6 places it
            rotation, origin = poses[f"foot_{side}"]
            sole = origin + rotation @ geometry.sole_centre_in_foot(side)
            assert np.allclose(sole, root + torso @ sole_centre(geometry, side, q[6 * i:6 * i + 6]), atol=1e-12)
            # and the sole frames of /tf_static (REP-120's, PlaCo's) are there
            for name in ((f"{side[0]}_sole", f"{side}_foot")):
                assert np.allclose(poses[name][1], sole, atol=1e-12) and np.allclose(poses[name][0], rotation)


def test_tree_names_and_held_joints():
    """A walking joint is on /tf (at 0 when not given), every fixed joint on /tf_static; every URDF link gets a
    transform from exactly one of them (so Foxglove draws the whole exported robot)."""
    from gaitbot.robot.description.urdf_writer import urdf_text
    import re

    cfg = config("op3")
    links = LinkTransforms(cfg)
    transforms = links.transforms(("knee_pitch_left",), [0.5], np.zeros(3))
    assert transforms[0].parent == WORLD_FRAME and transforms[0].child == BASE_LINK
    assert [t.child for t in transforms[1:]] == [links.link_of(j) for j in cfg.walking_joint_names]
    assert links.link_of("knee_pitch_left") == "shank_left" and links.link_of("ankle_roll_right") == "foot_right"
    assert all(t.rotation_xyzw == (0.0, 0.0, 0.0, 1.0) for t in transforms[1:] if t.child != "shank_left")
    children = [t.child for t in transforms[1:]] + [t.child for t in links.static]
    urdf_links = re.findall(r'<link name="([^"]+)"', urdf_text(cfg))
    assert sorted(children + [BASE_LINK]) == sorted(urdf_links)
    assert {"torso", "trunk", "l_sole", "r_sole", "left_foot", "right_foot"} <= {t.child for t in links.static}


def test_rotation_quaternion_round_trip():
    rng = np.random.default_rng(7)
    for _ in range(200):
        rotation = rotation_rpy(rng.uniform(-np.pi, np.pi, (1, 3)))[0]
        q = rotation_xyzw(rotation)
        assert np.isclose(np.linalg.norm(q), 1.0)
        assert np.allclose(quaternion_matrix(q), rotation, atol=1e-12)


def test_sole_poses_from_corners_are_the_foot_pose():
    """The footprints' poses (from the sole corners) against the foot link's rotation and the sole centre."""
    from gaitbot.gait.kinematics6 import foot_pose, sole_corners
    from gaitbot.view.walk_frames import sole_poses

    geometry = config("op3").body.geometry
    q = np.random.default_rng(3).uniform(-0.5, 0.5, (40, 6))
    for side in SIDES:
        centre, rotation = sole_poses(sole_corners(geometry, side, q))
        assert np.allclose(centre, sole_centre(geometry, side, q), atol=1e-12)
        assert np.allclose(rotation, foot_pose(geometry, side, q)[1], atol=1e-12)
