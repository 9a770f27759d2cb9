"""The bus recording format (``gaitbot-bus-log``, JSON Lines): its writer and its one reader, one module
each, with typed records (as python-can keeps a reader and a writer per log format in ``can.io``).

A recording holds every byte a bus sent and received, so a run (real, dry or simulated) can be
checked afterwards (gaitbot.check.recording). The writer wraps any PortHandler-like object (the SDK's
real one or the dry-run port) and writes a header object, then one object per packet::

    {"format": "gaitbot-bus-log", "version": 1, "backend": "dynamixel", "protocol": 2.0,
     "baudrate": 1000000, "robot": "...", "joints": {"hip_pitch_left": 1, ...}, "models": {"1": "XL430-W250"}}
    {"t": 0.0123, "dir": "tx", "hex": "fffffd00..."}

``writer`` (BusRecorder, RecordingPort, RecordingFailed), ``reader`` (read_log, read_header: the header
and every line as a :class:`~gaitbot.bus.recording.records.LogLine` with its parsed packet),
``records`` (the typed records and the one packet parser), ``goals`` (the goal frames of a recording).
docs/file-formats.md describes the format.
"""

from gaitbot.bus.recording.goals import decode_goal_frames
from gaitbot.bus.recording.reader import (BusLog, RecordingError, is_bus_log, parse_recording, read_header, read_log,
                                          read_recording, typed_header)
from gaitbot.bus.recording.records import Direction, LogLine, ParsedPacket, RecordedPacket, parse_packet
from gaitbot.bus.recording.writer import LOG_FORMAT, LOG_VERSION, BusRecorder, RecordingFailed, RecordingPort

__all__ = ["LOG_FORMAT", "LOG_VERSION", "BusLog", "BusRecorder", "Direction", "LogLine", "ParsedPacket",
           "RecordedPacket", "RecordingError", "RecordingFailed", "RecordingPort", "decode_goal_frames", "is_bus_log",
           "parse_packet", "parse_recording", "read_header", "read_log", "read_recording", "typed_header"]
