"""--mcap: the log read back with the mcap reader (and mcap-ros2-support's decoder) holds every channel once a
frame, and what it decodes to is what was sent (to the observer, and to the servos)."""

import math
from collections import defaultdict

import numpy as np
import pytest

pytest.importorskip("mcap_ros2")
from mcap.reader import make_reader  # noqa: E402
from mcap_ros2.decoder import DecoderFactory  # noqa: E402

from gaitbot.gait.joints import LEG_JOINTS  # noqa: E402
from gaitbot.robot.calibration import angles_to_ticks  # noqa: E402
from gaitbot.view.channels import CHANNELS, STATIC_CHANNELS  # noqa: E402
from gaitbot.view.mcap_log import McapSink  # noqa: E402
from gaitbot.view.publisher import TelemetryPublisher  # noqa: E402
from gaitbot.view.telemetry import FrameTelemetry, ImuSample, ServoHealth  # noqa: E402
from helpers import config, recorded_goal_ticks, run_cli  # noqa: E402

START_NS = 1_700_000_000_000_000_000


def read_back(path) -> dict:
    """topic -> [(log_time_ns, schema name, message encoding, decoded)]"""
    out = defaultdict(list)
    with open(path, "rb") as f:
        reader = make_reader(f, decoder_factories=[DecoderFactory()])
        assert reader.get_header().profile == "ros2"
        for schema, channel, message, decoded in reader.iter_decoded_messages(log_time_order=True):
            out[channel.topic].append((message.log_time, schema.name, channel.message_encoding, decoded))
    return out


def random_frames(n: int, rng) -> list[FrameTelemetry]:
    frames = []
    for k in range(n):
        read = rng.uniform(-1, 1, 12)
        read[k % 12] = math.nan  # a joint not read this frame
        frames.append(FrameTelemetry(
            t_s=k / 60, joints=LEG_JOINTS, goals_rad=rng.uniform(-1, 1, 12), root_m=rng.uniform(-1, 1, 3),
            root_rpy_rad=rng.uniform(-0.3, 0.3, 3), read_back_rad=read, com_m=rng.uniform(-1, 1, 3),
            zmp_m=rng.uniform(-1, 1, 2), measured_com_m=rng.uniform(-1, 1, 3), measured_zmp_m=rng.uniform(-1, 1, 2),
            soles_m={"left": (rng.uniform(-1, 1, 3), np.eye(3)), "right": (rng.uniform(-1, 1, 3), np.eye(3))},
            support_m=rng.uniform(-1, 1, (4, 2)), measured_pelvis=(rng.uniform(-1, 1, 3), np.eye(3)),
            imu=ImuSample(tuple(rng.uniform(-1, 1, 3)), tuple(rng.uniform(-9, 9, 3))),
            health=ServoHealth(1, "servo 7 at 61 °C", 61.0, 11.9, 40.0), command=tuple(rng.uniform(-1, 1, 3))))
    return frames


def test_every_channel_every_frame_decodes_to_what_was_sent(tmp_path):
    frames = random_frames(30, np.random.default_rng(24))
    publisher = TelemetryPublisher(config("op3"), [McapSink(tmp_path / "w.mcap")], start_ns=START_NS)
    for frame in frames:
        publisher.on_frame(frame)
    publisher.close()
    log = read_back(tmp_path / "w.mcap")
    assert set(log) == set(CHANNELS)
    for topic, messages in log.items():
        times = [START_NS] if topic in STATIC_CHANNELS else [START_NS + round(k * 1e9 / 60) for k in range(30)]
        assert [t for t, *_ in messages] == times, topic  # the static ones once, at the start
        assert {(s, e) for _, s, e, _ in messages} == {(CHANNELS[topic], "cdr")}
    for frame, (_, _, _, goals), (_, _, _, states), (_, _, _, com), (_, _, _, zmp), (_, _, _, twist), (_, _, _, imu), \
            (_, _, _, polygon), (_, _, _, diag) in zip(frames, log["/joint_goals"], log["/joint_states"], log["/com"],
                                                       log["/zmp"], log["/walk_command"], log["/imu"],
                                                       log["/support_polygon"], log["/diagnostics"]):
        assert goals.name == list(LEG_JOINTS) and goals.position == list(frame.goals_rad)
        known = ~np.isnan(frame.read_back_rad)
        assert states.name == [n for n, ok in zip(LEG_JOINTS, known) if ok]
        assert states.position == list(frame.read_back_rad[known])
        assert (com.point.x, com.point.y, com.point.z) == tuple(frame.com_m)
        assert (zmp.point.x, zmp.point.y, zmp.point.z) == (*frame.zmp_m, 0.0)
        assert (twist.linear.x, twist.linear.y, twist.angular.z) == frame.command
        assert (imu.linear_acceleration.x, imu.angular_velocity.z) == (frame.imu.linear_acceleration_m_s2[0],
                                                                       frame.imu.angular_velocity_rad_s[2])
        assert imu.orientation_covariance[0] == -1.0  # no orientation estimate, as sensor_msgs/Imu says
        assert np.allclose([(p.x, p.y) for p in polygon.polygon.points], frame.support_m, atol=1e-6)  # float32
        assert diag.status[0].level == 1 and diag.status[0].message == "servo 7 at 61 °C"
    for frame, (_, _, _, pose) in zip(frames, log["/pose_measured"]):
        p, q = pose.pose.position, pose.pose.orientation
        assert (p.x, p.y, p.z) == tuple(frame.measured_pelvis[0]) and (q.x, q.y, q.z, q.w) == (0.0, 0.0, 0.0, 1.0)


