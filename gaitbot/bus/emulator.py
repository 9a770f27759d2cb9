"""A servo chain in time, with faults, heat, a sagging supply and a scripted hand: the engine behind
tools/servo_emulator.py.

``ServoEmulator(EmulatorConfig(...))`` opens a pty pair and answers on it like a chain of Dynamixel
or Feetech servos (``start()`` serves it on a background thread; ``path`` is the device a driver
opens; ``stop()``, ``chain``, ``wait_closed()``). ``EmulatedChain`` is the chain alone, fed with
``receive(data, now_s)`` and read with ``due(now_s)``, for tests without a pty.

Instruction parsing, framing and the control tables are the mock's (gaitbot.bus.mock.MockPort, the
chain a dry run talks to) and the vendors' (gaitbot.servos); this module adds time (return delay,
byte time, motion at the no-load speed), the Status Return Level, the instructions a dry run never
sends (reg write, action, reboot, bulk read/write), faults (silent, late, corrupt, error bits, a port
that disappears), a hand that moves servos whose torque is off, and what bring-up needs:

* **servos as units**, each with its own control table: an ID or Baud Rate write (EEPROM) takes effect
  at once, so the servo answers at its new id and rate; EEPROM writes persist over ``power_cycle()``
  (Feetech: only those made with the Lock register at 0); a Protocol 2.0 servo refuses an EEPROM write
  while its torque is on (Access Error), as the e-Manual says;
* **the line's baud rate**: a servo hears only a host set to its rate (the pty's speed, read from the
  master side), and a reply sent at another rate is lost;
* **factory-fresh chains** (every servo at id 1 and its factory rate), connected one at a time
  (``plug_next()``, or Enter on the command line), and **collisions**: servos answering one packet at
  once (two at one id; Feetech and Protocol 1.0 broadcast pings) send one damaged status packet;
* **heat**: a servo with torque on holding a load (``loads``, % of its maximum torque) warms by
  ``heat_c_per_s`` x load^2 and cools towards ambient with time constant ``cool_time_s``; at its Temperature
  Limit it reports overheating and switches torque off, as the servos' factory Shutdown setting does;
* **the supply**: ``supply_v`` volts, falling by ``voltage_sag_v_per_s`` once faults are active; under a
  servo's Min Voltage Limit it reports an input voltage error (and keeps driving, as X servos do).

docs/emulator.md describes it; gaitbot.app.emulator is its command line.
"""

from __future__ import annotations

import array
import fcntl
import math
import os
import random
import select
import threading
import time
import tty
from collections import deque
from dataclasses import dataclass, field

from gaitbot.bus.log import BusRecorder
from gaitbot.bus.mock import MockPort, rates_match
from gaitbot.gait.trajectory import Trajectory
from gaitbot.robot.calibration import trajectory_ticks
from gaitbot.servos import baud_register_value, dynamixel, feetech, vendor, wire
from gaitbot.servos.health import encode_load, health_block
from gaitbot.servos.models import SERVO_MODELS, ServoModel
from gaitbot.servos.wire import INST_ACTION, INST_BULK_READ, INST_BULK_WRITE, INST_REBOOT, INST_REG_WRITE

FAULT_KINDS = ("overload", "overheating", "voltage")
#: Protocol 2.0 error number 7, "Access Error": an EEPROM write while torque is on (e-Manual Protocol 2.0).
ACCESS_ERROR = 7
#: Linux ioctls reading and writing a tty's termios2, whose c_ispeed / c_ospeed are the line rate even for
#: non-standard rates (CBAUD bits set to BOTHER); asm-generic/ioctls.h and termbits.h.
_TCGETS2, _TCSETS2 = 0x802C542A, 0x402C542B
_CBAUD, _BOTHER = 0o010017, 0o010000


