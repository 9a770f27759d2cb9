"""Packet framing written from the protocol documents, independent of the vendor SDKs.

Why a second implementation: the mock servo chain and the recording decoder must check the SDK's
bytes, not echo them. Everything here follows the ROBOTIS e-Manual (Protocol 1.0 / 2.0 pages) and
the Feetech SCS protocol manual, which frames packets exactly like Dynamixel Protocol 1.0.

Two framings exist:
  * "v1" (Dynamixel 1.0 and every Feetech servo): FF FF ID LEN INST|ERR PARAMS.. CHECKSUM,
    LEN = params + 2, CHECKSUM = ~(ID + LEN + INST + params) & 0xFF.
  * "v2" (Dynamixel 2.0): FF FF FD 00 ID LEN_L LEN_H INST [ERR] PARAMS.. CRC_L CRC_H,
    LEN = stuffed(INST..PARAMS) + 2, CRC-16 (poly 0x8005) over everything before the CRC, after
    byte stuffing (FF FF FD inside INST..PARAMS gets an extra FD).
"""

from __future__ import annotations

from dataclasses import dataclass

BROADCAST_ID = 0xFE
INST_PING, INST_READ, INST_WRITE = 0x01, 0x02, 0x03
INST_REG_WRITE, INST_ACTION, INST_REBOOT = 0x04, 0x05, 0x08
INST_STATUS_V2 = 0x55
INST_SYNC_READ, INST_SYNC_WRITE = 0x82, 0x83
INST_BULK_READ, INST_BULK_WRITE = 0x92, 0x93

#: Bytes of a packet around its parameters: v1 FF FF ID LEN INST CHECKSUM; v2 FF FF FD 00 ID LEN_L LEN_H
#: INST CRC_L CRC_H. A status packet has one more, its error byte (v1 counts it in place of INST).
PACKET_OVERHEAD_BYTES = {"v1": 6, "v2": 10}
STATUS_OVERHEAD_BYTES = {"v1": 6, "v2": 11}
#: Width of an address or a length parameter.
ADDRESS_BYTES = {"v1": 1, "v2": 2}

_V2_HEADER = b"\xff\xff\xfd\x00"
_STUFF_PATTERN = b"\xff\xff\xfd"


def framing_for(backend: str, protocol: float) -> str:
    """'v2' for Dynamixel protocol 2.0, else 'v1' (Dynamixel 1.0 and Feetech share a framing)."""
    return "v2" if backend == "dynamixel" and float(protocol) == 2.0 else "v1"


def checksum_v1(body: bytes) -> int:
    """Protocol 1.0 checksum of ID..last param: ones' complement of the low byte of the sum."""
    return ~sum(body) & 0xFF


def _crc16_table() -> tuple[int, ...]:
    """The CRC of every byte value alone, bit by bit, as the e-Manual defines it (poly 0x8005, MSB first)."""
    table = []
    for byte in range(256):
        crc = byte << 8
        for _ in range(8):
            crc = ((crc << 1) ^ 0x8005) if crc & 0x8000 else (crc << 1)
            crc &= 0xFFFF
        table.append(crc)
    return tuple(table)


_CRC16_TABLE = _crc16_table()


def crc16(data: bytes) -> int:
    """CRC-16 of the e-Manual 'CRC Calculation' page: poly 0x8005, init 0, MSB first, no final xor.

    Table-driven (one lookup per byte, the e-Manual's own method): the bit-by-bit loop was half the
    CPU of a dry run."""
    crc = 0
    table = _CRC16_TABLE
    for byte in data:
        crc = ((crc << 8) & 0xFFFF) ^ table[(crc >> 8) ^ byte]
    return crc


def stuff(payload: bytes) -> bytes:
    """Add a 0xFD after every FF FF FD so data can never look like a packet header."""
    if _STUFF_PATTERN not in payload:
        return bytes(payload)  # nothing to stuff: most packets (and the byte loop below is slow)
    out = bytearray()
    for byte in payload:
        out.append(byte)
        if out[-3:] == _STUFF_PATTERN:
            out.append(0xFD)
    return bytes(out)


def unstuff(payload: bytes) -> bytes:
    """Inverse of stuff(): drop the 0xFD that follows each FF FF FD."""
    if _STUFF_PATTERN not in payload:
        return bytes(payload)
    out = bytearray()
    i = 0
    while i < len(payload):
        out.append(payload[i])
        i += 1
        if out[-3:] == _STUFF_PATTERN and i < len(payload) and payload[i] == 0xFD:
            i += 1
    return bytes(out)


def build_v1(packet_id: int, inst_or_error: int, params: bytes = b"") -> bytes:
    """A Protocol 1.0 / Feetech packet (instruction or status) with its checksum."""
    body = bytes([packet_id, len(params) + 2, inst_or_error]) + bytes(params)
    return b"\xff\xff" + body + bytes([checksum_v1(body)])


def build_v2(packet_id: int, instruction: int, params: bytes = b"") -> bytes:
    """A Protocol 2.0 packet, stuffed, with CRC. For a status packet pass 0x55 and ERR as params[0]."""
    payload = stuff(bytes([instruction]) + bytes(params))
    length = len(payload) + 2
    head = _V2_HEADER + bytes([packet_id, length & 0xFF, length >> 8]) + payload
    crc = crc16(head)
    return head + bytes([crc & 0xFF, crc >> 8])


