"""The scripted hand of an emulated chain: it takes the legs at the first torque-off write and moves the
servos whose torque is off through its samples (ticks per servo: gaitbot.emulator.config.Hand), one sample
per read cycle or with time. A mixin of :class:`~gaitbot.emulator.chain.EmulatedChain`."""

from __future__ import annotations

from gaitbot.servos import wire
from gaitbot.servos.wire import INST_BULK_READ


class ScriptedHand:
    """Advancing the hand, and the reads that count as one of its samples."""

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
