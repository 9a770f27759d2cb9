"""How much of a frame period the serial bus needs, so a rate that cannot fit is refused up front.

Vendor facts only (baud rates, packet sizes): the robot room checks every config against it on load
(gaitbot.robot.config.check_bus_rate), so loading a robot runs no bus code.

Counts the bytes of one frame (the goal sync write, plus the read-back when asked) from the
packet layouts in the ROBOTIS e-Manual and the Feetech protocol manual, at 10 bits per byte
(start + 8 data + stop, no parity), plus each servo's return delay before its status packet.
Not counted: USB-serial latency (an FTDI adapter defaults to a 16 ms latency timer; set it to
1 ms) and host scheduling jitter -- that is what the 30 % margin is for.
"""

from __future__ import annotations

from dataclasses import dataclass

from gaitbot.servos import ASSUMED_RETURN_DELAY_S, BACKENDS, has_sync_read, wire
from gaitbot.servos.health import health_block
from gaitbot.servos.models import ServoModel, servo_model

BITS_PER_BYTE = 10
DEFAULT_RETURN_DELAY_S = ASSUMED_RETURN_DELAY_S


@dataclass(frozen=True)
class FrameBudget:
    """Bytes and wire time of one frame. ``wire_time_s`` includes ``turnarounds`` return delays."""

    write_bytes: int
    read_bytes: int
    turnarounds: int
    return_delay_s: float
    baudrate: int

    @property
    def bytes_per_frame(self) -> int:
        return self.write_bytes + self.read_bytes

    @property
    def wire_time_s(self) -> float:
        return self.bytes_per_frame * BITS_PER_BYTE / self.baudrate + self.turnarounds * self.return_delay_s


def frame_budget(backend: str, protocol: float, model: ServoModel | str, n_servos: int, baudrate: int,
                 read_back: bool, *, return_delay_s: float = DEFAULT_RETURN_DELAY_S) -> FrameBudget:
    """Bytes on the wire for one frame of ``n_servos`` servos of ``model``.

    Protocol 2.0: sync write 14 + n(1+L) bytes; sync read 14 + n, then per servo a status packet of
    11 + L. Protocol 1.0 and Feetech: sync write 8 + n(1+L); Dynamixel 1.0 reads each servo (read 8,
    status 6 + L); Feetech STS/SMS sync read 8 + n with statuses of 6 + L; SCS reads each servo.
    """
    model = servo_model(model) if isinstance(model, str) else model
    if n_servos < 1 or baudrate <= 0:
        raise ValueError(f"need n_servos >= 1 and baudrate > 0, got {n_servos} and {baudrate}")
    goal_len, present_len = model.len_goal_position, model.len_present_position
    if backend not in BACKENDS:
        raise ValueError(f"unknown backend {backend!r} (known: {', '.join(BACKENDS)})")
    framing = wire.framing_for(backend, protocol)
    # an instruction with an address and a length parameter: 14 bytes on 2.0, 8 on 1.0 / Feetech
    addressed = wire.PACKET_OVERHEAD_BYTES[framing] + 2 * wire.ADDRESS_BYTES[framing]
    write = addressed + n_servos * (1 + goal_len)
    read = 0
    if read_back:
        status = wire.STATUS_OVERHEAD_BYTES[framing] + present_len
        sync_read = has_sync_read(backend, protocol, model.byte_order)
        request = (addressed + n_servos) if sync_read else addressed * n_servos
        read = request + n_servos * status
    return FrameBudget(write, read, n_servos if read_back else 0, return_delay_s, int(baudrate))


def one_servo_read_back_bytes(backend: str, protocol: float, model: ServoModel | str, health: bool) -> int:
    """Bytes on the wire of the per-frame read-back of ONE servo (the session reads one servo a frame, in turn):
    its present position (a sync read of one where the protocol has one, else a READ), or with ``health`` its
    whole health block in one READ (gaitbot.servos.health: X 21 bytes, AX/STS/SCS 8, XL-320 10)."""
    model = servo_model(model) if isinstance(model, str) else model
    framing = wire.framing_for(backend, protocol)
    addressed = wire.PACKET_OVERHEAD_BYTES[framing] + 2 * wire.ADDRESS_BYTES[framing]
    status = wire.STATUS_OVERHEAD_BYTES[framing]
    if health:
        return addressed + status + health_block(model).length
    sync_read = has_sync_read(backend, protocol, model.byte_order)
    return addressed + (1 if sync_read else 0) + status + model.len_present_position


def max_rate_hz(backend: str, protocol: float, model: ServoModel | str, n_servos: int, baudrate: int,
                read_back: bool, margin: float = 0.7, **kwargs) -> float:
    """Highest frame rate whose frame uses at most ``margin`` of the period."""
    budget = frame_budget(backend, protocol, model, n_servos, baudrate, read_back, **kwargs)
    return margin / budget.wire_time_s


def check_rate(rate_hz: float, backend: str, protocol: float, model: ServoModel | str, n_servos: int,
               baudrate: int, read_back: bool, margin: float = 0.7, **kwargs) -> FrameBudget:
    """Raise ValueError if one frame would take more than ``margin`` of the period at ``rate_hz``."""
    budget = frame_budget(backend, protocol, model, n_servos, baudrate, read_back, **kwargs)
    period_s = 1.0 / rate_hz
    if budget.wire_time_s > margin * period_s:
        name = model if isinstance(model, str) else model.name
        raise ValueError(
            f"{rate_hz:g} Hz is too fast for {n_servos} {name} at {baudrate} baud "
            f"({'writes + reads' if read_back else 'writes'}): a frame needs {budget.wire_time_s * 1e3:.1f} ms "
            f"({budget.bytes_per_frame} bytes) of a {period_s * 1e3:.1f} ms period, more than {margin:.0%}; "
            f"at most {margin / budget.wire_time_s:.1f} Hz, or raise the baud rate")
    return budget
