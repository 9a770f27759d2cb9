"""The per-frame read-back of a walk session on an SDK bus: one READ of one servo that waits at most what is
left of the frame, never retried (docs/bus-faults.md, "The read-back").

A mixin of :class:`~gaitbot.bus.sdk_bus.SdkBus`: it uses the bus's port, packet handler, clock and
:class:`~gaitbot.bus.late_replies.LateReplies`.
"""

from __future__ import annotations

import time

from gaitbot.bus.base import ReadBack, ReadBackOutcome
from gaitbot.bus.packets import is_status_of, take_packets
from gaitbot.servos import wire

#: A read-back with less budget than this left in its frame is not sent (outcome "skipped").
MIN_READ_BACK_BUDGET_S = 0.5e-3
#: Before torque goes off after abandoned read-backs, the bus waits at most this long for the line to go quiet.
QUIET_WAIT_S = 0.25


class BudgetedReadBack:
    """``read_back`` and ``set_read_back_blocks`` of an SDK bus."""

    MIN_READ_BACK_BUDGET_S = MIN_READ_BACK_BUDGET_S

    def set_read_back_blocks(self, blocks: dict[int, tuple[int, int]]) -> None:
        for servo_id, (address, length) in blocks.items():
            start, size = self._present
            if not (address <= start and start + size <= address + length):
                raise ValueError(f"servo {servo_id}: a read-back block {address}..{address + length} must hold the "
                                 f"present position ({start}..{start + size})")
        self.read_back_blocks = dict(blocks)

    def read_device(self, device_id: int, address: int, length: int, budget_s: float) -> bytes | None:
        """One budgeted READ of a non-servo device (Bus.read_device: the OP3's OpenCR IMU): the read-back's
        exchange without its bookkeeping of late replies (a reply after its budget is dropped as stale input)."""
        self._require_open()
        if not budget_s >= MIN_READ_BACK_BUDGET_S:
            return None
        _, frame = self._budgeted_read(device_id, address, length, budget_s, self.clock())
        if frame is None or frame.error or len(frame.params) != length:
            return None
        return bytes(frame.params)

    def read_back(self, servo_id: int, budget_s: float) -> ReadBack:
        """One READ of the servo's read-back block (``set_read_back_blocks``) that waits at most ``budget_s`` on
        the bus's clock and is never retried: the per-frame read of a walk session.

        Input left over from earlier exchanges is read and dropped first (a late reply among it is
        matched to the abandoned read it answers, by id and length, and its lateness noted). The request
        goes out through the SDK; the status packet is awaited on the port's packet timeout capped to the
        budget, and accepted only if it has this servo's id, is a status packet and carries exactly the
        parameters asked for. Error bits raise ServoStatusError (the Hardware Error Status is read in
        what is left of the budget); a dead port raises PortError.
        """
        self._require_open()
        self._model(servo_id)
        late = self.late
        late_s = late.late_seen.pop(servo_id, None)
        if not budget_s >= MIN_READ_BACK_BUDGET_S:
            return ReadBack(servo_id, ReadBackOutcome.SKIPPED, late_s=late_s)
        start_s = self.clock()
        address, base_length = self.read_back_blocks.get(servo_id, self._present)
        length = late.free_length(servo_id, base_length, start_s)
        if length is None:  # every length still owed a reply: asking again could not be told apart
            return ReadBack(servo_id, ReadBackOutcome.MISSED, late_s=late_s)
        outcome, frame = self._budgeted_read(servo_id, address, length, budget_s, start_s)
        late_s = late.late_seen.pop(servo_id, late_s)
        if frame is None:
            if outcome != ReadBackOutcome.DAMAGED:
                late.abandon(servo_id, length, start_s)
            if outcome == ReadBackOutcome.MISSED and late.damaged_seen.pop(servo_id, 0):
                outcome = ReadBackOutcome.DAMAGED  # its reply to an earlier read came, damaged: the same fault, late
            return ReadBack(servo_id, outcome, late_s=late_s)
        data = bytes(frame.params)
        error = frame.error or 0
        self.last_status_errors[servo_id] = error
        late.suspects.discard(servo_id)
        if error:
            remaining_s = budget_s - (self.clock() - start_s)
            raise self._status_error(servo_id, error, budget_s=remaining_s)
        offset = self._present[0] - address
        ticks = self._decode(data[offset:offset + self._present[1]], self._model(servo_id))
        return ReadBack(servo_id, ReadBackOutcome.ANSWERED, ticks, data, error, late_s)

    def _budgeted_read(self, servo_id: int, address: int, length: int, budget_s: float,
                       start_s: float) -> tuple[ReadBackOutcome, wire.Frame | None]:
        """Send READ(address, length) to ``servo_id`` through the SDK and wait for its status packet until
        ``start_s + budget_s`` on the bus's clock: (ANSWERED, frame), (DAMAGED, None) or (MISSED, None)."""
        with self._transaction(servo_id):
            self._drop_stale_input()
            result = self._ph.readTx(self.port, servo_id, address, length)  # its lock: released by the transaction
            if result != self.sdk.COMM_SUCCESS:
                self._raise_on_port_failure(result, servo_id)
                return ReadBackOutcome.MISSED, None
            remaining_ms = max(0.0, budget_s - (self.clock() - start_s)) * 1000.0
            return self._await_status(servo_id, length, remaining_ms)

    def _await_status(self, servo_id: int, length: int, timeout_ms: float) -> tuple[ReadBackOutcome,
                                                                                     wire.Frame | None]:
        framing = self.framing
        self.port.setPacketTimeoutMillis(timeout_ms)  # the port's clock: virtual on the dry-run port
        buffer = bytearray()
        damaged = False
        while True:
            available = self.port.getBytesAvailable()
            if available:
                buffer += bytes(self.port.readPort(available))
                for _raw, frame in take_packets(buffer, framing, status=True):
                    if frame is None:
                        continue
                    if is_status_of(frame, servo_id, framing, length):
                        return ReadBackOutcome.ANSWERED, frame
                    if frame.packet_id == servo_id and not frame.checksum_ok:
                        damaged = True
                    else:
                        self.late.note(frame)
            elif self.port.isPacketTimeout():
                return (ReadBackOutcome.DAMAGED if damaged else ReadBackOutcome.MISSED), None
            else:
                time.sleep(0.0002)

    def _wait_for_quiet(self, quiet_s: float = 0.03, at_most_s: float = QUIET_WAIT_S) -> None:
        """Read (and note) whatever still arrives until the line has been quiet for ``quiet_s``, at most
        ``at_most_s`` of real time (late replies travel on the wire, whatever the session's clock says):
        after read-backs were abandoned, their late replies are still coming."""
        start = last = time.monotonic()
        while True:
            with self._transaction():
                self._collect_stale_input()
            now = time.monotonic()
            if self.collected_bytes:
                last = now
            if now - last >= quiet_s or now - start >= at_most_s:
                return
            time.sleep(0.001)