@dataclass(frozen=True)
class Layout:
    """Control-table addresses the emulator needs beyond ServoModel's, and the factory values it starts
    with (address, size, value): all read from the vendor's control table (gaitbot.servos)."""

    id_addr: int
    return_delay_addr: int
    status_return_addr: int
    moving_addr: int
    hardware_error_addr: int | None  # Hardware Error Status (Dynamixel X, XL-320) or Servo Status (Feetech)
    hardware_error_bits: dict[str, int]  # fault kind -> its bit in that register
    eeprom_end: int  # first RAM address
    lock_addr: int | None  # Feetech's Lock flag
    temperature_limit_addr: int
    min_voltage: tuple[int, int]  # Min Voltage Limit (address, size)
    max_voltage: tuple[int, int]
    baud_addr: int
    initial: tuple[tuple[int, int, int], ...]

    @classmethod
    def of(cls, model: ServoModel) -> "Layout":
        table = model.control_table
        hardware = table.get("Hardware Error Status") or table.get("Servo Status")
        if model.family == "feetech":
            bits = {name: bit for bit, name in feetech.ERROR_BITS.items()}
        else:
            bits = {name: bit for bit, name in dynamixel.HARDWARE_ERROR_BITS.get(model.name, {}).items()}
        bits = {("voltage" if name == "input voltage" else name): bit for name, bit in bits.items()}
        lock = table.get("Lock")
        temperature = table.get("Temperature Limit") or table["Max Temperature Limit"]
        return cls(table["ID"].address, table["Return Delay Time"].address, table["Status Return Level"].address,
                   table["Moving"].address, hardware.address if hardware is not None else None, bits,
                   vendor(model.family).EEPROM_END[model.name], lock.address if lock is not None else None,
                   temperature.address, tuple(table["Min Voltage Limit"][:2]), tuple(table["Max Voltage Limit"][:2]),
                   table["Baud Rate"].address,
                   tuple((r.address, r.size, r.factory) for r in table.values() if r.factory is not None))


LAYOUTS = {name: Layout.of(model) for name, model in SERVO_MODELS.items()}
_REGISTERS = {name: model.control_table for name, model in SERVO_MODELS.items()}


@dataclass(eq=False)
class Servo:
    """One emulated servo: its model, control table (``saved``: the EEPROM as it survives a power cycle),
    where it is (``present`` ticks), how warm, what it holds, and whether it is plugged in."""

    index: int
    model: ServoModel
    table: bytearray
    saved: bytearray
    present: float
    temperature_c: float
    load_pct: float = 0.0
    connected: bool = True
    rate_blind: bool = False  # made for a rate its register cannot hold: hears any rate
    moved_at_s: float | None = None  # None: time has not started for it (no packet yet)
    pending_error: int | None = None  # the error of the next status packet (a refused write)
    shown: tuple | None = None  # (temperature, voltage, torque, load) the registers show now

    @property
    def layout(self) -> Layout:
        return LAYOUTS[self.model.name]

    @property
    def block(self):
        return health_block(self.model)

    @property
    def servo_id(self) -> int:
        return self.table[self.layout.id_addr]

    @property
    def rate(self) -> int | None:
        return MockPort.servo_rate(self.model, self.table)

    def register(self, name: str) -> int:
        r = _REGISTERS[self.model.name][name]
        return int.from_bytes(self.table[r.address:r.address + r.size], self.model.byte_order)


@dataclass
class Faults:
    silent: set[int] = field(default_factory=set)
    late_s: dict[int, float] = field(default_factory=dict)
    corrupt_fraction: float = 0.0
    corrupt_ids: set[int] | None = None  # None: every servo
    errors: dict[int, set[str]] = field(default_factory=dict)
    after_frames: int = 0
    after_s: float = 0.0
    close_after_frames: int | None = None
    close_after_s: float | None = None


@dataclass
class Hand:
    """Ticks per servo id, one entry per sample; ``rate_hz`` None: one sample per read cycle."""

    ticks: dict[int, list[int]]
    rate_hz: float | None = None

    def __post_init__(self) -> None:
        lengths = {len(v) for v in self.ticks.values()}
        if len(lengths) != 1 or 0 in lengths:
            raise ValueError("the hand needs the same number (at least one) of samples for every servo")
        if self.rate_hz is not None and not self.rate_hz > 0:
            raise ValueError(f"--hand-rate must be a positive rate in Hz, got {self.rate_hz}")

    @property
    def samples(self) -> int:
        return len(next(iter(self.ticks.values())))


@dataclass
class Heat:
    """How servos warm and cool: with torque on and ``load`` (0..1 of the maximum torque) held, the temperature
    rises by ``heat_c_per_s`` x load^2 (resistive heating) and relaxes towards ``ambient_c`` with time constant
    ``cool_time_s``: T(t) = T_eq + (T0 - T_eq) exp(-t / tau), T_eq = ambient + heat x load^2 x tau. The
    defaults (0.5 C/s at full load, 300 s) make a stalled servo overheat in about a minute and a lightly
    loaded one stay near ambient: an order of magnitude, not a measured servo."""

    ambient_c: float = 25.0
    heat_c_per_s: float = 0.5
    cool_time_s: float = 300.0


