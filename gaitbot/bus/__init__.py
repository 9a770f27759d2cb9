"""The bus room: one abstract servo bus, one module per backend, and a recording mock port.

    make_bus(backend, protocol, port, baudrate, models, dry_run, recorder=None) -> Bus

The simulated robot (gaitbot.sim, needs the ``sim`` extra) is a port of its own under the same
backends; it is imported only when asked for, so MuJoCo stays optional.
"""

from gaitbot.bus.base import (Bus, BusError, CorruptReplies, PortError, ServoLate, ServoStatusError,
                              ServoTimeout)
from gaitbot.bus.factory import make_bus, make_mock_bus

__all__ = ["Bus", "BusError", "CorruptReplies", "PortError", "ServoLate", "ServoStatusError", "ServoTimeout",
           "make_bus", "make_mock_bus"]
