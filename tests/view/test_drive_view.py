"""``gaitbot drive --mcap`` and ``--foxglove``: a drive's MCAP read back holds every channel at the frame rate
(the goals the servos got, the commands the file gave, a planned ZMP inside the support polygon), and a
Foxglove-protocol client (v1, https://github.com/foxglove/ws-protocol, written from the spec) subscribes to
the joints and transforms of a simulated drive and steers it with Twists. Every wait is bounded."""

import asyncio
import json
import re
import struct
import subprocess
import sys
import time
from collections import defaultdict

import numpy as np
import pytest

pytest.importorskip("mcap_ros2")
pytest.importorskip("foxglove")
websockets = pytest.importorskip("websockets")

from gaitbot.check.balance import signed_distance  # noqa: E402
from gaitbot.robot.calibration import angles_to_ticks  # noqa: E402
from gaitbot.robot.description.urdf_writer import urdf_text  # noqa: E402
from gaitbot.view.ros2_messages import decoder  # noqa: E402
from helpers import REPO_ROOT, config, recorded_goal_ticks, run_cli  # noqa: E402
from mcap.reader import make_reader  # noqa: E402
from mcap_ros2.decoder import DecoderFactory  # noqa: E402

COMMANDS = [{"t": 0.0, "vx": 0.04, "vy": 0.0, "wz": 0.0}, {"t": 2.0, "vx": 0.0, "vy": 0.0, "wz": 8.0},
            {"t": 4.0, "stop": True}]


def read_back(path) -> dict:
    """topic -> [(log_time_ns, decoded message)]"""
    out = defaultdict(list)
    with open(path, "rb") as f:
        for _, channel, message, decoded in make_reader(f, decoder_factories=[DecoderFactory()]).iter_decoded_messages(
                log_time_order=True):
            out[channel.topic].append((message.log_time, decoded))
    return out


def test_a_drive_mcap_holds_every_channel_at_the_frame_rate(tmp_path, capsys):
    commands, mcap, record = tmp_path / "c.jsonl", tmp_path / "d.mcap", tmp_path / "d.jsonl"
    commands.write_text("".join(json.dumps(c) + "\n" for c in COMMANDS))
    code, out, err = run_cli(capsys, "drive", "--robot", "op3", "--dry-run", "--input", f"commands:{commands}",
                             "--json", "--record", record, "--mcap", mcap)
    assert code == 0, err
    report = json.loads(out)
    log = read_back(mcap)
    expected = {"/joint_goals", "/tf", "/walk_command", "/com", "/zmp", "/support_polygon", "/footprints",
                "/diagnostics"}  # a dry run has no IMU; its read-back (/joint_states) starts once every servo answered
    assert set(log) == expected | {"/joint_states", "/tf_static", "/robot_description"}  # the static ones once
    counts = {len(log[topic]) for topic in expected}
    assert counts == {report["frames"] - 1}  # the first frame is the start ramp's target, not streamed
    for topic in expected:
        assert np.allclose(np.diff([t for t, *_ in log[topic]]), 1e9 / 60, atol=1), topic
    # the goals logged, turned into ticks, are the goal packets the mock bus recorded, frame for frame
    cfg = config("op3")
    sent = recorded_goal_ticks(record, "op3", cfg.joints)
    logged = [list(angles_to_ticks(cfg, np.array(m.position), m.name)) for *_, m in log["/joint_goals"]]
    start = sent.index(logged[1]) - 1
    assert sent[start:start + len(logged)] == logged
    # the command channel says what the file said, when it said it (rad/s on the wire)
    t0 = log["/walk_command"][0][0]
    for t, twist in log["/walk_command"]:
        s = (t - t0) / 1e9
        entry = COMMANDS[0] if s < 1.99 else COMMANDS[1] if s < 3.99 else {"vx": 0.0, "wz": 0.0}
        if abs(s - 2.0) > 0.05 and abs(s - 4.0) > 0.05:
            assert (twist.linear.x, twist.angular.z) == pytest.approx((entry["vx"], np.radians(entry["wz"]))), s
    # physics: the planned ZMP stays in the support polygon (the preflight's own tolerance is 1 mm)
    margins = [signed_distance(np.array([z.point.x, z.point.y]), np.array([(p.x, p.y) for p in s.polygon.points]))
               for (*_, z), (*_, s) in zip(log["/zmp"], log["/support_polygon"])]
    assert min(margins) > -2e-3
    # the pelvis ends where the drive's odometry says (x, y, heading from the turn)
    last = log["/tf"][-1][-1].transforms[0].transform
    q = last.rotation
    heading = np.degrees(np.arctan2(2 * (q.w * q.z + q.x * q.y), 1 - 2 * (q.y ** 2 + q.z ** 2)))
    assert last.translation.x == pytest.approx(report["pose"]["x_m"], abs=0.02)
    assert last.translation.y == pytest.approx(report["pose"]["y_m"], abs=0.02)
    assert heading == pytest.approx(report["pose"]["heading_deg"], abs=2.0)
    assert report["pose"]["heading_deg"] > 5.0  # it did turn


BOUND_S = 60.0


