"""What the Dynamixel and Feetech backends share: both SDKs have the same PortHandler /
PacketHandler / GroupSyncWrite / GroupSyncRead shape, so open, ping, torque, goal writes and
retried reads are written once here and each backend supplies only the SDK module, the packet
handler and its quirks.
"""

from __future__ import annotations

import os
import time
from collections.abc import Iterable, Iterator, Mapping
from contextlib import contextmanager
from types import ModuleType
from typing import Any

from gaitbot.bus.base import (Bus, BusError, CorruptReplies, PortError, ReadBack, ServoLate, ServoStatusError,
                              ServoTimeout)
from gaitbot.bus.log import RecordingFailed
from gaitbot.servos import dynamixel, has_sync_read, max_servo_id, wire
from gaitbot.servos.health import HealthReading, decode_health, health_block
from gaitbot.servos.models import ServoModel
from gaitbot.servos.status import describe_status_error, hardware_error_address

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
#: Blocking exchanges (ping, torque, settings, the start-up reads): after a status packet did not come
#: within the SDK's reply timeout, listen this long for it before asking again. A reply arriving now
#: was late, not lost: the servo (or the adapter) is too slow, and its answers would be taken for
#: answers to later questions, so the bus stops (ServoLate) naming it. Long enough that a servo up to
#: about 230 ms late at start-up is named before any goal is written.
LATE_REPLY_WATCH_MS = 200.0
#: The per-frame read-back (``read_back``) asks for the register block with a length that differs
#: from every earlier request of that servo still unanswered (base length + 0, 1, 2, ...), so a late
#: reply to an abandoned read is never taken as the answer to a later one: the status packet must
#: carry exactly the parameters asked for. This many lengths: at most this many reads unanswered.
READ_BACK_LENGTHS = 8
#: An abandoned read-back whose reply has not come after this long is written off as lost.
STALE_REPLY_HORIZON_S = 1.0
#: A read-back with less budget than this left in its frame is not sent (outcome "skipped").
MIN_READ_BACK_BUDGET_S = 0.5e-3
#: Before torque goes off after abandoned read-backs, the bus waits at most this long for the line to go quiet.
QUIET_WAIT_S = 0.25
#: An attempt of a blocking exchange whose status packet came during the late-reply watch.
LATE_REPLY = "late"
#: Linux pseudo-terminal slaves (Unix98 ptys) have device majors 136..143.
_PTY_MAJORS = range(136, 144)


def is_pseudo_terminal(port_name: str) -> bool:
    """True for a pty slave such as /dev/pts/3 (the servo emulator's end): baud rates mean nothing there."""
    try:
        return os.major(os.stat(port_name).st_rdev) in _PTY_MAJORS
    except (OSError, ValueError):
        return False


