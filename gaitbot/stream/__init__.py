"""The stream room: the 60 Hz clock and its sessions.

``clock`` (real and virtual time), ``pacing`` (frames on absolute deadlines, their statistics),
``ramps`` (rest-to-rest ramps and the braking stop), ``session`` (the walk session and its safe
stop), ``record`` (the record-by-hand session), ``signals`` (SIGTERM as an exception).
"""

from gaitbot.stream.clock import Clock, MonotonicClock, VirtualClock
from gaitbot.stream.pacing import LATE_THRESHOLD_S, StreamStats, Streamer, paced_deadlines
from gaitbot.stream.ramps import brake_ticks, ramp_ticks, stop_ticks
from gaitbot.stream.record import RecordResult, record_session
from gaitbot.stream.session import EXIT_CODES, MissingServosError, SessionResult, prepare, walk_session, write_settings
from gaitbot.stream.signals import Terminated, sigterm_raises_terminated

__all__ = [
    "Clock", "MonotonicClock", "VirtualClock", "ramp_ticks", "brake_ticks", "stop_ticks",
    "StreamStats", "Streamer", "MissingServosError", "Terminated", "prepare", "write_settings", "paced_deadlines",
    "sigterm_raises_terminated", "SessionResult", "walk_session", "record_session", "RecordResult",
    "LATE_THRESHOLD_S", "EXIT_CODES",
]
