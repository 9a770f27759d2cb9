"""A servo chain on a pseudo-terminal: run ``gaitbot walk --port <pty>`` without hardware.

Opens a pty pair, prints the device path (the end a driver opens) as the first line of its
output, and answers like a chain of Dynamixel or Feetech servos:

    python tools/servo_emulator.py --robot config/xl430-biped.toml --log goals.jsonl
    python tools/servo_emulator.py --protocol dxl2 --ids 1-6 --late 3:60
    gaitbot walk --robot config/xl430-biped.toml --distance 0.3 --port /dev/pts/N

What it emulates, per servo, from the protocol documents (ROBOTIS e-Manual Protocol 1.0 / 2.0,
Feetech SCS/STS protocol manual):

* a control table with the model's real addresses (model number, firmware, id, baud rate, return
  delay, status return level, torque enable, goal/present position, voltage, temperature, moving,
  hardware error status, and the gain register at its factory value: a session's gain writes stay
  in the table, to be read back);
* ping, read, write, reg write + action, sync write, sync read (Dynamixel 2.0 and Feetech; AX-12A
  firmware has none), bulk read and bulk write (Dynamixel 2.0), reboot; other instructions get an
  Instruction Error status; damaged packets (bad checksum/CRC) get no answer; broadcast gets no
  status (except ping);
* status packets with the right checksum or CRC, Dynamixel 2.0 byte stuffing both ways, each
  servo's Return Delay Time (x 2 us) and the byte time at the configured baud rate, replies of a
  sync/bulk read one after the other in the requested order;
* the Status Return Level register (Dynamixel: 0 ping only, 1 ping and reads, 2 all; Feetech:
  0 ping and reads, 1 all);
* motion: with torque on, present position moves towards goal position at the model's no-load
  speed, so reads show a moving servo.

Instruction parsing, packet framing and the control-table basics are gaitbot.bus.mock.MockPort's
(the same chain the dry run talks to); this module adds time, motion and faults on a real pty.

Faults (command line or ``EmulatorConfig`` from tests); all start after ``--fault-after-frames``
goal frames and ``--fault-after-s`` seconds from the first packet received (default: at once):

* ``--silent ID``: the servo never answers;
* ``--late ID:MS``: the servo answers MS milliseconds late;
* ``--corrupt FRACTION[:ID]``: that fraction of status packets (of one servo, or of all) has a bad
  checksum/CRC (seeded by ``--seed``);
* ``--error ID:KIND[+KIND]``, KIND in overload, overheating, voltage: status packets carry the
  error bits (Dynamixel 2.0: the Alert bit and Hardware Error Status); overload and overheating
  also switch the servo's torque off, as the servos' shutdown settings do by default;
* ``--close-after-frames N`` / ``--close-after-s T``: the port disappears (the pty master is
  closed and the emulator exits) after N goal frames or T seconds from the first packet.

A scripted hand (``--hand FILE``, a trajectory .csv/.npz turned into ticks by ``--robot``'s
calibration, or ``Hand`` from tests) moves the servos while their torque is off, as a person moving
the legs for ``gaitbot record`` would: from the first torque-off write, a servo with torque off
reports the hand's current sample as its present position. The hand advances one sample per read
cycle (a present-position read of a servo already read at this sample starts the next one; sync
reads, bulk reads and one read per servo all count the same way), so a recording sees every sample
exactly once whatever the host's timing; with ``--hand-rate HZ`` it advances with time instead.
After its last sample the hand stays there.

``--log goals.jsonl`` writes every goal-position packet received in the bus recording format
(gaitbot.bus.recording), so ``gaitbot.bus.log_decoder.decode_goal_frames`` reads it back.

Importable: ``ServoEmulator(EmulatorConfig(...))`` with ``start()`` (a background thread),
``path``, ``stop()``, ``chain`` (the emulated servos) and ``wait_closed()``.
"""

from __future__ import annotations

import argparse
import os
import random
import select
import sys
import threading
import time
import tty
from collections import deque
from dataclasses import dataclass, field

try:
    from gaitbot.bus import wire
except ImportError:  # run from a checkout without installing
    sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), os.pardir))
    from gaitbot.bus import wire