class SdkBus(Bus):
    """A servo chain driven through a vendor SDK's packet handler.

    ``port_handler`` replaces the SDK's ``PortHandler(port_name)`` (the mock and the recorder plug in
    here), so dry runs send exactly the bytes a real run sends. One GroupSyncWrite and one GroupSyncRead
    per bus, made at open() and re-addressed only when the ids change: the 60 Hz path builds no objects.

    Fault policy (docs/bus-faults.md has the whole of it): reads are retried ``retries`` more times
    (one lost status packet must not end a walk) and, after a silent attempt, the bus listens
    ``LATE_REPLY_WATCH_MS`` for a late reply; all attempts failing raises ``ServoTimeout`` or
    ``CorruptReplies`` naming the servo. A late reply raises ``ServoLate`` and error bits raise
    ``ServoStatusError`` at once; a dead port raises ``PortError`` at once and writes time out after
    ``WRITE_TIMEOUT_S``. Torque and register writes wait for each status packet and are retried like
    reads; goal writes are never retried (no status packet, and the next frame supersedes them).
    """

    family = ""  # "dynamixel" or "feetech", set by subclasses
    sdk: ModuleType  # the vendor SDK module, set by subclasses

    def __init__(self, port_name: str, baudrate: int, protocol: float, models: Mapping[int, ServoModel],
                 port_handler: Any = None, retries: int = 3) -> None:
        if not models:
            raise ValueError(f"{type(self).__name__} on {port_name}: no servos given")
        if retries < 0:
            raise ValueError(f"retries must be >= 0, got {retries}")
        self.port_name = port_name
        self.baudrate = int(baudrate)
        self.protocol = float(protocol)
        self.models = dict(models)
        self.retries = int(retries)
        self.last_status_errors: dict[int, int] = {}  # servo id -> error byte of its last status packet
        self.model_numbers: dict[int, int] = {}  # servo id -> the model number its last ping reported
        self._check_models()
        first = next(iter(self.models.values()))
        self._goal = (first.addr_goal_position, first.len_goal_position)
        self._present = (first.addr_present_position, first.len_present_position)
        self._torque_addr = first.addr_torque_enable
        self.port = port_handler if port_handler is not None else self.sdk.PortHandler(port_name)
        self._ph: Any = None
        self._goal_group: Any = None  # one GroupSyncWrite per bus, its data changed frame by frame
        self._read_group: Any = None  # one GroupSyncRead per bus, re-addressed only when the ids change
        self._is_open = False
        self._timed_out_ids: set[int] = set()  # servos whose last attempt timed out (late-reply evidence)
        #: The per-frame read-back's register block per servo (address, length): the present position unless
        #: ``set_read_back_blocks`` gave a wider block holding it (the health block), decoded from inside it.
        self.read_back_blocks: dict[int, tuple[int, int]] = {}
        self._abandoned: dict[int, list[tuple[int, float]]] = {}  # servo -> [(length asked, sent at)] unanswered
        self._late_seen: dict[int, float] = {}  # servo -> lateness of its latest reply to an abandoned read
        self._damaged_seen: dict[int, int] = {}  # servo -> damaged status packets seen since its last read-back
        self.collected_bytes = 0  # bytes the last look at stale input found
        self.open_notes: list[str] = []  # how the port was opened, when that differs from the config

    # --- hooks for subclasses -------------------------------------------------------------
    def _make_packet_handler(self) -> Any:
        raise NotImplementedError

    def _uses_sync_read(self) -> bool:
        first = next(iter(self.models.values()))
        return has_sync_read(self.family, self.protocol, first.byte_order)

    def _before_transaction(self) -> None:
        """Called before every exchange (Feetech re-asserts its process-wide byte order)."""

    # --- validation -----------------------------------------------------------------------
    def _check_models(self) -> None:
        where = f"{type(self).__name__} on {self.port_name}"
        max_id = max_servo_id(self.family, self.protocol)
        for servo_id, model in self.models.items():
            if not 0 <= servo_id <= max_id:
                raise ValueError(f"{where}: servo id {servo_id} outside 0..{max_id}")
            if model.family != self.family:
                raise ValueError(f"{where}: servo {servo_id} is a {model.family} {model.name}, not {self.family}")
            if self.protocol not in model.protocols:
                raise ValueError(f"{where}: servo {servo_id} ({model.name}) does not speak protocol "
                                 f"{self.protocol}; it speaks {', '.join(map(str, model.protocols))}")
        layouts = {(m.addr_goal_position, m.len_goal_position, m.addr_present_position, m.len_present_position,
                    m.addr_torque_enable) for m in self.models.values()}
        if len(layouts) > 1:
            names = sorted({m.name for m in self.models.values()})
            raise ValueError(f"{where}: models {', '.join(names)} keep goal/present position at different "
                             "addresses, so one sync write cannot address them all; use one bus per layout")

    # --- Bus API --------------------------------------------------------------------------
    def open(self) -> None:
        self._ph = self._make_packet_handler()
        self._goal_group = self.sdk.GroupSyncWrite(self.port, self._ph, *self._goal)
        self._read_group = self.sdk.GroupSyncRead(self.port, self._ph, *self._present) \
            if self._uses_sync_read() else None
        try:
            opened = self.port.openPort() and self._set_baud_rate()
        except PORT_EXCEPTIONS as exc:  # serial.SerialException is an OSError
            raise PortError(f"cannot open serial port {self.port_name}: {exc}; {LIST_PORTS_HINT}") from exc
        if not opened:
            raise PortError(f"cannot open serial port {self.port_name} at {self.baudrate} baud (the SDK "
                            f"refused the port or the baud rate); {LIST_PORTS_HINT}")
        self._is_open = True
        self._bound_write_time()

    def _set_baud_rate(self) -> bool:
        """The SDK's setBaudRate; on a pseudo-terminal, where the rate means nothing, a rate the SDK or
        the kernel refuses is not an error: the port stays at a standard rate and the SDK's timeouts
        are still computed from the configured one."""
        try:
            if self.port.setBaudRate(self.baudrate):
                return True
            refusal: BaseException | None = None
        except PORT_EXCEPTIONS as exc:
            refusal = exc
        if not is_pseudo_terminal(self.port_name):
            if refusal is not None:
                raise refusal
            return False
        if not getattr(self.port, "is_open", False) and not self.port.setBaudRate(1_000_000):
            return False
        if hasattr(self.port, "tx_time_per_byte"):
            self.port.tx_time_per_byte = (1000.0 / self.baudrate) * 10.0  # ms per byte, as the SDK computes it
        self.port.baudrate = self.baudrate
        self.open_notes.append(f"{self.port_name} is a pseudo-terminal: {self.baudrate} baud not set on it "
                               "(rates mean nothing on a pty); timeouts still follow that rate")
        return True

    def _bound_write_time(self) -> None:
        serial_port = getattr(self.port, "ser", None)
        if serial_port is not None and getattr(serial_port, "write_timeout", 0) is None:
            try:
                serial_port.write_timeout = WRITE_TIMEOUT_S
            except PORT_EXCEPTIONS:
                pass

    def close(self) -> None:
        if self._is_open:
            self._is_open = False
            try:
                self.port.closePort()
            except PORT_EXCEPTIONS:
                pass  # the port is already gone; closing it has nothing left to do

    @contextmanager
    def _port_guard(self, servo_id: int | None = None) -> Iterator[None]:
        """Turn an OS-level failure of the port inside the SDK into PortError (never retried)."""
        try:
            yield
        except RecordingFailed:  # the recorder under the port failed, not the port: the bus goes on
            self._release_port()
            raise
        except PORT_EXCEPTIONS as exc:
            self._release_port()
            raise PortError(f"serial port {self.port_name} failed: {exc} (the adapter was unplugged or the "
                            "port closed)", servo_id=servo_id) from exc

    def _release_port(self) -> None:
        try:
            self.port.is_using = False  # the SDK's lock, left taken by the exchange that failed
        except AttributeError:
            pass

    def ping(self, servo_id: int) -> bool:
        """True if the servo answers (retried). For a configured servo, a silent attempt is followed by the
        late-reply watch: a reply that comes then is consumed (never taken as the answer to the next
        attempt), and a servo whose every attempt was answered only late raises ServoLate, named."""
        self._require_open()
        late = 0
        for _ in range(1 + self.retries):
            self._before_transaction()
            with self._port_guard(servo_id):
                self._drop_stale_input()
                model_number, result, error = self._ph.ping(self.port, servo_id)
            self._raise_on_port_failure(result, servo_id)
            if result == self.sdk.COMM_SUCCESS:
                self._timed_out_ids.discard(servo_id)
                self.last_status_errors[servo_id] = error
                self.model_numbers[servo_id] = model_number  # the SDKs read it with the ping (2.0: in the status)
                return True
            if result == self.sdk.COMM_RX_TIMEOUT and servo_id in self.models:
                late += self._watch_for_late_reply(servo_id)
        if late:
            raise self._late(servo_id, f"to {late} of {1 + self.retries} pings")
        return False

    def set_torque(self, ids: Iterable[int], enabled: bool) -> None:
        """Write Torque Enable to each servo and wait for its status packet.

        Disabling goes through every servo before raising, so one silent servo does not leave the
        others powered; a servo that confirms the write with error bits set has taken it, so those
        bits are recorded in ``last_status_errors`` and not raised when disabling.
        """
        self._require_open()
        if not enabled and self._abandoned_any():
            self._wait_for_quiet()  # late replies still on their way would be taken for the servos' answers
        failures: list[BusError] = []
        for servo_id in ids:
            self._model(servo_id)
            try:
                self._write_confirmed(servo_id, self._torque_addr, bytes([1 if enabled else 0]), raise_status=enabled,
                                      quick=not enabled)
            except BusError as exc:
                if enabled:
                    raise
                failures.append(exc)
        if failures:
            raise failures[0]

    def write_register(self, ids: Iterable[int], address: int, length: int, value: int) -> None:
        """Write ``value`` (unsigned, ``length`` bytes in each servo's byte order) to ``address`` of each
        servo in turn, retried like a torque write (rewriting a setting is harmless); a servo that answers
        with error bits set raises ServoStatusError. Goal position and torque enable are refused: they go
        through write_goal_ticks (checked by the LimitGuard) and set_torque."""
        self._require_open()
        if length not in (1, 2, 4) or not 0 <= int(value) < 1 << (8 * length):
            raise ValueError(f"register write of {value} at address {address}: needs 1, 2 or 4 bytes and an "
                             f"unsigned value that fits (got {length} bytes)")
        for servo_id in ids:
            model = self._model(servo_id)
            touched = model.command_register_touched(address, length)
            if touched is not None:
                raise ValueError(f"register write at address {address} ({length} bytes) would touch servo "
                                 f"{servo_id}'s register at {touched[0]}; use {touched[1]}")
            self._write_confirmed(servo_id, address, int(value).to_bytes(length, model.byte_order))

    def write_goal_ticks(self, goals: Mapping[int, int]) -> None:
        """Refuses a goal outside the servo model's tick range (the bytes could not say it), then sends."""
        self._require_open()
        for servo_id, tick in goals.items():
            model = self._model(servo_id)
            if not model.min_tick <= int(tick) <= model.max_tick:
                raise ValueError(f"goal {int(tick)} ticks for servo {servo_id} ({model.name}) outside "
                                 f"{model.min_tick}..{model.max_tick}")
        self.send_goal_ticks(goals)

    def send_goal_ticks(self, goals: Mapping[int, int]) -> None:
        """One goal sync write, its goals already checked (by the LimitGuard, whose limits lie inside the
        servos' tick ranges): the 60 Hz path, on the bus's one GroupSyncWrite."""
        self._require_open()
        if not goals:
            return
        models = self.models
        length = self._goal[1]
        group = self._goal_group
        try:
            params = [(servo_id, list(int(tick).to_bytes(length, models[servo_id].byte_order)))
                      for servo_id, tick in goals.items()]
        except KeyError as exc:
            raise self._unknown_id(exc.args[0]) from None
        if list(group.data_dict) == [servo_id for servo_id, _ in params]:
            for servo_id, data in params:
                group.changeParam(servo_id, data)
        else:
            group.clearParam()
            for servo_id, data in params:
                group.addParam(servo_id, data)
        self._before_transaction()
        with self._port_guard():
            if self._abandoned_any():
                self._collect_stale_input()  # before the SDK's clearPort drops a late reply unseen
            result = group.txPacket()
        self._raise_on_port_failure(result, None)
        if result != self.sdk.COMM_SUCCESS:
            raise BusError(f"goal sync write on {self.port_name} failed: {self._ph.getTxRxResult(result)}",
                           result_code=result)

    def read_present_ticks(self, ids: Iterable[int]) -> dict[int, int]:
        self._require_open()
        wanted = list(ids)
        for servo_id in wanted:
            self._model(servo_id)
        if not wanted:
            return {}
        if self._uses_sync_read():
            ticks = self._sync_read(wanted)
        else:
            ticks = {servo_id: self._read_one(servo_id) for servo_id in wanted}
        return {servo_id: ticks[servo_id] for servo_id in wanted}

    def read_health(self, servo_id: int) -> HealthReading:
        """The servo's health block (gaitbot.servos.health: position, voltage, temperature, load) in one READ,
        retried like a present-position read; error bits in its status raise ServoStatusError."""
        self._require_open()
        block = health_block(self._model(servo_id))
        return decode_health(block, servo_id, self._read_block(servo_id, block.address, block.length))

    def set_read_back_blocks(self, blocks: dict[int, tuple[int, int]]) -> None:
        for servo_id, (address, length) in blocks.items():
            start, size = self._present
            if not (address <= start and start + size <= address + length):
                raise ValueError(f"servo {servo_id}: a read-back block {address}..{address + length} must hold the "
                                 f"present position ({start}..{start + size})")
        self.read_back_blocks = dict(blocks)

    def read_back(self, servo_id: int, budget_s: float) -> ReadBack:
        """One READ of the servo's read-back block (``set_read_back_blocks``) that waits at most ``budget_s`` and is never
        retried: the per-frame read of a walk session (docs/bus-faults.md, "The read-back").

        Input left over from earlier exchanges is read and dropped first (a late reply among it is
        matched to the abandoned read it answers, by id and length, and its lateness noted). The request
        goes out through the SDK; the status packet is awaited on the port's packet timeout capped to the
        budget, and accepted only if it has this servo's id, is a status packet and carries exactly the
        parameters asked for. Error bits raise ServoStatusError (the Hardware Error Status is read in
        what is left of the budget); a dead port raises PortError.
        """
        self._require_open()
        self._model(servo_id)
        late_s = self._late_seen.pop(servo_id, None)
        if not budget_s >= MIN_READ_BACK_BUDGET_S:
            return ReadBack(servo_id, "skipped", late_s=late_s)
        start_s = time.monotonic()
        address, base_length = self.read_back_blocks.get(servo_id, self._present)
        abandoned = self._abandoned.setdefault(servo_id, [])
        abandoned[:] = [(n, t) for n, t in abandoned if start_s - t < STALE_REPLY_HORIZON_S]
        used = {n for n, _ in abandoned}
        free = [base_length + extra for extra in range(READ_BACK_LENGTHS) if base_length + extra not in used]
        if not free:  # every length still owed a reply: asking again could not be told apart
            return ReadBack(servo_id, "missed", late_s=late_s)
        length = free[0]
        outcome, frame = self._budgeted_read(servo_id, address, length, budget_s, start_s)
        late_s = self._late_seen.pop(servo_id, late_s)
        if frame is None:
            if outcome != "damaged":
                abandoned.append((length, start_s))
            if outcome == "missed" and self._damaged_seen.pop(servo_id, 0):
                outcome = "damaged"  # its reply to an earlier read came, damaged: the same fault, seen late
            return ReadBack(servo_id, outcome, late_s=late_s)
        data = bytes(frame.params)
        error = frame.error or 0
        self.last_status_errors[servo_id] = error
        self._timed_out_ids.discard(servo_id)
        if error:
            remaining_s = budget_s - (time.monotonic() - start_s)
            raise self._status_error(servo_id, error, budget_s=remaining_s)
        offset = self._present[0] - address
        ticks = self._decode(data[offset:offset + self._present[1]], self._model(servo_id))
        return ReadBack(servo_id, "answered", ticks, data, error, late_s)

    def read_device(self, device_id: int, address: int, length: int, budget_s: float) -> bytes | None:
        """One budgeted READ of a non-servo device (Bus.read_device): the read-back's exchange, without its
        bookkeeping of late replies (a reply that comes after its budget is dropped as stale input)."""
        self._require_open()
        if not budget_s >= MIN_READ_BACK_BUDGET_S:
            return None
        outcome, frame = self._budgeted_read(device_id, address, length, budget_s, time.monotonic())
        if frame is None or frame.error or len(frame.params) != length:
            return None
        return bytes(frame.params)

    def _budgeted_read(self, servo_id: int, address: int, length: int, budget_s: float,
                       start_s: float) -> tuple[str, wire.Frame | None]:
        """Send READ(address, length) to ``servo_id`` through the SDK and wait for its status packet until
        ``start_s + budget_s``: ("answered", frame), ("damaged", None) or ("missed", None)."""
        self._before_transaction()
        with self._port_guard(servo_id):
            self._drop_stale_input()
            result = self._ph.readTx(self.port, servo_id, address, length)
            if result != self.sdk.COMM_SUCCESS:
                self.port.is_using = False
                self._raise_on_port_failure(result, servo_id)
                return "missed", None
            remaining_ms = max(0.0, budget_s - (time.monotonic() - start_s)) * 1000.0
            try:
                return self._await_status(servo_id, length, remaining_ms)
            finally:
                self.port.is_using = False  # readTx took the SDK's lock; no rxPacket of the SDK releases it

    def _await_status(self, servo_id: int, length: int, timeout_ms: float) -> tuple[str, wire.Frame | None]:
        framing = wire.framing_for(self.family, self.protocol)
        self.port.setPacketTimeoutMillis(timeout_ms)  # the port's clock: virtual on the mock, real on a port
        buffer = bytearray()
        damaged = False
        while True:
            available = self.port.getBytesAvailable()
            if available:
                buffer += bytes(self.port.readPort(available))
                for raw, is_packet in wire.split_complete(buffer, framing):
                    if not is_packet:
                        continue
                    frame = wire.parse(raw, framing, status=True)
                    if self._answers(frame, servo_id, length, framing):
                        return "answered", frame
                    if frame.packet_id == servo_id and not frame.checksum_ok:
                        damaged = True
                    elif not self._note_stale_status(frame) and not frame.checksum_ok \
                            and self._abandoned.get(frame.packet_id):
                        self._damaged_seen[frame.packet_id] = self._damaged_seen.get(frame.packet_id, 0) + 1
            elif self.port.isPacketTimeout():
                return ("damaged" if damaged else "missed"), None
            else:
                time.sleep(0.0002)

    def _wait_for_quiet(self, quiet_s: float = 0.03, at_most_s: float = QUIET_WAIT_S) -> None:
        """Read (and note) whatever still arrives until the line has been quiet for ``quiet_s``, at most
        ``at_most_s``: after read-backs were abandoned, their late replies are still coming."""
        start = last = time.monotonic()
        while True:
            with self._port_guard():
                self._collect_stale_input()
            now = time.monotonic()
            if self.collected_bytes:
                last = now
            if now - last >= quiet_s or now - start >= at_most_s:
                return
            time.sleep(0.001)

    def _abandoned_any(self) -> bool:
        return any(self._abandoned.values())

    @staticmethod
    def _answers(frame: wire.Frame, servo_id: int, length: int, framing: str) -> bool:
        return (frame.checksum_ok and frame.packet_id == servo_id and len(frame.params) == length
                and (framing == "v1" or frame.instruction == wire.INST_STATUS_V2))

    def _note_stale_status(self, frame: wire.Frame) -> bool:
        """A status packet that answers an abandoned read-back (same id, same length): note how late it
        came and forget that request. True if it did."""
        if not frame.checksum_ok:
            return False
        abandoned = self._abandoned.get(frame.packet_id)
        if not abandoned:
            return False
        for k, (length, sent_s) in enumerate(abandoned):
            if length == len(frame.params):
                del abandoned[k]
                self._late_seen[frame.packet_id] = time.monotonic() - sent_s
                return True
        return False

    # --- internals ------------------------------------------------------------------------
    def _sync_read(self, wanted: list[int]) -> dict[int, int]:
        """GroupSyncRead's exchange, but keeping each status packet's error byte (GroupSyncRead drops it)."""
        address, length = self._present
        got: dict[int, int] = {}
        pending = list(wanted)
        failed_id, result = pending[0], self.sdk.COMM_SUCCESS
        outcomes: dict[int, list[int]] = {}
        group = self._read_group
        for _ in range(1 + self.retries):
            self._before_transaction()
            if list(group.data_dict) != pending:
                group.clearParam()
                for servo_id in pending:
                    group.addParam(servo_id)
            with self._port_guard():
                self._drop_stale_input()
                result = group.txPacket()
            self._raise_on_port_failure(result, None)
            if result != self.sdk.COMM_SUCCESS:
                raise BusError(f"sync read on {self.port_name} failed: {self._ph.getTxRxResult(result)}",
                               result_code=result)
            for servo_id in pending:
                with self._port_guard(servo_id):
                    data, result, error = self._ph.readRx(self.port, servo_id, length)
                if result != self.sdk.COMM_SUCCESS or len(data) < length:
                    failed_id = servo_id
                    break  # the SDK's timeout covered the whole sync read; ask the rest again
                self._answered(servo_id, error)
                got[servo_id] = self._decode(bytes(data[:length]), self._model(servo_id))
            pending = [i for i in pending if i not in got]
            if not pending:
                return got
            self._failed_attempt(failed_id, result, outcomes)
        raise self._no_answer(failed_id, outcomes[failed_id], "sync reads")

    def _read_one(self, servo_id: int) -> int:
        return self._decode(self._read_block(servo_id, *self._present), self._model(servo_id))

    def _read_block(self, servo_id: int, address: int, length: int) -> bytes:
        """One READ of ``length`` bytes at ``address``, retried (the fault policy of every read)."""
        outcomes: dict[int, list[int]] = {}
        for _ in range(1 + self.retries):
            self._before_transaction()
            with self._port_guard(servo_id):
                self._drop_stale_input()
                data, result, error = self._ph.readTxRx(self.port, servo_id, address, length)
            self._raise_on_port_failure(result, servo_id)
            if result == self.sdk.COMM_SUCCESS and len(data) >= length:
                self._answered(servo_id, error)
                return bytes(data[:length])
            self._failed_attempt(servo_id, result, outcomes)
        raise self._no_answer(servo_id, outcomes[servo_id], "reads")

    def _answered(self, servo_id: int, error: int) -> None:
        """A good status packet: remember its error byte and raise ServoStatusError if bits are set."""
        self._timed_out_ids.discard(servo_id)
        self.last_status_errors[servo_id] = error
        if error:
            raise self._status_error(servo_id, error)

    def _status_error(self, servo_id: int, error: int, budget_s: float | None = None) -> ServoStatusError:
        """ServoStatusError naming the fault; on Dynamixel 2.0 the Hardware Error Status is read once to say
        what the Alert bit means: blocking, or within ``budget_s`` (the read-back's frame) when given."""
        model = self._model(servo_id)
        hardware = None
        address = hardware_error_address(model.name)
        if self.family == "dynamixel" and self.protocol == 2.0 and error & dynamixel.V2_ALERT and address is not None:
            try:  # one attempt: the message is better with it, the stop does not depend on it
                if budget_s is None:
                    with self._port_guard(servo_id):
                        self._drop_stale_input()
                        value, result, _ = self._ph.read1ByteTxRx(self.port, servo_id, address)
                    hardware = value if result == self.sdk.COMM_SUCCESS else None
                elif budget_s >= MIN_READ_BACK_BUDGET_S:
                    outcome, frame = self._budgeted_read(servo_id, address, 1, budget_s, time.monotonic())
                    hardware = frame.params[0] if frame is not None else None
            except BusError:
                hardware = None
        fault = describe_status_error(self.family, self.protocol, error, hardware, model.name)
        detail = f"status error 0x{error:02X}" + (f", hardware error status 0x{hardware:02X}" if hardware else "")
        exc = ServoStatusError(f"servo {servo_id} on {self.port_name} reports {fault} ({detail})",
                               servo_id=servo_id, status_error=error, fault=fault)
        exc.detail_pending = hardware is None and address is not None and bool(error & dynamixel.V2_ALERT) \
            and self.family == "dynamixel" and self.protocol == 2.0  # read it once the robot is safe
        return exc

    def explain_status_error(self, exc: BusError) -> BusError:
        """The same fault with the Hardware Error Status read (blocking, one attempt) if the read-back had no
        time left for it in its frame: called by the session after the stop ramp, so the message says
        which hardware error the Alert bit meant."""
        if not (isinstance(exc, ServoStatusError) and getattr(exc, "detail_pending", False) and self._is_open):
            return exc
        try:
            return self._status_error(exc.servo_id, exc.status_error)
        except BusError:
            return exc

    def _failed_attempt(self, servo_id: int, result: int, outcomes: dict[int, list]) -> None:
        """Note one failed attempt; after a silent one, listen for the servo's late status packet (a late
        reply is consumed there, so the next attempt's answer cannot be confused with it)."""
        self._raise_on_port_failure(result, servo_id)
        if result == self.sdk.COMM_RX_TIMEOUT and self._watch_for_late_reply(servo_id):
            result = LATE_REPLY
        outcomes.setdefault(servo_id, []).append(result)

    def _no_answer(self, servo_id: int, results: list, what: str) -> ServoTimeout:
        attempts = len(results)
        result = results[-1]
        if LATE_REPLY in results:
            late = sum(r == LATE_REPLY for r in results)
            return self._late(servo_id, f"in {late} of {attempts} {what}")
        if all(r == self.sdk.COMM_RX_CORRUPT for r in results):
            return CorruptReplies(
                f"servo {servo_id} on {self.port_name} sent a damaged status packet (bad checksum/CRC) in all "
                f"{attempts} {what}; check its cable, connectors and the bus wiring",
                result_code=result, servo_id=servo_id)
        corrupt = sum(r == self.sdk.COMM_RX_CORRUPT for r in results)
        how = f" ({corrupt} of the replies damaged)" if corrupt else ""
        return ServoTimeout(
            f"servo {servo_id} on {self.port_name} did not return its present position after {attempts} {what}"
            f"{how}: no status packet within the reply timeout; check its power, cable, id and baud rate",
            result_code=result, servo_id=servo_id)

    def _watch_for_late_reply(self, servo_id: int) -> bool:
        """After a silent attempt: listen up to LATE_REPLY_WATCH_MS for a status packet of ``servo_id``.
        True if one came (it is consumed: the attempt was answered late); False if none (the servo stays
        suspect, and a still later reply of it seen before any later exchange raises ServoLate).

        Uses the port's own timeout (MockPort's is virtual), so a dry run costs no wall-clock time.
        """
        self._timed_out_ids.add(servo_id)
        if not callable(getattr(self.port, "setPacketTimeoutMillis", None)):
            return False
        buffer = bytearray()
        with self._port_guard(servo_id):
            self.port.setPacketTimeoutMillis(LATE_REPLY_WATCH_MS)
            while True:
                available = self.port.getBytesAvailable()
                if available:
                    buffer += bytes(self.port.readPort(available))
                    if self._status_packet_from(buffer, servo_id):
                        self._timed_out_ids.discard(servo_id)
                        return True
                elif self.port.isPacketTimeout():
                    return False
                else:
                    time.sleep(0.0002)

    def _late(self, servo_id: int, how: str = "") -> ServoLate:
        return ServoLate(f"servo {servo_id} on {self.port_name} answered late{' ' + how if how else ''}: its "
                         "status packet arrived after the reply timeout (about 34 ms at 1 Mbaud); check its Return "
                         "Delay Time and the adapter's latency timer", servo_id=servo_id)

    def _status_packet_from(self, data: bytes | bytearray, servo_id: int) -> bool:
        framing = wire.framing_for(self.family, self.protocol)
        for raw, is_packet in wire.split_complete(bytearray(data), framing):
            if not is_packet:
                continue
            frame = wire.parse(raw, framing, status=True)
            if frame.checksum_ok and frame.packet_id == servo_id and \
                    (framing == "v1" or frame.instruction == wire.INST_STATUS_V2):
                return True
        return False

    def _write_confirmed(self, servo_id: int, address: int, data: bytes, raise_status: bool = True,
                         quick: bool = False) -> None:
        """One WRITE instruction of ``data`` at ``address``, retried until the servo's status packet comes.

        ``quick`` (torque off at the end of a session): one retry and no late-reply watch, so a servo that
        fell silent costs two reply timeouts, not a second, and the others are reached at once."""
        result, error, late = self.sdk.COMM_SUCCESS, 0, 0
        attempts = min(2, 1 + self.retries) if quick else 1 + self.retries
        for _ in range(attempts):  # rewriting the same bytes is harmless, so retry
            self._before_transaction()
            with self._port_guard(servo_id):
                self._drop_stale_input()
                result, error = self._ph.writeTxRx(self.port, servo_id, address, len(data), list(data))
            self._raise_on_port_failure(result, servo_id)
            if result == self.sdk.COMM_SUCCESS:
                break
            if result == self.sdk.COMM_RX_TIMEOUT and not quick and self._watch_for_late_reply(servo_id):
                late += 1
        else:
            if late:
                raise self._late(servo_id, f"to {late} of {attempts} writes to address {address}")
            shown = data[0] if len(data) == 1 else f"0x{data.hex()}"
            raise ServoTimeout(f"servo {servo_id} on {self.port_name} did not confirm writing {shown} to "
                               f"address {address} ({self._ph.getTxRxResult(result)})",
                               result_code=result, servo_id=servo_id)
        self.last_status_errors[servo_id] = error
        if error and raise_status:
            raise self._status_error(servo_id, error)

    def _collect_stale_input(self) -> bytes:
        """Read whatever input is pending (a recording port logs it) and note the status packets among it
        that answer abandoned read-backs (late, by id and length) or are damaged; return the rest.

        Called before each goal write too: the SDK's txPacket clears the input buffer (Dynamixel's
        clearPort), and a late reply dropped unseen could not be told from a lost one."""
        self.collected_bytes = 0
        available = getattr(self.port, "getBytesAvailable", None)
        if not callable(available):
            return b""
        pending = available()
        if not pending:
            return b""
        stale = bytes(self.port.readPort(pending))
        self.collected_bytes = len(stale)
        framing = wire.framing_for(self.family, self.protocol)
        unmatched = bytearray()
        for raw, is_packet in wire.split_complete(bytearray(stale), framing):
            if is_packet:
                frame = wire.parse(raw, framing, status=True)
                if self._note_stale_status(frame):
                    continue  # a late reply to an abandoned read-back: noted, not an answer to anything
                if not frame.checksum_ok and self._abandoned.get(frame.packet_id):
                    self._damaged_seen[frame.packet_id] = self._damaged_seen.get(frame.packet_id, 0) + 1
            unmatched += raw
        return bytes(unmatched)

    def _drop_stale_input(self) -> None:
        """Discard bytes left over from an earlier, timed-out exchange before asking anew.

        Feetech's PortHandler.clearPort only flushes output, so a late status packet would be read
        as the answer to the next question; we drop input ourselves for both backends. The stale
        bytes are read first (a recording port logs them, so the recording stays complete), and a
        status packet among them from a servo that timed out is a late reply: ServoLate.
        """
        unmatched = self._collect_stale_input()
        for servo_id in sorted(self._timed_out_ids):
            if self._status_packet_from(unmatched, servo_id):
                raise self._late(servo_id)
        reset = getattr(self.port, "reset_input_buffer", None)
        if callable(reset):
            reset()
            return
        serial_port = getattr(self.port, "ser", None)
        if serial_port is not None:
            serial_port.reset_input_buffer()

    def _raise_on_port_failure(self, result: int, servo_id: int | None) -> None:
        if result in (self.sdk.COMM_TX_FAIL, self.sdk.COMM_PORT_BUSY, self.sdk.COMM_TX_ERROR):
            raise PortError(f"serial port {self.port_name} failed to send: {self._ph.getTxRxResult(result)}",
                            result_code=result, servo_id=servo_id)

    def _decode(self, data: bytes, model: ServoModel) -> int:
        """Present position: 4-byte registers are two's complement (X series), 2-byte ones unsigned."""
        return int.from_bytes(data, model.byte_order, signed=len(data) == 4)

    def _model(self, servo_id: int) -> ServoModel:
        try:
            return self.models[servo_id]
        except KeyError:
            raise self._unknown_id(servo_id) from None

    def _unknown_id(self, servo_id: int) -> ValueError:
        return ValueError(f"servo id {servo_id} is not on bus {self.port_name} (ids: {sorted(self.models)})")

    def _require_open(self) -> None:
        if not self._is_open:
            raise PortError(f"bus on {self.port_name} is not open; call open() or use it as a context manager")
