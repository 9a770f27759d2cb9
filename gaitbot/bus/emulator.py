"""A servo chain in time, with faults and a scripted hand: the engine behind tools/servo_emulator.py.

``ServoEmulator(EmulatorConfig(...))`` opens a pty pair and answers on it like a chain of Dynamixel
or Feetech servos (``start()`` serves it on a background thread; ``path`` is the device a driver
opens; ``stop()``, ``chain``, ``wait_closed()``). ``EmulatedChain`` is the chain alone, fed with
``receive(data, now_s)`` and read with ``due(now_s)``, for tests without a pty.

Instruction parsing, framing and the control tables are the mock's (gaitbot.bus.mock.MockPort, the
chain a dry run talks to) and the vendors' (gaitbot.servos); this module adds time (return delay,
byte time, motion at the no-load speed), the Status Return Level, the instructions a dry run never
sends (reg write, action, reboot, bulk read/write), faults (silent, late, corrupt, error bits, a port
that disappears) and a hand that moves servos whose torque is off. docs/emulator.md describes it;
gaitbot.app.emulator is its command line.
"""

from __future__ import annotations

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
from gaitbot.bus.mock import MockPort
from gaitbot.gait.trajectory import Trajectory
from gaitbot.robot.calibration import angles_to_ticks
from gaitbot.servos import dynamixel, wire
from gaitbot.servos.models import SERVO_MODELS, ServoModel
from gaitbot.servos.wire import INST_ACTION, INST_BULK_READ, INST_BULK_WRITE, INST_REBOOT, INST_REG_WRITE

FAULT_KINDS = ("overload", "overheating", "voltage")


@dataclass(frozen=True)
class Layout:
    """Control-table addresses the emulator needs beyond ServoModel's, and the factory values it starts
    with (address, size, value): all read from the vendor's control table (gaitbot.servos)."""

    id_addr: int
    return_delay_addr: int
    status_return_addr: int
    moving_addr: int
    hardware_error_addr: int | None  # Dynamixel 2.0 Hardware Error Status
    initial: tuple[tuple[int, int, int], ...]

    @classmethod
    def of(cls, model: ServoModel) -> "Layout":
        table = model.control_table
        hardware = table.get("Hardware Error Status")
        return cls(table["ID"].address, table["Return Delay Time"].address, table["Status Return Level"].address,
                   table["Moving"].address, hardware.address if hardware is not None else None,
                   tuple((r.address, r.size, r.factory) for r in table.values() if r.factory is not None))


LAYOUTS = {name: Layout.of(model) for name, model in SERVO_MODELS.items()}


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


