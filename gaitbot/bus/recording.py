"""Record every byte a bus sends and receives, so a run (real or dry) can be checked afterwards.

The recorder wraps any PortHandler-like object (the SDK's real one or MockPort) and writes JSON
Lines: a header object, then one object per packet::

    {"format": "gaitbot-bus-log", "version": 1, "backend": "dynamixel", "protocol": 2.0,
     "baudrate": 1000000, "robot": "...", "joints": {"hip_pitch_left": 1, ...}, "models": {"1": "XL430-W250"}}
    {"t": 0.0123, "dir": "tx", "hex": "fffffd00..."}

Each line is written with one write() and flushed, so after a crash or Ctrl-C every line but
possibly the last is complete (the decoder reports a partial last line; see read_recording).
Received bytes are coalesced into whole status packets using the protocol's framing; stray
bytes are logged as their own rx line when the next instruction is sent.
"""

from __future__ import annotations

import json
import time
from collections.abc import Callable, Mapping
from pathlib import Path
from typing import Any, TextIO

from gaitbot.bus import wire
from gaitbot.bus.log_decoder import (  # the reader, re-exported: a recording and its reader belong together
    LOG_FORMAT, LOG_VERSION, ParsedPacket, RecordedPacket, RecordingError, decode_goal_frames, parse_packet,
    parse_recording, read_recording)
from gaitbot.robot.servo_models import ServoModel


class BusRecorder:
    """Writes one bus log. ``clock`` returns seconds (monotonic); injectable for tests."""

    def __init__(self, path: str | Path, *, robot: str, joints: Mapping[str, int],
                 clock: Callable[[], float] = time.monotonic) -> None:
        self.path = Path(path)
        self.robot = robot
        self.joints = dict(joints)
        self._clock = clock
        self._t0_s: float | None = None
        self._file: TextIO | None = None

    def start(self, *, backend: str, protocol: float, baudrate: int, models: Mapping[int, ServoModel]) -> None:
        """Open the file and write the header; the clock's zero is now."""
        if self._file is not None:
            raise RuntimeError(f"recorder {self.path} already started")
        header = {"format": LOG_FORMAT, "version": LOG_VERSION, "backend": backend, "protocol": float(protocol),
                  "baudrate": int(baudrate), "robot": self.robot, "joints": self.joints,
                  "models": {str(i): m.name for i, m in models.items()}}
        self._file = open(self.path, "w", encoding="utf-8")
        self._t0_s = self._clock()
        self._write_line(header)

    def wrap(self, port_handler: Any, *, backend: str, protocol: float, baudrate: int,
             models: Mapping[int, ServoModel]) -> "RecordingPort":
        """Start the log and return a port that logs through this recorder."""
        self.start(backend=backend, protocol=protocol, baudrate=baudrate, models=models)
        return RecordingPort(port_handler, self, wire.framing_for(backend, protocol))

    def log(self, direction: str, data: bytes) -> None:
        if self._file is None or self._t0_s is None:
            raise RuntimeError(f"recorder {self.path} not started")
        t_s = round(self._clock() - self._t0_s, 6)
        self._write_line({"t": t_s, "dir": direction, "hex": bytes(data).hex()})

    def close(self) -> None:
        if self._file is not None:
            self._file.close()
            self._file = None

    def __enter__(self) -> "BusRecorder":
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    def _write_line(self, obj: dict) -> None:
        assert self._file is not None
        self._file.write(json.dumps(obj, separators=(",", ":")) + "\n")
        self._file.flush()


class RecordingPort:
    """A PortHandler wrapper that logs tx packets and rx packets; everything else passes through."""

    def __init__(self, inner: Any, recorder: BusRecorder, framing: str) -> None:
        self._inner = inner
        self._recorder = recorder
        self._framing = framing
        self._rx_pending = bytearray()
        self.is_using = False  # the SDK's lock lives on the object it talks to

    def __getattr__(self, name: str) -> Any:  # port_name, baudrate, ser, getBaudRate, setPacketTimeout ...
        return getattr(self._inner, name)

    def writePort(self, packet) -> int:  # noqa: N802 (SDK name)
        self._flush_rx(partial=True)
        written = self._inner.writePort(packet)
        self._recorder.log("tx", bytes(packet))
        return written

    def readPort(self, length: int):  # noqa: N802
        data = self._inner.readPort(length)
        if data:
            self._rx_pending += bytes(data)
            self._flush_rx(partial=False)
        return data

    def clearPort(self) -> None:  # noqa: N802
        self._flush_rx(partial=True)
        self._inner.clearPort()

    def reset_input_buffer(self) -> None:
        self._flush_rx(partial=True)
        reset = getattr(self._inner, "reset_input_buffer", None)
        if callable(reset):
            reset()
        elif getattr(self._inner, "ser", None) is not None:
            self._inner.ser.reset_input_buffer()

    def closePort(self) -> None:  # noqa: N802
        try:
            self._flush_rx(partial=True)
            self._inner.closePort()
        finally:  # a port that is already gone must not leave the recording unflushed
            self._recorder.close()

    def _flush_rx(self, partial: bool) -> None:
        for chunk, _is_packet in wire.split_complete(self._rx_pending, self._framing):
            self._recorder.log("rx", chunk)
        if partial and self._rx_pending:
            self._recorder.log("rx", bytes(self._rx_pending))
            self._rx_pending.clear()


__all__ = ["BusRecorder", "RecordingPort", "LOG_FORMAT", "LOG_VERSION", "ParsedPacket", "RecordedPacket",
           "RecordingError", "decode_goal_frames", "parse_packet", "parse_recording", "read_recording"]
