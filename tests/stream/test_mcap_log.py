"""MCAP logs (gaitbot.stream.mcap_log) read back with the mcap reader and the ROS 2 decoder of the mcap
libraries: every channel at the frame rate, ROS 2 schemas and CDR encoding, the goals as written, and the
transforms composed here (from the decoded quaternions, frame by frame down the tree) putting every leg link
where gaitbot's kinematics do (1e-9 m)."""

from __future__ import annotations

import numpy as np
import pytest

from gaitbot.app.cli import main
from gaitbot.gait.body import LEG_LINKS
from gaitbot.gait.joints import LEG_JOINT_KINDS, SIDES
from gaitbot.gait.kinematics6 import leg_frames
from gaitbot.gait.trajectory import Trajectory
from gaitbot.robot.config import load_robot_config, resolve_config
from gaitbot.robot.description.urdf_writer import urdf_text

pytest.importorskip("mcap_ros2")
from mcap.reader import make_reader  # noqa: E402
from mcap_ros2.decoder import DecoderFactory  # noqa: E402

from gaitbot.stream.mcap_log import McapLog, write_trajectory  # noqa: E402

START_NS = 1_700_000_000_000_000_000


def read(path):
    with open(path, "rb") as f:
        reader = make_reader(f, decoder_factories=[DecoderFactory()])
        header, summary = reader.get_header(), reader.get_summary()
        messages = [(channel.topic, schema.name, channel.message_encoding, message.log_time, decoded)
                    for schema, channel, message, decoded in reader.iter_decoded_messages()]
    return header, summary, messages


def matrix(q) -> np.ndarray:
    w, x, y, z = q.w, q.x, q.y, q.z
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
                     [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
                     [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]])


@pytest.fixture(scope="module")
def walk(tmp_path_factory):
    folder = tmp_path_factory.mktemp("mcap")
    assert main(["generate", "--robot", "op3", "--distance", "0.2", "-o", str(folder / "walk.npz")]) == 0
    config = load_robot_config(resolve_config("op3"))
    trajectory = Trajectory.load(folder / "walk.npz")
    written = write_trajectory(folder / "walk.mcap", config, trajectory, start_ns=START_NS)
    return config, trajectory, written, read(folder / "walk.mcap")


def test_every_channel_at_the_frame_rate_as_ros2_messages(walk):
    config, trajectory, written, (header, summary, messages) = walk
    assert header.profile == "ros2" and written == len(trajectory)
    counts = {c.topic: summary.statistics.channel_message_counts[i] for i, c in summary.channels.items()}
    assert counts == {"/robot_description": 1, "/tf_static": 1, "/joint_goals": written, "/tf": written,
                      "/com/planned": written}
    schemas = {topic: (schema, encoding) for topic, schema, encoding, _, _ in messages}
    assert schemas["/joint_goals"] == ("sensor_msgs/msg/JointState", "cdr")
    assert schemas["/tf"] == ("tf2_msgs/msg/TFMessage", "cdr")
    for topic in ("/joint_goals", "/tf", "/com/planned"):
        times = np.array([t for name, _, _, t, _ in messages if name == topic], dtype=np.int64) - START_NS
        assert np.allclose(times / 1e9, trajectory.t_s, atol=1e-9)
    description = next(m for name, _, _, _, m in messages if name == "/robot_description")
    assert description.data == urdf_text(config)
    goals = np.array([m.position for name, _, _, _, m in messages if name == "/joint_goals"])
    first = next(m for name, _, _, _, m in messages if name == "/joint_goals")
    assert list(first.name) == list(config.joint_names)
    assert np.allclose(goals, trajectory.angles_of(config.joint_names), atol=1e-12)


def test_the_transforms_put_every_link_where_gaitbots_kinematics_do(walk):
    config, trajectory, _, (_, _, messages) = walk
    static = next(m for name, _, _, _, m in messages if name == "/tf_static").transforms
    frames = [m.transforms for name, _, _, _, m in messages if name == "/tf"]
    for k in range(0, len(frames), 25):
        parent_of = {}
        for t in list(static) + list(frames[k]):
            v = t.transform.translation
            parent_of[t.child_frame_id] = (t.header.frame_id, np.array([v.x, v.y, v.z]), matrix(t.transform.rotation))

        def pose(frame):
            if frame == "odom":
                return np.eye(3), np.zeros(3)
            parent, p, r = parent_of[frame]
            pr, pp = pose(parent)
            return pr @ r, pp + pr @ p

        root_r, root_p = pose("base_link")
        assert np.allclose(root_p, trajectory.root_m[k], atol=1e-12)
        for side in SIDES:
            q = trajectory.angles_of([f"{kind}_{side}" for kind in LEG_JOINT_KINDS])[k]
            rotations, origins = leg_frames(config.body.geometry, side, q)
            for i, link in enumerate(LEG_LINKS):
                r, p = pose(f"{link}_{side}")
                assert np.abs(root_r.T @ (p - root_p) - origins[i]).max() < 1e-9
                assert np.abs(root_r.T @ r - rotations[i]).max() < 1e-9


def test_points_polygons_commands_and_health_read_back(tmp_path):
    config = load_robot_config(resolve_config("ax12a-biped"))
    with McapLog(tmp_path / "x.mcap", config, compress=False) as log:
        log.point("/zmp/measured", 0.5, (0.01, -0.02, 0.0))
        log.polygon("/support_polygon", 0.5, [(0, 0, 0), (0.1, 0, 0), (0.1, 0.05, 0)])
        log.twist(0.5, 0.1, 0.0, 0.2)
        log.diagnostics(0.5, [("knee_pitch_left", 1, "hot", {"temperature_c": 61})])
        log.joint_states(0.5, ["knee_pitch_left"], [0.3], [1.0], [0.2])
    _, _, messages = read(tmp_path / "x.mcap")
    got = {name: m for name, _, _, _, m in messages}
    assert (got["/zmp/measured"].point.x, got["/zmp/measured"].point.y) == (0.01, -0.02)
    assert got["/zmp/measured"].header.frame_id == "odom"
    corners = [(p.x, p.y) for p in got["/support_polygon"].polygon.points]  # float32 (geometry_msgs/Point32)
    assert np.allclose(corners, [(0, 0), (0.1, 0), (0.1, 0.05)], atol=1e-7)
    assert (got["/cmd_vel"].linear.x, got["/cmd_vel"].angular.z) == (0.1, 0.2)
    status = got["/diagnostics"].status[0]
    assert (status.name, status.level, status.values[0].key, status.values[0].value) == \
        ("knee_pitch_left", 1, "temperature_c", "61")
    js = got["/joint_states"]
    assert (list(js.position), list(js.velocity), list(js.effort)) == ([0.3], [1.0], [0.2])
    assert js.header.stamp.sec == 0 and js.header.stamp.nanosec == 500_000_000
