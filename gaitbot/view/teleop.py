"""Foxglove's Teleop panel as a ``drive`` command source: geometry_msgs/Twist messages that a Foxglove client
publishes (JSON) on ``TELEOP_TOPIC`` through the live server (gaitbot.view.live).

Twist linear.x and linear.y (m/s) and angular.z (rad/s) become a VelocityCommand (vx, vy in m/s, wz in
deg/s); the newest message wins and holds; a publisher silent for 0.5 s (gaitbot.inputs.source.Watchdog)
brings the walk to standing, so the panel's publish rate must be above 2 Hz (docs/live-view.md). The
server's thread only queues the raw messages (bounded); ``poll`` parses them in the walk's thread without
ever waiting.
"""

from __future__ import annotations

import json
import math
import threading
from collections import deque

from gaitbot.gait.steer.command import STILL, CommandError, VelocityCommand, velocity_from_mapping
from gaitbot.inputs.source import Reading, Watchdog

TELEOP_TOPIC = "/cmd_vel"
TWIST_SCHEMAS = ("geometry_msgs/msg/Twist", "geometry_msgs/Twist")
MAX_QUEUED_MESSAGES = 64  # bounded whatever a client floods: the oldest are dropped
MAX_MESSAGE_BYTES = 4096


def twist_command(data: bytes) -> VelocityCommand:
    """The command of one JSON Twist; CommandError if it is not one (or asks for the absurd)."""
    if len(data) > MAX_MESSAGE_BYTES:
        raise CommandError(f"message larger than {MAX_MESSAGE_BYTES} bytes")
    try:
        fields = json.loads(data.decode("utf-8"))
    except (UnicodeDecodeError, json.JSONDecodeError, RecursionError):
        raise CommandError("not a JSON object") from None
    if not isinstance(fields, dict) or not isinstance(fields.get("linear", {}), dict) \
            or not isinstance(fields.get("angular", {}), dict):
        raise CommandError("not a geometry_msgs/Twist (expected linear and angular objects)")
    linear, angular = fields.get("linear", {}), fields.get("angular", {})
    wz = angular.get("z", 0.0)
    if isinstance(wz, (int, float)) and not isinstance(wz, bool) and math.isfinite(wz):
        wz = math.degrees(wz)
    return velocity_from_mapping({"vx": linear.get("x", 0.0), "vy": linear.get("y", 0.0), "wz": wz}, "Twist")


class TeleopInbox:
    """Filled by the server's thread: which client channels publish Twists on the teleop topic, and their
    messages (raw bytes, bounded queue). Thread-safe; never blocks the caller for long (one lock, no I/O)."""

    def __init__(self, topic: str = TELEOP_TOPIC) -> None:
        self.topic = topic
        self._lock = threading.Lock()
        self._channels: set[tuple[int, int]] = set()
        self._queue: deque = deque(maxlen=MAX_QUEUED_MESSAGES)
        self._refused: list[str] = []

    def advertise(self, client_id: int, channel_id: int, topic: str, encoding: str, schema_name: str) -> None:
        if topic != self.topic:
            return
        with self._lock:
            if encoding != "json" or schema_name not in TWIST_SCHEMAS:
                self._refused.append(f"foxglove: ignored a client channel on {topic} ({schema_name or 'no schema'}, "
                                     f"{encoding}); expected a geometry_msgs/Twist in json")
                return
            self._channels.add((client_id, channel_id))

    def unadvertise(self, client_id: int, channel_id: int) -> None:
        with self._lock:
            self._channels.discard((client_id, channel_id))

    def message(self, client_id: int, channel_id: int, data: bytes) -> None:
        with self._lock:
            if (client_id, channel_id) in self._channels:
                self._queue.append(bytes(data[:MAX_MESSAGE_BYTES + 1]))

    def drain(self) -> tuple[list[bytes], list[str]]:
        """The queued messages, oldest first, and what was refused since the last drain."""
        with self._lock:
            messages, refused = list(self._queue), self._refused
            self._queue.clear()
            self._refused = []
        return messages, refused


class TeleopSource:
    """A command source (gaitbot.inputs.source.CommandSource) over a TeleopInbox."""

    name = "foxglove"

    def __init__(self, inbox: TeleopInbox, on_close=None) -> None:
        self.inbox = inbox
        self.command = STILL
        self.watchdog = Watchdog()
        self.ignored = 0
        self._on_close = on_close

    def poll(self, now_s: float) -> Reading:
        reading = Reading(self.command)
        messages, refused = self.inbox.drain()
        reading.messages.extend(refused)
        for data in messages:
            try:
                command = twist_command(data)
            except CommandError as exc:
                self.ignored += 1
                if self.ignored == 1:
                    reading.messages.append(f"foxglove: ignored a Twist on {self.inbox.topic}: {exc} (said once)")
                continue
            self.command = command
            self.watchdog.feed(now_s)
        self.command = self.watchdog.stand_if_silent(self.command, now_s, reading, "foxglove: no Twist")
        reading.command = self.command
        return reading

    def close(self) -> None:
        if self._on_close is not None:
            self._on_close()
            self._on_close = None
