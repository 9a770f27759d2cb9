"""UDP JSON datagrams: each one a command (``{"vx": 0.1, "vy": 0, "wz": 10}`` or ``{"stop": true}``); the last
one holds, and a sender silent for 0.5 s brings the robot to standing (the watchdog).

Bound to 127.0.0.1 unless the spec names another address (``udp:0.0.0.0:9870`` listens on every interface:
anyone on the network can then steer the robot). A bad datagram is ignored and said once, with a count.
"""

from __future__ import annotations

import json
import socket

from gaitbot.gait.steer.command import STILL, CommandError, VelocityCommand, velocity_from_mapping
from gaitbot.inputs.source import InputError, Reading, Watchdog

MAX_DATAGRAM_BYTES = 1024
MAX_DATAGRAMS_PER_POLL = 64  # bounded work per frame whatever a sender floods


def parse_address(rest: str) -> tuple[str, int]:
    """``[HOST:]PORT`` (HOST defaults to 127.0.0.1)."""
    host, _, port_text = rest.rpartition(":")
    try:
        port = int(port_text)
    except ValueError:
        port = -1
    if not 0 <= port <= 65535:
        raise InputError(f"--input udp:{rest}: expected udp:[HOST:]PORT with PORT 0..65535")
    return host or "127.0.0.1", port


def parse_datagram(data: bytes) -> tuple[VelocityCommand | None, bool]:
    """(command, end) from one datagram; CommandError if it is not a command."""
    if len(data) > MAX_DATAGRAM_BYTES:
        raise CommandError(f"datagram larger than {MAX_DATAGRAM_BYTES} bytes")
    try:
        fields = json.loads(data.decode("utf-8"))
    except (UnicodeDecodeError, json.JSONDecodeError, RecursionError):
        raise CommandError("not a JSON object") from None
    if not isinstance(fields, dict):
        raise CommandError("not a JSON object")
    unknown = sorted(set(fields) - {"vx", "vy", "wz", "stop", "t"})
    if unknown:
        raise CommandError(f"unknown field {unknown[0]!r} (allowed: vx, vy, wz, stop)")
    if fields.get("stop") is True:
        return None, True
    return velocity_from_mapping(fields, "datagram"), False


class UdpSource:
    """Non-blocking UDP socket; the newest valid datagram wins."""

    name = "udp"

    def __init__(self, sock: socket.socket) -> None:
        self.sock = sock
        self.command = STILL
        self.watchdog = Watchdog()
        self.ignored = 0

    @classmethod
    def bind(cls, rest: str) -> "UdpSource":
        host, port = parse_address(rest)
        sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        try:
            sock.bind((host, port))
        except OSError as exc:
            sock.close()
            raise InputError(f"--input udp:{rest}: cannot listen on {host}:{port}: {exc.strerror or exc}") from None
        sock.setblocking(False)
        return cls(sock)

    @property
    def address(self) -> tuple[str, int]:
        return self.sock.getsockname()

    def poll(self, now_s: float) -> Reading:
        reading = Reading(self.command)
        for _ in range(MAX_DATAGRAMS_PER_POLL):
            try:
                data, sender = self.sock.recvfrom(MAX_DATAGRAM_BYTES + 1)
            except (BlockingIOError, InterruptedError):
                break
            try:
                command, end = parse_datagram(data)
            except CommandError as exc:
                self.ignored += 1
                if self.ignored == 1:
                    reading.messages.append(f"udp: ignored a datagram from {sender[0]}: {exc} (said once)")
                continue
            self.watchdog.feed(now_s)
            if end:
                reading.end = True
                self.command = STILL
            else:
                self.command = command
        self.command = self.watchdog.stand_if_silent(self.command, now_s, reading, "udp: no command")
        reading.command = self.command
        return reading

    def close(self) -> None:
        self.sock.close()
