"""The serial port under the vendor SDKs: what every bus (a known chain, a probe) does with it.

Written once here: which exceptions mean the port failed (and their one translation into
:class:`~gaitbot.bus.base.PortError`, with the SDK's port lock released however an exchange ends),
reading and dropping stale input, the reply-timeout patch, opening at a baud rate (leniently on a
pseudo-terminal) and the bounded write time.
"""

from __future__ import annotations

import os
from collections.abc import Iterator
from contextlib import contextmanager
from typing import Any

from gaitbot.bus.base import PortError

try:  # pyserial raises termios.error (not an OSError) from tcflush on a hung-up terminal
    import termios
    PORT_EXCEPTIONS: tuple[type[BaseException], ...] = (OSError, termios.error)
except ImportError:  # pragma: no cover - not POSIX
    PORT_EXCEPTIONS = (OSError,)

LIST_PORTS_HINT = "list serial ports with: python -m serial.tools.list_ports -v"

#: pyserial blocks forever in write() when nobody drains the line (a stuck adapter, a pty whose
#: other end stopped reading). A 60 Hz frame is at most a few hundred bytes, so half a second
#: is only ever reached when the port is dead.
WRITE_TIMEOUT_S = 0.5
#: Linux pseudo-terminal slaves (Unix98 ptys) have device majors 136..143.
_PTY_MAJORS = range(136, 144)


def is_pseudo_terminal(port_name: str) -> bool:
    """True for a pty slave such as /dev/pts/3 (the servo emulator's end): baud rates mean nothing there."""
    try:
        return os.major(os.stat(port_name).st_rdev) in _PTY_MAJORS
    except (OSError, ValueError):
        return False


def release_lock(port: Any) -> None:
    """Give back the SDK's port lock (``is_using``), which an exchange that did not finish leaves taken."""
    try:
        port.is_using = False
    except AttributeError:
        pass


class port_errors:  # noqa: N801 (used as a function: with port_errors(...))
    """One exchange with the SDK on ``port``: an OS-level failure of the port becomes PortError (never
    retried), and the SDK's lock is released however the block ends -- a KeyboardInterrupt or SIGTERM
    landing between the SDK taking its lock and giving it back must not leave every later packet, a stop
    ramp's included, refused as "Port is in use!". ``pass_through``: exceptions of the layers
    under the port that are not the port's failure (a recording that could not be written). A class, not a
    generator: it wraps every exchange of the 60 Hz path."""

    __slots__ = ("port", "port_name", "servo_id", "reason", "pass_through")

    def __init__(self, port: Any, port_name: str, servo_id: int | None = None, reason: str = "",
                 pass_through: tuple[type[BaseException], ...] = ()) -> None:
        self.port, self.port_name, self.servo_id = port, port_name, servo_id
        self.reason, self.pass_through = reason, pass_through

    def __enter__(self) -> None:
        return None

    def __exit__(self, kind, exc, traceback) -> bool:
        release_lock(self.port)
        if exc is None or isinstance(exc, self.pass_through) or not isinstance(exc, PORT_EXCEPTIONS):
            return False
        raise PortError(f"serial port {self.port_name} failed: {exc}{self.reason}", servo_id=self.servo_id) from exc


def read_pending(port: Any) -> bytes:
    """Every input byte waiting on ``port`` (a recording port logs them as they are read)."""
    available = getattr(port, "getBytesAvailable", None)
    if not callable(available):
        return b""
    pending = available()
    return bytes(port.readPort(pending)) if pending else b""


def reset_input(port: Any) -> None:
    """Drop whatever input is still buffered (the port's own reset, or pyserial's under the SDK's port)."""
    reset = getattr(port, "reset_input_buffer", None)
    if callable(reset):
        reset()
        return
    serial_port = getattr(port, "ser", None)
    if serial_port is not None:
        serial_port.reset_input_buffer()