from gaitbot.bus.mock import MockPort
from gaitbot.bus.recording import BusRecorder
from gaitbot.bus.status import ERRBIT_INPUT_VOLTAGE, ERRBIT_OVERHEATING, ERRBIT_OVERLOAD, HARDWARE_ERROR_STATUS
from gaitbot.robot.servo_models import ServoModel, servo_model

#: --protocol name -> (backend, protocol, default model)
PROTOCOLS = {"dxl1": ("dynamixel", 1.0, "AX-12A"), "dxl2": ("dynamixel", 2.0, "XL430-W250"),
             "feetech-sts": ("feetech", 1.0, "STS3215"), "feetech-scs": ("feetech", 1.0, "SCS0009")}

INST_REG_WRITE, INST_ACTION, INST_REBOOT = 0x04, 0x05, 0x08
INST_BULK_READ, INST_BULK_WRITE = 0x92, 0x93
V2_ALERT, V2_INSTRUCTION_ERROR, V1_INSTRUCTION_ERROR = 0x80, 0x02, 0x40
FAULT_KINDS = ("overload", "overheating", "voltage")


@dataclass(frozen=True)
class Layout:
    """Control-table addresses beyond ServoModel's, and factory values (address, size, value)."""

    id_addr: int
    return_delay_addr: int
    status_return_addr: int
    moving_addr: int
    hardware_error_addr: int | None  # Dynamixel 2.0 Hardware Error Status
    initial: tuple[tuple[int, int, int], ...]


# Sources: ROBOTIS e-Manual control tables (XL430-W250, XM430-W350, XL-320, AX-12A); Feetech SMS/STS
# and SCSCL memory tables (as transcribed in LeRobot's feetech tables.py).
_X = Layout(7, 9, 68, 122, 70, ((6, 1, 46), (8, 1, 3), (9, 1, 250), (11, 1, 3), (13, 1, 2), (31, 1, 72),
                                (32, 2, 140), (34, 2, 60), (48, 4, 4095), (52, 4, 0), (63, 1, 0x34),
                                (68, 1, 2), (144, 2, 120), (146, 1, 30)))
LAYOUTS = {
    "XL430-W250": _X,
    "XM430-W350": _X,
    "XL-320": Layout(3, 5, 17, 49, 50, ((2, 1, 30), (4, 1, 3), (5, 1, 250), (8, 2, 1023), (11, 1, 2), (12, 1, 65),
                                        (13, 1, 60), (14, 1, 90), (15, 2, 1023), (17, 1, 2), (18, 1, 3),
                                        (45, 1, 74), (46, 1, 30))),
    "AX-12A": Layout(3, 5, 16, 46, None, ((2, 1, 24), (4, 1, 1), (5, 1, 250), (8, 2, 1023), (11, 1, 70),
                                          (12, 1, 60), (13, 1, 140), (14, 2, 1023), (16, 1, 2), (17, 1, 0x24),
                                          (18, 1, 0x24), (34, 2, 1023), (42, 1, 120), (43, 1, 30))),
    "STS3215": Layout(5, 7, 8, 66, None, ((0, 1, 3), (1, 1, 9), (6, 1, 0), (7, 1, 0), (8, 1, 1), (11, 2, 4095),
                                          (13, 1, 70), (14, 1, 140), (15, 1, 40), (16, 2, 1000), (62, 1, 74),
                                          (63, 1, 30))),
    "SCS0009": Layout(5, 7, 8, 66, None, ((0, 1, 3), (1, 1, 9), (6, 1, 0), (7, 1, 0), (8, 1, 1), (11, 2, 1023),
                                          (13, 1, 70), (14, 1, 80), (15, 1, 40), (16, 2, 1000), (62, 1, 60),
                                          (63, 1, 30))),
}


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
            return V2_ALERT
        return ((ERRBIT_OVERLOAD if "overload" in kinds else 0) | (ERRBIT_OVERHEATING if "overheating" in kinds else 0)
                | (ERRBIT_INPUT_VOLTAGE if "voltage" in kinds else 0))

    def _apply_error_faults(self) -> None:
        if not self.faults_active():
            return
        for servo_id, kinds in self.faults.errors.items():
            if servo_id not in self.tables or not kinds:
                continue
            model, table = self.models[servo_id], self.tables[servo_id]
            layout = LAYOUTS[model.name]
            if layout.hardware_error_addr is not None:
                bits = {name: bit for bit, name in HARDWARE_ERROR_STATUS[model.name][1].items()}
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
            step = model.no_load_speed_dps * model.ticks_per_rad * (3.141592653589793 / 180.0) * dt_s
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
            address, rest = self._address_and_rest(p)
            length = rest[0] | (rest[1] << 8 if v2 else 0)
            return [frame.packet_id] if frame.packet_id in self.tables and covers(address, length) else []
        if frame.instruction == wire.INST_SYNC_READ:
            address, rest = self._address_and_rest(p)
            length, ids = (rest[0] | rest[1] << 8, rest[2:]) if v2 else (rest[0], rest[1:])
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
            error = V2_INSTRUCTION_ERROR if self.framing == "v2" else V1_INSTRUCTION_ERROR
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
        if active:
            delay_s += self.faults.late_s.get(servo_id, 0.0)
        send_s = max(self.now_s, self._busy_until_s) + delay_s
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