@dataclass
class EmulatorConfig:
    backend: str
    protocol: float
    models: dict[int, ServoModel]
    baudrate: int = 1_000_000
    faults: Faults = field(default_factory=Faults)
    log_path: str | None = None
    robot: str = "emulated"
    joints: dict[str, int] | None = None
    seed: int = 0
    return_delay_us: float | None = None  # overrides every servo's Return Delay Time register
    hand: Hand | None = None  # moves servos whose torque is off (see the module docstring)
    fresh: tuple[ServoModel, ...] = ()  # factory-fresh servos (id 1, factory rate) instead of ``models``
    one_at_a_time: bool = False  # only one servo connected at a time (plug_next() swaps it for the next)
    heat: Heat = field(default_factory=Heat)
    loads_pct: dict[int, float] = field(default_factory=dict)  # servo id -> load it holds with torque on, %
    temperatures_c: dict[int, float] = field(default_factory=dict)  # servo id -> temperature at the start
    supply_v: float | None = None  # None: the first servo's usual supply (its Present Voltage factory value)
    voltage_sag_v_per_s: float = 0.0  # the supply falls this fast once faults are active
    imu: object | None = None  # an IMU device on the line (gaitbot.bus.imu_device.ImuDevice), answering at its id


class EmulatedChain(MockPort):
    """MockPort's chain with time: replies are scheduled, servos move, warm and cool, faults apply.

    Feed received bytes with ``receive(data, now_s)``; take due replies with ``due(now_s)``. ``line_baud``
    is the host's rate (None: every servo hears). ``units`` are the servos, plugged in or not; ``tables``
    and ``models`` map the ids that hear the line to theirs (MockPort's view, rebuilt for each packet).
    ``writes`` lists every WRITE a servo received: (servo index, its id, address, data, accepted).
    """

    def __init__(self, config: EmulatorConfig) -> None:
        super().__init__(config.backend, config.protocol, {})
        self.tx_packets = deque(maxlen=256)  # MockPort keeps every packet; a long run needs only the latest
        self.config = config
        self.faults = config.faults
        self.baudrate = config.baudrate
        self.line_baud: int | None = None
        self.now_s = 0.0
        self.first_packet_s: float | None = None
        self.faults_since_s: float | None = None
        self.goal_frames = 0
        self.goal_log: BusRecorder | None = None
        self.outbox: list[tuple[float, bytes, int | None]] = []
        self.writes: list[tuple[int, int, int, bytes, bool]] = []
        self._busy_until_s = 0.0
        self._instruction = 0
        self._instruction_rate: int | None = None
        self._rng = random.Random(config.seed)
        self._registered: dict[int, tuple[int, bytes]] = {}
        self.hand = config.hand
        self.hand_sample = 0
        self._hand_grabbed_s: float | None = None  # when the first torque-off came; None: not yet
        self._hand_read: set[int] = set()  # servos read at the current hand sample
        self.units = self._make_units(config)
        first = self.units[0].model if self.units else None
        factory_v = (health_block(first).voltage.factory / 10.0) if first is not None else 12.0
        self.supply_v = config.supply_v if config.supply_v is not None else factory_v
        self._supply_v = self.supply_v
        if config.one_at_a_time:
            self.connect_only(0)
        self._route()
        if config.log_path:
            joints = config.joints or {f"servo_{i}": i for i in config.models}
            self.goal_log = BusRecorder(config.log_path, robot=config.robot, joints=joints, clock=time.monotonic)
            self.goal_log.start(backend=config.backend, protocol=config.protocol, baudrate=config.baudrate,
                                models=config.models or {u.servo_id: u.model for u in self.units})

    def _make_units(self, config: EmulatorConfig) -> list[Servo]:
        fresh = bool(config.fresh)
        entries = [(vendor(m.family).FACTORY_ID, m) for m in config.fresh] if fresh else list(config.models.items())
        units = []
        for index, (servo_id, model) in enumerate(entries):
            table = MockPort.initial_table(model, servo_id, None if fresh else config.baudrate)
            layout = LAYOUTS[model.name]
            if config.return_delay_us is not None:
                table[layout.return_delay_addr] = min(254, int(round(config.return_delay_us / 2)))
            blind = not fresh and baud_register_value(model.name, config.baudrate) is None
            ambient = config.heat.ambient_c
            units.append(Servo(index, model, table, bytearray(table[:layout.eeprom_end]), float(model.centre_tick),
                               config.temperatures_c.get(servo_id, ambient), config.loads_pct.get(servo_id, 0.0),
                               rate_blind=blind))
        return units

    # --- which servos hear the line -------------------------------------------------------
    def _hears_line(self, unit: Servo) -> bool:
        return unit.connected and (unit.rate_blind or rates_match(unit.rate, self.line_baud))

    def _route(self) -> None:
        """Map the ids of the servos that hear the line to them; a second servo at an id waits in a layer.
        Rebuilt only when a servo's id, rate or plug, or the line's rate, changed."""
        signature = (self.line_baud, *((u.connected, u.table[u.layout.id_addr], u.table[u.layout.baud_addr])
                                       for u in self.units))
        if signature == getattr(self, "_route_signature", None):
            self._use(self._primary)
            return
        self._route_signature = signature
        primary: dict[int, Servo] = {}
        self._layers: list[dict[int, Servo]] = []
        for unit in self.units:
            if not self._hears_line(unit):
                continue
            servo_id = unit.servo_id
            if servo_id not in primary:
                primary[servo_id] = unit
                continue
            for layer in self._layers:
                if servo_id not in layer:
                    layer[servo_id] = unit
                    break
            else:
                self._layers.append({servo_id: unit})
        self._primary = primary
        self._use(primary)

    def _use(self, units: dict[int, Servo]) -> None:
        self.units_by_id = units
        self.tables = {i: u.table for i, u in units.items()}
        self.models = {i: u.model for i, u in units.items()}

    def hears(self, servo_id: int) -> bool:
        return servo_id in self.units_by_id  # routing already chose who hears

    # --- plugging servos in and out, power ---------------------------------------------------
    def connect_only(self, index: int) -> None:
        """Unplug every servo but the one at ``index`` (its position in the chain)."""
        if not 0 <= index < len(self.units):
            raise IndexError(f"no servo {index} in a chain of {len(self.units)}")
        for unit in self.units:
            unit.connected = unit.index == index
        self._route()

    def plug_next(self) -> Servo | None:
        """Swap the plugged-in servo for the next one (one at a time); None when there is no next."""
        current = max((u.index for u in self.units if u.connected), default=-1)
        if current + 1 >= len(self.units):
            return None
        self.connect_only(current + 1)
        return self.units[current + 1]

    def connect_all(self) -> None:
        for unit in self.units:
            unit.connected = True
        self._route()

    def power_cycle(self) -> None:
        """Power off and on: the EEPROM as saved, RAM back to its power-on values, torque off."""
        for unit in self.units:
            layout = unit.layout
            fresh = MockPort.initial_table(unit.model, unit.servo_id)
            fresh[:layout.eeprom_end] = unit.saved
            for name, register in unit.model.control_table.items():
                if register.address >= layout.eeprom_end and register.factory is None and \
                        name not in ("Goal Position", "Present Position"):
                    fresh[register.address:register.address + register.size] = bytes(register.size)
            unit.table[:] = fresh
            unit.shown = None
        self._route()

    # --- time and faults ------------------------------------------------------------------
    def receive(self, data: bytes, now_s: float) -> None:
        self.now_s = now_s
        self.writePort(data)

    def due(self, now_s: float) -> list[bytes]:
        """The replies due by ``now_s``; one sent at a rate the host is no longer set to is lost."""
        ready = [(packet, rate) for t_s, packet, rate in self.outbox if t_s <= now_s]
        self.outbox = [entry for entry in self.outbox if entry[0] > now_s]
        return [packet for packet, rate in ready
                if rate is None or self.line_baud is None or rates_match(rate, self.line_baud)]

    def next_due_s(self) -> float | None:
        return min((t_s for t_s, _, _ in self.outbox), default=None)

    def faults_active(self) -> bool:
        if self.first_packet_s is None or self.goal_frames < self.faults.after_frames:
            return False
        active = self.now_s - self.first_packet_s >= self.faults.after_s
        if active and self.faults_since_s is None:
            self.faults_since_s = self.now_s
        return active

    def should_close(self, now_s: float) -> bool:
        f = self.faults
        if f.close_after_frames is not None and self.goal_frames >= f.close_after_frames:
            return True
        return (f.close_after_s is not None and self.first_packet_s is not None
                and now_s - self.first_packet_s >= f.close_after_s)

    def supply_now_v(self) -> float:
        """The supply's voltage now: ``supply_v`` less the sag since faults became active."""
        self.faults_active()
        if self.faults_since_s is None or not self.config.voltage_sag_v_per_s:
            return self.supply_v
        return max(0.0, self.supply_v - self.config.voltage_sag_v_per_s * (self.now_s - self.faults_since_s))

    def _natural_kinds(self, unit: Servo) -> set[str]:
        """What the servo itself reports: overheating at its Temperature Limit, input voltage outside its limits."""
        layout, table, order = unit.layout, unit.table, unit.model.byte_order
        kinds = set()
        if unit.temperature_c >= table[layout.temperature_limit_addr]:
            kinds.add("overheating")
        tenths = self._supply_v * 10
        (low, low_size), (high, high_size) = layout.min_voltage, layout.max_voltage
        if tenths < int.from_bytes(table[low:low + low_size], order) or \
                tenths > int.from_bytes(table[high:high + high_size], order):
            kinds.add("voltage")
        return kinds

    def _kinds(self, servo_id: int) -> set[str]:
        unit = self.units_by_id.get(servo_id)
        configured = self.faults.errors.get(servo_id, set()) if self.faults_active() else set()
        return set(configured) | (self._natural_kinds(unit) if unit is not None else set())

    def error_byte(self, servo_id: int) -> int:
        unit = self.units_by_id.get(servo_id)
        if unit is not None and unit.pending_error is not None:
            error, unit.pending_error = unit.pending_error, None
            return error
        kinds = self._kinds(servo_id)
        if not kinds:
            return 0
        if self.framing == "v2":
            return dynamixel.V2_ALERT
        bits = self.vendor  # Protocol 1.0 and Feetech: the same bits
        return ((bits.ERRBIT_OVERLOAD if "overload" in kinds else 0)
                | (bits.ERRBIT_OVERHEATING if "overheating" in kinds else 0)
                | (bits.ERRBIT_INPUT_VOLTAGE if "voltage" in kinds else 0))

    def _apply_error_faults(self) -> None:
        configured = self.faults.errors if self.faults_active() else {}
        for unit in self.units:
            kinds = set(configured.get(unit.servo_id, set())) | self._natural_kinds(unit)
            if not kinds:
                continue
            model, table, layout = unit.model, unit.table, unit.layout
            if layout.hardware_error_addr is not None:
                table[layout.hardware_error_addr] |= sum(layout.hardware_error_bits.get(k, 0) for k in kinds)
            if kinds & {"overload", "overheating"} and table[model.addr_torque_enable]:
                self._advance_unit(unit)
                table[model.addr_torque_enable] = 0  # the shutdown the servos do by default

    # --- motion, heat, supply ---------------------------------------------------------------
    def _advance(self, servo_id: int) -> None:
        unit = self.units_by_id.get(servo_id)
        if unit is not None:
            self._advance_unit(unit)

    def _advance_unit(self, unit: Servo) -> None:
        """Move present position towards goal at the no-load speed, warm or cool, read the supply, up to now."""
        model, table = unit.model, unit.table
        dt_s = 0.0 if unit.moved_at_s is None else max(0.0, self.now_s - unit.moved_at_s)
        unit.moved_at_s = self.now_s
        goal = int.from_bytes(table[model.addr_goal_position:model.addr_goal_position + model.len_goal_position],
                              model.byte_order, signed=model.len_goal_position == 4)
        torque = bool(table[model.addr_torque_enable])
        present = unit.present
        hand = self.hand
        if not torque and self._hand_grabbed_s is not None and unit.servo_id in hand.ticks:
            script = hand.ticks[unit.servo_id]
            present = unit.present = float(script[min(self.hand_sample, len(script) - 1)])
        elif torque:
            step = model.no_load_speed_dps * model.ticks_per_rad * (math.pi / 180.0) * dt_s
            present = goal if abs(goal - present) <= step else present + step * (1 if goal > present else -1)
            unit.present = present
        length = model.len_present_position
        value = int(round(present))
        table[model.addr_present_position:model.addr_present_position + length] = \
            value.to_bytes(length, model.byte_order, signed=length == 4)
        table[unit.layout.moving_addr] = int(round(present) != goal and torque)
        self._warm(unit, dt_s, torque)

    def _warm(self, unit: Servo, dt_s: float, torque: bool) -> None:
        if dt_s > 0.0:
            heat = self.config.heat
            load = unit.load_pct / 100.0 if torque else 0.0
            equilibrium_c = heat.ambient_c + heat.heat_c_per_s * load * load * heat.cool_time_s
            unit.temperature_c = equilibrium_c + (unit.temperature_c - equilibrium_c) * math.exp(
                -dt_s / heat.cool_time_s)
        shown = (int(round(unit.temperature_c)), int(round(self._supply_v * 10)), torque, unit.load_pct)
        if shown == unit.shown:
            return  # the registers already say so
        unit.shown = shown
        block, table, order = unit.block, unit.table, unit.model.byte_order
        table[block.temperature.address] = max(0, min(255, shown[0]))
        size = block.voltage.size
        table[block.voltage.address:block.voltage.address + size] = \
            max(0, min(shown[1], (1 << (8 * size)) - 1)).to_bytes(size, order)
        if block.load is not None:
            raw = encode_load(unit.load_pct if torque else 0.0, block.load_encoding, block.load.size)
            table[block.load.address:block.load.address + block.load.size] = raw.to_bytes(block.load.size, order)

    # --- instruction handling (MockPort's, extended) --------------------------------------
    def _answer(self, raw: bytes) -> None:
        if self.first_packet_s is None:
            self.first_packet_s = self.now_s
        frame = wire.parse(raw, self.framing, status=False)
        self._route()
        if frame.checksum_ok and self._hand_grabbed_s is not None:
            self._move_hand(frame)
        self._supply_v = self.supply_now_v()
        for unit in self.units:
            self._advance_unit(unit)
        self._apply_error_faults()
        if not frame.checksum_ok:
            self.rejected.append((raw, frame.problem))
            return
        if self.framing == "v2" and frame.instruction == wire.INST_STATUS_V2:
            return  # a status packet on the line is not for us
        if self.config.imu is not None and frame.packet_id == self.config.imu.device_id:
            self._imu_answer(frame)
            return
        self._instruction = frame.instruction
        self._instruction_rate = self.line_baud
        first_reply = len(self.outbox)
        self._handle(frame, raw)
        for layer in self._layers:  # a second servo at an id hears the packet too
            self._use(layer)
            self._handle(frame, raw)
        self._use(self._primary)
        self._collide(first_reply, frame)
        self._log_goals(raw, frame)

    def _imu_answer(self, frame: wire.Frame) -> None:
        """The IMU device's status packet, on the line after what is already on it (its Return Delay Time is 0)."""
        packet = self.config.imu.answer(frame, self.now_s)
        if packet is None:
            return
        send_s = max(self.now_s, self._busy_until_s)
        self._busy_until_s = send_s + len(packet) * 10 / (self.line_baud or self.baudrate)
        self.rx_packets.append(packet)
        self.outbox.append((send_s, packet, self.line_baud))

    def _handle(self, frame: wire.Frame, raw: bytes) -> None:
        extra = {INST_REG_WRITE: self._reg_write, INST_ACTION: self._action, INST_REBOOT: self._reboot}
        if self.framing == "v2":
            extra.update({INST_BULK_READ: self._bulk_read, INST_BULK_WRITE: self._bulk_write})
        if self.backend == "dynamixel" and self.protocol == 1.0:
            extra[wire.INST_SYNC_READ] = self._unsupported  # AX firmware has no sync read
            if frame.packet_id == wire.BROADCAST_ID:
                extra[wire.INST_PING] = lambda _frame: None  # Protocol 1.0: no status to a broadcast
        handler = extra.get(frame.instruction)
        if handler is not None:
            handler(frame)
        elif frame.instruction in (wire.INST_PING, wire.INST_READ, wire.INST_WRITE, wire.INST_SYNC_WRITE,
                                   wire.INST_SYNC_READ):
            super()._answer(raw)
        else:
            self._unsupported(frame)

    def _collide(self, first_reply: int, frame: wire.Frame) -> None:
        """Servos that answer one packet at the same moment garble each other: their replies become one
        damaged packet. That is two servos at one id, and every servo answering a Protocol 1.0 / Feetech
        broadcast ping (Protocol 2.0 servos take turns by id)."""
        replies = self.outbox[first_reply:]
        if len(replies) < 2:
            return
        id_at = 4 if self.framing == "v2" else 2
        groups: dict[int, list[tuple[float, bytes, int | None]]] = {}
        for entry in replies:
            groups.setdefault(entry[1][id_at], []).append(entry)
        if self.framing == "v1" and frame.instruction == wire.INST_PING and frame.packet_id == wire.BROADCAST_ID:
            colliding = [replies]
        else:
            colliding = [group for group in groups.values() if len(group) > 1]
        for group in colliding:
            longest = max(group, key=lambda e: len(e[1]))
            garbled = bytearray(longest[1])
            garbled[-1] ^= 0x5A  # superimposed bits never add up to a valid checksum/CRC
            for entry in group:
                self.outbox.remove(entry)
            self.outbox.append((min(e[0] for e in group), bytes(garbled), longest[2]))

    # --- the scripted hand -----------------------------------------------------------------
    def _move_hand(self, frame: wire.Frame) -> None:
        """Advance the hand: with time at ``rate_hz``, or by one sample when a read cycle ends."""
        if self.hand.rate_hz is not None:
            self.hand_sample = int((self.now_s - self._hand_grabbed_s) * self.hand.rate_hz)
            return
        read = self._present_position_reads(frame)
        if self._hand_read & set(read):
            self.hand_sample += 1
            self._hand_read.clear()
        self._hand_read.update(read)

    def _present_position_reads(self, frame: wire.Frame) -> list[int]:
        """Servo ids whose present position this instruction reads (read, sync read, bulk read of exactly the
        Present Position register: a health block read, which spans it, is not a sample of the hand's)."""
        if not self.models:
            return []
        first = next(iter(self.models.values()))
        wanted = (first.addr_present_position, first.len_present_position)

        def covers(address: int, length: int) -> bool:
            return (address, length) == wanted

        p, v2 = frame.params, self.framing == "v2"
        if frame.instruction == wire.INST_READ:
            address, length, _ = wire.address_length_and_rest(p, self.framing)
            return [frame.packet_id] if frame.packet_id in self.tables and covers(address, length) else []
        if frame.instruction == wire.INST_SYNC_READ:
            address, length, ids = wire.address_length_and_rest(p, self.framing)
            return [i for i in ids if i in self.tables] if covers(address, length) else []
        if frame.instruction == INST_BULK_READ and v2:
            return [p[o] for o in range(0, len(p) - 4, 5)
                    if p[o] in self.tables and covers(p[o + 1] | p[o + 2] << 8, p[o + 3] | p[o + 4] << 8)]
        return []

    def _grab_by_hand(self, servo_id: int, address: int, data: bytes) -> None:
        """The hand takes the legs at the first torque-off write (its sample 0 is read next)."""
        model = self.models[servo_id]
        if self.hand is None or self._hand_grabbed_s is not None or not address <= model.addr_torque_enable < address + len(data):
            return
        if data[model.addr_torque_enable - address] == 0:
            self._hand_grabbed_s = self.now_s
            self.hand_sample = 0
            self._hand_read.clear()

    def _unsupported(self, frame: wire.Frame) -> None:
        if frame.packet_id in self.tables:
            error = self.vendor.INSTRUCTION_ERROR[self.protocol]
            self._reply(frame.packet_id, b"", error=error)

    def _log_goals(self, raw: bytes, frame: wire.Frame) -> None:
        if frame.instruction != wire.INST_SYNC_WRITE:
            return
        address, _ = self._address_and_rest(frame.params)
        if self.units and address == self.units[0].model.addr_goal_position:  # whoever hears it
            self.goal_frames += 1
            if self.goal_log is not None:
                self.goal_log.log("tx", raw)

    def _reg_write(self, frame: wire.Frame) -> None:
        address, data = self._address_and_rest(frame.params)
        for servo_id in self._targets(frame.packet_id):
            self._registered[servo_id] = (address, data)
        if frame.packet_id in self.tables:
            self._reply(frame.packet_id, b"")

    def _action(self, frame: wire.Frame) -> None:
        for servo_id in self._targets(frame.packet_id):
            if servo_id in self._registered:
                self._store(servo_id, *self._registered.pop(servo_id))
        if frame.packet_id in self.tables:
            self._reply(frame.packet_id, b"")

    def _reboot(self, frame: wire.Frame) -> None:
        for servo_id in self._targets(frame.packet_id):
            model = self.models[servo_id]
            self.tables[servo_id][model.addr_torque_enable] = 0
            hw = LAYOUTS[model.name].hardware_error_addr
            if hw is not None and self.backend == "dynamixel":
                self.tables[servo_id][hw] = 0
        if frame.packet_id in self.tables:
            self._reply(frame.packet_id, b"")

    def _bulk_read(self, frame: wire.Frame) -> None:
        """Dynamixel 2.0 Bulk Read: [ID, ADDR_L, ADDR_H, LEN_L, LEN_H] per servo, answered in order."""
        p = frame.params
        for o in range(0, len(p) - 4, 5):
            servo_id, address, length = p[o], p[o + 1] | p[o + 2] << 8, p[o + 3] | p[o + 4] << 8
            if servo_id in self.tables:
                self._reply(servo_id, bytes(self.tables[servo_id][address:address + length]))

    def _bulk_write(self, frame: wire.Frame) -> None:
        p, o = frame.params, 0
        while o + 5 <= len(p):
            servo_id, address, length = p[o], p[o + 1] | p[o + 2] << 8, p[o + 3] | p[o + 4] << 8
            if servo_id in self.tables:
                self._store(servo_id, address, bytes(p[o + 5:o + 5 + length]))
            o += 5 + length

    def _store(self, servo_id: int, address: int, data: bytes) -> None:
        """Write the control table; unlike the ideal mock servo, present position is left to motion.

        EEPROM (below the model's first RAM address): refused with Access Error while torque is on
        (Protocol 2.0); kept over a power cycle, on Feetech only while its Lock flag is 0."""
        unit = self.units_by_id[servo_id]
        self._advance_unit(unit)
        layout, table = unit.layout, unit.table
        if address < layout.eeprom_end and self.framing == "v2" and table[unit.model.addr_torque_enable]:
            unit.pending_error = ACCESS_ERROR
            self.writes.append((unit.index, servo_id, address, bytes(data), False))
            return
        table[address:address + len(data)] = data
        if address < layout.eeprom_end:
            locked = layout.lock_addr is not None and table[layout.lock_addr] != 0
            if not locked:
                end = min(layout.eeprom_end, address + len(data))
                unit.saved[address:end] = data[:end - address]
        self.writes.append((unit.index, servo_id, address, bytes(data), True))
        self._grab_by_hand(servo_id, address, data)

    # --- replies ------------------------------------------------------------------------------
    def _status_wanted(self, servo_id: int) -> bool:
        level = self.tables[servo_id][LAYOUTS[self.models[servo_id].name].status_return_addr]
        if self._instruction == wire.INST_PING:
            return True
        is_read = self._instruction in (wire.INST_READ, wire.INST_SYNC_READ, INST_BULK_READ)
        if self.backend == "feetech":
            return level >= 1 or is_read
        return level >= 2 or (level == 1 and is_read)

    def _reply(self, servo_id: int, params: bytes, error: int | None = None) -> None:
        if not self._status_wanted(servo_id):
            return
        active = self.faults_active()
        if active and servo_id in self.faults.silent:
            return
        error = self.error_byte(servo_id) if error is None else error
        if self.framing == "v2":
            packet = bytearray(wire.build_v2(servo_id, wire.INST_STATUS_V2, bytes([error]) + params))
        else:
            packet = bytearray(wire.build_v1(servo_id, error, params))
        corrupt_ids = self.faults.corrupt_ids
        if active and self.faults.corrupt_fraction > 0 and (corrupt_ids is None or servo_id in corrupt_ids) \
                and self._rng.random() < self.faults.corrupt_fraction:
            packet[-1] ^= 0x5A  # checksum (v1) or CRC high byte (v2) no longer matches
        table, model = self.tables[servo_id], self.models[servo_id]
        delay_s = table[LAYOUTS[model.name].return_delay_addr] * 2e-6
        late_s = self.faults.late_s.get(servo_id, 0.0) if active else 0.0
        send_s = max(self.now_s, self._busy_until_s) + delay_s
        if late_s:  # a servo that is slow to answer does not hold the line while it thinks: others go on
            send_s += late_s
        else:
            rate = self._instruction_rate or self.baudrate
            self._busy_until_s = send_s + len(packet) * 10 / rate
        self.rx_packets.append(bytes(packet))
        self.outbox.append((send_s, bytes(packet), self._instruction_rate))

    def close_log(self) -> None:
        if self.goal_log is not None:
            self.goal_log.close()


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


