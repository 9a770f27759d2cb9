"""The one packet splitter and parser of the bus room: bytes in, whole packets out, each parsed with the
bus's framing (gaitbot.servos.wire, written from the protocol documents). The dry-run port reads the
host's instructions through it, the recording writer cuts received bytes into status packets with it,
and the read-back, the late-reply watch and the probe find status packets with it.
"""

from __future__ import annotations

from collections.abc import Iterator

from gaitbot.servos import wire
from gaitbot.servos.wire import Frame


def take_packets(buffer: bytearray, framing: str, *, status: bool) -> Iterator[tuple[bytes, Frame | None]]:
    """Take every complete packet, and every run of bytes outside a packet, off the front of ``buffer``
    (an incomplete packet at its end stays for more bytes): ``(raw bytes, parsed frame)`` for a packet,
    ``(raw bytes, None)`` for stray bytes. ``status``: parse them as status packets (replies) or as
    instruction packets. A damaged packet is still a frame: see ``checksum_ok`` and ``problem``."""
    for raw, is_packet in wire.split_complete(buffer, framing):
        yield raw, (wire.parse(raw, framing, status=status) if is_packet else None)


def status_frames(data: bytes | bytearray, framing: str) -> Iterator[Frame]:
    """The status packets (damaged ones included) among ``data``, a whole chunk read off the port."""
    for _raw, frame in take_packets(bytearray(data), framing, status=True):
        if frame is not None:
            yield frame


def is_status_of(frame: Frame, servo_id: int, framing: str, length: int | None = None) -> bool:
    """A clean status packet of ``servo_id`` (Protocol 2.0: instruction 0x55), carrying exactly ``length``
    parameters when given."""
    return (frame.checksum_ok and frame.packet_id == servo_id
            and (length is None or len(frame.params) == length)
            and (framing == "v1" or frame.instruction == wire.INST_STATUS_V2))