# --- command line ---------------------------------------------------------------------------
def parse_ids(text: str) -> list[int]:
    """``1-6`` / ``1,2,5`` / ``9-16,20`` -> ids."""
    ids: list[int] = []
    for part in text.split(","):
        part = part.strip()
        if "-" in part:
            low, high = (int(x) for x in part.split("-", 1))
            ids.extend(range(low, high + 1))
        elif part:
            ids.append(int(part))
    if not ids or len(set(ids)) != len(ids) or not all(0 <= i <= 252 for i in ids):
        raise ValueError(f"--ids {text!r}: give distinct ids 0..252, e.g. 1-6 or 1,2,5")
    return ids


def _id_value(text: str, what: str) -> tuple[int, str]:
    servo_id, sep, value = text.partition(":")
    if not sep:
        raise ValueError(f"{what} {text!r}: expected ID:VALUE")
    return int(servo_id), value


def config_from_args(args: argparse.Namespace) -> EmulatorConfig:
    faults = Faults(after_frames=args.fault_after_frames, after_s=args.fault_after_s,
                    close_after_frames=args.close_after_frames, close_after_s=args.close_after_s)
    faults.silent = set(args.silent or [])
    for item in args.late or []:
        servo_id, value = _id_value(item, "--late")
        faults.late_s[servo_id] = float(value) / 1000.0
    if args.corrupt:
        fraction, _, which = args.corrupt.partition(":")
        faults.corrupt_fraction = float(fraction)
        faults.corrupt_ids = {int(which)} if which else None
        if not 0.0 <= faults.corrupt_fraction <= 1.0:
            raise ValueError(f"--corrupt {args.corrupt!r}: the fraction must be within 0..1")
    for item in args.error or []:
        servo_id, value = _id_value(item, "--error")
        kinds = set(value.split("+"))
        if not kinds <= set(FAULT_KINDS):
            raise ValueError(f"--error {item!r}: kinds are {', '.join(FAULT_KINDS)} (join with +)")
        faults.errors[servo_id] = kinds
    if args.robot:
        from gaitbot.robot.config import load_robot_config, resolve_config

        robot = load_robot_config(resolve_config(args.robot))
        hand = hand_from_trajectory(robot, args.hand, args.hand_rate) if args.hand else None
        return EmulatorConfig(robot.bus.backend, robot.bus.protocol, robot.models_by_id,
                              args.baudrate or robot.bus.baudrate, faults, args.log, robot.name,
                              {j.name: j.id for j in robot.joints}, args.seed, args.return_delay_us, hand)
    if args.hand:
        raise ValueError("--hand needs --robot (its calibration turns the trajectory's angles into ticks)")
    if not args.protocol:
        raise ValueError("give --robot CONFIG or --protocol dxl1|dxl2|feetech-sts|feetech-scs with --ids")
    backend, protocol, default_model = PROTOCOLS[args.protocol]
    model = servo_model(args.model or default_model)
    if model.family != backend or protocol not in model.protocols:
        raise ValueError(f"--model {model.name} does not speak {args.protocol}")
    models = {i: model for i in parse_ids(args.ids)}
    return EmulatorConfig(backend, protocol, models, args.baudrate or 1_000_000, faults, args.log,
                          seed=args.seed, return_delay_us=args.return_delay_us)


