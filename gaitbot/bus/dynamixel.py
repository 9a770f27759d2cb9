"""Dynamixel backend on ROBOTIS' dynamixel_sdk, protocols 1.0 and 2.0.

Goal positions of one frame go out as one GroupSyncWrite packet (instruction 0x83, broadcast,
no status packet). Present positions come back with GroupSyncRead on protocol 2.0; protocol 1.0
has no sync read in the SDK, so each servo is read on its own.
"""

from __future__ import annotations

import dynamixel_sdk
from dynamixel_sdk.protocol2_packet_handler import Protocol2PacketHandler

from gaitbot.bus.sdk_bus import SdkBus


class StuffingProtocol2PacketHandler(Protocol2PacketHandler):
    """Protocol2PacketHandler whose byte stuffing reaches the wire.

    dynamixel-sdk's txPacket calls ``self.addStuffing(txpacket)`` and ignores the result; when
    stuffing lengthens the packet, addStuffing builds a new list, so the caller's packet goes out
    unstuffed and a servo would see a false header inside the data. Here addStuffing writes the
    stuffed bytes back into the caller's list, after which the SDK's own length and CRC code works
    on the stuffed packet, as the e-Manual requires (stuff first, then length, then CRC).
    """

    def addStuffing(self, packet):  # noqa: N802 (SDK method name)
        stuffed = super().addStuffing(list(packet))
        packet[:] = stuffed
        return packet


class DynamixelBus(SdkBus):
    """A chain of Dynamixel servos on one port, one protocol version."""

    family = "dynamixel"
    sdk = dynamixel_sdk

    def __init__(self, port_name, baudrate, protocol, models, **kwargs):
        if float(protocol) not in (1.0, 2.0):
            raise ValueError(f"Dynamixel protocol must be 1.0 or 2.0, got {protocol!r}")
        super().__init__(port_name, baudrate, protocol, models, **kwargs)

    @classmethod
    def make_packet_handler(cls, protocol: float, byte_order: str = "little"):
        if float(protocol) == 2.0:
            return StuffingProtocol2PacketHandler()
        return dynamixel_sdk.PacketHandler(1.0)  # the SDK compares with the float 1.0
