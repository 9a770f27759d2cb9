"""Build a bus from configuration: the one place that knows which class and which port to use.

The vendor (``backend``: gaitbot.servos.BACKENDS) chooses the bus class (:data:`BUS_CLASSES`); the
interface chooses the port under the vendor's SDK (:data:`INTERFACES`), by name as python-can chooses
its ``interface``: ``"serial"`` (the SDK's own PortHandler on a serial device) or ``"dry-run"`` (the
dry-run port, gaitbot.bus.dry_run: a healthy chain behind the real SDK code). The simulated robot
(gaitbot.sim) hands in a port of its own. A new vendor is a bus class here (its module beside
dynamixel.py and feetech.py) and a vendor module in gaitbot.servos; a new interface is an entry in
INTERFACES.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Mapping
from typing import Any

from gaitbot.bus.base import Bus
from gaitbot.bus.dry_run import DryRunPort
from gaitbot.bus.dynamixel import DynamixelBus
from gaitbot.bus.feetech import FeetechBus
from gaitbot.bus.guard import LimitGuard
from gaitbot.bus.port import set_reply_timeout
from gaitbot.bus.probe import ProbeBus
from gaitbot.bus.recording.writer import BusRecorder
from gaitbot.robot.calibration import standing_ticks, tick_limits
from gaitbot.robot.config import RobotConfig
from gaitbot.servos.models import ServoModel

#: Backend name (gaitbot.servos.BACKENDS) -> its bus class.
BUS_CLASSES: dict[str, type] = {cls.family: cls for cls in (DynamixelBus, FeetechBus)}

SERIAL, DRY_RUN = "serial", "dry-run"


def _serial_port(backend: str, protocol: float, port: str, baudrate: int | None,
                 models: Mapping[int, ServoModel], reply_timeout_ms: float | None,
                 start_ticks: Mapping[int, int] | None = None) -> Any:
    handler = bus_class(backend).sdk.PortHandler(port)
    set_reply_timeout(handler, reply_timeout_ms)
    return handler


def _dry_run_port(backend: str, protocol: float, port: str, baudrate: int | None,
                  models: Mapping[int, ServoModel], reply_timeout_ms: float | None,
                  start_ticks: Mapping[int, int] | None = None) -> Any:
    port_handler = DryRunPort(backend, protocol, models, port_name=port, baudrate=baudrate)
    port_handler.stand_at(start_ticks or {})
    return port_handler


#: Interface name -> the port handler it makes: (backend, protocol, port name, baud rate, the servos
#: behind it, reply timeout in ms or None, and where a mock chain's servos stand at power-on: servo id ->
#: ticks, None for the centre tick; a real port ignores it) -> a PortHandler-like object.
INTERFACES: dict[str, Callable[..., Any]] = {SERIAL: _serial_port, DRY_RUN: _dry_run_port}


def port_handler(interface: str, backend: str, protocol: float, port: str, baudrate: int | None,
                 models: Mapping[int, ServoModel], reply_timeout_ms: float | None = None,
                 start_ticks: Mapping[int, int] | None = None) -> Any:
    """The port of ``interface`` (ValueError naming the known ones)."""
    try:
        make = INTERFACES[interface]
    except KeyError:
        raise ValueError(f"unknown bus interface {interface!r} (known: {', '.join(INTERFACES)})") from None
    return make(backend, protocol, port, baudrate, models, reply_timeout_ms, start_ticks)


def make_bus(backend: str, protocol: float, port: str, baudrate: int, models: Mapping[int, ServoModel], *,
             interface: str = SERIAL, recorder: BusRecorder | None = None, retries: int = 3,
             reply_timeout_ms: float | None = None, clock: Callable[[], float] = time.monotonic,
             start_ticks: Mapping[int, int] | None = None) -> Bus:
    """The bus for ``backend`` on the port of ``interface`` (``"serial"``: ``port`` is a device;
    ``"dry-run"``: the dry-run port, ``port`` only names it).

    With ``recorder`` every byte in both directions is logged. The bus is not opened here; use it as a
    context manager or call open(). ``reply_timeout_ms`` replaces the SDK's reply timeout (2 x 16 ms USB
    latency + 2 ms + the packet's bytes) when set. ``clock`` (seconds) measures the read-back's budgets:
    pass the session's clock. ``start_ticks`` (servo id -> ticks): where a dry-run chain's servos stand at power-on.
    """
    cls = bus_class(backend)
    handler = port_handler(interface, backend, protocol, port, baudrate, models, reply_timeout_ms, start_ticks)
    if recorder is not None:
        handler = recorder.wrap(handler, backend=backend, protocol=protocol, baudrate=baudrate, models=models)
    return cls(port, baudrate, protocol, models, port_handler=handler, retries=retries, clock=clock)


def bus_class(backend: str) -> type:
    """The Bus class of ``backend``; ValueError naming the known ones."""
    try:
        return BUS_CLASSES[backend]
    except KeyError:
        raise ValueError(f"unknown bus backend {backend!r} (known: {', '.join(BUS_CLASSES)})") from None


def stand_ticks_by_id(config: RobotConfig) -> dict[int, int]:
    """Servo id -> its tick in the config's stand pose (gaitbot.robot.calibration.standing_ticks)."""
    return {j.id: int(t) for j, t in zip(config.joints, standing_ticks(config))}


