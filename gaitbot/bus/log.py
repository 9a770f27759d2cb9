"""The bus-log format (``gaitbot-bus-log``, JSON Lines): its writer and its one reader.

A recording holds every byte a bus sent and received, so a run (real, dry or simulated) can be
checked afterwards (gaitbot.check.recording). One module for the format, as python-can keeps one
per log format: the writer wraps any PortHandler-like object (the SDK's real one or MockPort) and
writes a header object, then one object per packet::

    {"format": "gaitbot-bus-log", "version": 1, "backend": "dynamixel", "protocol": 2.0,
     "baudrate": 1000000, "robot": "...", "joints": {"hip_pitch_left": 1, ...}, "models": {"1": "XL430-W250"}}
    {"t": 0.0123, "dir": "tx", "hex": "fffffd00..."}

Each line is written with one write() and flushed, so after a crash or Ctrl-C every line but
possibly the last is complete. Received bytes are coalesced into whole status packets using the
protocol's framing; stray bytes are logged as their own rx line when the next instruction is sent.

The reader (:func:`read_log`) validates the header and every line. A truncated last line (no
newline: the writer was interrupted) is an error unless ``allow_partial_last_line``, because
silently shortening a run could hide the very frames a check is about; a line whose hex is not hex
is kept with its problem, for the checks to report. docs/file-formats.md describes the format.
"""

from __future__ import annotations

import json
import math
import time
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, BinaryIO

import numpy as np

from gaitbot.bus.base import BusError
from gaitbot.errors import UserError
from gaitbot.fields import read_user_file
from gaitbot.robot.config import RATE_RANGE_HZ
from gaitbot.servos import BACKENDS, wire
from gaitbot.servos.models import ServoModel, servo_model

LOG_FORMAT = "gaitbot-bus-log"
LOG_VERSION = 1
MAX_HEADER_CHARS = 1_000_000
_HEADER_KEYS = ("backend", "protocol", "baudrate", "robot", "joints", "models")


class RecordingError(UserError, ValueError):
    """A bus log cannot be read; the message names the file, the line and the problem."""


class RecordingFailed(BusError):
    """The recording could not be written (a full disk, a failing drive) while the bus itself is fine.

    Raised once, from the packet that could not be logged; the recorder then stops writing (what was
    written stays, each line whole but possibly the last) and the session stops the walk with its
    normal ramp, which still goes out on the healthy port. Not an OSError, so the bus never takes it
    for a failure of the serial port."""


# ---------------------------------------------------------------------------------------------- writing