def test_walk_mcap_holds_every_channel_at_the_frame_rate_and_the_goals_the_servos_got(tmp_path, capsys):
    mcap, record = tmp_path / "walk.mcap", tmp_path / "walk.jsonl"
    code, out, err = run_cli(capsys, "walk", "--robot", "op3", "--dry-run", "--distance", "0.1", "--record", record,
                             "--mcap", mcap)
    assert code == 0, err
    walk_frames = int(out.split("Sent ")[1].split()[0])
    log = read_back(mcap)
    expected = {"/joint_goals", "/tf", "/com", "/zmp", "/support_polygon", "/footprints", "/diagnostics"}
    # a dry run has no IMU (the mock bus has no OpenCR) and no command; its mock servos are read back
    assert set(log) == expected | {"/joint_states"} | set(STATIC_CHANNELS)
    for topic in expected:
        times = np.array([t for t, *_ in log[topic]])
        assert len(times) == walk_frames, topic
        assert np.allclose(np.diff(times), 1e9 / 60, atol=1), topic
    # the goals logged, turned into ticks, are the goal packets the mock bus recorded, frame for frame
    cfg = config("op3")
    sent = recorded_goal_ticks(record, "op3", cfg.joints)
    logged = [list(angles_to_ticks(cfg, np.array(m.position), m.name)) for *_, m in log["/joint_goals"]]
    start = sent.index(logged[1]) - 1
    assert sent[start:start + len(logged)] == logged
    # /joint_states: each mock servo reports the goal it was sent last (gaitbot.bus.dry_run), read one servo a
    # frame in turn: every angle read back is, to half a tick, a goal its joint was logged with in the frames
    # since its last read (one frame ahead too: /joint_goals shows the planned row before the one sent)
    goal_rows, goal_times = np.array([m.position for *_, m in log["/joint_goals"]]), [t for t, *_ in log["/joint_goals"]]
    half_tick_rad = 0.5 / np.array([j.model.ticks_per_rad for j in cfg.joints])
    assert len(log["/joint_states"]) >= walk_frames - len(cfg.joints)  # from when every servo answered once
    for t, _, _, states in log["/joint_states"]:
        k = goal_times.index(t)
        assert states.name == list(cfg.joint_names)
        recent = goal_rows[max(0, k - 2 * len(cfg.joints)):k + 2]
        assert np.all(np.abs(recent - np.array(states.position)).min(axis=0) <= half_tick_rad + 1e-12)
    # /tf: the pelvis walks the planned distance
    x = [m.transforms[0].transform.translation.x for *_, m in log["/tf"]]
    assert x[-1] - x[0] == pytest.approx(0.1, abs=0.01)


def test_the_log_carries_the_exported_urdf_and_its_fixed_frames(tmp_path, capsys):
    """/robot_description is the file ``gaitbot robot export --urdf`` writes, and /tf_static holds every fixed
    joint of it with the origin it gives (so Foxglove's 3D panel draws the robot from the log alone)."""
    import xml.etree.ElementTree as ET

    mcap, urdf = tmp_path / "walk.mcap", tmp_path / "op3.urdf"
    assert run_cli(capsys, "robot", "export", "op3", "--urdf", urdf)[0] == 0
    code, _, err = run_cli(capsys, "walk", "--robot", "op3", "--dry-run", "--distance", "0.05", "--mcap", mcap)
    assert code == 0, err
    log = read_back(mcap)
    (_, _, _, description), = log["/robot_description"]
    assert description.data == urdf.read_text()
    (_, _, _, static), = log["/tf_static"]
    fixed = {j.get("name"): j for j in ET.parse(urdf).getroot().iter("joint") if j.get("type") == "fixed"}
    assert len(static.transforms) == len(fixed)
    by_child = {t.child_frame_id: t for t in static.transforms}
    for joint in fixed.values():
        t = by_child[joint.find("child").get("link")]
        assert t.header.frame_id == joint.find("parent").get("link")
        xyz = [float(v) for v in joint.find("origin").get("xyz").split()]
        assert np.allclose([t.transform.translation.x, t.transform.translation.y, t.transform.translation.z], xyz,
                           atol=1e-12)


def test_static_channels_once_in_a_log_and_every_few_seconds_live():
    """A client may connect to the live server at any time: it must get the URDF and the fixed frames too."""
    from gaitbot.view.publisher import STATIC_EVERY_S

    class Sink:
        def __init__(self, repeats: bool) -> None:
            self.repeats_static, self.times = repeats, []
            self.label, self.closing_note = "sink", ""

        def write(self, topic, type_name, data, log_time_ns) -> None:
            if topic == "/robot_description":
                self.times.append((log_time_ns - START_NS) / 1e9)

        def close(self) -> None:
            pass

    log, live = Sink(False), Sink(True)
    publisher = TelemetryPublisher(config("op3"), [log, live], start_ns=START_NS)
    for frame in random_frames(300, np.random.default_rng(1)):  # 5 s at 60 Hz
        publisher.on_frame(frame)
    assert log.times == [0.0]
    assert live.times == pytest.approx([k * STATIC_EVERY_S for k in range(int(5 / STATIC_EVERY_S) + 1)], abs=1 / 60)