def guarded(config: RobotConfig, bus: Bus) -> LimitGuard:
    """``bus`` behind the LimitGuard of ``config``'s joint limits: every goal checked, once, before a byte is sent."""
    return LimitGuard(bus, tick_limits(config), {j.id: j.name for j in config.joints})


def make_robot_bus(config: RobotConfig, port: str | None = None, *, dry_run: bool = False,
                   recorder: BusRecorder | None = None, reply_timeout_ms: float | None = None,
                   clock: Callable[[], float] = time.monotonic) -> LimitGuard:
    """The bus of a robot config (on ``port``, default the config's; ``dry_run``: on the dry-run port),
    wrapped in its LimitGuard. Not opened: use it as a context manager, or hand it to a session. The dry-run
    servos start where the robot stands (the stand pose in the config's calibrated ticks), not at their
    centre tick, where a calibrated robot's joint may be outside its limits."""
    bus = make_bus(config.bus.backend, config.bus.protocol, port or config.bus.port, config.bus.baudrate,
                   config.models_by_id, interface=DRY_RUN if dry_run else SERIAL, recorder=recorder,
                   reply_timeout_ms=reply_timeout_ms, clock=clock, start_ticks=stand_ticks_by_id(config))
    return guarded(config, bus)


def make_dry_run_bus(backend: str, protocol: float, models: Mapping[int, ServoModel], baudrate: int = 1_000_000,
                     recorder: BusRecorder | None = None) -> Bus:
    """A bus on the dry-run port (the real backend class on a DryRunPort); its port is ``bus.port``."""
    return make_bus(backend, protocol, "mock", baudrate, models, interface=DRY_RUN, recorder=recorder)


def make_probe_bus(backend: str, protocol: float, port: str, *, dry_run: bool = False,
                   models: Mapping[int, ServoModel] | None = None, baudrate: int | None = None,
                   reply_timeout_ms: float | None = None, start_ticks: Mapping[int, int] | None = None) -> ProbeBus:
    """A bus of servos not known yet (gaitbot setup, scan) on ``port``: the same vendor class's SDK and
    packet handler, on the port of the same interfaces (``dry_run``: a dry-run port holding ``models`` set
    to ``baudrate``, standing at ``start_ticks``). Not opened here."""
    handler = port_handler(DRY_RUN if dry_run else SERIAL, backend, protocol, port, baudrate, models or {},
                           start_ticks=start_ticks)
    return ProbeBus(bus_class(backend), protocol, port, handler, reply_timeout_ms=reply_timeout_ms)