def hand_from_trajectory(robot, path: str, rate_hz: float | None = None) -> Hand:
    """A hand playing a trajectory file (.csv/.npz): its angles through the robot's calibration, held
    joints at their hold angle. Ticks outside a servo's encoder range cannot be reported: refused."""
    from gaitbot.gait.trajectory import Trajectory
    from gaitbot.robot.calibration import angles_to_ticks

    ticks = angles_to_ticks(robot, Trajectory.load(path).angles_rad)
    for column, joint in enumerate(robot.joints):
        low, high = int(ticks[:, column].min()), int(ticks[:, column].max())
        if low < joint.model.min_tick or high > joint.model.max_tick:
            raise ValueError(f"--hand {path}: {joint.name} goes to ticks {low}..{high}, outside the "
                             f"{joint.model.name}'s {joint.model.min_tick}..{joint.model.max_tick}")
    return Hand({joint.id: ticks[:, column].tolist() for column, joint in enumerate(robot.joints)}, rate_hz)


def build_parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(description="Emulate a Dynamixel/Feetech servo chain on a pty "
                                            "(the first line printed is the device path).")
    p.add_argument("--robot", help="robot config (.toml path or shipped name): its bus and servos")
    p.add_argument("--protocol", choices=sorted(PROTOCOLS), help="without --robot: the chain's protocol")
    p.add_argument("--ids", default="1-6", help="without --robot: servo ids, e.g. 1-6 or 1,2,5 (default 1-6)")
    p.add_argument("--model", help="without --robot: servo model (default per protocol)")
    p.add_argument("--baudrate", type=int, help="byte time of replies (default: the config's or 1000000)")
    p.add_argument("--return-delay-us", type=float, help="override every servo's Return Delay Time")
    p.add_argument("--log", help="write every goal packet received to this .jsonl (bus recording format)")
    p.add_argument("--seed", type=int, default=0, help="random seed of --corrupt")
    p.add_argument("--silent", type=int, action="append", metavar="ID", help="this servo never answers")
    p.add_argument("--late", action="append", metavar="ID:MS", help="this servo answers MS ms late")
    p.add_argument("--corrupt", metavar="FRACTION[:ID]", help="damage this fraction of replies (of one servo)")
    p.add_argument("--error", action="append", metavar="ID:KIND[+KIND]",
                   help=f"status error bits on this servo's replies; KIND in {', '.join(FAULT_KINDS)}")
    p.add_argument("--fault-after-frames", type=int, default=0, help="faults start after this many goal frames")
    p.add_argument("--fault-after-s", type=float, default=0.0, help="faults start this long after the first packet")
    p.add_argument("--close-after-frames", type=int, help="the port disappears after this many goal frames")
    p.add_argument("--close-after-s", type=float, help="the port disappears this long after the first packet")
    p.add_argument("--hand", metavar="FILE", help="with --robot: a trajectory (.csv/.npz) a hand plays on the servos "
                   "while their torque is off, one sample per read cycle")
    p.add_argument("--hand-rate", type=float, metavar="HZ", help="advance the --hand script with time at HZ instead")
    return p


def main(argv: list[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    try:
        config = config_from_args(args)
    except (ValueError, KeyError, OSError) as exc:
        print(f"servo_emulator: error: {exc}", file=sys.stderr)
        return 2
    emulator = ServoEmulator(config)
    print(emulator.path, flush=True)
    names = sorted({m.name for m in config.models.values()})
    print(f"emulating {len(config.models)} {'/'.join(names)} servos (ids {sorted(config.models)}) on "
          f"{config.backend} protocol {config.protocol}; Ctrl-C to stop", file=sys.stderr, flush=True)
    try:
        emulator.serve()
    except KeyboardInterrupt:
        pass
    finally:
        emulator.stop()
    if emulator.closed_reason:
        print(f"servo_emulator: {emulator.closed_reason}", file=sys.stderr)
    if config.log_path:
        print(f"servo_emulator: {emulator.chain.goal_frames} goal frames logged to {config.log_path}",
              file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
