"""--foxglove: a WebSocket client speaking the Foxglove protocol (v1, https://github.com/foxglove/ws-protocol,
written here from the spec) subscribes to the joint and transform channels and decodes them, and publishes a
Twist that the teleop source turns into a command. Loopback only, every wait bounded."""

import argparse
import asyncio
import json
import struct

import numpy as np
import pytest

pytest.importorskip("foxglove")
websockets = pytest.importorskip("websockets")

from gaitbot.gait.joints import LEG_JOINTS  # noqa: E402
from gaitbot.app.view_options import host_port  # noqa: E402
from gaitbot.view.live import FoxgloveSink  # noqa: E402
from gaitbot.view.publisher import TelemetryPublisher  # noqa: E402
from gaitbot.view.ros2_messages import decoder  # noqa: E402
from gaitbot.view.telemetry import FrameTelemetry  # noqa: E402
from gaitbot.view.teleop import TeleopSource  # noqa: E402
from helpers import config  # noqa: E402

BOUND_S = 10.0


def frame(k: int) -> FrameTelemetry:
    goals = np.full(12, 0.01 * k)
    return FrameTelemetry(t_s=k / 60, joints=LEG_JOINTS, goals_rad=goals, root_m=np.array([0.001 * k, 0.0, 0.28]))


async def session(url: str, publisher, teleop: TeleopSource) -> dict:
    got = {}
    async with websockets.connect(url, subprotocols=["foxglove.sdk.v1", "foxglove.websocket.v1"], open_timeout=BOUND_S) as ws:
        assert ws.subprotocol in ("foxglove.sdk.v1", "foxglove.websocket.v1")
        channels, k = {}, 0
        while not {"/joint_goals", "/tf"} <= set(channels):  # channels are advertised once they carry a message
            publisher.on_frame(frame(k))
            k += 1
            try:
                message = await asyncio.wait_for(ws.recv(), 0.2)
            except asyncio.TimeoutError:
                continue
            if isinstance(message, str):
                parsed = json.loads(message)
                if parsed["op"] == "serverInfo":
                    got["capabilities"] = parsed["capabilities"]
                    got["encodings"] = parsed.get("supportedEncodings", [])
                if parsed["op"] == "advertise":
                    channels.update({c["topic"]: c for c in parsed["channels"]})
        subscriptions = {1: "/joint_goals", 2: "/tf"}
        await ws.send(json.dumps({"op": "subscribe", "subscriptions": [
            {"id": sid, "channelId": channels[topic]["id"]} for sid, topic in subscriptions.items()]}))
        got["schemas"] = {t: (channels[t]["schemaName"], channels[t]["encoding"]) for t in subscriptions.values()}
        while not {"/joint_goals", "/tf"} <= set(got):  # frames logged before the subscription holds are not sent
            publisher.on_frame(frame(k))
            k += 1
            try:
                message = await asyncio.wait_for(ws.recv(), 0.2)
            except asyncio.TimeoutError:
                continue
            if isinstance(message, bytes) and message[0] == 0x01:  # MessageData: opcode, subscription, time, payload
                sid, _ = struct.unpack_from("<IQ", message, 1)
                topic = subscriptions[sid]
                got[topic] = decoder(channels[topic]["schemaName"])(message[13:])
        # the Teleop panel: a client channel carrying geometry_msgs/Twist in JSON, then one message on it
        await ws.send(json.dumps({"op": "advertise", "channels": [
            {"id": 7, "topic": "/cmd_vel", "encoding": "json", "schemaName": "geometry_msgs/msg/Twist"}]}))
        twist = {"linear": {"x": 0.05, "y": -0.02, "z": 0.0}, "angular": {"x": 0.0, "y": 0.0, "z": 0.3}}
        reading, t = teleop.poll(0.0), 0.0
        for _ in range(int(BOUND_S / 0.05)):
            await ws.send(b"\x01" + struct.pack("<I", 7) + json.dumps(twist).encode())
            await asyncio.sleep(0.05)
            t += 0.05
            reading = teleop.poll(t)
            if not reading.command.is_still:
                break
        got["command"] = reading.command
        got["silent"] = teleop.poll(t + 0.6)  # the watchdog: no Twist for 0.5 s
    return got


def test_a_foxglove_client_sees_joints_and_transforms_and_steers():
    sink = FoxgloveSink("127.0.0.1", 0)
    publisher = TelemetryPublisher(config("op3"), [sink])
    teleop = TeleopSource(sink.inbox)
    try:
        got = asyncio.run(asyncio.wait_for(session(f"ws://127.0.0.1:{sink.port}", publisher, teleop), 4 * BOUND_S))
    finally:
        publisher.close()
    assert "clientPublish" in got["capabilities"] and "json" in got["encodings"]
    assert got["schemas"] == {"/joint_goals": ("sensor_msgs/msg/JointState", "cdr"),
                              "/tf": ("tf2_msgs/msg/TFMessage", "cdr")}
    goals = got["/joint_goals"]
    assert goals.name == list(LEG_JOINTS)
    assert np.allclose(goals.position, goals.position[0]) and goals.position[0] >= 0  # one frame: 0.01 k for all
    tf = got["/tf"].transforms
    assert (tf[0].header.frame_id, tf[0].child_frame_id) == ("odom", "base_link")
    assert [t.child_frame_id for t in tf[1:]] == [f"{link}_{side}" for side in ("left", "right")
                                                  for link in ("hip_yaw", "hip_roll", "thigh", "shank", "ankle", "foot")]
    assert (got["command"].vx_m_s, got["command"].vy_m_s) == (0.05, -0.02)
    assert got["command"].wz_deg_s == pytest.approx(np.degrees(0.3))
    assert got["silent"].command.is_still and any("no Twist" in m for m in got["silent"].messages)


def test_host_port_parsing_and_binding_warning():
    assert host_port("127.0.0.1:8765") == ("127.0.0.1", 8765)
    assert host_port("0.0.0.0:9000") == ("0.0.0.0", 9000)
    assert host_port("9001") == ("127.0.0.1", 9001)
    assert host_port("localhost") == ("localhost", 8765)
    for bad in ("host:99999", "host:x", "[::1]:80", "host:", ":"):
        with pytest.raises(argparse.ArgumentTypeError, match="HOST:.PORT"):
            host_port(bad)
    lines = []
    sink = FoxgloveSink("0.0.0.0", 0, warn=lines.append)
    sink.close()
    assert len(lines) == 1 and "anyone who can reach it" in lines[0]