class BusRecorder:
    """Writes one bus log. ``clock`` returns seconds (monotonic); injectable for tests."""

    def __init__(self, path: str | Path, *, robot: str, joints: Mapping[str, int],
                 clock: Callable[[], float] = time.monotonic, rate_hz: float | None = None) -> None:
        self.path = Path(path)
        self.rate_hz = rate_hz  # the frame rate of the run, written in the header (gaitbot check uses it)
        self.robot = robot
        self.joints = dict(joints)
        self._clock = clock
        self._t0_s: float | None = None
        self._file: BinaryIO | None = None
        self.failed: OSError | None = None  # the write that failed; nothing is written after it
        self.lines_written = 0

    def start(self, *, backend: str, protocol: float, baudrate: int, models: Mapping[int, ServoModel]) -> None:
        """Open the file and write the header; the clock's zero is now."""
        if self._file is not None:
            raise RuntimeError(f"recorder {self.path} already started")
        header = {"format": LOG_FORMAT, "version": LOG_VERSION, "backend": backend, "protocol": float(protocol),
                  "baudrate": int(baudrate), "robot": self.robot, "joints": self.joints,
                  "models": {str(i): m.name for i, m in models.items()}}
        if self.rate_hz is not None:
            header["rate_hz"] = float(self.rate_hz)
        self._file = open(self.path, "wb", buffering=0)  # one os-level write per line: no buffer to lose
        self._t0_s = self._clock()
        try:
            self._write_line(header)
        except RecordingFailed:
            self.close()
            raise

    def wrap(self, port_handler: Any, *, backend: str, protocol: float, baudrate: int,
             models: Mapping[int, ServoModel]) -> "RecordingPort":
        """Start the log and return a port that logs through this recorder."""
        self.start(backend=backend, protocol=protocol, baudrate=baudrate, models=models)
        return RecordingPort(port_handler, self, wire.framing_for(backend, protocol))

    def now(self) -> float:
        return self._clock()

    def log(self, direction: str, data: bytes, at_s: float | None = None) -> None:
        if self.failed is not None:
            return  # the recording already failed (and said so once): the walk's stop goes on without it
        if self._file is None or self._t0_s is None:
            raise RuntimeError(f"recorder {self.path} not started")
        t_s = round((self._clock() if at_s is None else at_s) - self._t0_s, 6)
        self._write_line({"t": t_s, "dir": direction, "hex": bytes(data).hex()})

    def close(self) -> None:
        if self._file is not None:
            try:
                self._file.close()
            except OSError as exc:  # nothing is buffered; a failing close is only noted
                self.failed = self.failed or exc
            self._file = None

    def __enter__(self) -> "BusRecorder":
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    def _write_line(self, obj: dict) -> None:
        assert self._file is not None
        data = (json.dumps(obj, separators=(",", ":")) + "\n").encode("utf-8")
        try:
            written = self._file.write(data)
            while written is not None and written < len(data):  # a raw write may be short; finish the line
                more = self._file.write(data[written:])
                if not more:
                    raise OSError(28, "No space left on device")
                written += more
        except OSError as exc:
            self.failed = exc
            raise RecordingFailed(f"the recording {self.path} could not be written ({exc.strerror or exc}) after "
                                  f"{self.lines_written} lines; what was written is kept") from exc
        self.lines_written += 1


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
        sent_s = self._recorder.now()  # stamped as it is handed to the port, not after (a busy host may pause there)
        written = self._inner.writePort(packet)
        self._recorder.log("tx", bytes(packet), at_s=sent_s)
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


# ---------------------------------------------------------------------------------------------- reading


@dataclass(frozen=True)
class LogLine:
    """One packet line: ``data`` as sent or received, or None with ``problem`` when its hex is not hex."""

    line_no: int
    t_s: float
    direction: str  # "tx" or "rx"
    hex: str
    data: bytes | None
    problem: str = ""


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
    packets = [_line(path, n, line) for n, line in enumerate(lines[1:], start=2) if line.strip()]
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
    if backend == "feetech" and float(protocol) != 1.0:
        raise RecordingError(f"{where}: header protocol of a feetech bus must be 1.0, got {_shown(protocol)}")
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
    return header


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


def _line(path: Path, line_no: int, line: str) -> LogLine:
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
        return LogLine(line_no, t_s, direction, hex_text, None, "bytes are not valid hex (corrupted line)")
    return LogLine(line_no, t_s, direction, hex_text, data)


# ---------------------------------------------------------------------------------------------- packets


@dataclass(frozen=True)
class RecordedPacket:
    """One logged chunk: ``data`` as sent or received, ``t_s`` seconds since the log started."""

    line_no: int
    t_s: float
    direction: str  # "tx" or "rx"
    data: bytes


@dataclass(frozen=True)
class ParsedPacket:
    """A logged packet split into fields.

    ids: the servo ids addressed (sync write/read: the listed ids; otherwise the packet id).
    address / data_length: the control-table range touched (None where the instruction has none).
    data: the bytes written (write) or returned (status); per_id_data: sync write payload per id.
    """

    line_no: int
    t_s: float
    direction: str
    raw: bytes
    packet_id: int
    instruction: int | None
    error: int | None
    ids: tuple[int, ...]
    address: int | None
    data_length: int | None
    data: bytes
    checksum_ok: bool
    problem: str
    per_id_data: dict[int, bytes] = field(default_factory=dict)


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
    header, packets = read_recording(path, allow_partial_last_line=allow_partial_last_line)
    framing = wire.framing_for(header["backend"], header["protocol"])
    return header, [parse_packet(p, framing) for p in packets]


