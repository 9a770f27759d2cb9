"""The per-frame read-back of a walk session: one servo read after each goal frame, within what is
left of that frame.

After the goals of frame k go out (at its deadline d), one servo is read with a budget that ends at
``d + period - READ_BACK_MARGIN_S``, so the read never delays frame k + 1. A read that cannot finish in
its budget is abandoned for that frame (the bus never retries it inside the frame, and tells a late
reply to it from the answer to any later read: gaitbot.bus.sdk_bus). Servos are read in turn; a servo
that missed is read again in the next frames until it answers; ``READ_BACK_MISSES`` misses in a row
over at least ``READ_BACK_SILENCE_S`` stop the walk naming it (ServoTimeout, ServoLate or CorruptReplies).
Only reads of at least ``FAIR_BUDGET_S`` count; in a stream that stays late, every few frames one read
gets that long anyway (the one exception to the frame's budget), so a silent servo is still named.
docs/bus-faults.md has the policy and its timing figures.

Kept general on purpose: :class:`ReadBackMonitor` reads whatever register block the bus's
``read_back`` reads, and ``on_answer`` receives every answered :class:`~gaitbot.bus.base.ReadBack`
(its ``data`` holds the block), for whoever wants more of the servo than its position.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

from gaitbot.bus.base import Bus, CorruptReplies, ReadBack, ServoLate, ServoTimeout, miss_kind
from gaitbot.stream.clock import Clock

#: A servo stops the walk when it has missed this many read-backs in a row (no status packet answering
#: the read within its frame's budget) over at least READ_BACK_SILENCE_S.
READ_BACK_MISSES = 3
#: ... and the first of those misses was asked this long ago: a host or adapter that stalls for less
#: (a busy machine, one USB hiccup) does not stop a walk; a servo silent or late by more does (and so
#: does a host too busy to hear its servos for that long: the walk is not under control then either).
READ_BACK_SILENCE_S = 0.5

#: A miss counts toward the stop only if its read had at least this long: a frame that started late leaves
#: its read too little time, and such a miss says more about the host than the servo. The servo is still
#: read again (it is the suspect) until it answers, and a read that follows SHORT_READS_BEFORE_FAIR short
#: ones gets this long whatever is left of its frame: so a servo that is silent is named even in a stream
#: that stays late, and a healthy one on a busy host answers that read and is cleared.
FAIR_BUDGET_S = 4.0e-3
#: After this many reads in a row with less than FAIR_BUDGET_S (none sent, or too short to be fair), the
#: next read gets FAIR_BUDGET_S anyway; the cost is at most that much more lateness every few frames of a
#: stream that is late already.
SHORT_READS_BEFORE_FAIR = 5
#: The read-back's budget ends this long before the next frame's deadline: room for the clock's wake-up
#: (the MonotonicClock spins its last 1.5 ms) so the next goals still go out on time.
READ_BACK_MARGIN_S = 2.0e-3


class ReadBackMonitor:
    """Called by the Streamer after each frame's goal write with that frame's deadline; raises to stop.

    ``misses`` and ``silence_s``: a servo stops the walk after that many misses in a row spanning at least
    that long (READ_BACK_MISSES, READ_BACK_SILENCE_S).
    """

    def __init__(self, bus: Bus, ids: Sequence[int], clock: Clock, period_s: float, *,
                 misses: int = READ_BACK_MISSES, silence_s: float = READ_BACK_SILENCE_S,
                 margin_s: float = READ_BACK_MARGIN_S,
                 on_answer: Callable[[ReadBack], None] | None = None) -> None:
        if misses < 1:
            raise ValueError(f"misses must be >= 1, got {misses}")
        self.bus = bus
        self.ids = [int(i) for i in ids]
        self.clock = clock
        self.period_s = float(period_s)
        self.misses = int(misses)
        self.silence_s = float(silence_s)
        self.margin_s = min(float(margin_s), 0.25 * self.period_s)
        self.fair_s = min(FAIR_BUDGET_S, 0.25 * self.period_s)  # a read this long may blame its servo
        self.first_miss_s: dict[int, float] = {}  # servo -> when the first read of its current run of misses began
        self.on_answer = on_answer
        self.next_index = 0
        self.suspect: int | None = None  # the servo that missed last: read again until it answers
        self.missed: dict[int, list[ReadBack]] = {}  # servo -> its misses in a row
        self.reads = 0
        self.skipped = 0
        self.short_in_row = 0  # reads in a row with less than a fair budget (skipped or short)

    def budget_s(self, deadline_s: float) -> float:
        return deadline_s + self.period_s - self.margin_s - self.clock.now()

    def __call__(self, deadline_s: float) -> None:
        if self.suspect is not None:
            servo_id = self.suspect
        else:
            servo_id = self.ids[self.next_index % len(self.ids)]
        budget_s = self.budget_s(deadline_s)
        if self.short_in_row >= SHORT_READS_BEFORE_FAIR:
            budget_s = max(budget_s, self.fair_s)
        self.short_in_row = self.short_in_row + 1 if budget_s < self.fair_s else 0
        asked_s = self.clock.now()
        result = self.bus.read_back(servo_id, budget_s)
        self.reads += 1
        if result.outcome == "skipped":
            self.skipped += 1
            return
        if result.outcome == "answered":
            self.missed.pop(servo_id, None)
            self.first_miss_s.pop(servo_id, None)
            if self.suspect == servo_id:
                self.suspect = None
            self.next_index += 1
            if self.on_answer is not None:
                self.on_answer(result)
            return
        self.suspect = servo_id  # read again until it answers
        if budget_s < self.fair_s:  # too short to blame it: a fair read comes within a few frames
            return
        self.first_miss_s.setdefault(servo_id, asked_s)
        misses = self.missed.setdefault(servo_id, [])
        misses.append(result)
        if len(misses) >= self.misses and self.clock.now() - self.first_miss_s[servo_id] >= self.silence_s:
            raise self.error(servo_id, misses, budget_s)

    def error(self, servo_id: int, misses: list[ReadBack], budget_s: float) -> ServoTimeout:
        port = self.bus.port_name
        count = len(misses)
        budget_ms = max(0.0, budget_s) * 1e3
        # a damaged reply came within its budget: it counts as damaged even if a late reply to an earlier
        # read was seen beside it (late_s)
        damaged = sum(m.outcome == "damaged" for m in misses)
        late = sum(m.late_s is not None and m.outcome != "damaged" for m in misses)
        kind = miss_kind(late, damaged, count - late - damaged)
        if kind == "damaged":
            some = "" if damaged == count else f"{damaged} of "
            return CorruptReplies(
                f"servo {servo_id} on {port} sent a damaged status packet (bad checksum/CRC) in {some}{count} "
                "read-backs in a row, and no good one; check its cable, connectors and the bus wiring",
                servo_id=servo_id)
        if kind == "late":
            late_ms = max(m.late_s or 0.0 for m in misses) * 1e3
            return ServoLate(
                f"servo {servo_id} on {port} answers late: {count} read-backs in a row missed their frame's budget "
                f"(about {budget_ms:.0f} ms), its status packets came {late_ms:.0f} ms after the request; "
                "check its Return Delay Time and the adapter's latency timer", servo_id=servo_id)
        return ServoTimeout(
            f"servo {servo_id} on {port} did not answer {count} read-backs in a row within their frame's budget "
            f"(about {budget_ms:.0f} ms each); check its power, cable, id and baud rate", servo_id=servo_id)