def address_and_rest(params: bytes, framing: str) -> tuple[int, bytes]:
    """(control-table address, the parameters after it) of a READ, WRITE, SYNC READ or SYNC WRITE:
    the address is 2 bytes, low first, on 2.0 and 1 byte on 1.0 / Feetech."""
    if framing == "v2":
        return params[0] | params[1] << 8, params[2:]
    return params[0], params[1:]


def address_length_and_rest(params: bytes, framing: str) -> tuple[int, int, bytes]:
    """(address, data length, the parameters after them) of a READ, SYNC READ or SYNC WRITE (both fields
    2 bytes on 2.0, 1 byte on 1.0 / Feetech)."""
    address, rest = address_and_rest(params, framing)
    length, rest = address_and_rest(rest, framing) if len(rest) >= (2 if framing == "v2" else 1) else (0, b"")
    return address, length, rest


@dataclass(frozen=True)
class Frame:
    """One packet split into its fields. ``params`` are unstuffed; for status packets the error
    byte is in ``error`` and not in ``params``. ``checksum_ok`` covers checksum/CRC and length."""

    packet_id: int
    instruction: int | None  # None for a v1 status packet (v1 status has no instruction byte)
    error: int | None  # status packets only
    params: bytes
    checksum_ok: bool
    problem: str  # "" when ok, else a one-line reason


def packet_length(buffer: bytes, framing: str) -> int | None:
    """Total length of the packet at the start of ``buffer`` (which begins with a header), or None
    if not enough bytes have arrived to know it."""
    if framing == "v2":
        return (buffer[5] | buffer[6] << 8) + 7 if len(buffer) >= 7 else None
    return buffer[3] + 4 if len(buffer) >= 4 else None


def find_header(buffer: bytes, framing: str, start: int = 0) -> int:
    """Index of the next packet header at or after ``start``, or -1."""
    if framing == "v2":
        i = buffer.find(_V2_HEADER, start)
        return i
    return buffer.find(b"\xff\xff", start)


def parse(raw: bytes, framing: str, *, status: bool) -> Frame:
    """Split one whole packet; never raises on bad bytes (reports them in ``problem``)."""
    if framing == "v2":
        return _parse_v2(raw, status)
    return _parse_v1(raw, status)


def _bad(problem: str) -> Frame:
    return Frame(packet_id=-1, instruction=None, error=None, params=b"", checksum_ok=False, problem=problem)


def _parse_v1(raw: bytes, status: bool) -> Frame:
    if len(raw) < 6 or raw[:2] != b"\xff\xff":
        return _bad("not a Protocol 1.0/Feetech packet (too short or no FF FF header)")
    if raw[3] + 4 != len(raw):
        return _bad(f"length field says {raw[3] + 4} bytes, packet has {len(raw)}")
    ok = checksum_v1(raw[2:-1]) == raw[-1]
    problem = "" if ok else f"bad checksum 0x{raw[-1]:02X} (expected 0x{checksum_v1(raw[2:-1]):02X})"
    if status:
        return Frame(raw[2], None, raw[4], bytes(raw[5:-1]), ok, problem)
    return Frame(raw[2], raw[4], None, bytes(raw[5:-1]), ok, problem)


def _parse_v2(raw: bytes, status: bool) -> Frame:
    if len(raw) < 10 or raw[:4] != _V2_HEADER:
        return _bad("not a Protocol 2.0 packet (too short or no FF FF FD 00 header)")
    if (raw[5] | raw[6] << 8) + 7 != len(raw):
        return _bad(f"length field says {(raw[5] | raw[6] << 8) + 7} bytes, packet has {len(raw)}")
    crc = crc16(raw[:-2])
    ok = crc == (raw[-2] | raw[-1] << 8)
    problem = "" if ok else f"bad CRC 0x{raw[-2] | raw[-1] << 8:04X} (expected 0x{crc:04X})"
    payload = unstuff(raw[7:-2])
    if status or payload[0] == INST_STATUS_V2:
        return Frame(raw[4], payload[0], payload[1] if len(payload) > 1 else None, payload[2:], ok, problem)
    return Frame(raw[4], payload[0], None, payload[1:], ok, problem)


def split_complete(buffer: bytearray, framing: str) -> list[tuple[bytes, bool]]:
    """Remove whole packets from the front of ``buffer``, in arrival order.

    Returns (bytes, is_packet) pairs: is_packet False marks a byte run before a header (line noise,
    a truncated reply). A trailing incomplete packet, or the start of a header, stays in ``buffer``
    for more bytes to arrive.
    """
    chunks: list[tuple[bytes, bool]] = []
    while buffer:
        start = find_header(bytes(buffer), framing)
        if start < 0:
            keep = _partial_header_suffix(bytes(buffer), framing)
            if len(buffer) > keep:
                chunks.append((bytes(buffer[: len(buffer) - keep]), False))
                del buffer[: len(buffer) - keep]
            break
        if start > 0:
            chunks.append((bytes(buffer[:start]), False))
            del buffer[:start]
        total = packet_length(bytes(buffer), framing)
        if total is None or len(buffer) < total:
            break
        chunks.append((bytes(buffer[:total]), True))
        del buffer[:total]
    return chunks


def _partial_header_suffix(buffer: bytes, framing: str) -> int:
    """How many trailing bytes could be the start of a header still arriving."""
    header = _V2_HEADER if framing == "v2" else b"\xff\xff"
    for k in range(min(len(header) - 1, len(buffer)), 0, -1):
        if buffer[-k:] == header[:k]:
            return k
    return 0