def set_reply_timeout(handler: Any, reply_timeout_ms: float | None) -> Any:
    """Make the SDK's PortHandler wait ``reply_timeout_ms`` (beyond the packet's own bytes) for each status
    packet; None: the SDK's own figure. Returns what to hand back to restore the previous setting.

    Both SDKs compute the timeout in setPacketTimeout from a module-wide 16 ms latency constant; slow
    adapters (or a busy host driving a pseudo-terminal) need more. Patched on this instance only, so other
    ports keep the SDK's figure. Ports without the SDK's timing (the dry-run port) are left alone."""
    previous = handler.__dict__.get("setPacketTimeout") if hasattr(handler, "__dict__") else None
    if reply_timeout_ms is None or not hasattr(handler, "tx_time_per_byte"):
        return previous

    def set_packet_timeout(packet_length, _handler=handler):
        _handler.packet_start_time = _handler.getCurrentTime()
        _handler.packet_timeout = _handler.tx_time_per_byte * packet_length + reply_timeout_ms

    handler.setPacketTimeout = set_packet_timeout
    return previous


def restore_reply_timeout(handler: Any, previous: Any) -> None:
    """Undo :func:`set_reply_timeout` (``previous``: what it returned)."""
    if not hasattr(handler, "__dict__"):
        return
    if previous is None:
        handler.__dict__.pop("setPacketTimeout", None)
    else:
        handler.setPacketTimeout = previous


@contextmanager
def reply_timeout(handler: Any, reply_timeout_ms: float | None) -> Iterator[None]:
    """Within the block, the port waits ``reply_timeout_ms`` for a status packet (None: as it did)."""
    if reply_timeout_ms is None:
        yield
        return
    previous = set_reply_timeout(handler, reply_timeout_ms)
    try:
        yield
    finally:
        restore_reply_timeout(handler, previous)


def bound_write_time(port: Any) -> None:
    """Give pyserial's blocking write a timeout (WRITE_TIMEOUT_S), so a dead line raises instead of hanging."""
    serial_port = getattr(port, "ser", None)
    if serial_port is not None and getattr(serial_port, "write_timeout", 0) is None:
        try:
            serial_port.write_timeout = WRITE_TIMEOUT_S
        except PORT_EXCEPTIONS:
            pass


def open_at(port: Any, port_name: str, baudrate: int, notes: list[str]) -> None:
    """Open ``port`` at ``baudrate``; PortError naming the port when it cannot be. On a pseudo-terminal,
    where the rate means nothing, a rate the SDK or the kernel refuses is not an error: the port stays at a
    standard rate, the SDK's timeouts still follow the configured one, and ``notes`` says so."""
    try:
        opened = port.openPort() and _set_baud_rate(port, port_name, baudrate, notes)
    except PORT_EXCEPTIONS as exc:  # serial.SerialException is an OSError
        raise PortError(f"cannot open serial port {port_name}: {exc}; {LIST_PORTS_HINT}") from exc
    if not opened:
        raise PortError(f"cannot open serial port {port_name} at {baudrate} baud (the SDK refused the port or "
                        f"the baud rate); {LIST_PORTS_HINT}")
    bound_write_time(port)


def _set_baud_rate(port: Any, port_name: str, baudrate: int, notes: list[str]) -> bool:
    try:
        if port.setBaudRate(baudrate):
            return True
        refusal: BaseException | None = None
    except PORT_EXCEPTIONS as exc:
        refusal = exc
    if not is_pseudo_terminal(port_name):
        if refusal is not None:
            raise refusal
        return False
    if not getattr(port, "is_open", False) and not port.setBaudRate(1_000_000):
        return False
    if hasattr(port, "tx_time_per_byte"):
        port.tx_time_per_byte = (1000.0 / baudrate) * 10.0  # ms per byte, as the SDK computes it
    port.baudrate = baudrate
    notes.append(f"{port_name} is a pseudo-terminal: {baudrate} baud not set on it (rates mean nothing on a "
                 "pty); timeouts still follow that rate")
    return True


def close_quietly(port: Any) -> None:
    """Close the port; one that is already gone has nothing left to close."""
    try:
        port.closePort()
    except PORT_EXCEPTIONS:
        pass
