"""Injected faults of an emulated chain: silent, late and damaged replies, error bits (configured, or the
servos' own from heat and the supply: gaitbot.emulator.heat), collisions of servos answering at once, and
a port that disappears. A mixin of :class:`~gaitbot.emulator.chain.EmulatedChain`."""

from __future__ import annotations

from gaitbot.servos import dynamixel, wire


class FaultInjection:
    """When faults are active, which errors a servo reports, and what replies that collide become."""

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
