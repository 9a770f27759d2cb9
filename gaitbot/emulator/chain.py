"""An emulated servo chain in time: DryRunPort's chain (gaitbot.bus.dry_run: the control tables and the
bus's one packet codec) with replies scheduled by return delay and byte time, servos that move at their
no-load speed, units that can be plugged in and out, and EEPROM that survives a power cycle. Faults, heat
and the supply, the scripted hand and the extra instructions are its mixins (faults, heat, hand,
instructions); gaitbot.emulator.pty serves it on a pseudo-terminal."""

from __future__ import annotations

import math
import random
import time
from collections import deque

from gaitbot.bus.dry_run import DryRunPort, rates_match
from gaitbot.bus.recording import BusRecorder
from gaitbot.emulator.config import EmulatorConfig
from gaitbot.emulator.faults import FaultInjection
from gaitbot.emulator.hand import ScriptedHand
from gaitbot.emulator.heat import HeatAndSupply
from gaitbot.emulator.instructions import MoreInstructions
from gaitbot.emulator.state import write_state
from gaitbot.emulator.units import ACCESS_ERROR, LAYOUTS, Servo
from gaitbot.servos import baud_register_value, vendor, wire
from gaitbot.servos.health import health_block


class EmulatedChain(FaultInjection, HeatAndSupply, ScriptedHand, MoreInstructions, DryRunPort):
    """DryRunPort's chain with time: replies are scheduled, servos move, warm and cool, faults apply.

    Feed received bytes with ``receive(data, now_s)``; take due replies with ``due(now_s)``. ``line_baud``
    is the host's rate (None: every servo hears). ``units`` are the servos, plugged in or not; ``tables``
    and ``models`` map the ids that hear the line to theirs (DryRunPort's view, rebuilt for each packet).
    ``writes`` lists every WRITE a servo received: (servo index, its id, address, data, accepted).
    """

    def __init__(self, config: EmulatorConfig) -> None:
        super().__init__(config.backend, config.protocol, {})
        self.tx_packets = deque(maxlen=256)  # DryRunPort keeps every packet; a long run needs only the latest
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
        self.state_changed = False  # an EEPROM write was kept since the state file was last saved
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
        self.save_state()
        if config.log_path:
            joints = config.joints or {f"servo_{i}": i for i in config.models}
            self.goal_log = BusRecorder(config.log_path, robot=config.robot, joints=joints, clock=time.monotonic)
            self.goal_log.start(backend=config.backend, protocol=config.protocol, baudrate=config.baudrate,
                                models=config.models or {u.servo_id: u.model for u in self.units})

    def _make_units(self, config: EmulatorConfig) -> list[Servo]:
        fresh = bool(config.fresh or config.restored)
        if config.restored:
            entries = [(eeprom[LAYOUTS[m.name].id_addr], m) for m, eeprom in config.restored]
        elif fresh:
            entries = [(vendor(m.family).FACTORY_ID, m) for m in config.fresh]
        else:
            entries = list(config.models.items())
        units = []
        for index, (servo_id, model) in enumerate(entries):
            start = config.start_ticks.get(servo_id, model.centre_tick) if not config.fresh else model.centre_tick
            table = DryRunPort.initial_table(model, servo_id, None if fresh else config.baudrate)
            DryRunPort.place(model, table, start)
            if config.restored:  # the EEPROM as the servo kept it (its id, rate, limits ...)
                eeprom = config.restored[index][1][:LAYOUTS[model.name].eeprom_end]
                table[:len(eeprom)] = eeprom
            if servo_id in config.model_numbers and not fresh:  # a servo of another model behind this one's table
                number = model.control_table["Model Number"]
                table[number.address:number.address + number.size] = \
                    config.model_numbers[servo_id].to_bytes(number.size, model.byte_order)
            layout = LAYOUTS[model.name]
            if config.return_delay_us is not None:
                table[layout.return_delay_addr] = min(254, int(round(config.return_delay_us / 2)))
            blind = not fresh and baud_register_value(model.name, config.baudrate) is None
            ambient = config.heat.ambient_c
            units.append(Servo(index, model, table, bytearray(table[:layout.eeprom_end]), float(start),
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

    def save_state(self) -> None:
        """Keep every servo's EEPROM as saved in the state file, if one was asked for (gaitbot.emulator.state)."""
        self.state_changed = False
        if self.config.state_path:
            write_state(self.config.state_path, self.config.backend, self.config.protocol,
                        [(u.model, bytes(u.saved)) for u in self.units])

    def power_cycle(self) -> None:
        """Power off and on: the EEPROM as saved, RAM back to its power-on values, torque off."""
        for unit in self.units:
            layout = unit.layout
            fresh = DryRunPort.initial_table(unit.model, unit.servo_id)
            fresh[:layout.eeprom_end] = unit.saved
            for name, register in unit.model.control_table.items():
                if register.address >= layout.eeprom_end and register.factory is None and \
                        name not in ("Goal Position", "Present Position"):
                    fresh[register.address:register.address + register.size] = bytes(register.size)
            unit.table[:] = fresh
            unit.shown = None
        self._route()

    # --- time -----------------------------------------------------------------------------
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

    # --- motion ---------------------------------------------------------------------------
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

    # --- instruction handling (DryRunPort's, extended) ---------------------------------------
    def _answer(self, raw: bytes, frame: wire.Frame) -> None:
        if self.first_packet_s is None:
            self.first_packet_s = self.now_s
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
        """The IMU device's status packet, on the line after what is already on it (its Return Delay Time is 0).
        Its scripted motion, fall and fault run on the time since the line's first packet, as --imu-fall-at-s
        and --imu-fault say (the pty's clock is the host's monotonic one)."""
        packet = self.config.imu.answer(frame, self.now_s - self.first_packet_s)
        if packet is None:
            return
        send_s = max(self.now_s, self._busy_until_s)
        self._busy_until_s = send_s + len(packet) * 10 / (self.line_baud or self.baudrate)
        self.rx_packets.append(packet)
        self.outbox.append((send_s, packet, self.line_baud))

    def _log_goals(self, raw: bytes, frame: wire.Frame) -> None:
        if frame.instruction != wire.INST_SYNC_WRITE:
            return
        address, _ = self._address_and_rest(frame.params)
        if self.units and address == self.units[0].model.addr_goal_position:  # whoever hears it
            self.goal_frames += 1
            if self.goal_log is not None:
                self.goal_log.log("tx", raw)

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
                self.state_changed = True  # saved once the replies are out (ServoEmulator.serve), not in their way
        self.writes.append((unit.index, servo_id, address, bytes(data), True))
        self._grab_by_hand(servo_id, address, data)

    # --- replies ------------------------------------------------------------------------------
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
