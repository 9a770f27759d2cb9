"""The reader of the bus recording format (gaitbot.bus.recording): the header and every line, validated.

A truncated last line (no newline: the writer was interrupted) is an error unless
``allow_partial_last_line``, because silently shortening a run could hide the very frames a check is
about; a line whose hex is not hex is kept with its problem, for the checks to report. Every other line
comes with its packet parsed (:class:`~gaitbot.bus.recording.records.LogLine`).
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from gaitbot.bus.recording.records import Direction, LogLine, ParsedPacket, RecordedPacket, parse_packet
from gaitbot.bus.recording.writer import LOG_FORMAT, LOG_VERSION
from gaitbot.errors import UserError
from gaitbot.fields import read_user_file
from gaitbot.robot.config import RATE_RANGE_HZ
from gaitbot.servos import BACKENDS, vendor, wire
from gaitbot.servos.models import servo_model

MAX_HEADER_CHARS = 1_000_000
_HEADER_KEYS = ("backend", "protocol", "baudrate", "robot", "joints", "models")


class RecordingError(UserError, ValueError):
    """A bus log cannot be read; the message names the file, the line and the problem."""


@dataclass(frozen=True)
class BusLog:
    """A read bus log: the validated header (as written; ``typed_header`` gives its typed values), every
    packet line, and the line number of a truncated last line that was dropped (None: none)."""

    path: Path
    header: dict
    lines: list[LogLine]
    dropped_partial_line: int | None = None

    @property
    def framing(self) -> str:
        return wire.framing_for(self.header["backend"], self.header["protocol"])


def is_bus_log(path: str | Path) -> bool:
    """A bus log (JSON Lines) rather than a trajectory file: a ``.jsonl`` file, or any other file
    (not ``.csv``/``.npz``) whose first character is ``{``."""
    path = Path(path)
    if path.suffix == ".jsonl":
        return True
    if path.suffix in (".csv", ".npz") or not path.is_file():
        return False
    try:
        with open(path, "rb") as f:
            return f.read(64).lstrip()[:1] == b"{"
    except OSError:
        return False


def _unreadable(path: Path, exc: OSError | UnicodeDecodeError) -> RecordingError:
    """Why a bus log cannot be read, in one line (exit 2)."""
    if isinstance(exc, FileNotFoundError):
        return RecordingError(f"{path}: no such file")
    if isinstance(exc, UnicodeDecodeError):
        return RecordingError(f"{path}: cannot read (not UTF-8 text: {exc.reason} at byte {exc.start})")
    return RecordingError(f"{path}: cannot read ({exc.strerror or exc})")


def read_log(path: str | Path, *, allow_partial_last_line: bool = False) -> BusLog:
    """The header and every packet line of a bus log. Raises RecordingError (exit 2) for a file that
    cannot be read as a bus log; bad bytes inside a packet are left for the checks."""
    path = Path(path)
    try:
        text = read_user_file(path).decode("utf-8")
    except (OSError, UnicodeDecodeError) as exc:
        raise _unreadable(path, exc) from None
    lines = text.split("\n")
    dropped = None
    if lines and lines[-1] == "":
        lines.pop()
    elif lines and lines[-1].strip():
        dropped = len(lines)
        if not allow_partial_last_line:
            raise RecordingError(f"{path}:{dropped}: truncated last line (no newline: the file was cut short, "
                                 "e.g. by a crash while writing); pass --allow-partial to check the complete lines")
        lines.pop()
    if not lines or not lines[0].strip():
        raise RecordingError(f"{path}:1: empty file, no {LOG_FORMAT} header")
    header = _header(path, lines[0])
    framing = wire.framing_for(header["backend"], header["protocol"])
    packets = [_line(path, n, line, framing) for n, line in enumerate(lines[1:], start=2) if line.strip()]
    return BusLog(path, header, packets, dropped)


def read_header(path: str | Path) -> dict:
    """The validated header alone (the first line), without reading the rest of the file."""
    path = Path(path)
    try:
        if not path.is_file():
            read_user_file(path, 0)  # the reason: missing, a directory, a FIFO or a device
        with open(path, encoding="utf-8") as f:
            first = f.readline(MAX_HEADER_CHARS)
    except (OSError, UnicodeDecodeError) as exc:
        raise _unreadable(path, exc) from None
    if not first.strip():
        raise RecordingError(f"{path}:1: empty file, no {LOG_FORMAT} header")
    return _header(path, first)


def _header(path: Path, line: str) -> dict:
    where = f"{path}:1"
    try:
        header = json.loads(line)
    except json.JSONDecodeError as exc:
        raise RecordingError(f"{where}: no {LOG_FORMAT} header (line 1 is not JSON: {exc.msg})") from None
    except RecursionError:
        raise RecordingError(f"{where}: no {LOG_FORMAT} header (line 1 is nested too deeply)") from None
    if not isinstance(header, dict) or header.get("format") != LOG_FORMAT:
        raise RecordingError(f"{where}: no {LOG_FORMAT} header (the first line must be "
                             f"{{\"format\": \"{LOG_FORMAT}\", ...}}; is the file a bus recording, complete from its start?)")
    if header.get("version") != LOG_VERSION or isinstance(header.get("version"), bool):
        raise RecordingError(f"{where}: unsupported log version {_shown(header.get('version'))} (reads {LOG_VERSION})")
    missing = [k for k in _HEADER_KEYS if k not in header]
    if missing:
        raise RecordingError(f"{where}: header lacks {', '.join(missing)}")
    backend, protocol, baudrate = header["backend"], header["protocol"], header["baudrate"]
    if not isinstance(backend, str) or backend not in BACKENDS:
        raise RecordingError(f"{where}: header backend must be {' or '.join(BACKENDS)}, got {_shown(backend)}")
    if not _is_number(protocol) or float(protocol) not in (1.0, 2.0):
        raise RecordingError(f"{where}: header protocol must be 1.0 or 2.0, got {_shown(protocol)}")
    if float(protocol) not in vendor(backend).PROTOCOLS:
        allowed = " or ".join(str(p) for p in vendor(backend).PROTOCOLS)
        raise RecordingError(f"{where}: header protocol of a {backend} bus must be {allowed}, got {_shown(protocol)}")
    if isinstance(baudrate, bool) or not isinstance(baudrate, int) or not 0 < baudrate <= 100_000_000:
        raise RecordingError(f"{where}: header baudrate must be a whole number of bits per second, "
                             f"got {_shown(baudrate)}")
    if not isinstance(header["robot"], str):
        raise RecordingError(f"{where}: header robot must be a name (a string), got {_shown(header['robot'])}")
    if "rate_hz" in header:
        low, high, _unit = RATE_RANGE_HZ
        rate = header["rate_hz"]
        if not _is_number(rate) or not low <= float(rate) <= high:
            raise RecordingError(f"{where}: header rate_hz must be a frame rate within {low:g}..{high:g} Hz, "
                                 f"got {_shown(rate)}")
    joints, models = header["joints"], header["models"]
    if not isinstance(joints, dict) or not isinstance(models, dict):
        raise RecordingError(f"{where}: header joints and models must be objects")
    for name, servo_id in joints.items():
        if isinstance(servo_id, bool) or not isinstance(servo_id, int) or not 0 <= servo_id <= 253:
            raise RecordingError(f"{where}: header joints.{name} must be a servo id 0..253, got {_shown(servo_id)}")
    for key, name in models.items():
        if not key.isdigit() or not 0 <= int(key) <= 253 or not isinstance(name, str):
            raise RecordingError(f"{where}: header models must map servo ids 0..253 to model names, got "
                                 f"{_shown(key)}: {_shown(name)}")
        try:
            servo_model(name)
        except (TypeError, ValueError, KeyError) as exc:
            raise RecordingError(f"{where}: header models.{key}: {' '.join(str(exc).split())}") from None
    if "calibration" in header:
        _check_calibration(where, header["calibration"], joints)
    return header


def _check_calibration(where: str, sent: Any, joints: dict) -> None:
    """The optional ``calibration`` header field: the zero tick and direction each joint was sent with
    (``{"file": path or null, "joints": {name: {"zero_tick": int, "direction": 1 or -1}}}``)."""
    if not isinstance(sent, dict) or set(sent) != {"file", "joints"} or not isinstance(sent["joints"], dict):
        raise RecordingError(f"{where}: header calibration must be an object {{\"file\": ..., \"joints\": {{...}}}}")
    if sent["file"] is not None and not isinstance(sent["file"], str):
        raise RecordingError(f"{where}: header calibration.file must be a path or null, got {_shown(sent['file'])}")
    for name, joint in sent["joints"].items():
        field = f"header calibration.joints.{name}"
        if name not in joints:
            raise RecordingError(f"{where}: {field}: not one of the header's joints")
        if not isinstance(joint, dict) or set(joint) != {"zero_tick", "direction"}:
            raise RecordingError(f"{where}: {field} must be {{\"zero_tick\": ..., \"direction\": ...}}")
        tick, direction = joint["zero_tick"], joint["direction"]
        if isinstance(tick, bool) or not isinstance(tick, int) or not 0 <= tick <= 65535:
            raise RecordingError(f"{where}: {field}.zero_tick must be a tick 0..65535, got {_shown(tick)}")
        if direction not in (1, -1) or isinstance(direction, bool):
            raise RecordingError(f"{where}: {field}.direction must be 1 or -1, got {_shown(direction)}")


def _is_number(value: Any) -> bool:
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        return False
    return abs(value) < 1e300 if isinstance(value, int) else math.isfinite(value)


def _shown(value: Any) -> str:
    """A header value in a message: short, one line."""
    text = json.dumps(value) if isinstance(value, (str, int, float, bool, type(None))) else type(value).__name__
    return text if len(text) <= 40 else text[:37] + "..."


def typed_header(header: dict) -> dict:
    """A copy of a header as read (JSON: string keys) with typed values: joints name -> int id, models
    int id -> name, protocol a float."""
    return {**header, "joints": {str(k): int(v) for k, v in header["joints"].items()},
            "models": {int(k): str(v) for k, v in header["models"].items()}, "protocol": float(header["protocol"])}


def _line(path: Path, line_no: int, line: str, framing: str) -> LogLine:
    try:
        obj = json.loads(line)
    except json.JSONDecodeError as exc:
        raise RecordingError(f"{path}:{line_no}: bad JSON ({exc.msg}); not a bus recording line") from None
    except RecursionError:
        raise RecordingError(f"{path}:{line_no}: nested too deeply; not a bus recording line") from None
    if not isinstance(obj, dict) or not all(k in obj for k in ("t", "dir", "hex")):
        raise RecordingError(f"{path}:{line_no}: not a packet line (needs t, dir, hex)")
    if not _is_number(obj["t"]):
        raise RecordingError(f"{path}:{line_no}: t must be a finite number of seconds, got {_shown(obj['t'])}")
    t_s = float(obj["t"])
    direction, hex_text = obj["dir"], obj["hex"]
    if not isinstance(direction, str) or direction not in ("tx", "rx"):
        raise RecordingError(f"{path}:{line_no}: dir must be \"tx\" or \"rx\", got {_shown(direction)}")
    if not isinstance(hex_text, str):
        raise RecordingError(f"{path}:{line_no}: hex must be a string")
    try:
        data = bytes.fromhex(hex_text)
    except ValueError:
        return LogLine(line_no, t_s, Direction(direction), hex_text, None, "bytes are not valid hex (corrupted line)")
    packet = parse_packet(RecordedPacket(line_no, t_s, Direction(direction), data), framing)
    return LogLine(line_no, t_s, Direction(direction), hex_text, data, packet=packet)


def read_recording(path: str | Path, *, allow_partial_last_line: bool = False) -> tuple[dict, list[RecordedPacket]]:
    """The header and every logged chunk; a line whose bytes are not hex is an error here."""
    log = read_log(path, allow_partial_last_line=allow_partial_last_line)
    for line in log.lines:
        if line.data is None:
            raise RecordingError(f"{log.path}:{line.line_no}: {line.problem}")
    return log.header, [RecordedPacket(p.line_no, p.t_s, p.direction, p.data) for p in log.lines]


def parse_recording(path: str | Path, *, allow_partial_last_line: bool = False) -> tuple[dict, list[ParsedPacket]]:
    """Every logged chunk parsed with the framing named in the header (never raises on bad bytes;
    see ``checksum_ok`` / ``problem``)."""
    log = read_log(path, allow_partial_last_line=allow_partial_last_line)
    for line in log.lines:
        if line.packet is None:
            raise RecordingError(f"{log.path}:{line.line_no}: {line.problem}")
    return log.header, [line.packet for line in log.lines]
