"""The bus room: packets. One abstract servo bus, one transport per vendor on its SDK, and what sits around them.

    make_bus(backend, protocol, port, baudrate, models, interface="serial"|"dry-run", recorder=None) -> Bus
    make_robot_bus(config, port=None, dry_run=False, recorder=None, clock=...) -> LimitGuard

``base`` (the Bus, its errors, BusLayer), ``sdk_bus`` (the transport both SDKs share) with its parts
``read_back`` (the per-frame budgeted read), ``late_replies`` and ``bus_faults``, ``dynamixel`` and
``feetech`` (one transport per vendor: only the SDK and its quirks), ``port`` (the serial port under the
SDK: errors, stale input, reply timeout), ``packets`` (the one packet splitter and parser), ``factory``
(a bus by vendor and interface name), ``guard`` (the LimitGuard: no goal outside a joint's limits),
``dry_run`` (the dry-run port, under the real SDK code), ``recording`` (the recording format: writer and
reader), ``probe`` and ``bringup`` (servos not known yet: scan, setup) and ``serial_latency`` (the USB
adapter's latency timer). The servo emulator is a room of its own (gaitbot.emulator); the simulated robot
(gaitbot.sim) is a port of its own under the same transports.
"""

from gaitbot.bus.base import (Bus, BusError, CorruptReplies, PortError, ServoLate, ServoStatusError,
                              ServoTimeout, WrongServoModel)
from gaitbot.bus.factory import make_bus, make_dry_run_bus, make_robot_bus

__all__ = ["Bus", "BusError", "CorruptReplies", "PortError", "ServoLate", "ServoStatusError", "ServoTimeout",
           "WrongServoModel", "make_bus", "make_dry_run_bus", "make_robot_bus"]
