"""A port of servos nobody has introduced yet: find them at any id and baud rate, read any register, and
write the few registers bring-up needs (gaitbot setup, gaitbot scan).

:class:`SdkBus` drives a known chain (ids and models from a config); a probe knows only the backend and
the protocol. It uses the vendor SDK's PortHandler and packet handler (ping, read, write) like the walk
does; two exchanges are its own, because the SDKs offer none that fits:

* **broadcast ping** (Dynamixel 2.0 and Feetech: ``BROADCAST_PING`` of the vendor facts): one PING to id
  254 and every status packet that comes back, read with gaitbot.bus.packets. Dynamixel 2.0 servos answer one after another in id order
  (e-Manual Protocol 2.0, "Ping"); the probe waits the SDK's own window for that (253 status packets'
  bytes + 3 ms a servo + 16 ms, ``broadcastPing`` in dynamixel_sdk), or, given ``reply_timeout_ms``,
  until the line has been quiet that long. Feetech servos all answer a broadcast ping at once
  (Feetech's protocol manual: "cannot be used when multiple servos are connected"), so one clean status
  packet means one servo and a damaged one means several.
* **one id at a time** (Dynamixel 1.0, which has no broadcast ping, and Feetech when its broadcast ping
  came back damaged): a PING per id, each waiting the reply timeout. A status packet that arrives after
  its timeout (SEARCH_PING_TIMEOUT_MS unless given) is not lost: every byte read from the port passes a tap that notes the id of each clean
  status packet (the SDK skips a reply whose id is not the one it asked), and those ids are pinged again
  with a long timeout.

Two servos at one id and baud rate answer at once and garble each other (e-Manual: "If DYNAMIXELs with
the same ID are connected, packet collision and network problems will occur"): every damaged status
packet is counted in :attr:`ProbeResult.damaged`, so bring-up can refuse a bus with more than one servo.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Collection
from dataclasses import dataclass, field
from typing import Any

from gaitbot.bus.base import PortError, ServoTimeout
from gaitbot.bus.packets import status_frames, take_packets
from gaitbot.bus.port import (PORT_EXCEPTIONS, close_quietly, is_pseudo_terminal, port_errors, read_pending,
                              reply_timeout, reset_input)
from gaitbot.bus.sdk_bus import SdkBus
from gaitbot.servos import control_table, max_servo_id, model_name_of, vendor, wire
from gaitbot.servos.models import SERVO_MODELS, ServoModel

#: dynamixel_sdk's broadcastPing window: status packets of 14 bytes from every id, 3 ms a servo, 16 ms latency.
_BROADCAST_STATUS_BYTES = 14
_BROADCAST_MS_PER_SERVO = 3.0
_USB_LATENCY_MS = 16.0
#: A second look at a servo that answered late, or whose answer must be sure: this long per reply.
CONFIRM_TIMEOUT_MS = 100.0
#: A PING of one id during a search waits this long unless the caller set a reply timeout: the SDK's 34 ms
#: made a Protocol 1.0 scan (254 ids at six rates) take 52 s and more. A servo answers within its Return
#: Delay Time (0.5 ms as shipped) plus the reply's bytes; a USB adapter that holds the reply back longer
#: (a 16 ms latency timer) costs nothing either: the late reply is seen by the tap and its id asked again
#: with CONFIRM_TIMEOUT_MS.
SEARCH_PING_TIMEOUT_MS = 2.0
#: A broadcast ping waits at least this long for a first reply, whatever the reply timeout: once per baud
#: rate, and a servo missed there is a servo not found (the SDK's own window is longer still).
FIRST_REPLY_MS = 250.0


@dataclass(frozen=True)
class ServoFound:
    """A servo that answered: its id, the baud rate it answered at, its model number (None: not read) and
    model name (None: a number gaitbot does not know)."""

    servo_id: int
    baudrate: int
    model_number: int | None
    model_name: str | None

    @property
    def model(self) -> ServoModel | None:
        return SERVO_MODELS.get(self.model_name) if self.model_name else None


@dataclass
class ProbeResult:
    """What a search at one baud rate saw: the servos that answered and the damaged status packets."""

    baudrate: int
    found: list[ServoFound] = field(default_factory=list)
    damaged: int = 0


class ProbeBus:
    """A bus of the vendor of ``transport`` (its SdkBus class: the SDK module and the packet handler a walk
    uses) speaking ``protocol`` on ``port_handler`` (the SDK's PortHandler, a dry-run port or a recorder
    around either), its servos unknown. Open it, set a baud rate, then ``search`` / ``read`` / ``write``.
    ``reply_timeout_ms`` replaces the SDK's reply timeout (about 34 ms) for every exchange."""

    def __init__(self, transport: type[SdkBus], protocol: float, port_name: str, port_handler: Any,
                 reply_timeout_ms: float | None = None, retries: int = 3) -> None:
        self.transport = transport
        self.backend = transport.family
        self.vendor = vendor(self.backend)
        self.protocol = float(protocol)
        self.port_name = port_name
        self._inner_port = port_handler
        self.framing = wire.framing_for(self.backend, protocol)
        self.port = _Tap(port_handler, self.framing)
        self.reply_timeout_ms = reply_timeout_ms
        self.retries = retries
        self.sdk = transport.sdk
        self._ph: Any = None
        self.baudrate: int | None = None
        self.open_notes: list[str] = []

    # --- the port ---------------------------------------------------------------------------
    def open(self) -> None:
        self._ph = self.transport.make_packet_handler(self.protocol)  # words decoded here, in each servo's order
        try:
            opened = self.port.openPort()
        except PORT_EXCEPTIONS as exc:
            raise PortError(f"cannot open serial port {self.port_name}: {exc}") from exc
        if not opened:
            raise PortError(f"cannot open serial port {self.port_name}")

    def close(self) -> None:
        close_quietly(self.port)

    def __enter__(self) -> "ProbeBus":
        self.open()
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    def drain(self, settle_s: float = 0.01) -> None:
        """Wait until every byte written has left the port (tcdrain), then ``settle_s`` more: before the host
        switches rate after a Baud Rate write, so the servo hears the whole write at the old rate."""
        serial_port = getattr(self._inner_port, "ser", None)
        if serial_port is not None:
            with port_errors(self.port, self.port_name):
                serial_port.flush()
        time.sleep(settle_s)

    def set_baudrate(self, baudrate: int) -> None:
        """Switch the host to ``baudrate``; PortError when the SDK or the adapter refuses it."""
        try:
            ok = self.port.setBaudRate(int(baudrate))
        except PORT_EXCEPTIONS as exc:
            raise PortError(f"serial port {self.port_name} refused {baudrate} baud: {exc}") from exc
        if not ok:
            raise PortError(f"serial port {self.port_name} refused {baudrate} baud (the SDK does not offer it)")
        self.baudrate = int(baudrate)

    # --- finding servos ---------------------------------------------------------------------
    def search(self, ids: range | None = None, on_ping: Callable[[int], None] | None = None,
               expected: Collection[int] = ()) -> ProbeResult:
        """Every servo answering at the current baud rate (ids: every usable id). ``on_ping(servo_id)`` is
        called after each PING of one id (progress; a broadcast ping calls it with the broadcast id).
        ``expected`` ids (a config's servos) that did not answer get a second look: a PING of their own that
        waits CONFIRM_TIMEOUT_MS, since a reply lost to a busy host or a slow adapter would otherwise be a
        servo reported missing (0.1 s a silent joint: 2 s for an OP3's 20 with the bus unpowered)."""
        if self.baudrate is None:
            raise RuntimeError("set a baud rate first")
        ids = ids if ids is not None else range(0, max_servo_id(self.backend, self.protocol) + 1)
        result = ProbeResult(self.baudrate)
        on_ping = on_ping or (lambda _servo_id: None)
        broadcast = self.vendor.BROADCAST_PING.get(self.protocol)
        if broadcast == "in turn":
            answered, result.damaged = self._broadcast_ping(all_at_once=False)
            on_ping(wire.BROADCAST_ID)
            numbers = answered
        elif broadcast == "at once":
            answered, result.damaged = self._broadcast_ping(all_at_once=True)
            on_ping(wire.BROADCAST_ID)
            if result.damaged or not answered:
                numbers = {}
                if result.damaged:  # several servos: ask them one by one
                    numbers, result.damaged = self._ping_each(ids, on_ping)
            else:
                numbers = answered
        else:
            numbers, result.damaged = self._ping_each(ids, on_ping)
        for servo_id in sorted(set(expected) & set(ids) - set(numbers)):
            self._drop_stale()
            outcome, number = self._ping_once(servo_id, CONFIRM_TIMEOUT_MS)
            if outcome == "ok":
                numbers[servo_id] = number
        for servo_id in sorted(i for i in numbers if i in ids):
            number = numbers[servo_id]
            if number is None:
                number = self.model_number(servo_id)
            result.found.append(ServoFound(servo_id, self.baudrate, number,
                                           model_name_of(self.backend, number) if number is not None else None))
        return result

    def _broadcast_ping(self, all_at_once: bool) -> tuple[dict[int, int | None], int]:
        """{id: model number (2.0) or None} of every clean status packet, and the count of damaged ones."""
        packet = (wire.build_v2 if self.framing == "v2" else wire.build_v1)(wire.BROADCAST_ID, wire.INST_PING)
        self._drop_stale()
        self._write(packet)
        byte_ms = 10_000.0 / self.baudrate
        if all_at_once:  # one status packet's time, as for a ping of one servo
            window_ms = 6 * byte_ms + max(self._reply_ms(), FIRST_REPLY_MS)
        else:
            window_ms = (_BROADCAST_STATUS_BYTES * (max_servo_id(self.backend, self.protocol) + 1) * byte_ms
                         + _BROADCAST_MS_PER_SERVO * (max_servo_id(self.backend, self.protocol) + 1)
                         + _USB_LATENCY_MS)
        data = self._listen(window_ms, quiet_ms=self.reply_timeout_ms)
        answered: dict[int, int | None] = {}
        damaged = 0
        for _raw, frame in take_packets(bytearray(data), self.framing, status=True):
            if frame is None or not frame.checksum_ok:
                damaged += 1
                continue
            number = None
            if self.framing == "v2" and len(frame.params) >= 2:
                number = frame.params[0] | frame.params[1] << 8
            if frame.packet_id in answered:
                damaged += 1  # one id twice: two servos there
            answered[frame.packet_id] = number
        return answered, damaged

    def _ping_each(self, ids, on_ping: Callable[[int], None]) -> tuple[dict[int, int | None], int]:
        answered: dict[int, int | None] = {}
        self.port.seen.clear()
        self.port.damaged = 0
        timeout_ms = SEARCH_PING_TIMEOUT_MS if self.reply_timeout_ms is None else self.reply_timeout_ms
        for servo_id in ids:
            self._drop_stale()
            outcome, number = self._ping_once(servo_id, timeout_ms)
            on_ping(servo_id)
            if outcome == "ok":
                answered[servo_id] = number
        self._drop_stale()
        damaged = self.port.damaged  # every garbled reply read, in time or late (the tap sees them all)
        late = {i for i in self.port.seen if i in ids}
        for servo_id in sorted(late - set(answered)):
            outcome, number = self._ping_once(servo_id, CONFIRM_TIMEOUT_MS)
            if outcome == "ok":
                answered[servo_id] = number
        return answered, damaged

    def _ping_once(self, servo_id: int, timeout_ms: float | None = None) -> tuple[str, int | None]:
        """("ok" | "silent" | "damaged", the model number the SDK's ping read) of one PING, no retry.
        Dynamixel's ping returns the model number (2.0: in the status; 1.0: read at address 0); the Feetech
        SDK's assumes one byte order for every servo, so it is left to :meth:`model_number`."""
        with self._timeout(timeout_ms):
            try:
                number, result, _error = self._guard(lambda: self._ph.ping(self.port, servo_id))
            except IndexError:  # dynamixel_sdk 1.0's ping indexes a model-number reply too short: a stale packet
                self.port.seen.add(servo_id)  # it answered something: ask again with time to spare
                return "silent", None
        if result == self.sdk.COMM_SUCCESS:
            return "ok", (number if self.vendor.ONE_BYTE_ORDER else None)
        return ("damaged" if result == self.sdk.COMM_RX_CORRUPT else "silent"), None

    def ping(self, servo_id: int, timeout_ms: float = CONFIRM_TIMEOUT_MS) -> bool:
        """Whether ``servo_id`` answers a PING (with the retries of every read; a confirmation, so it waits
        CONFIRM_TIMEOUT_MS, not the search's reply timeout)."""
        for _ in range(1 + self.retries):
            self._drop_stale()
            if self._ping_once(servo_id, timeout_ms)[0] == "ok":
                return True
        return False

    # --- registers --------------------------------------------------------------------------
    def read(self, servo_id: int, address: int, length: int) -> tuple[bytes, int]:
        """(``length`` bytes at ``address``, the status error byte); ServoTimeout after the retries. Reads and
        confirmed writes wait CONFIRM_TIMEOUT_MS for their status packet: they are few, and must not fail."""
        result = self.sdk.COMM_SUCCESS
        for _ in range(1 + self.retries):
            self._drop_stale()
            with self._timeout(CONFIRM_TIMEOUT_MS):
                data, result, error = self._guard(lambda: self._ph.readTxRx(self.port, servo_id, address, length))
            if result == self.sdk.COMM_SUCCESS and len(data) >= length:
                return bytes(data[:length]), error
        raise ServoTimeout(f"servo {servo_id} on {self.port_name} at {self.baudrate} baud did not answer a read of "
                           f"address {address} ({self._ph.getTxRxResult(result)})", servo_id=servo_id,
                           result_code=result)

    def write(self, servo_id: int, address: int, data: bytes, *, confirm: bool = True) -> int:
        """One WRITE of ``data`` at ``address``: with ``confirm``, retried until the status packet comes and
        its error byte returned; without, sent once and not waited for (an id or baud-rate write, which
        the servo may answer as its new self). Bring-up reads every write back anyway."""
        data = bytes(data)
        if not confirm:
            self._drop_stale()
            self._guard(lambda: self._ph.writeTxOnly(self.port, servo_id, address, len(data), list(data)))
            return 0
        result = self.sdk.COMM_SUCCESS
        for _ in range(1 + self.retries):
            self._drop_stale()
            with self._timeout(CONFIRM_TIMEOUT_MS):
                result, error = self._guard(lambda: self._ph.writeTxRx(self.port, servo_id, address, len(data),
                                                                        list(data)))
            if result == self.sdk.COMM_SUCCESS:
                return error
        raise ServoTimeout(f"servo {servo_id} on {self.port_name} did not confirm writing to address {address} "
                           f"({self._ph.getTxRxResult(result)})", servo_id=servo_id, result_code=result)

    def model_number(self, servo_id: int) -> int | None:
        """The servo's model number from its Model Number register (Dynamixel address 0, Feetech 3, the
        word in the servo's own byte order: Feetech's END register at 2 says which)."""
        table = control_table(next(iter(self.vendor.CONTROL_TABLES)))
        register = table["Model Number"]
        try:
            if not self.vendor.ONE_BYTE_ORDER:
                end = table["Byte Order"].address
                data, _ = self.read(servo_id, end, register.address + register.size - end)
                order = "big" if data[0] else "little"
                return int.from_bytes(data[register.address - end:], order)
            data, _ = self.read(servo_id, register.address, register.size)
        except ServoTimeout:
            return None
        return int.from_bytes(data, "little")

    # --- internals --------------------------------------------------------------------------
    def _reply_ms(self) -> float:
        return self.reply_timeout_ms if self.reply_timeout_ms is not None else 2 * _USB_LATENCY_MS + 2.0

    def _timeout(self, timeout_ms: float | None):
        return reply_timeout(self._inner_port, timeout_ms if timeout_ms is not None else self.reply_timeout_ms)

    def _guard(self, call):
        """One exchange (gaitbot.bus.port.port_errors: PortError, the SDK's lock released)."""
        with port_errors(self.port, self.port_name):
            return call()

    def _write(self, packet: bytes) -> None:
        self._guard(lambda: self.port.writePort(list(packet)))

    def _listen(self, window_ms: float, quiet_ms: float | None) -> bytes:
        """Every byte within ``window_ms``; with ``quiet_ms``, stop once the line has been quiet that long after
        a reply, or after FIRST_REPLY_MS (at least ``quiet_ms``) if nothing came at all."""
        data = bytearray()
        self.port.setPacketTimeoutMillis(window_ms)
        start_s = last_s = time.monotonic()
        first_s = None if quiet_ms is None else max(quiet_ms, FIRST_REPLY_MS) / 1000.0
        while True:
            available = self._guard(self.port.getBytesAvailable)
            now_s = time.monotonic()
            if available:
                data += bytes(self._guard(lambda: self.port.readPort(available)))
                last_s = now_s
            elif self.port.isPacketTimeout():
                return bytes(data)
            elif quiet_ms is not None and data and (now_s - last_s) * 1000.0 > quiet_ms:
                return bytes(data)
            elif first_s is not None and not data and now_s - start_s > first_s:
                return bytes(data)
            else:
                time.sleep(0.0002)

    def _drop_stale(self) -> set[int]:
        """Read and drop bytes left over from an earlier exchange; the ids of clean status packets among them."""
        stale = self._guard(lambda: read_pending(self.port))
        ids = {frame.packet_id for frame in status_frames(stale, self.framing) if frame.checksum_ok}
        reset_input(self.port)
        return ids


class _Tap:
    """The port handler, with every byte read from it parsed on the side: ``seen`` holds the id of each clean
    status packet, whoever asked for it (a reply that came after its timeout included)."""

    def __init__(self, inner: Any, framing: str) -> None:
        self._inner = inner
        self._framing = framing
        self._pending = bytearray()
        self.seen: set[int] = set()
        self.damaged = 0  # status packets whose checksum/CRC failed: two servos answering at once
        self.is_using = False  # the SDK's lock lives on the object it talks to

    def __getattr__(self, name: str) -> Any:
        return getattr(self._inner, name)

    def readPort(self, length: int):  # noqa: N802 (SDK name)
        data = self._inner.readPort(length)
        if data:
            self._pending += bytes(data)
            for _raw, frame in take_packets(self._pending, self._framing, status=True):
                if frame is None:
                    continue
                if frame.checksum_ok:
                    self.seen.add(frame.packet_id)
                else:
                    self.damaged += 1
        return data

    def writePort(self, packet) -> int:  # noqa: N802
        self._pending.clear()  # a new exchange: what was half-read belongs to the last one
        return self._inner.writePort(packet)


__all__ = ["ProbeBus", "ProbeResult", "ServoFound", "model_name_of", "is_pseudo_terminal"]