async def steer(url: str, twist_s: float) -> dict:
    """Subscribe to /joint_goals and /tf, then publish a forward Twist at 10 Hz for ``twist_s`` seconds."""
    got = {"count": {}}
    async with websockets.connect(url, subprotocols=["foxglove.sdk.v1", "foxglove.websocket.v1"],
                                  open_timeout=BOUND_S) as ws:
        channels = {}
        wanted = {"/joint_goals", "/tf", "/tf_static", "/robot_description"}
        while not wanted <= set(channels):  # advertised once the drive's frames flow
            message = json.loads(await asyncio.wait_for(ws.recv(), BOUND_S))
            if message["op"] == "advertise":
                channels.update({c["topic"]: c for c in message["channels"]})
        subscriptions = {1: "/joint_goals", 2: "/tf", 3: "/tf_static", 4: "/robot_description"}
        await ws.send(json.dumps({"op": "subscribe", "subscriptions": [
            {"id": sid, "channelId": channels[topic]["id"]} for sid, topic in subscriptions.items()]}))
        await ws.send(json.dumps({"op": "advertise", "channels": [
            {"id": 7, "topic": "/cmd_vel", "encoding": "json", "schemaName": "geometry_msgs/msg/Twist"}]}))
        twist = json.dumps({"linear": {"x": 0.04, "y": 0.0, "z": 0.0}, "angular": {"x": 0.0, "y": 0.0, "z": 0.0}})
        end = time.monotonic() + twist_s
        while time.monotonic() < end or not set(subscriptions.values()) <= set(got):  # the drive's end closes it
            if time.monotonic() < end:
                await ws.send(b"\x01" + struct.pack("<I", 7) + twist.encode())
            next_send = time.monotonic() + 0.1  # 10 Hz, well above the watchdog's 2 Hz
            while (left := next_send - time.monotonic()) > 0:
                try:
                    message = await asyncio.wait_for(ws.recv(), left)
                except asyncio.TimeoutError:
                    break
                except websockets.ConnectionClosed:
                    return decoded(got, channels)
                if isinstance(message, bytes) and message[0] == 0x01:  # MessageData
                    sid, _ = struct.unpack_from("<IQ", message, 1)
                    topic = subscriptions[sid]
                    got[topic] = message[13:]  # decoded at the end: a client this slow on a loaded machine
                    got["count"][topic] = got["count"].get(topic, 0) + 1  # fills the server's backlog
    return decoded(got, channels)


def decoded(got: dict, channels: dict) -> dict:
    """The last message of each topic decoded by its advertised schema."""
    return {topic: (data if topic == "count" else decoder(channels[topic]["schemaName"])(data))
            for topic, data in got.items()}


@pytest.mark.slow
def test_a_foxglove_client_watches_and_steers_a_simulated_drive():
    process = subprocess.Popen([sys.executable, "-m", "gaitbot.app.cli", "drive", "--robot", "op3", "--sim", "--foxglove",
                                "127.0.0.1:0", "--max-time", "20", "--json"], stdout=subprocess.PIPE,
                               stderr=subprocess.PIPE, text=True, cwd=REPO_ROOT)
    try:
        line = process.stderr.readline()
        match = re.search(r"ws://127\.0\.0\.1:(\d+)", line)
        assert match, line
        got = asyncio.run(asyncio.wait_for(steer(f"ws://127.0.0.1:{match.group(1)}", 4.0), 3 * BOUND_S))
        out, err = process.communicate(timeout=3 * BOUND_S)
    finally:
        if process.poll() is None:
            process.kill()
            process.communicate()
    assert process.returncode == 0, err
    report = json.loads(out)
    assert report["input"] == "foxglove" and not report["fell"]
    assert report["steps"] >= 2 and report["pose"]["x_m"] > 0.02  # the Twist made it walk forwards
    assert "no Twist for 0.5 s" in err  # and the silence after it stood it
    goals = got["/joint_goals"]
    assert goals.name == list(config("op3").joint_names) and len(goals.position) == len(goals.name)
    assert got["count"]["/joint_goals"] > 60 and got["count"]["/tf"] > 60
    tf = got["/tf"].transforms
    assert (tf[0].header.frame_id, tf[0].child_frame_id) == ("odom", "base_link")
    assert {t.child_frame_id for t in tf[1:]} >= {"foot_left", "foot_right"}
    # a client that connected after the start still gets the robot to draw (sent again every 2 s)
    assert got["/robot_description"].data == urdf_text(config("op3"))
    assert {"left_foot", "right_foot", "trunk"} <= {t.child_frame_id for t in got["/tf_static"].transforms}


@pytest.mark.slow
def test_a_simulated_drive_logs_what_its_imu_felt(tmp_path, capsys):
    """A drive whose feedback reads the IMU logs it a frame at a time: standing and walking on level ground,
    the accelerometer's mean is gravity (9.81 m/s^2) along the torso's up axis, the gyro's mean about zero."""
    commands, mcap = tmp_path / "c.jsonl", tmp_path / "d.mcap"
    commands.write_text("".join(json.dumps(c) + "\n" for c in COMMANDS))
    code, out, err = run_cli(capsys, "drive", "--robot", "op3", "--sim", "--input", f"commands:{commands}",
                             "--json", "--mcap", mcap)
    assert code == 0, err
    log = read_back(mcap)
    imu = [m for *_, m in log["/imu"]]
    assert len(imu) == len(log["/joint_goals"])
    assert np.allclose(np.diff([t for t, *_ in log["/imu"]]), 1e9 / 60, atol=1)
    accel = np.array([[m.linear_acceleration.x, m.linear_acceleration.y, m.linear_acceleration.z] for m in imu])
    gyro = np.array([[m.angular_velocity.x, m.angular_velocity.y, m.angular_velocity.z] for m in imu])
    assert accel.mean(axis=0) == pytest.approx([0.0, 0.0, 9.81], abs=0.3)
    assert np.abs(gyro.mean(axis=0)).max() < 0.05  # rad/s: it sways, but comes back
