"""The emulated chain served on a pseudo-terminal: the device a driver opens (``path``), a thread answering
on the master side, and the line's baud rate read from and set on the tty (termios2)."""

from __future__ import annotations

import array
import fcntl
import os
import select
import threading
import time
import tty

from gaitbot.emulator.chain import EmulatedChain
from gaitbot.emulator.config import EmulatorConfig
from gaitbot.emulator.units import Servo

#: Linux ioctls reading and writing a tty's termios2, whose c_ispeed / c_ospeed are the line rate even for
#: non-standard rates (CBAUD bits set to BOTHER); asm-generic/ioctls.h and termbits.h.
_TCGETS2, _TCSETS2 = 0x802C542A, 0x402C542B
_CBAUD, _BOTHER = 0o010017, 0o010000


class ServoEmulator:
    """The chain on a pty: ``start()`` serves it on a thread, ``path`` is the device to open."""

    def __init__(self, config: EmulatorConfig) -> None:
        self.chain = EmulatedChain(config)
        self.master_fd, self.slave_fd = os.openpty()
        tty.setraw(self.slave_fd)  # no echo, no line editing: bytes pass untouched until a driver opens it
        set_line_rate(self.slave_fd, config.baudrate)  # a driver that never sets a rate talks at the chain's
        self.path = os.ttyname(self.slave_fd)
        os.set_blocking(self.master_fd, False)
        self.closed_reason = ""
        self.lock = threading.Lock()  # the chain is served on a thread; plug_next() and tests take it too
        self._stop = threading.Event()
        self._done = threading.Event()
        self._thread: threading.Thread | None = None
        self.received_bytes = 0

    def start(self) -> "ServoEmulator":
        self._thread = threading.Thread(target=self.serve, name="servo-emulator", daemon=True)
        self._thread.start()
        return self

    def stop(self) -> None:
        self._stop.set()
        if self._thread is not None:
            self._thread.join(timeout=5)
        self._close("stopped")

    def wait_closed(self, timeout_s: float | None = None) -> bool:
        return self._done.wait(timeout_s)

    def plug_next(self) -> Servo | None:
        """Unplug the servo connected now and plug in the next (a one-at-a-time chain)."""
        with self.lock:
            return self.chain.plug_next()

    def connect_all(self) -> None:
        """Plug in every servo: the whole chain, as on the robot."""
        with self.lock:
            self.chain.connect_all()

    def line_baud(self) -> int | None:
        """The rate the driver set on its end of the pty (read from the master side), None if unknown."""
        return line_rate(self.master_fd)

    def __enter__(self) -> "ServoEmulator":
        return self.start()

    def __exit__(self, *exc) -> None:
        self.stop()

    def serve(self) -> None:
        """Answer until stopped or until the port-disappears fault closes the master."""
        chain = self.chain
        try:
            while not self._stop.is_set():
                now_s = time.monotonic()
                due_s = chain.next_due_s()
                wait_s = 0.05 if due_s is None else max(0.0, min(0.05, due_s - now_s))
                readable, _, _ = select.select([self.master_fd], [], [], wait_s)
                with self.lock:
                    chain.line_baud = line_rate(self.master_fd)
                    if readable:
                        try:
                            data = os.read(self.master_fd, 4096)
                        except BlockingIOError:
                            data = b""
                        except OSError:  # EIO: no slave open (we keep one, so only on odd platforms)
                            data = b""
                            time.sleep(0.001)
                        if data:
                            self.received_bytes += len(data)
                            chain.receive(data, time.monotonic())
                    now_s = time.monotonic()
                    due = chain.due(now_s)
                for packet in due:
                    self._write(packet)
                if chain.state_changed and not chain.outbox:  # the servos' EEPROM to the state file, off the line
                    with self.lock:
                        chain.save_state()
                if chain.should_close(now_s):
                    self._close(f"port closed after {chain.goal_frames} goal frames (fault injection)")
                    return
        finally:
            self._close("stopped")

    def _write(self, packet: bytes) -> None:
        view = memoryview(packet)
        deadline_s = time.monotonic() + 0.5
        while view and time.monotonic() < deadline_s:
            try:
                view = view[os.write(self.master_fd, view):]
            except BlockingIOError:
                time.sleep(0.0005)

    def _close(self, reason: str) -> None:
        if self._done.is_set():
            return
        self.closed_reason = reason
        if self.chain.state_changed:
            self.chain.save_state()
        for fd in (self.master_fd, self.slave_fd):  # closing the master hangs up the driver's end
            try:
                os.close(fd)
            except OSError:
                pass
        self.chain.close_log()
        self._done.set()


def line_rate(fd: int) -> int | None:
    """The input speed of the tty behind ``fd`` (a pty master reports the slave's settings), or None."""
    buffer = array.array("i", [0] * 64)
    try:
        fcntl.ioctl(fd, _TCGETS2, buffer)
    except OSError:
        return None
    return int(buffer[9]) or None  # struct termios2: 4 flags, c_line + c_cc[19], then c_ispeed


def set_line_rate(fd: int, rate: int) -> None:
    """Set the tty behind ``fd`` to ``rate`` baud (any rate, as pyserial does); ignored where not supported."""
    buffer = array.array("i", [0] * 64)
    try:
        fcntl.ioctl(fd, _TCGETS2, buffer)
        buffer[2] = (buffer[2] & ~_CBAUD) | _BOTHER
        buffer[9] = buffer[10] = int(rate)
        fcntl.ioctl(fd, _TCSETS2, buffer)
    except OSError:
        pass