class EmulatedChain(MockPort):
    """MockPort's chain with time: replies are scheduled, servos move, faults apply.

    Feed received bytes with ``receive(data, now_s)``; take due replies with ``due(now_s)``.
    """

    def __init__(self, config: EmulatorConfig) -> None:
        super().__init__(config.backend, config.protocol, config.models)
        self.tx_packets = deque(maxlen=256)  # MockPort keeps every packet; a long run needs only the latest
        self.config = config
        self.faults = config.faults
        self.baudrate = config.baudrate
        self.now_s = 0.0
        self.first_packet_s: float | None = None
        self.goal_frames = 0
        self.goal_log: BusRecorder | None = None
        self.outbox: list[tuple[float, bytes]] = []
        self._busy_until_s = 0.0
        self._instruction = 0
        self._rng = random.Random(config.seed)
        self._registered: dict[int, tuple[int, bytes]] = {}
        self._present = {i: float(m.centre_tick) for i, m in self.models.items()}
        self.hand = config.hand
        self.hand_sample = 0
        self._hand_grabbed_s: float | None = None  # when the first torque-off came; None: not yet
        self._hand_read: set[int] = set()  # servos read at the current hand sample
        self._moved_at_s = {i: 0.0 for i in self.models}
        for servo_id, model in self.models.items():
            layout = LAYOUTS[model.name]
            table = self.tables[servo_id]
            for address, size, value in layout.initial:
                table[address:address + size] = value.to_bytes(size, model.byte_order)
            table[layout.id_addr] = servo_id
            if config.return_delay_us is not None:
                table[layout.return_delay_addr] = min(254, int(round(config.return_delay_us / 2)))
        if config.log_path:
            joints = config.joints or {f"servo_{i}": i for i in self.models}
            self.goal_log = BusRecorder(config.log_path, robot=config.robot, joints=joints, clock=time.monotonic)
            self.goal_log.start(backend=config.backend, protocol=config.protocol, baudrate=config.baudrate,
                                models=self.models)

    # --- time and faults ------------------------------------------------------------------
    def receive(self, data: bytes, now_s: float) -> None:
        self.now_s = now_s
        self.writePort(data)

    def due(self, now_s: float) -> list[bytes]:
        ready = [packet for t_s, packet in self.outbox if t_s <= now_s]
        self.outbox = [(t_s, packet) for t_s, packet in self.outbox if t_s > now_s]
        return ready

    def next_due_s(self) -> float | None:
        return min((t_s for t_s, _ in self.outbox), default=None)

    def faults_active(self) -> bool:
        if self.first_packet_s is None or self.goal_frames < self.faults.after_frames:
            return False
        return self.now_s - self.first_packet_s >= self.faults.after_s

    def should_close(self, now_s: float) -> bool:
        f = self.faults
        if f.close_after_frames is not None and self.goal_frames >= f.close_after_frames:
            return True
        return (f.close_after_s is not None and self.first_packet_s is not None
                and now_s - self.first_packet_s >= f.close_after_s)

    def error_byte(self, servo_id: int) -> int:
        kinds = self.faults.errors.get(servo_id, set()) if self.faults_active() else set()
        if not kinds:
            return 0
        if self.framing == "v2":
            return dynamixel.V2_ALERT
        bits = self.vendor  # Protocol 1.0 and Feetech: the same bits
        return ((bits.ERRBIT_OVERLOAD if "overload" in kinds else 0)
                | (bits.ERRBIT_OVERHEATING if "overheating" in kinds else 0)
                | (bits.ERRBIT_INPUT_VOLTAGE if "voltage" in kinds else 0))

    def _apply_error_faults(self) -> None:
        if not self.faults_active():
            return
        for servo_id, kinds in self.faults.errors.items():
            if servo_id not in self.tables or not kinds:
                continue
            model, table = self.models[servo_id], self.tables[servo_id]
            layout = LAYOUTS[model.name]
            if layout.hardware_error_addr is not None:
                bits = {name: bit for bit, name in dynamixel.HARDWARE_ERROR_BITS[model.name].items()}
                value = sum(bits["input voltage" if k == "voltage" else k] for k in kinds)
                table[layout.hardware_error_addr] = value
            if kinds & {"overload", "overheating"} and table[model.addr_torque_enable]:
                self._advance(servo_id)
                table[model.addr_torque_enable] = 0  # the shutdown the servos do by default

    # --- motion ---------------------------------------------------------------------------
    def _advance(self, servo_id: int) -> None:
        """Move present position towards goal at the no-load speed, up to now."""
        model, table = self.models[servo_id], self.tables[servo_id]
        dt_s = max(0.0, self.now_s - self._moved_at_s[servo_id])
        self._moved_at_s[servo_id] = self.now_s
        goal = int.from_bytes(table[model.addr_goal_position:model.addr_goal_position + model.len_goal_position],
                              model.byte_order, signed=model.len_goal_position == 4)
        present = self._present[servo_id]
        if not table[model.addr_torque_enable] and self._hand_grabbed_s is not None and servo_id in self.hand.ticks:
            script = self.hand.ticks[servo_id]
            present = self._present[servo_id] = float(script[min(self.hand_sample, len(script) - 1)])
        elif table[model.addr_torque_enable]:
            step = model.no_load_speed_dps * model.ticks_per_rad * (math.pi / 180.0) * dt_s
            present = goal if abs(goal - present) <= step else present + step * (1 if goal > present else -1)
            self._present[servo_id] = present
        length = model.len_present_position
        value = int(round(present))
        table[model.addr_present_position:model.addr_present_position + length] = \
            value.to_bytes(length, model.byte_order, signed=length == 4)
        table[LAYOUTS[model.name].moving_addr] = int(round(present) != goal and bool(table[model.addr_torque_enable]))

    # --- instruction handling (MockPort's, extended) --------------------------------------
    def _answer(self, raw: bytes) -> None:
        if self.first_packet_s is None:
            self.first_packet_s = self.now_s
        frame = wire.parse(raw, self.framing, status=False)
        if frame.checksum_ok and self._hand_grabbed_s is not None:
            self._move_hand(frame)
        for servo_id in self.models:
            self._advance(servo_id)
        self._apply_error_faults()
        if not frame.checksum_ok:
            self.rejected.append((raw, frame.problem))
            return
        if self.framing == "v2" and frame.instruction == wire.INST_STATUS_V2:
            return  # a status packet on the line is not for us
        self._instruction = frame.instruction
        extra = {INST_REG_WRITE: self._reg_write, INST_ACTION: self._action, INST_REBOOT: self._reboot}
        if self.framing == "v2":
            extra.update({INST_BULK_READ: self._bulk_read, INST_BULK_WRITE: self._bulk_write})
        if frame.instruction == wire.INST_SYNC_READ and self.backend == "dynamixel" and self.protocol == 1.0:
            extra[wire.INST_SYNC_READ] = self._unsupported  # AX firmware has no sync read
        handler = extra.get(frame.instruction)
        if handler is not None:
            handler(frame)
        elif frame.instruction in (wire.INST_PING, wire.INST_READ, wire.INST_WRITE, wire.INST_SYNC_WRITE,
                                   wire.INST_SYNC_READ):
            super()._answer(raw)
        else:
            self._unsupported(frame)
        self._log_goals(raw, frame)

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
        """Servo ids whose present position this instruction reads (read, sync read, bulk read)."""
        first = next(iter(self.models.values()))
        wanted = first.addr_present_position

        def covers(address: int, length: int) -> bool:
            return address <= wanted < address + length

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
        first = next(iter(self.models.values()))
        if address == first.addr_goal_position:
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
            if hw is not None:
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
        """Write the control table; unlike the ideal mock servo, present position is left to motion."""
        self._advance(servo_id)
        self.tables[servo_id][address:address + len(data)] = data
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
            self._busy_until_s = send_s + len(packet) * 10 / self.baudrate
        self.rx_packets.append(bytes(packet))
        self.outbox.append((send_s, bytes(packet)))

    def close_log(self) -> None:
        if self.goal_log is not None:
            self.goal_log.close()


