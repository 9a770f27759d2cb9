"""The writer of the bus recording format (gaitbot.bus.recording): a port wrapper that logs every packet.

Each line is written with one write() and flushed, so after a crash or Ctrl-C every line but
possibly the last is complete. Received bytes are coalesced into whole status packets using the
protocol's framing (gaitbot.bus.packets); stray bytes are logged as their own rx line when the next
instruction is sent.
"""

from __future__ import annotations

import json
import time
from collections.abc import Callable, Mapping
from pathlib import Path
from typing import Any, BinaryIO

from gaitbot.bus.base import BusError
from gaitbot.bus.packets import take_packets
from gaitbot.bus.port import reset_input
from gaitbot.servos import wire
from gaitbot.servos.models import ServoModel

LOG_FORMAT = "gaitbot-bus-log"
LOG_VERSION = 1


class RecordingFailed(BusError):
    """The recording could not be written (a full disk, a failing drive) while the bus itself is fine.

    Raised once, from the packet that could not be logged; the recorder then stops writing (what was
    written stays, each line whole but possibly the last) and the session stops the walk with its
    normal ramp, which still goes out on the healthy port. Not an OSError, so the bus never takes it
    for a failure of the serial port."""


class BusRecorder:
    """Writes one bus log. ``clock`` returns seconds (monotonic); injectable for tests."""

    def __init__(self, path: str | Path, *, robot: str, joints: Mapping[str, int],
                 clock: Callable[[], float] = time.monotonic, rate_hz: float | None = None,
                 calibration: Mapping[str, Any] | None = None) -> None:
        self.path = Path(path)
        self.calibration = calibration  # the zero ticks and directions sent with (gaitbot check decodes by them)
        self.rate_hz = rate_hz  # the frame rate of the run, written in the header (gaitbot check uses it)
        self.robot = robot
        self.joints = dict(joints)
        self._clock = clock
        self._t0_s: float | None = None
        self._file: BinaryIO | None = None
        self.failed: OSError | None = None  # the write that failed; nothing is written after it
        self.lines_written = 0

    def start(self, *, backend: str, protocol: float, baudrate: int, models: Mapping[int, ServoModel]) -> None:
        """Open the file and write the header; the clock's zero is now."""
        if self._file is not None:
            raise RuntimeError(f"recorder {self.path} already started")
        header = {"format": LOG_FORMAT, "version": LOG_VERSION, "backend": backend, "protocol": float(protocol),
                  "baudrate": int(baudrate), "robot": self.robot, "joints": self.joints,
                  "models": {str(i): m.name for i, m in models.items()}}
        if self.rate_hz is not None:
            header["rate_hz"] = float(self.rate_hz)
        if self.calibration is not None:
            header["calibration"] = dict(self.calibration)
        self._file = open(self.path, "wb", buffering=0)  # one os-level write per line: no buffer to lose
        self._t0_s = self._clock()
        try:
            self._write_line(header)
        except RecordingFailed:
            self.close()
            raise

    def wrap(self, port_handler: Any, *, backend: str, protocol: float, baudrate: int,
             models: Mapping[int, ServoModel]) -> "RecordingPort":
        """Start the log and return a port that logs through this recorder."""
        self.start(backend=backend, protocol=protocol, baudrate=baudrate, models=models)
        return RecordingPort(port_handler, self, wire.framing_for(backend, protocol))

    def now(self) -> float:
        return self._clock()

    def log(self, direction: str, data: bytes, at_s: float | None = None) -> None:
        if self.failed is not None:
            return  # the recording already failed (and said so once): the walk's stop goes on without it
        if self._file is None or self._t0_s is None:
            raise RuntimeError(f"recorder {self.path} not started")
        t_s = round((self._clock() if at_s is None else at_s) - self._t0_s, 6)
        self._write_line({"t": t_s, "dir": direction, "hex": bytes(data).hex()})

    def close(self) -> None:
        if self._file is not None:
            try:
                self._file.close()
            except OSError as exc:  # nothing is buffered; a failing close is only noted
                self.failed = self.failed or exc
            self._file = None

    def __enter__(self) -> "BusRecorder":
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    def _write_line(self, obj: dict) -> None:
        assert self._file is not None
        data = (json.dumps(obj, separators=(",", ":")) + "\n").encode("utf-8")
        try:
            written = self._file.write(data)
            while written is not None and written < len(data):  # a raw write may be short; finish the line
                more = self._file.write(data[written:])
                if not more:
                    raise OSError(28, "No space left on device")
                written += more
        except OSError as exc:
            self.failed = exc
            raise RecordingFailed(f"the recording {self.path} could not be written ({exc.strerror or exc}) after "
                                  f"{self.lines_written} lines; what was written is kept") from exc
        self.lines_written += 1


class RecordingPort:
    """A PortHandler wrapper that logs tx packets and rx packets; everything else passes through."""

    def __init__(self, inner: Any, recorder: BusRecorder, framing: str) -> None:
        self._inner = inner
        self._recorder = recorder
        self._framing = framing
        self._rx_pending = bytearray()
        self.is_using = False  # the SDK's lock lives on the object it talks to

    def __getattr__(self, name: str) -> Any:  # port_name, baudrate, ser, getBaudRate, setPacketTimeout ...
        return getattr(self._inner, name)

    def writePort(self, packet) -> int:  # noqa: N802 (SDK name)
        self._flush_rx(partial=True)
        sent_s = self._recorder.now()  # stamped as it is handed to the port, not after (a busy host may pause there)
        written = self._inner.writePort(packet)
        self._recorder.log("tx", bytes(packet), at_s=sent_s)
        return written

    def readPort(self, length: int):  # noqa: N802
        data = self._inner.readPort(length)
        if data:
            self._rx_pending += bytes(data)
            self._flush_rx(partial=False)
        return data

    def clearPort(self) -> None:  # noqa: N802
        self._flush_rx(partial=True)
        self._inner.clearPort()

    def reset_input_buffer(self) -> None:
        self._flush_rx(partial=True)
        reset_input(self._inner)

    def closePort(self) -> None:  # noqa: N802
        try:
            self._flush_rx(partial=True)
            self._inner.closePort()
        finally:  # a port that is already gone must not leave the recording unflushed
            self._recorder.close()

    def _flush_rx(self, partial: bool) -> None:
        for chunk, _frame in take_packets(self._rx_pending, self._framing, status=True):
            self._recorder.log("rx", chunk)
        if partial and self._rx_pending:
            self._recorder.log("rx", bytes(self._rx_pending))
            self._rx_pending.clear()
