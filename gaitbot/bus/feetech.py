"""Feetech backend on feetech-servo-sdk (module ``scservo_sdk``).

Feetech frames packets like Dynamixel Protocol 1.0 but stores two-byte registers in a per-series
byte order: STS/SMS low byte first, SCS high byte first. The SDK keeps that order in one
process-wide global, ``scservo_sdk.scservo_def.SCS_END`` (0 = low byte first, 1 = high byte
first), read by its SCS_LOBYTE/SCS_HIBYTE/SCS_MAKEWORD helpers. Hence one bus holds one byte
order: it is set when the bus opens and re-asserted before every exchange, so that two buses of
different orders in one process (used from one thread) do not corrupt each other. Goal bytes are
encoded here from the model's byte order, not through the global, so the packets are right even
if some other code flips it.
"""

from __future__ import annotations

import scservo_sdk
from scservo_sdk import scservo_def

from gaitbot.bus.sdk_bus import SdkBus

SCS_END_FOR_BYTE_ORDER = {"little": 0, "big": 1}


class FeetechBus(SdkBus):
    """A chain of Feetech servos of one byte order on one port."""

    family = "feetech"
    sdk = scservo_sdk

    def __init__(self, port_name, baudrate, protocol, models, **kwargs):
        orders = {}
        for servo_id, model in models.items():
            orders.setdefault(model.byte_order, (servo_id, model.name))
        if len(orders) > 1:
            (id_a, name_a), (id_b, name_b) = orders.get("little"), orders.get("big")
            raise ValueError(
                f"FeetechBus on {port_name}: servo {id_a} ({name_a}, low byte first) and servo {id_b} "
                f"({name_b}, high byte first) cannot share one bus: scservo_sdk keeps the byte order in one "
                "process-wide setting (scservo_def.SCS_END). Put STS/SMS and SCS servos on separate buses.")
        super().__init__(port_name, baudrate, protocol, models, **kwargs)
        self.byte_order = next(iter(self.models.values())).byte_order
        self.scs_end = SCS_END_FOR_BYTE_ORDER[self.byte_order]

    @classmethod
    def make_packet_handler(cls, protocol: float, byte_order: str = "little"):
        return scservo_sdk.PacketHandler(SCS_END_FOR_BYTE_ORDER[byte_order])  # sets SCS_END as a side effect

    def _before_transaction(self) -> None:
        scservo_def.SCS_SETEND(self.scs_end)
