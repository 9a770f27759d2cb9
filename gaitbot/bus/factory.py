"""Build a bus from configuration: the one place that knows which class and port to use."""

from __future__ import annotations

from collections.abc import Mapping

from gaitbot.bus.base import Bus
from gaitbot.bus.dynamixel import DynamixelBus
from gaitbot.bus.feetech import FeetechBus
from gaitbot.bus.guard import LimitGuard
from gaitbot.bus.log import BusRecorder
from gaitbot.bus.mock import MockPort
from gaitbot.bus.probe import ProbeBus
from gaitbot.robot.calibration import tick_limits
from gaitbot.robot.config import RobotConfig
from gaitbot.servos.models import ServoModel

#: Backend name (gaitbot.servos.BACKENDS) -> its bus class.
BUS_CLASSES: dict[str, type] = {cls.family: cls for cls in (DynamixelBus, FeetechBus)}


def make_bus(backend: str, protocol: float, port: str, baudrate: int, models: Mapping[int, ServoModel],
             dry_run: bool, recorder: BusRecorder | None = None, retries: int = 3,
             reply_timeout_ms: float | None = None) -> Bus:
    """The bus for ``backend``; with ``dry_run`` the same class talks to a MockPort instead of ``port``.

    With ``recorder`` every byte in both directions is logged (dry run or real). The bus is not
    opened here; use it as a context manager or call open(). ``reply_timeout_ms`` replaces the
    SDK's reply timeout (2 x 16 ms USB latency + 2 ms + the packet's bytes) when set.
    """
    cls = bus_class(backend)
    handler = MockPort(backend, protocol, models, port_name=port, baudrate=baudrate) if dry_run \
        else cls.sdk.PortHandler(port)
    if reply_timeout_ms is not None and not dry_run:
        _set_reply_timeout(handler, reply_timeout_ms)
    if recorder is not None:
        handler = recorder.wrap(handler, backend=backend, protocol=protocol, baudrate=baudrate, models=models)
    return cls(port, baudrate, protocol, models, port_handler=handler, retries=retries)


def bus_class(backend: str) -> type:
    """The Bus class of ``backend``; ValueError naming the known ones."""
    try:
        return BUS_CLASSES[backend]
    except KeyError:
        raise ValueError(f"unknown bus backend {backend!r} (known: {', '.join(BUS_CLASSES)})") from None


def guarded(config: RobotConfig, bus: Bus) -> LimitGuard:
    """``bus`` behind the LimitGuard of ``config``'s joint limits: every goal checked, once, before a byte is sent."""
    return LimitGuard(bus, tick_limits(config), {j.id: j.name for j in config.joints})


def make_robot_bus(config: RobotConfig, port: str | None = None, *, dry_run: bool = False,
                   recorder: BusRecorder | None = None, reply_timeout_ms: float | None = None) -> LimitGuard:
    """The bus of a robot config (on ``port``, default the config's), wrapped in its LimitGuard.

    Not opened: use it as a context manager, or hand it to a session."""
    bus = make_bus(config.bus.backend, config.bus.protocol, port or config.bus.port, config.bus.baudrate,
                   config.models_by_id, dry_run=dry_run, recorder=recorder, reply_timeout_ms=reply_timeout_ms)
    return guarded(config, bus)


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


def make_probe_bus(backend: str, protocol: float, port: str, *, dry_run: bool = False,
                   models: Mapping[int, ServoModel] | None = None, baudrate: int | None = None,
                   reply_timeout_ms: float | None = None) -> ProbeBus:
    """A bus of servos not known yet (gaitbot setup, scan) on ``port``; with ``dry_run`` a MockPort holding
    ``models`` set to ``baudrate``. Not opened here."""
    handler = MockPort(backend, protocol, models or {}, port_name=port, baudrate=baudrate) if dry_run \
        else bus_class(backend).sdk.PortHandler(port)
    return ProbeBus(backend, protocol, port, handler, reply_timeout_ms=reply_timeout_ms)