class ServoEmulator:
    """The chain on a pty: ``start()`` serves it on a thread, ``path`` is the device to open."""

    def __init__(self, config: EmulatorConfig) -> None:
        self.chain = EmulatedChain(config)
        self.master_fd, self.slave_fd = os.openpty()
        tty.setraw(self.slave_fd)  # no echo, no line editing: bytes pass untouched until a driver opens it
        self.path = os.ttyname(self.slave_fd)
        os.set_blocking(self.master_fd, False)
        self.closed_reason = ""
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
                for packet in chain.due(now_s):
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


def hand_from_trajectory(robot, path: str, rate_hz: float | None = None) -> Hand:
    """A hand playing a trajectory file (.csv/.npz): its angles through the robot's calibration, held
    joints at their hold angle. Ticks outside a servo's encoder range cannot be reported: refused."""
    ticks = angles_to_ticks(robot, Trajectory.load(path).angles_rad)
    for column, joint in enumerate(robot.joints):
        low, high = int(ticks[:, column].min()), int(ticks[:, column].max())
        if low < joint.model.min_tick or high > joint.model.max_tick:
            raise ValueError(f"--hand {path}: {joint.name} goes to ticks {low}..{high}, outside the "
                             f"{joint.model.name}'s {joint.model.min_tick}..{joint.model.max_tick}")
    return Hand({joint.id: ticks[:, column].tolist() for column, joint in enumerate(robot.joints)}, rate_hz)
