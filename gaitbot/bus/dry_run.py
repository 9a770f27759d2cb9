"""The dry-run port: a serial port with a healthy servo chain behind it (``gaitbot walk --dry-run``, tests).

DryRunPort stands where the SDK's PortHandler stands (the httpx MockTransport idea, python-can's virtual
bus): the factory picks it by name (``interface="dry-run"``), and the real DynamixelBus / FeetechBus and
the real SDK packet code run on top of it, so a dry run produces byte for byte what a real run would
send. It reads each instruction packet with gaitbot.bus.packets (on gaitbot.servos.wire, written from
the protocol documents, not from the SDK) and answers as the servos would:

* ping: status packet (Dynamixel 2.0 adds the Model Number register and firmware version);
* write: stored in the servo's control table, status packet unless broadcast (the table starts with
  the vendor table's factory values, the servo's id, the Baud Rate register of the bus's rate, the
  model number and the centre tick as goal and present position);
* sync write: stored, no status packet;
* read / sync read: status packets with the control-table bytes; present position mirrors the last
  goal position written (initially the model's centre tick, or where the robot stands: ``start_ticks``).

Servos made for a bus rate (``baudrate``) answer only while the port is set to that rate, as real
servos do (a scan at other rates finds nothing); without it they answer at any rate.

Time is virtual: when no reply bytes are pending, ``isPacketTimeout`` is True at once, so a
missing servo costs no wall-clock time.
"""

from __future__ import annotations

from collections.abc import Mapping

from gaitbot.bus.packets import take_packets
from gaitbot.servos import baud_rates, baud_register_value, vendor, wire
from gaitbot.servos.models import ServoModel

#: A UART reads bytes sent at a rate within about 3 % of its own (a 10-bit frame drifts half a bit by then).
BAUD_TOLERANCE = 0.03

_TABLE_SIZE_BYTES = 1024


