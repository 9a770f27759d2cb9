"""The transport both vendor backends share: both SDKs have the same PortHandler / PacketHandler /
GroupSyncWrite / GroupSyncRead shape, so open, ping, torque, goal writes and retried reads are written
once here; each vendor's subclass (gaitbot.bus.dynamixel, gaitbot.bus.feetech) supplies the SDK module,
its packet handler and its quirks as overrides, and the vendor facts come from gaitbot.servos.

The per-frame read-back is :class:`~gaitbot.bus.read_back.BudgetedReadBack`, the bookkeeping of late
replies :class:`~gaitbot.bus.late_replies.LateReplies`, what a failed exchange says
:class:`~gaitbot.bus.bus_faults.FaultReports`; the port itself is gaitbot.bus.port.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Iterable, Mapping
from types import ModuleType
from typing import Any

from gaitbot.bus.base import Bus, BusError, PortError, WrongServoModel
from gaitbot.bus.bus_faults import LATE_REPLY, FaultReports
from gaitbot.bus.late_replies import LateReplies
from gaitbot.bus.packets import is_status_of, status_frames
from gaitbot.bus.port import close_quietly, open_at, port_errors, read_pending, reset_input
from gaitbot.bus.read_back import BudgetedReadBack
from gaitbot.bus.recording.writer import RecordingFailed
from gaitbot.servos import has_sync_read, max_servo_id, vendor, wire
from gaitbot.servos.health import HealthReading, decode_health, health_block
from gaitbot.servos.models import ServoModel

#: Blocking exchanges (ping, torque, settings, the start-up reads): after a status packet did not come
#: within the SDK's reply timeout, listen this long for it before asking again. A reply arriving now
#: was late, not lost: the servo (or the adapter) is too slow, and its answers would be taken for
#: answers to later questions, so the bus stops (ServoLate) naming it. Long enough that a servo up to
#: about 230 ms late at start-up is named before any goal is written.
LATE_REPLY_WATCH_MS = 200.0


class SdkBus(BudgetedReadBack, FaultReports, Bus):
    """A servo chain driven through a vendor SDK's packet handler.

    ``port_handler`` is the port the SDK talks to (the SDK's own PortHandler, the dry-run port, the
    simulated robot's, or a recording port around any of them: gaitbot.bus.factory chooses), so dry runs
    send exactly the bytes a real run sends. One GroupSyncWrite and one GroupSyncRead per bus, made at
    open() and re-addressed only when the ids change: the 60 Hz path builds no objects. ``clock``
    (seconds) measures the read-back's budget: the session's clock, injected by the factory.

    Fault policy (docs/bus-faults.md has the whole of it): reads are retried ``retries`` more times
    (one lost status packet must not end a walk) and, after a silent attempt, the bus listens
    ``LATE_REPLY_WATCH_MS`` for a late reply; all attempts failing raises ``ServoTimeout`` or
    ``CorruptReplies`` naming the servo. A late reply raises ``ServoLate`` and error bits raise
    ``ServoStatusError`` at once; a dead port raises ``PortError`` at once and writes time out after
    ``WRITE_TIMEOUT_S``. Torque and register writes wait for each status packet and are retried like
    reads; goal writes are never retried (no status packet, and the next frame supersedes them).
    """

    family = ""  # the backend name (gaitbot.servos.BACKENDS), set by subclasses
    sdk: ModuleType  # the vendor SDK module, set by subclasses

    def __init__(self, port_name: str, baudrate: int, protocol: float, models: Mapping[int, ServoModel],
                 port_handler: Any = None, retries: int = 3, clock: Callable[[], float] = time.monotonic) -> None:
        if not models:
            raise ValueError(f"{type(self).__name__} on {port_name}: no servos given")
        if retries < 0:
            raise ValueError(f"retries must be >= 0, got {retries}")
        self.port_name = port_name
        self.baudrate = int(baudrate)
        self.protocol = float(protocol)
        self.framing = wire.framing_for(self.family, self.protocol)
        self.vendor = vendor(self.family)
        self.models = dict(models)
        self.retries = int(retries)
        self.clock = clock
        self.last_status_errors: dict[int, int] = {}  # servo id -> error byte of its last status packet
        self.model_numbers: dict[int, int] = {}  # servo id -> the model number its last ping reported
        self._check_models()
        first = next(iter(self.models.values()))
        self._goal = (first.addr_goal_position, first.len_goal_position)
        self._present = (first.addr_present_position, first.len_present_position)
        self._torque_addr = first.addr_torque_enable
        #: servo id -> (lowest, highest tick, byte order) of its goal: checked and encoded in one pass
        self._goal_encoding = {i: (m.min_tick, m.max_tick, m.byte_order) for i, m in self.models.items()}
        self.port = port_handler if port_handler is not None else self.sdk.PortHandler(port_name)
        self._ph: Any = None
        self._goal_group: Any = None  # one GroupSyncWrite per bus, its data changed frame by frame
        self._read_group: Any = None  # one GroupSyncRead per bus, re-addressed only when the ids change
        self._is_open = False
        self.late = LateReplies(clock)
        #: The per-frame read-back's register block per servo (address, length): the present position unless
        #: ``set_read_back_blocks`` gave a wider block holding it (the health block), decoded from inside it.
        self.read_back_blocks: dict[int, tuple[int, int]] = {}
        self.collected_bytes = 0  # bytes the last look at stale input found
        self.open_notes: list[str] = []  # how the port was opened, when that differs from the config

    # --- what a vendor's subclass overrides ---------------------------------------------------
    @classmethod
    def make_packet_handler(cls, protocol: float, byte_order: str = "little") -> Any:
        """The SDK's packet handler for ``protocol`` (and, where the SDK keeps one, the words' byte order)."""
        raise NotImplementedError

    def _before_transaction(self) -> None:
        """Called before every exchange (Feetech re-asserts its process-wide byte order)."""

    def _uses_sync_read(self) -> bool:
        first = next(iter(self.models.values()))
        return has_sync_read(self.family, self.protocol, first.byte_order)

    # --- validation -------------------------------------------------------------------------
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

    # --- the port -----------------------------------------------------------------------------
    def open(self) -> None:
        self._ph = self.make_packet_handler(self.protocol, next(iter(self.models.values())).byte_order)
        self._goal_group = self.sdk.GroupSyncWrite(self.port, self._ph, *self._goal)
        self._read_group = self.sdk.GroupSyncRead(self.port, self._ph, *self._present) \
            if self._uses_sync_read() else None
        open_at(self.port, self.port_name, self.baudrate, self.open_notes)
        self._is_open = True

    def close(self) -> None:
        if self._is_open:
            self._is_open = False
            close_quietly(self.port)

    def _transaction(self, servo_id: int | None = None):
        """One exchange with the SDK: the vendor's preparation, then gaitbot.bus.port.port_errors (a failing
        port becomes PortError; the SDK's lock is released however the exchange ends)."""
        self._before_transaction()
        return port_errors(self.port, self.port_name, servo_id, " (the adapter was unplugged or the port closed)",
                           pass_through=(RecordingFailed,))

    # --- Bus API --------------------------------------------------------------------------------
    def ping(self, servo_id: int) -> bool:
        """True if the servo answers (retried). For a configured servo, a silent attempt is followed by the
        late-reply watch: a reply that comes then is consumed (never taken as the answer to the next
        attempt), and a servo whose every attempt was answered only late raises ServoLate, named."""
        self._require_open()
        late = 0
        for _ in range(1 + self.retries):
            with self._transaction(servo_id):
                self._drop_stale_input()
                model_number, result, error = self._ph.ping(self.port, servo_id)
            self._raise_on_port_failure(result, servo_id)
            if result == self.sdk.COMM_SUCCESS:
                self.late.suspects.discard(servo_id)
                self.last_status_errors[servo_id] = error
                self.model_numbers[servo_id] = model_number  # the SDKs read it with the ping (2.0: in the status)
                return True
            if result == self.sdk.COMM_RX_TIMEOUT and servo_id in self.models:
                late += self._watch_for_late_reply(servo_id)
        if late:
            raise self._late(servo_id, f"to {late} of {1 + self.retries} pings")
        return False

    def scan(self, ids: Iterable[int]) -> list[int]:
        """The ids among ``ids`` that answer a ping; WrongServoModel when a configured servo that answered
        reports another model number than its configured model's (the ping read it: nothing is written)."""
        answering = super().scan(ids)
        wrong = [(i, self.model_numbers[i]) for i in answering
                 if i in self.models and self.model_numbers.get(i, self.models[i].model_number)
                 != self.models[i].model_number]
        if wrong:
            raise WrongServoModel(wrong, self.models, self.family, self.port_name)
        return answering

    def set_torque(self, ids: Iterable[int], enabled: bool) -> None:
        """Write Torque Enable to each servo and wait for its status packet.

        Disabling goes through every servo before raising, so one silent servo does not leave the
        others powered; a servo that confirms the write with error bits set has taken it, so those
        bits are recorded in ``last_status_errors`` and not raised when disabling.
        """
        self._require_open()
        if not enabled and self.late.any_abandoned():
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
        """One goal sync write on the bus's one GroupSyncWrite (the 60 Hz path). A goal outside its servo
        model's tick range (which the bytes could not say) is refused before anything is sent."""
        self._require_open()
        if not goals:
            return
        length = self._goal[1]
        encoding = self._goal_encoding
        params = []
        for servo_id, tick in goals.items():
            try:
                low, high, order = encoding[servo_id]
            except KeyError:
                raise self._unknown_id(servo_id) from None
            tick = int(tick)
            if not low <= tick <= high:
                raise ValueError(f"goal {tick} ticks for servo {servo_id} ({self.models[servo_id].name}) outside "
                                 f"{low}..{high}")
            params.append((servo_id, list(tick.to_bytes(length, order))))
        group = self._goal_group
        if list(group.data_dict) == [servo_id for servo_id, _ in params]:
            for servo_id, data in params:
                group.changeParam(servo_id, data)
        else:
            group.clearParam()
            for servo_id, data in params:
                group.addParam(servo_id, data)
        with self._transaction():
            if self.late.any_abandoned():
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

    # --- exchanges ---------------------------------------------------------------------------------
    def _sync_read(self, wanted: list[int]) -> dict[int, int]:
        """GroupSyncRead's exchange, but keeping each status packet's error byte (GroupSyncRead drops it)."""
        address, length = self._present
        got: dict[int, int] = {}
        pending = list(wanted)
        failed_id, result = pending[0], self.sdk.COMM_SUCCESS
        outcomes: dict[int, list[int]] = {}
        group = self._read_group
        for _ in range(1 + self.retries):
            if list(group.data_dict) != pending:
                group.clearParam()
                for servo_id in pending:
                    group.addParam(servo_id)
            with self._transaction():
                self._drop_stale_input()
                result = group.txPacket()
            self._raise_on_port_failure(result, None)
            if result != self.sdk.COMM_SUCCESS:
                raise BusError(f"sync read on {self.port_name} failed: {self._ph.getTxRxResult(result)}",
                               result_code=result)
            for servo_id in pending:
                with self._transaction(servo_id):
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
            with self._transaction(servo_id):
                self._drop_stale_input()
                data, result, error = self._ph.readTxRx(self.port, servo_id, address, length)
            self._raise_on_port_failure(result, servo_id)
            if result == self.sdk.COMM_SUCCESS and len(data) >= length:
                self._answered(servo_id, error)
                return bytes(data[:length])
            self._failed_attempt(servo_id, result, outcomes)
        raise self._no_answer(servo_id, outcomes[servo_id], "reads")

    def _write_confirmed(self, servo_id: int, address: int, data: bytes, raise_status: bool = True,
                         quick: bool = False) -> None:
        """One WRITE instruction of ``data`` at ``address``, retried until the servo's status packet comes.

        ``quick`` (torque off at the end of a session): one retry and no late-reply watch, so a servo that
        fell silent costs two reply timeouts, not a second, and the others are reached at once."""
        result, error, late = self.sdk.COMM_SUCCESS, 0, 0
        attempts = min(2, 1 + self.retries) if quick else 1 + self.retries
        for _ in range(attempts):  # rewriting the same bytes is harmless, so retry
            with self._transaction(servo_id):
                self._drop_stale_input()
                result, error = self._ph.writeTxRx(self.port, servo_id, address, len(data), list(data))
            self._raise_on_port_failure(result, servo_id)
            if result == self.sdk.COMM_SUCCESS:
                break
            if result == self.sdk.COMM_RX_TIMEOUT and not quick and self._watch_for_late_reply(servo_id):
                late += 1
        else:
            raise self._unconfirmed(servo_id, address, data, result, late, attempts)
        self.last_status_errors[servo_id] = error
        if error and raise_status:
            raise self._status_error(servo_id, error)

    def _answered(self, servo_id: int, error: int) -> None:
        """A good status packet: remember its error byte and raise ServoStatusError if bits are set."""
        self.late.suspects.discard(servo_id)
        self.last_status_errors[servo_id] = error
        if error:
            raise self._status_error(servo_id, error)

    def _failed_attempt(self, servo_id: int, result: int, outcomes: dict[int, list]) -> None:
        """Note one failed attempt; after a silent one, listen for the servo's late status packet (a late
        reply is consumed there, so the next attempt's answer cannot be confused with it)."""
        self._raise_on_port_failure(result, servo_id)
        if result == self.sdk.COMM_RX_TIMEOUT and self._watch_for_late_reply(servo_id):
            result = LATE_REPLY
        outcomes.setdefault(servo_id, []).append(result)

    # --- late and stale input -------------------------------------------------------------------------
    def _watch_for_late_reply(self, servo_id: int) -> bool:
        """After a silent attempt: listen up to LATE_REPLY_WATCH_MS for a status packet of ``servo_id``.
        True if one came (it is consumed: the attempt was answered late); False if none (the servo stays
        suspect, and a still later reply of it seen before any later exchange raises ServoLate).

        Uses the port's own timeout (the dry-run port's is virtual), so a dry run costs no wall-clock time.
        """
        self.late.suspects.add(servo_id)
        if not callable(getattr(self.port, "setPacketTimeoutMillis", None)):
            return False
        buffer = bytearray()
        with self._transaction(servo_id):
            self.port.setPacketTimeoutMillis(LATE_REPLY_WATCH_MS)
            while True:
                available = self.port.getBytesAvailable()
                if available:
                    buffer += bytes(self.port.readPort(available))
                    if self._status_packet_from(buffer, servo_id):
                        self.late.suspects.discard(servo_id)
                        return True
                elif self.port.isPacketTimeout():
                    return False
                else:
                    time.sleep(0.0002)

    def _status_packet_from(self, data: bytes | bytearray, servo_id: int) -> bool:
        return any(is_status_of(frame, servo_id, self.framing) for frame in status_frames(data, self.framing))

    def _collect_stale_input(self) -> bytes:
        """Read whatever input is pending (a recording port logs it) and note the status packets among it
        that answer abandoned read-backs (late, by id and length) or are damaged; return the rest.

        Called before each goal write too: the SDK's txPacket clears the input buffer (Dynamixel's
        clearPort), and a late reply dropped unseen could not be told from a lost one."""
        stale = read_pending(self.port)
        self.collected_bytes = len(stale)
        return self.late.sort(stale, self.framing) if stale else b""

    def _drop_stale_input(self) -> None:
        """Discard bytes left over from an earlier, timed-out exchange before asking anew.

        Feetech's PortHandler.clearPort only flushes output, so a late status packet would be read
        as the answer to the next question; we drop input ourselves for both backends. The stale
        bytes are read first (a recording port logs them, so the recording stays complete), and a
        status packet among them from a servo that timed out is a late reply: ServoLate.
        """
        unmatched = self._collect_stale_input()
        for servo_id in sorted(self.late.suspects):
            if self._status_packet_from(unmatched, servo_id):
                raise self._late(servo_id)
        reset_input(self.port)

    # --- small helpers ------------------------------------------------------------------------------------
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
