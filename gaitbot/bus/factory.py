"""Build a bus from configuration: the one place that knows which class and port to use."""

from __future__ import annotations

from collections.abc import Mapping

from gaitbot.bus.base import Bus
from gaitbot.bus.dynamixel import DynamixelBus
from gaitbot.bus.feetech import FeetechBus
from gaitbot.bus.mock import MockPort
from gaitbot.bus.recording import BusRecorder
from gaitbot.robot.servo_models import ServoModel

BACKENDS = {"dynamixel": DynamixelBus, "feetech": FeetechBus}


def make_bus(backend: str, protocol: float, port: str, baudrate: int, models: Mapping[int, ServoModel],
             dry_run: bool, recorder: BusRecorder | None = None, retries: int = 3,
             reply_timeout_ms: float | None = None) -> Bus:
    """The bus for ``backend``; with ``dry_run`` the same class talks to a MockPort instead of ``port``.

    With ``recorder`` every byte in both directions is logged (dry run or real). The bus is not
    opened here; use it as a context manager or call open(). ``reply_timeout_ms`` replaces the
    SDK's reply timeout (2 x 16 ms USB latency + 2 ms + the packet's bytes) when set.
    """
    try:
        cls = BACKENDS[backend]
    except KeyError:
        raise ValueError(f"unknown bus backend {backend!r} (known: {', '.join(BACKENDS)})") from None
    handler = MockPort(backend, protocol, models, port_name=port) if dry_run else cls.sdk.PortHandler(port)
    if reply_timeout_ms is not None and not dry_run:
        _set_reply_timeout(handler, reply_timeout_ms)
    if recorder is not None:
        handler = recorder.wrap(handler, backend=backend, protocol=protocol, baudrate=baudrate, models=models)
    return cls(port, baudrate, protocol, models, port_handler=handler, retries=retries)


def _set_reply_timeout(handler, reply_timeout_ms: float) -> None:
    """Make the SDK's PortHandler wait ``reply_timeout_ms`` for each status packet.

    Both SDKs compute the timeout in setPacketTimeout from a module-wide 16 ms latency constant;
    slow adapters (or a busy host driving a pseudo-terminal) need more. Patched on this instance
    only, so other buses keep the SDK's figure."""
    def set_packet_timeout(packet_length, _handler=handler):
        _handler.packet_start_time = _handler.getCurrentTime()
        _handler.packet_timeout = _handler.tx_time_per_byte * packet_length + reply_timeout_ms

    handler.setPacketTimeout = set_packet_timeout


def make_mock_bus(backend: str, protocol: float, models: Mapping[int, ServoModel], baudrate: int = 1_000_000,
                  recorder: BusRecorder | None = None) -> Bus:
    """A dry-run bus (the real backend class on a MockPort); its port is ``bus.port``."""
    return make_bus(backend, protocol, "mock", baudrate, models, dry_run=True, recorder=recorder)
