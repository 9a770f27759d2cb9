"""The stream room: the 60 Hz clock and its sessions.

``clock`` (real and virtual time), ``pacing`` (frames on absolute deadlines, their statistics),
``ramps`` (rest-to-rest ramps and the braking stop), ``session`` (the walk session and its safe
stop: ``WalkSession``), ``record`` (the record-by-hand session), ``signals`` (SIGTERM as an exception, repeated signals), ``readback`` (the per-frame read-back).

Names are imported when first used, so ``gaitbot.stream.signals`` (which the command line installs
before anything heavy is imported) stays light.
"""

import importlib

_NAMES = {
    "Clock": "clock", "MonotonicClock": "clock", "VirtualClock": "clock",
    "LATE_THRESHOLD_S": "pacing", "StreamStats": "pacing", "Streamer": "pacing", "paced_deadlines": "pacing",
    "brake_ticks": "ramps", "ramp_ticks": "ramps", "stop_ticks": "ramps",
    "RecordResult": "record", "record_session": "record",
    "EXIT_CODES": "session", "MissingServosError": "session", "SessionResult": "session", "prepare": "session",
    "walk_session": "session", "write_settings": "session", "WalkSession": "session", "SessionLimits": "session",
    "Outcome": "session", "FrameSource": "pacing",
    "Terminated": "signals", "sigterm_raises_terminated": "signals",
}

__all__ = [
    "Clock", "MonotonicClock", "VirtualClock", "ramp_ticks", "brake_ticks", "stop_ticks",
    "StreamStats", "Streamer", "MissingServosError", "Terminated", "prepare", "write_settings", "paced_deadlines",
    "sigterm_raises_terminated", "SessionResult", "walk_session", "record_session", "RecordResult",
    "LATE_THRESHOLD_S", "EXIT_CODES", "WalkSession", "SessionLimits", "Outcome", "FrameSource",
]


def __getattr__(name: str):
    if name in _NAMES:
        value = getattr(importlib.import_module(f"gaitbot.stream.{_NAMES[name]}"), name)
        globals()[name] = value
        return value
    raise AttributeError(f"module 'gaitbot.stream' has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(__all__))
