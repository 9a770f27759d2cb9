"""Read a bus log written by BusRecorder back into packets and goal frames.

Used by the limit-check tool: ``decode_goal_frames`` turns a recorded run into goal ticks over
time, and ``parse_recording`` exposes every packet's fields for other checks.

Truncated last line: a run killed mid-write can leave a final line without its newline. By
default that is an error (RecordingError naming the file and line), because silently shortening a
run could hide the very frames a limit check is about. ``allow_partial_last_line=True`` drops that
one line and nothing else; a damaged line anywhere else is always an error.
"""

from __future__ import annotations

import json
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from gaitbot.bus import wire
from gaitbot.robot.servo_models import servo_model

LOG_FORMAT = "gaitbot-bus-log"
LOG_VERSION = 1
_HEADER_KEYS = ("backend", "protocol", "baudrate", "robot", "joints", "models")


class RecordingError(ValueError):
    """A bus log cannot be read; the message names the file, the line and the problem."""


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
    """The header and every logged chunk, validated line by line."""
    path = Path(path)
    text = path.read_text(encoding="utf-8")
    lines = text.split("\n")
    if lines and lines[-1] == "":
        lines.pop()
    elif lines:  # last line lacks its newline: the writer was interrupted
        if not allow_partial_last_line:
            raise RecordingError(f"{path}:{len(lines)}: truncated last line (no newline; the run was probably "
                                 "interrupted while writing). Pass allow_partial_last_line=True to ignore it.")
        lines.pop()
    if not lines:
        raise RecordingError(f"{path}:1: empty file, no {LOG_FORMAT} header")
    header = _header(path, lines[0])
    packets = [_packet(path, n, line) for n, line in enumerate(lines[1:], start=2)]
    return header, packets


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


# --- internals ----------------------------------------------------------------------------
def _header(path: Path, line: str) -> dict:
    try:
        header = json.loads(line)
    except json.JSONDecodeError as exc:
        raise RecordingError(f"{path}:1: no {LOG_FORMAT} header (line 1 is not JSON: {exc.msg})") from None
    if not isinstance(header, dict) or header.get("format") != LOG_FORMAT:
        raise RecordingError(f"{path}:1: no {LOG_FORMAT} header (first line has no \"format\": \"{LOG_FORMAT}\")")
    if header.get("version") != LOG_VERSION:
        raise RecordingError(f"{path}:1: unsupported log version {header.get('version')!r} (reads {LOG_VERSION})")
    missing = [k for k in _HEADER_KEYS if k not in header]
    if missing:
        raise RecordingError(f"{path}:1: header lacks {', '.join(missing)}")
    return header


def _packet(path: Path, line_no: int, line: str) -> RecordedPacket:
    try:
        obj = json.loads(line)
        t_s, direction, data = float(obj["t"]), obj["dir"], bytes.fromhex(obj["hex"])
    except json.JSONDecodeError as exc:
        raise RecordingError(f"{path}:{line_no}: bad JSON ({exc.msg})") from None
    except (KeyError, TypeError, ValueError) as exc:
        raise RecordingError(f"{path}:{line_no}: not a packet line (needs t, dir, hex): {exc}") from None
    if direction not in ("tx", "rx"):
        raise RecordingError(f"{path}:{line_no}: dir must be \"tx\" or \"rx\", got {direction!r}")
    return RecordedPacket(line_no, t_s, direction, data)


def _instruction_fields(frame: wire.Frame, framing: str):
    """ids, address, data_length, data, per_id_data of an instruction packet."""
    params, wide = frame.params, framing == "v2"
    step = 2 if wide else 1

    def word(i: int) -> int:
        return params[i] | (params[i + 1] << 8 if wide else 0)

    inst = frame.instruction
    if inst == wire.INST_SYNC_WRITE and len(params) >= 2 * step:
        address, length = word(0), word(step)
        body = params[2 * step:]
        per_id = {body[o]: bytes(body[o + 1:o + 1 + length]) for o in range(0, len(body) - length, length + 1)}
        return tuple(per_id), address, length, bytes(body), per_id
    if inst == wire.INST_SYNC_READ and len(params) >= 2 * step:
        return tuple(params[2 * step:]), word(0), word(step), b"", {}
    if inst == wire.INST_READ and len(params) >= 2 * step:
        return (frame.packet_id,), word(0), word(step), b"", {}
    if inst == wire.INST_WRITE and len(params) >= step:
        data = bytes(params[step:])
        return (frame.packet_id,), word(0), len(data), data, {}
    return (frame.packet_id,), None, None, bytes(params), {}


def _goal_layout(path: Path, header: dict) -> tuple[tuple[int, int], dict[int, str]]:
    """((goal address, length), {id: byte order}) from the header's models."""
    try:
        models = {int(i): servo_model(name) for i, name in header["models"].items()}
    except (KeyError, ValueError) as exc:
        raise RecordingError(f"{path}:1: header models: {exc}") from None
    layouts = {(m.addr_goal_position, m.len_goal_position) for m in models.values()}
    if len(layouts) != 1:
        raise RecordingError(f"{path}:1: header models do not share one goal-position address")
    return layouts.pop(), {i: m.byte_order for i, m in models.items()}
