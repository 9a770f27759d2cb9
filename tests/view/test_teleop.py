"""Foxglove Teleop as a drive command source: Twist (m/s, rad/s) to VelocityCommand (m/s, deg/s), the newest
message wins, bad ones are said once, the 0.5 s watchdog stands the robot, and the queue stays bounded."""

import json
import math

import pytest

from gaitbot.gait.steer.command import CommandError
from gaitbot.view.teleop import MAX_QUEUED_MESSAGES, TeleopInbox, TeleopSource, twist_command


def twist(vx=0.0, vy=0.0, wz=0.0) -> bytes:
    return json.dumps({"linear": {"x": vx, "y": vy, "z": 0}, "angular": {"x": 0, "y": 0, "z": wz}}).encode()


def test_twist_units():
    command = twist_command(twist(0.1, -0.05, math.pi / 4))
    assert (command.vx_m_s, command.vy_m_s) == (0.1, -0.05)
    assert command.wz_deg_s == pytest.approx(45.0)
    assert twist_command(b'{"linear": {"x": 0.2}}').wz_deg_s == 0.0  # missing fields are 0


@pytest.mark.parametrize("data", [b"nope", b"[1]", b'{"linear": 3}', b'{"linear": {"x": "fast"}}',
                                  b'{"linear": {"x": 1e9}}', b'{"angular": {"z": NaN}}', b"x" * 5000])
def test_bad_twists_are_refused(data):
    with pytest.raises(CommandError):
        twist_command(data)


def test_source_newest_wins_bad_said_once_and_watchdog():
    inbox = TeleopInbox()
    inbox.advertise(1, 5, "/cmd_vel", "json", "geometry_msgs/msg/Twist")
    source = TeleopSource(inbox)
    inbox.message(1, 5, twist(0.1))
    inbox.message(1, 5, b"garbage")
    inbox.message(1, 5, twist(0.05, wz=0.1))
    inbox.message(1, 5, b"garbage again")
    reading = source.poll(1.0)
    assert reading.command.vx_m_s == 0.05 and reading.command.wz_deg_s == pytest.approx(math.degrees(0.1))
    assert len(reading.messages) == 1 and "said once" in reading.messages[0]
    assert source.poll(1.4).command.vx_m_s == 0.05  # holds within the watchdog
    silent = source.poll(1.6)
    assert silent.command.is_still and silent.messages == ["foxglove: no Twist for 0.5 s: standing"]
    assert source.poll(1.7).messages == []  # said once


def test_other_channels_and_encodings_are_not_commands():
    inbox = TeleopInbox()
    inbox.advertise(1, 1, "/other", "json", "geometry_msgs/msg/Twist")
    inbox.advertise(1, 2, "/cmd_vel", "cdr", "geometry_msgs/msg/Twist")
    source = TeleopSource(inbox)
    for channel in (1, 2, 3):
        inbox.message(1, channel, twist(0.1))
    reading = source.poll(0.0)
    assert reading.command.is_still
    assert len(reading.messages) == 1 and "expected a geometry_msgs/Twist in json" in reading.messages[0]
    inbox.advertise(2, 1, "/cmd_vel", "json", "geometry_msgs/Twist")
    inbox.unadvertise(2, 1)
    inbox.message(2, 1, twist(0.1))
    assert source.poll(0.1).command.is_still


def test_a_flood_is_bounded():
    inbox = TeleopInbox()
    inbox.advertise(1, 1, "/cmd_vel", "json", "geometry_msgs/msg/Twist")
    for k in range(10 * MAX_QUEUED_MESSAGES):
        inbox.message(1, 1, twist(0.001 * k))
    messages, _ = inbox.drain()
    assert len(messages) == MAX_QUEUED_MESSAGES
    assert twist_command(messages[-1]).vx_m_s == pytest.approx(0.001 * (10 * MAX_QUEUED_MESSAGES - 1))
