"""What the Dynamixel and Feetech backends share: both SDKs have the same PortHandler /
PacketHandler / GroupSyncWrite / GroupSyncRead shape, so open, ping, torque, goal writes and
retried reads are written once here and each backend supplies only the SDK module, the packet
handler and its quirks.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from types import ModuleType
from typing import Any

from gaitbot.bus.base import Bus, BusError, PortError, ServoStatusError, ServoTimeout
from gaitbot.robot.servo_models import ServoModel

LIST_PORTS_HINT = "list serial ports with: python -m serial.tools.list_ports -v"


class SdkBus(Bus):
    """A servo chain driven through a vendor SDK's packet handler.

    ``port_handler`` replaces the SDK's ``PortHandler(port_name)`` (the mock and the recorder plug in
    here), so dry runs send exactly the bytes a real run sends. Reads are retried ``retries`` more
    times after the first attempt, because one lost status packet must not end a walk. Writes are
    never retried: a goal sync write has no status packet to tell success from loss, and the next
    frame supersedes it anyway.
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
        self._check_models()
        first = next(iter(self.models.values()))
        self._goal = (first.addr_goal_position, first.len_goal_position)
        self._present = (first.addr_present_position, first.len_present_position)
        self._torque_addr = first.addr_torque_enable
        self.port = port_handler if port_handler is not None else self.sdk.PortHandler(port_name)
        self._ph: Any = None
        self._is_open = False

    # --- hooks for subclasses -------------------------------------------------------------
    def _make_packet_handler(self) -> Any:
        raise NotImplementedError

    def _uses_sync_read(self) -> bool:
        raise NotImplementedError

    def _before_transaction(self) -> None:
        """Called before every exchange (Feetech re-asserts its process-wide byte order)."""

    # --- validation -----------------------------------------------------------------------
    def _check_models(self) -> None:
        where = f"{type(self).__name__} on {self.port_name}"
        max_id = 252 if self.protocol == 2.0 else 253
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
        try:
            opened = self.port.openPort() and self.port.setBaudRate(self.baudrate)
        except OSError as exc:  # serial.SerialException is an OSError
            raise PortError(f"cannot open serial port {self.port_name}: {exc}; {LIST_PORTS_HINT}") from exc
        if not opened:
            raise PortError(f"cannot open serial port {self.port_name} at {self.baudrate} baud (the SDK "
                            f"refused the port or the baud rate); {LIST_PORTS_HINT}")
        self._is_open = True

    def close(self) -> None:
        if self._is_open:
            self._is_open = False
            self.port.closePort()

    def ping(self, servo_id: int) -> bool:
        self._require_open()
        for _ in range(1 + self.retries):
            self._before_transaction()
            self._drop_stale_input()
            _model_number, result, error = self._ph.ping(self.port, servo_id)
            self._raise_on_port_failure(result, servo_id)
            if result == self.sdk.COMM_SUCCESS:
                self.last_status_errors[servo_id] = error
                return True
        return False

    def set_torque(self, ids: Iterable[int], enabled: bool) -> None:
        """Write Torque Enable to each servo and wait for its status packet.

        Disabling goes through every servo before raising, so one silent servo does not leave the
        others powered.
        """
        self._require_open()
        failures: list[BusError] = []
        for servo_id in ids:
            self._model(servo_id)
            try:
                self._write_byte_confirmed(servo_id, self._torque_addr, 1 if enabled else 0)
            except BusError as exc:
                if enabled:
                    raise
                failures.append(exc)
        if failures:
            raise failures[0]

    def write_goal_ticks(self, goals: Mapping[int, int]) -> None:
        self._require_open()
        address, length = self._goal
        group = self.sdk.GroupSyncWrite(self.port, self._ph, address, length)
        for servo_id, tick in goals.items():
            model = self._model(servo_id)
            tick = int(tick)
            if not model.min_tick <= tick <= model.max_tick:
                raise ValueError(f"goal {tick} ticks for servo {servo_id} ({model.name}) outside "
                                 f"{model.min_tick}..{model.max_tick}")
            group.addParam(servo_id, list(tick.to_bytes(length, model.byte_order)))
        if not goals:
            return
        self._before_transaction()
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

    # --- internals ------------------------------------------------------------------------
    def _sync_read(self, wanted: list[int]) -> dict[int, int]:
        address, length = self._present
        got: dict[int, int] = {}
        pending = list(wanted)
        result = self.sdk.COMM_SUCCESS
        for _ in range(1 + self.retries):
            self._before_transaction()
            self._drop_stale_input()
            group = self.sdk.GroupSyncRead(self.port, self._ph, address, length)
            for servo_id in pending:
                group.addParam(servo_id)
            result = group.txRxPacket()
            self._raise_on_port_failure(result, None)
            for servo_id in pending:
                data = group.data_dict.get(servo_id) or []
                if len(data) >= length:
                    got[servo_id] = self._decode(bytes(data[:length]), self._model(servo_id))
            pending = [i for i in pending if i not in got]
            if not pending:
                return got
        raise ServoTimeout(f"servo {pending[0]} on {self.port_name} did not return its present position "
                           f"after {1 + self.retries} sync reads ({self._ph.getTxRxResult(result)})",
                           result_code=result, servo_id=pending[0])

    def _read_one(self, servo_id: int) -> int:
        address, length = self._present
        result = self.sdk.COMM_SUCCESS
        for _ in range(1 + self.retries):
            self._before_transaction()
            self._drop_stale_input()
            data, result, error = self._ph.readTxRx(self.port, servo_id, address, length)
            self._raise_on_port_failure(result, servo_id)
            if result == self.sdk.COMM_SUCCESS and len(data) >= length:
                self.last_status_errors[servo_id] = error
                return self._decode(bytes(data[:length]), self._model(servo_id))
        raise ServoTimeout(f"servo {servo_id} on {self.port_name} did not return its present position after "
                           f"{1 + self.retries} reads ({self._ph.getTxRxResult(result)})",
                           result_code=result, servo_id=servo_id)

    def _write_byte_confirmed(self, servo_id: int, address: int, value: int) -> None:
        result, error = self.sdk.COMM_SUCCESS, 0
        for _ in range(1 + self.retries):  # rewriting the same byte is harmless, so retry
            self._before_transaction()
            self._drop_stale_input()
            result, error = self._ph.write1ByteTxRx(self.port, servo_id, address, value)
            self._raise_on_port_failure(result, servo_id)
            if result == self.sdk.COMM_SUCCESS:
                break
        else:
            raise ServoTimeout(f"servo {servo_id} on {self.port_name} did not confirm writing {value} to "
                               f"address {address} ({self._ph.getTxRxResult(result)})",
                               result_code=result, servo_id=servo_id)
        self.last_status_errors[servo_id] = error
        if error:
            raise ServoStatusError(f"servo {servo_id} on {self.port_name} reports error 0x{error:02X}: "
                                   f"{self._ph.getRxPacketError(error)}",
                                   result_code=result, servo_id=servo_id, status_error=error)

    def _drop_stale_input(self) -> None:
        """Discard bytes left over from an earlier, timed-out exchange before asking anew.

        Feetech's PortHandler.clearPort only flushes output, so a late status packet would be read
        as the answer to the next question; we drop input ourselves for both backends.
        """
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
            raise ValueError(f"servo id {servo_id} is not on bus {self.port_name} "
                             f"(ids: {sorted(self.models)})") from None

    def _require_open(self) -> None:
        if not self._is_open:
            raise PortError(f"bus on {self.port_name} is not open; call open() or use it as a context manager")
