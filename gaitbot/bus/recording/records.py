"""The typed records of a bus recording (gaitbot.bus.recording): a line as read, a packet and its fields.

:func:`parse_packet` is the one parser of a recorded packet, on gaitbot.servos.wire (the same framing
code the dry-run port and the read-back use, gaitbot.bus.packets).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from enum import StrEnum

from gaitbot.servos import wire


class Direction(StrEnum):
    """Which way a recorded packet went: ``tx`` from the host, ``rx`` to it (the format's ``dir``)."""

    TX = "tx"
    RX = "rx"


@dataclass(frozen=True)
class LogLine:
    """One packet line as read: ``data`` as sent or received and ``packet``, those bytes parsed with the
    recording's framing (never raises on bad bytes: see its ``checksum_ok`` and ``problem``); or, when the
    line's hex is not hex, ``data`` and ``packet`` None and ``problem`` saying so."""

    line_no: int
    t_s: float
    direction: Direction
    hex: str
    data: bytes | None
    problem: str = ""
    packet: "ParsedPacket | None" = None


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


def parse_packet(packet: RecordedPacket, framing: str) -> ParsedPacket:
    """A recorded packet split into its fields (a tx packet: its instruction's; an rx packet: a status)."""
    frame = wire.parse(packet.data, framing, status=packet.direction == "rx")
    ids, address, length, data, per_id = (frame.packet_id,), None, None, frame.params, {}
    if packet.direction == "tx" and frame.checksum_ok:
        ids, address, length, data, per_id = _instruction_fields(frame, framing)
    return ParsedPacket(packet.line_no, packet.t_s, packet.direction, packet.data, frame.packet_id,
                        frame.instruction, frame.error, ids, address, length, data, frame.checksum_ok,
                        frame.problem, per_id)


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
