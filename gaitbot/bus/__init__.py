"""The bus room: packets. One abstract servo bus, the vendor SDKs' backends, and what sits around them.

    make_bus(backend, protocol, port, baudrate, models, dry_run, recorder=None) -> Bus
    make_robot_bus(config, port=None, dry_run=False, recorder=None) -> LimitGuard

``base`` (the Bus and its errors), ``sdk_bus`` + ``dynamixel`` + ``feetech`` (the SDK backends),
``factory``, ``guard`` (the LimitGuard: no goal outside a joint's limits), ``budget`` (what a frame
costs on the wire), ``mock`` (MockPort, under the real SDK code in dry runs), ``log`` (the bus-log
format: its writer and its one reader), ``serial_latency`` (the USB adapter's latency timer) and
``emulator`` (a servo chain in time on a pty). The simulated robot (gaitbot.sim) is a port of its
own under the same backends.
"""

from gaitbot.bus.base import (Bus, BusError, CorruptReplies, PortError, ServoLate, ServoStatusError,
                              ServoTimeout)
from gaitbot.bus.factory import make_bus, make_mock_bus, make_robot_bus

__all__ = ["Bus", "BusError", "CorruptReplies", "PortError", "ServoLate", "ServoStatusError", "ServoTimeout",
           "make_bus", "make_mock_bus", "make_robot_bus"]