class DryRunPort:
    """Duck-typed PortHandler for dynamixel_sdk and scservo_sdk with emulated servos behind it.

    tx_packets / rx_packets keep every packet written by the host / answered by the chain, as bytes.
    """

    def __init__(self, backend: str, protocol: float, models: Mapping[int, ServoModel],
                 port_name: str = "mock", baudrate: int | None = None,
                 start_ticks: Mapping[int, int] | None = None) -> None:
        self.vendor = vendor(backend)  # ValueError for an unknown backend
        self.backend = backend
        self.protocol = float(protocol)
        self.framing = wire.framing_for(backend, protocol)
        self.models = dict(models)
        self.port_name = port_name
        self.baudrate = 1_000_000
        self.is_open = False
        self.is_using = False  # the SDK uses this attribute as its bus lock
        self.tx_packets: list[bytes] = []
        self.rx_packets: list[bytes] = []
        self.rejected: list[tuple[bytes, str]] = []  # instruction packets a servo would ignore
        self._tx_buffer = bytearray()
        self._rx_buffer = bytearray()
        self._drop_replies = 0
        if baudrate is not None and any(baud_register_value(m.name, baudrate) is None for m in self.models.values()):
            baudrate = None  # a rate some servo's register cannot hold: a rate-blind chain, as before
        self.servo_baudrate = baudrate  # the rate the servos were set to (None: they answer at any rate)
        self.tables = {servo_id: self.initial_table(model, servo_id, baudrate)
                       for servo_id, model in self.models.items()}
        self.stand_at(start_ticks or {})

    # --- PortHandler interface -------------------------------------------------------------
    def openPort(self) -> bool:  # noqa: N802 (SDK names)
        self.is_open = True
        return True

    def closePort(self) -> None:  # noqa: N802
        self.is_open = False

    def setBaudRate(self, baudrate: int) -> bool:  # noqa: N802
        if baudrate not in self.vendor.SDK_BAUDRATES:
            return False
        self.baudrate = baudrate
        return True

    def getBaudRate(self) -> int:  # noqa: N802
        return self.baudrate

    def getPortName(self) -> str:  # noqa: N802
        return self.port_name

    def setPortName(self, port_name: str) -> None:  # noqa: N802
        self.port_name = port_name

    def clearPort(self) -> None:  # noqa: N802
        """Behave like the SDK under it: dynamixel_sdk drops input, scservo_sdk only flushes output."""
        if self.vendor.SDK_CLEAR_PORT_DROPS_INPUT:
            self._rx_buffer.clear()

    def reset_input_buffer(self) -> None:
        self._rx_buffer.clear()

    def getBytesAvailable(self) -> int:  # noqa: N802
        return len(self._rx_buffer)

    def readPort(self, length: int) -> bytes:  # noqa: N802
        chunk = bytes(self._rx_buffer[:length])
        del self._rx_buffer[:length]
        return chunk

    def writePort(self, packet) -> int:  # noqa: N802
        data = bytes(packet)
        self._tx_buffer += data
        for raw, frame in take_packets(self._tx_buffer, self.framing, status=False):
            if frame is None:
                self.rejected.append((raw, "bytes outside any packet"))
                continue
            self.tx_packets.append(raw)
            self._answer(raw, frame)
        return len(data)

    def setPacketTimeout(self, packet_length) -> None:  # noqa: N802
        pass

    def setPacketTimeoutMillis(self, msec) -> None:  # noqa: N802
        pass

    def isPacketTimeout(self) -> bool:  # noqa: N802
        return not self._rx_buffer  # nothing pending now means nothing will ever come

    # --- test helpers ----------------------------------------------------------------------
    def drop_next_replies(self, count: int = 1) -> None:
        """Lose the next ``count`` status packets, as a noisy bus would."""
        self._drop_replies += count

    def inject_input(self, data: bytes) -> None:
        """Put stray bytes in the input buffer (a late reply from an earlier exchange)."""
        self._rx_buffer += data

    def present_ticks(self, servo_id: int) -> int:
        model = self.models[servo_id]
        start = model.addr_present_position
        return int.from_bytes(self.tables[servo_id][start:start + model.len_present_position], model.byte_order)

    # --- the emulated chain ----------------------------------------------------------------
    @staticmethod
    def initial_table(model: ServoModel, servo_id: int, baudrate: int | None = None) -> bytearray:
        """A servo's control table after power-on: the vendor table's factory values, ``servo_id`` in its
        ID register, the Baud Rate register of ``baudrate`` (when the model can run at it; else the
        factory rate), the model number and the centre tick as goal and present position."""
        table = bytearray(_TABLE_SIZE_BYTES)
        for register in model.control_table.values():
            if register.factory is not None:
                table[register.address:register.address + register.size] = \
                    register.factory.to_bytes(register.size, model.byte_order)
        number = model.control_table["Model Number"]
        table[number.address:number.address + number.size] = model.model_number.to_bytes(number.size, model.byte_order)
        table[model.control_table["ID"].address] = servo_id
        value = baud_register_value(model.name, baudrate) if baudrate is not None else None
        if value is not None:
            table[model.control_table["Baud Rate"].address] = value
        DryRunPort.place(model, table, model.centre_tick)
        if model.gain is not None:  # the factory stiffness, until a session writes its own
            factory = model.gain.factory_value.to_bytes(model.gain.length, model.byte_order)
            for address in model.gain.addresses:
                table[address:address + model.gain.length] = factory
        return table

    @staticmethod
    def place(model: ServoModel, table: bytearray, ticks: int) -> None:
        """Put a servo at ``ticks``: its goal and present position registers."""
        goal = int(ticks).to_bytes(model.len_goal_position, model.byte_order)
        table[model.addr_goal_position:model.addr_goal_position + model.len_goal_position] = goal
        table[model.addr_present_position:model.addr_present_position + model.len_present_position] = \
            int(ticks).to_bytes(model.len_present_position, model.byte_order)

    def stand_at(self, ticks: Mapping[int, int]) -> None:
        """Servos at these ticks (servo id -> ticks) instead of their centre: where the robot stands."""
        for servo_id, tick in ticks.items():
            if servo_id in self.tables:
                self.place(self.models[servo_id], self.tables[servo_id], tick)

    @staticmethod
    def servo_rate(model: ServoModel, table: bytearray) -> int | None:
        """The rate a servo listens at, from its Baud Rate register (None: a value gaitbot does not know)."""
        return baud_rates(model.name).get(table[model.control_table["Baud Rate"].address])

    def hears(self, servo_id: int) -> bool:
        """Whether the servo reads what the host sends: set to the port's rate (or made rate-blind)."""
        if self.servo_baudrate is None:
            return True
        return rates_match(self.servo_rate(self.models[servo_id], self.tables[servo_id]), self.baudrate)

    def _answer(self, raw: bytes, frame: wire.Frame) -> None:
        if not frame.checksum_ok:
            self.rejected.append((raw, frame.problem))  # a servo ignores a damaged packet
            return
        handler = {wire.INST_PING: self._ping, wire.INST_READ: self._read, wire.INST_WRITE: self._write,
                   wire.INST_SYNC_WRITE: self._sync_write, wire.INST_SYNC_READ: self._sync_read}.get(frame.instruction)
        if handler is None:
            self.rejected.append((raw, f"instruction 0x{frame.instruction:02X} not emulated"))
            return
        handler(frame)

    def _targets(self, packet_id: int) -> list[int]:
        if packet_id == wire.BROADCAST_ID:
            return [i for i in self.tables if self.hears(i)]
        return [packet_id] if packet_id in self.tables and self.hears(packet_id) else []

    def _address_and_rest(self, params: bytes) -> tuple[int, bytes]:
        return wire.address_and_rest(params, self.framing)

    def _ping(self, frame: wire.Frame) -> None:
        for servo_id in self._targets(frame.packet_id):
            extra = b""
            if self.framing == "v2":  # Protocol 2.0 ping: model number (2 bytes) and firmware version
                table, registers = self.tables[servo_id], self.models[servo_id].control_table
                number = registers["Model Number"].address
                extra = bytes(table[number:number + 2]) + bytes([table[registers["Firmware Version"].address]])
            self._reply(servo_id, extra)

    def _read(self, frame: wire.Frame) -> None:
        address, length, _ = wire.address_length_and_rest(frame.params, self.framing)
        if self._targets(frame.packet_id) == [frame.packet_id]:
            self._reply(frame.packet_id, bytes(self.tables[frame.packet_id][address:address + length]))

    def _write(self, frame: wire.Frame) -> None:
        address, data = self._address_and_rest(frame.params)
        targets = self._targets(frame.packet_id)
        for servo_id in targets:
            self._store(servo_id, address, data)
        if frame.packet_id in targets:  # a broadcast write gets no status packet
            self._reply(frame.packet_id, b"")

    def _sync_write(self, frame: wire.Frame) -> None:
        address, length, body = wire.address_length_and_rest(frame.params, self.framing)
        for offset in range(0, len(body) - length, length + 1):
            servo_id = body[offset]
            if servo_id in self.tables and self.hears(servo_id):
                self._store(servo_id, address, body[offset + 1:offset + 1 + length])

    def _sync_read(self, frame: wire.Frame) -> None:
        address, length, ids = wire.address_length_and_rest(frame.params, self.framing)
        for servo_id in ids:
            if servo_id in self.tables and self.hears(servo_id):
                self._reply(servo_id, bytes(self.tables[servo_id][address:address + length]))

    def _store(self, servo_id: int, address: int, data: bytes) -> None:
        table, model = self.tables[servo_id], self.models[servo_id]
        table[address:address + len(data)] = data
        goal, length = model.addr_goal_position, model.len_goal_position
        if address < goal + length and goal < address + len(data):
            # an ideal servo: it is where it was told to be; copying raw bytes keeps the byte order
            table[model.addr_present_position:model.addr_present_position + model.len_present_position] = \
                table[goal:goal + model.len_present_position]

    def _reply(self, servo_id: int, params: bytes) -> None:
        if self.framing == "v2":
            packet = wire.build_v2(servo_id, wire.INST_STATUS_V2, bytes([0]) + params)
        else:
            packet = wire.build_v1(servo_id, 0, params)
        if self._drop_replies:
            self._drop_replies -= 1
            return
        self.rx_packets.append(packet)
        self._rx_buffer += packet


def rates_match(servo_rate: int | None, line_rate: int | None) -> bool:
    """A servo at ``servo_rate`` reads bytes sent at ``line_rate`` (within BAUD_TOLERANCE); None line: any."""
    if line_rate is None:
        return True
    return servo_rate is not None and abs(servo_rate - line_rate) <= BAUD_TOLERANCE * servo_rate
