"""The instructions an emulated chain answers beyond the dry-run port's (gaitbot.bus.dry_run): reg write,
action, reboot, bulk read and write, an instruction error for what the firmware lacks, and the Status
Return Level deciding which instructions get a status packet. A mixin of
:class:`~gaitbot.emulator.chain.EmulatedChain`."""

from __future__ import annotations

from gaitbot.emulator.units import LAYOUTS
from gaitbot.servos import has_sync_read, wire
from gaitbot.servos.wire import INST_ACTION, INST_BULK_READ, INST_BULK_WRITE, INST_REBOOT, INST_REG_WRITE


class MoreInstructions:
    """Dispatching an instruction packet, and the instructions a dry run never sends."""

    def _handle(self, frame: wire.Frame, raw: bytes) -> None:
        extra = {INST_REG_WRITE: self._reg_write, INST_ACTION: self._action, INST_REBOOT: self._reboot}
        if self.framing == "v2":
            extra.update({INST_BULK_READ: self._bulk_read, INST_BULK_WRITE: self._bulk_write})
        if self.units and not has_sync_read(self.backend, self.protocol, self.units[0].model.byte_order):
            extra[wire.INST_SYNC_READ] = self._unsupported  # e.g. AX firmware has no sync read
        if frame.packet_id == wire.BROADCAST_ID and self.protocol not in self.vendor.BROADCAST_PING:
            extra[wire.INST_PING] = lambda _frame: None  # e.g. Dynamixel 1.0: no status to a broadcast ping
        handler = extra.get(frame.instruction)
        if handler is not None:
            handler(frame)
        elif frame.instruction in (wire.INST_PING, wire.INST_READ, wire.INST_WRITE, wire.INST_SYNC_WRITE,
                                   wire.INST_SYNC_READ):
            super()._answer(raw, frame)
        else:
            self._unsupported(frame)

    def _unsupported(self, frame: wire.Frame) -> None:
        if frame.packet_id in self.tables:
            error = self.vendor.INSTRUCTION_ERROR[self.protocol]
            self._reply(frame.packet_id, b"", error=error)

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
            if hw is not None and self.vendor.REBOOT_CLEARS_HARDWARE_ERROR:
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

    def _status_wanted(self, servo_id: int) -> bool:
        level = self.tables[servo_id][LAYOUTS[self.models[servo_id].name].status_return_addr]
        if self._instruction == wire.INST_PING:
            return True
        is_read = self._instruction in (wire.INST_READ, wire.INST_SYNC_READ, INST_BULK_READ)
        return level >= self.vendor.STATUS_RETURN_ALL_FROM or (is_read and level >= self.vendor.STATUS_RETURN_READS_FROM)
