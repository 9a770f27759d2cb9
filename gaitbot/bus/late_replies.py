"""What a bus remembers about replies that did not come in time, so that a late one is never taken for the
answer to a later question (docs/bus-faults.md).

* A blocking exchange whose attempt timed out leaves its servo *suspect*: a status packet of that servo
  seen before its next exchange is a late reply (ServoLate).
* A per-frame read-back that got no reply in its budget is *abandoned*, remembered by the length it
  asked for (each unanswered read of a servo asks a different length), so a late reply is matched to the
  very read it answers and its lateness measured on the bus's clock.
"""

from __future__ import annotations

from collections.abc import Callable

from gaitbot.bus.packets import take_packets
from gaitbot.servos.wire import Frame

#: The per-frame read-back asks for the register block with a length that differs from every earlier
#: request of that servo still unanswered (base length + 0, 1, 2, ...), so a late reply to an abandoned
#: read is never taken as the answer to a later one: the status packet must carry exactly the parameters
#: asked for. This many lengths: at most this many reads unanswered.
READ_BACK_LENGTHS = 8
#: An abandoned read-back whose reply has not come after this long is written off as lost.
STALE_REPLY_HORIZON_S = 1.0


class LateReplies:
    """The suspects, the abandoned read-backs and what was seen of their replies; ``clock`` (seconds) is the
    bus's, the one the session paces frames with."""

    def __init__(self, clock: Callable[[], float]) -> None:
        self.clock = clock
        self.suspects: set[int] = set()  # servos whose last attempt timed out
        self.abandoned: dict[int, list[tuple[int, float]]] = {}  # servo -> [(length asked, sent at)]
        self.late_seen: dict[int, float] = {}  # servo -> lateness of its latest reply to an abandoned read
        self.damaged_seen: dict[int, int] = {}  # servo -> damaged status packets seen since its last read-back

    def any_abandoned(self) -> bool:
        return any(self.abandoned.values())

    def free_length(self, servo_id: int, base_length: int, now_s: float) -> int | None:
        """The length a new read-back of ``servo_id`` asks for: one no unanswered read of it asked (None: every
        length is still owed a reply, so a new read could not be told apart). Old requests are written off."""
        abandoned = self.abandoned.setdefault(servo_id, [])
        abandoned[:] = [(n, t) for n, t in abandoned if now_s - t < STALE_REPLY_HORIZON_S]
        used = {n for n, _ in abandoned}
        free = [base_length + extra for extra in range(READ_BACK_LENGTHS) if base_length + extra not in used]
        return free[0] if free else None

    def abandon(self, servo_id: int, length: int, sent_s: float) -> None:
        self.abandoned.setdefault(servo_id, []).append((length, sent_s))

    def note(self, frame: Frame) -> bool:
        """Note a status packet that answers no current request: a late reply to an abandoned read-back (same
        id, same length: its lateness is noted and the request forgotten; True), or a damaged packet of a
        servo with abandoned reads (counted). False when it is neither."""
        abandoned = self.abandoned.get(frame.packet_id)
        if not abandoned:
            return False
        if not frame.checksum_ok:
            self.damaged_seen[frame.packet_id] = self.damaged_seen.get(frame.packet_id, 0) + 1
            return False
        for k, (length, sent_s) in enumerate(abandoned):
            if length == len(frame.params):
                del abandoned[k]
                self.late_seen[frame.packet_id] = self.clock() - sent_s
                return True
        return False

    def sort(self, stale: bytes, framing: str) -> bytes:
        """Note the late replies and damaged packets among ``stale`` input; return the bytes that are neither
        (a reply to a timed-out blocking exchange is among them)."""
        unmatched = bytearray()
        for raw, frame in take_packets(bytearray(stale), framing, status=True):
            if frame is not None and self.note(frame):
                continue  # a late reply to an abandoned read-back: noted, not an answer to anything
            unmatched += raw
        return bytes(unmatched)