def hand_from_ticks(path: str, rate_hz: float | None = None) -> Hand:
    """A hand from a CSV of raw ticks: a header of servo ids, then one row per sample (docs/emulator.md)."""
    import csv

    with open(path, newline="", encoding="utf-8") as f:
        rows = [row for row in csv.reader(f) if row and any(cell.strip() for cell in row)]
    if len(rows) < 2:
        raise ValueError(f"--hand-ticks {path}: needs a header of servo ids and at least one row of ticks")
    try:
        ids = [int(cell) for cell in rows[0]]
        samples = [[int(cell) for cell in row] for row in rows[1:]]
    except ValueError as exc:
        raise ValueError(f"--hand-ticks {path}: {exc} (the header holds servo ids, the rows whole ticks)") from None
    if any(len(row) != len(ids) for row in samples):
        raise ValueError(f"--hand-ticks {path}: every row needs {len(ids)} ticks, one per servo id in the header")
    return Hand({servo_id: [row[k] for row in samples] for k, servo_id in enumerate(ids)}, rate_hz)


def hand_from_trajectory(robot, path: str, rate_hz: float | None = None) -> Hand:
    """A hand playing a trajectory file (.csv/.npz): its angles through the robot's calibration, held
    joints at their hold angle. Ticks outside a servo's encoder range cannot be reported: refused."""
    ticks = trajectory_ticks(robot, Trajectory.load(path))
    for column, joint in enumerate(robot.joints):
        low, high = int(ticks[:, column].min()), int(ticks[:, column].max())
        if low < joint.model.min_tick or high > joint.model.max_tick:
            raise ValueError(f"--hand {path}: {joint.name} goes to ticks {low}..{high}, outside the "
                             f"{joint.model.name}'s {joint.model.min_tick}..{joint.model.max_tick}")
    return Hand({joint.id: ticks[:, column].tolist() for column, joint in enumerate(robot.joints)}, rate_hz)