def parse_packet(packet: RecordedPacket, framing: str) -> ParsedPacket:
    frame = wire.parse(packet.data, framing, status=packet.direction == "rx")
    ids, address, length, data, per_id = (frame.packet_id,), None, None, frame.params, {}
    if packet.direction == "tx" and frame.checksum_ok:
        ids, address, length, data, per_id = _instruction_fields(frame, framing)
    return ParsedPacket(packet.line_no, packet.t_s, packet.direction, packet.data, frame.packet_id,
                        frame.instruction, frame.error, ids, address, length, data, frame.checksum_ok,
                        frame.problem, per_id)


def decode_goal_frames(path: str | Path, *, allow_partial_last_line: bool = False
                       ) -> tuple[dict, np.ndarray, np.ndarray]:
    """(header, t_s (N,), ticks (N, n_joints)) from the goal-position sync writes of a log.

    Columns follow the header's joint order. Every tx packet must pass its checksum/CRC. A joint
    missing from a frame is NaN in that row (ticks is float64 so it can say so).
    """
    header, parsed = parse_recording(path, allow_partial_last_line=allow_partial_last_line)
    goal = _goal_layout(path, header)
    joint_ids = list(header["joints"].values())
    column = {servo_id: c for c, servo_id in enumerate(joint_ids)}
    times, rows = [], []
    for p in parsed:
        if p.direction != "tx":
            continue
        if not p.checksum_ok:
            raise RecordingError(f"{path}:{p.line_no}: tx packet rejected: {p.problem}")
        if p.instruction != wire.INST_SYNC_WRITE or (p.address, p.data_length) != goal[0]:
            continue
        row = np.full(len(joint_ids), np.nan)
        for servo_id, raw in p.per_id_data.items():
            if servo_id in column:
                row[column[servo_id]] = int.from_bytes(raw, goal[1][servo_id])
        times.append(p.t_s)
        rows.append(row)
    ticks = np.array(rows, dtype=float).reshape(len(rows), len(joint_ids))
    return header, np.array(times, dtype=float), ticks


def _instruction_fields(frame: wire.Frame, framing: str):
    """ids, address, data_length, data, per_id_data of an instruction packet."""
    params, inst, width = frame.params, frame.instruction, wire.ADDRESS_BYTES[framing]
    if inst in (wire.INST_SYNC_WRITE, wire.INST_SYNC_READ, wire.INST_READ) and len(params) >= 2 * width:
        address, length, rest = wire.address_length_and_rest(params, framing)
        if inst == wire.INST_SYNC_WRITE:
            per_id = {rest[o]: bytes(rest[o + 1:o + 1 + length]) for o in range(0, len(rest) - length, length + 1)}
            return tuple(per_id), address, length, bytes(rest), per_id
        if inst == wire.INST_SYNC_READ:
            return tuple(rest), address, length, b"", {}
        return (frame.packet_id,), address, length, b"", {}
    if inst == wire.INST_WRITE and len(params) >= width:
        address, data = wire.address_and_rest(params, framing)
        return (frame.packet_id,), address, len(data), bytes(data), {}
    return (frame.packet_id,), None, None, bytes(params), {}


def _goal_layout(path: Path, header: dict) -> tuple[tuple[int, int], dict[int, str]]:
    """((goal address, length), {id: byte order}) from the header's models."""
    models = {i: servo_model(name) for i, name in typed_header(header)["models"].items()}
    layouts = {(m.addr_goal_position, m.len_goal_position) for m in models.values()}
    if len(layouts) != 1:
        raise RecordingError(f"{path}:1: header models do not share one goal-position address")
    return layouts.pop(), {i: m.byte_order for i, m in models.items()}
