"""Pacing: frames of servo ticks sent on absolute deadlines, and the statistics of how they went out.

Frame k is due at ``start + k * period`` on the monotonic clock. Deadlines are never re-anchored,
so sleep overshoot and bus jitter cannot add up into drift over long runs. A frame that misses its
deadline is sent late and counted. No frame is ever skipped: every frame is part of a trajectory
whose velocities and accelerations were limit-checked, and skipping one would double a step. No
burst is sent to catch up either: two goals sent back to back would do the same. So frame k goes
out at ``max(deadline_k, previous_send + min_frame_interval_s)``: after a stall the motion is
stretched, never bunched. The default is MIN_SEND_INTERVAL_SHARE (0.95) of a period
(gaitbot.robot.motion_margin): after a stall (say one 40 ms USB hiccup) the stream gets back onto
its original deadlines at a twentieth of a period per frame, and meanwhile the servos move at most
1/0.95 = 1.053 times the planned speed, which the planning margin (PLANNED_SHARE, 0.9) covers: at
send times a planned motion stays under 0.947 of its limits. Later frames keep their absolute
deadlines, and the ones sent during recovery are counted as late against them.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Iterable, Iterator, Sequence
from dataclasses import dataclass, field
from typing import Union

import numpy as np
from numpy.typing import ArrayLike

from gaitbot.bus.base import Bus
from gaitbot.robot.motion_margin import MIN_SEND_INTERVAL_SHARE
from gaitbot.stream.clock import Clock, MonotonicClock

#: A frame is late when it starts more than this after its deadline. 0.5 ms is 3 % of a
#: 60 Hz period. On an idle Linux machine the spin-wait sends within tens of microseconds,
#: so anything beyond 0.5 ms is the OS or the bus taking the time, and worth counting. It is
#: still far below anything a servo can show in its motion.
LATE_THRESHOLD_S = 0.5e-3

# --------------------------------------------------------------------------- statistics

def _percentile(values: np.ndarray, q: float) -> float:
    """numpy's default (linear interpolation between closest ranks); 0.0 when empty."""
    return float(np.percentile(values, q)) if values.size else 0.0


@dataclass
class StreamStats:
    """Timing of one streamed run, filled in as frames go out.

    ``frames``, ``late_frames``, ``last_lateness_s`` and ``max_lateness_s`` are kept up to
    date at every frame and cost nothing to read (for a live status line). Medians and
    percentiles are computed when asked, so read them at the end.

    lateness = send start - deadline (seconds); bus call = duration of the
    ``write_goal_ticks`` call. CPU time comes from ``time.process_time`` (all threads
    of the process). ``cpu_s`` covers the whole run, including the clock's spin-wait.
    ``work_cpu_s`` counts only the per-frame work: building the packet, the bus call and
    the callback.
    """

    period_s: float
    late_threshold_s: float = LATE_THRESHOLD_S
    frames: int = 0
    late_frames: int = 0
    last_lateness_s: float = 0.0
    max_lateness_s: float = 0.0
    wall_s: float = 0.0
    cpu_s: float = 0.0
    work_cpu_s: float = 0.0
    lateness_s: np.ndarray = field(default_factory=lambda: np.empty(0), repr=False)
    bus_call_s: np.ndarray = field(default_factory=lambda: np.empty(0), repr=False)

    def _record(self, lateness_s: float, bus_call_s: float) -> None:
        k = self.frames
        if k == self.lateness_s.size:  # a frame source of unknown length: room for twice as many
            self.lateness_s = np.concatenate([self.lateness_s, np.zeros(max(k, 64))])
            self.bus_call_s = np.concatenate([self.bus_call_s, np.zeros(max(k, 64))])
        self.lateness_s[k] = lateness_s
        self.bus_call_s[k] = bus_call_s
        self.frames = k + 1
        self.last_lateness_s = lateness_s
        if lateness_s > self.late_threshold_s:
            self.late_frames += 1
        if lateness_s > self.max_lateness_s:
            self.max_lateness_s = lateness_s

    @property
    def lateness_median_s(self) -> float:
        return _percentile(self.lateness_s[: self.frames], 50)

    @property
    def lateness_p99_s(self) -> float:
        return _percentile(self.lateness_s[: self.frames], 99)

    @property
    def bus_call_median_s(self) -> float:
        return _percentile(self.bus_call_s[: self.frames], 50)

    @property
    def bus_call_p99_s(self) -> float:
        return _percentile(self.bus_call_s[: self.frames], 99)

    @property
    def bus_call_max_s(self) -> float:
        return float(self.bus_call_s[: self.frames].max()) if self.frames else 0.0

    @property
    def cpu_per_frame_s(self) -> float:
        return self.cpu_s / self.frames if self.frames else 0.0

    @property
    def work_cpu_per_frame_s(self) -> float:
        return self.work_cpu_s / self.frames if self.frames else 0.0

    def to_dict(self) -> dict[str, float | int]:
        """Plain numbers (seconds, counts) for JSON reports."""
        return {
            "frames": self.frames,
            "late_frames": self.late_frames,
            "late_threshold_s": self.late_threshold_s,
            "period_s": self.period_s,
            "lateness_median_s": self.lateness_median_s,
            "lateness_p99_s": self.lateness_p99_s,
            "lateness_max_s": self.max_lateness_s,
            "bus_call_median_s": self.bus_call_median_s,
            "bus_call_p99_s": self.bus_call_p99_s,
            "bus_call_max_s": self.bus_call_max_s,
            "cpu_per_frame_s": self.cpu_per_frame_s,
            "work_cpu_per_frame_s": self.work_cpu_per_frame_s,
            "wall_s": self.wall_s,
        }

    def summary(self, simulated_clock: bool = False) -> str:
        """One paragraph for people. On a simulated clock (a dry run, the simulated robot) every frame is on
        time and the bus costs no time by construction, so only the frames and the CPU they took are said."""
        ms = 1e3
        rate_hz = 1.0 / self.period_s if self.period_s > 0 else float("nan")
        if simulated_clock:
            return (f"Sent {self.frames} frames at {rate_hz:.0f} Hz, {self.wall_s:.2f} s of walking on a simulated "
                    f"clock; CPU per frame {self.cpu_per_frame_s * ms:.3f} ms.")
        return (
            f"Sent {self.frames} frames at {rate_hz:.0f} Hz in {self.wall_s:.2f} s; "
            f"{self.late_frames} late by more than {self.late_threshold_s * ms:.1f} ms. "
            f"Lateness median {self.lateness_median_s * ms:.3f} ms, p99 {self.lateness_p99_s * ms:.3f} ms, "
            f"max {self.max_lateness_s * ms:.3f} ms. "
            f"Bus call median {self.bus_call_median_s * ms:.3f} ms, p99 {self.bus_call_p99_s * ms:.3f} ms, "
            f"max {self.bus_call_max_s * ms:.3f} ms. "
            f"CPU per frame {self.cpu_per_frame_s * ms:.3f} ms "
            f"({self.work_cpu_per_frame_s * ms:.3f} ms of it outside the wait)."
        )


# --------------------------------------------------------------------------- the loop

class Streamer:
    """Sends frames of goal ticks to ``ids`` on ``bus``, one ``write_goal_ticks`` per frame.

    on_frame(k, stats) is called after frame k went out, in the loop's own time: keep it
    to reading the cheap fields of :class:`StreamStats` and printing now and then.

    monitor(deadline_s) is called right after each write with that frame's deadline, inside the
    frame's bus time (``bus_call_s`` covers both): walk_session reads a servo back there within
    what is left of the frame (gaitbot.stream.readback), so that a servo that stops answering or
    reports a fault ends the walk within a few frames. It raises to stop.

    After ``run`` returns or raises, ``stats`` holds the figures so far,
    ``last_sent_ticks`` the last frame whose write was started (None before the first) and
    ``previous_sent_ticks`` the one before it (the safe stop's velocity estimate).
    A write that was interrupted may or may not have reached the servos, so the safe stop
    starts from that frame: it is at most one planned step away from either possibility.
    """

    def __init__(self, bus: Bus, ids: Sequence[int], period_s: float, clock: Clock | None = None,
                 on_frame: Callable[[int, StreamStats], None] | None = None, *,
                 late_threshold_s: float = LATE_THRESHOLD_S,
                 min_frame_interval_s: float | None = None,
                 cpu_time_s: Callable[[], float] = time.process_time,
                 monitor: Callable[[float], None] | None = None, feedback=None) -> None:
        if not period_s > 0:
            raise ValueError(f"period_s must be > 0, got {period_s}")
        self.bus = bus
        self.ids = [int(i) for i in ids]
        if len(set(self.ids)) != len(self.ids):
            raise ValueError(f"servo ids repeat: {self.ids}")
        self.period_s = float(period_s)
        self.clock = clock if clock is not None else MonotonicClock()
        self.on_frame = on_frame
        self.late_threshold_s = late_threshold_s
        self.min_frame_interval_s = (MIN_SEND_INTERVAL_SHARE * self.period_s if min_frame_interval_s is None
                                     else min_frame_interval_s)
        self.cpu_time_s = cpu_time_s
        self.monitor = monitor
        self.feedback = feedback  # gaitbot.feel.Feedback: corrects each row from the IMU (None: as planned)
        self.stats = StreamStats(period_s=self.period_s, late_threshold_s=late_threshold_s)
        self.last_sent_ticks: np.ndarray | None = None
        self.previous_sent_ticks: np.ndarray | None = None
        self.last_send_s: float | None = None

    def run(self, frames: FrameSource, start_s: float | None = None, previous_send_s: float | None = None,
            stop_requested: Callable[[], bool] | None = None) -> StreamStats:
        """Stream ``frames`` (an (N, len(ids)) array of int ticks, or any iterable of such rows, taken one
        at a time as they are due: a live walk plans each frame while the one before is on the wire);
        return their timing.

        ``start_s`` is the first frame's deadline (default: now); a session passes the deadline
        after its previous run so consecutive runs keep one period apart on one absolute grid.
        ``next_deadline_s`` holds the deadline after the last frame sent (also when interrupted).
        ``previous_send_s``: when the frame before this run went out (a session's previous run), so the
        pacing rule holds across runs too: a stop ramp never follows a late walk frame by less than
        ``min_frame_interval_s``. ``last_send_s`` holds the send time of this run's last frame.
        ``stop_requested``: asked before each frame is sent (between bus exchanges, never inside one);
        when it says so, ``run`` raises StopRequestedError without sending that frame."""
        count = len(frames) if hasattr(frames, "__len__") else 0
        source = tick_frames(frames, len(self.ids))
        stats = StreamStats(period_s=self.period_s, late_threshold_s=self.late_threshold_s,
                            lateness_s=np.zeros(count or 1024), bus_call_s=np.zeros(count or 1024))
        self.stats = stats
        clock, bus, ids, cpu, monitor = self.clock, self.bus, self.ids, self.cpu_time_s, self.monitor
        cpu_start = cpu()
        start_s = clock.now() if start_s is None else start_s
        self.next_deadline_s = start_s
        try:
            earliest_s = start_s if previous_send_s is None else max(start_s, previous_send_s + self.min_frame_interval_s)
            ticks = paced_deadlines(clock, self.period_s, start_s, self.min_frame_interval_s, earliest_s)
            last_write_s = previous_send_s
            min_interval_s = self.min_frame_interval_s
            for frame in source:
                k, deadline_s, send_s = next(ticks)
                if stop_requested is not None and stop_requested():
                    raise StopRequestedError
                work_cpu_start = cpu()
                # Python ints (SDK packet builders want ints, not numpy scalars), one frame at a
                # time: converting a whole one-hour walk up front would take ~100 MB.
                row = frame if self.feedback is None else self.feedback.correct(k, frame)
                goals = dict(zip(ids, row.tolist()))
                # The pacing rule on the wire itself: had the host paused between the previous frame's
                # start and its write, this write still waits the minimum interval after that one.
                if last_write_s is not None and clock.now() < last_write_s + min_interval_s:
                    clock.sleep_until(last_write_s + min_interval_s)
                last_write_s = self.last_send_s = clock.now()
                self.previous_sent_ticks, self.last_sent_ticks = self.last_sent_ticks, row
                bus.write_goal_ticks(goals)
                # The grid moves on as soon as the goals went out: whatever the read-back raises, the
                # next frame sent (a stop ramp's first) is due one period after this one, not at once.
                self.next_deadline_s = deadline_s + self.period_s
                if monitor is not None:
                    monitor(deadline_s)
                done_s = clock.now()
                stats._record(send_s - deadline_s, done_s - send_s)
                stats.wall_s = done_s - start_s
                if self.on_frame is not None:
                    self.on_frame(k, stats)
                stats.work_cpu_s += cpu() - work_cpu_start
        finally:
            stats.cpu_s = cpu() - cpu_start
        return stats


class StopRequestedError(Exception):
    """A frame was due, and ``stop_requested`` said stop: nothing of it was sent (pacing.Streamer.run)."""


def paced_deadlines(clock: Clock, period_s: float, start_s: float, min_interval_s: float,
                    earliest_s: float | None = None):
    """The pacing rule of the module docstring, for any per-frame work (sending goals, reading positions).

    Yields ``(k, deadline_s, start_s_of_work)`` for k = 0, 1, ...: waits until frame k's absolute
    deadline ``start_s + k * period_s`` but never less than ``min_interval_s`` after the previous
    frame's work started, then reports the time the work starts. Deadlines are never re-anchored;
    nothing is skipped. Stop iterating to stop (the generator sleeps only when asked for a frame).
    ``earliest_s``: the first frame's work starts no sooner (default ``start_s``)."""
    earliest_s = start_s if earliest_s is None else earliest_s
    k = 0
    while True:
        deadline_s = start_s + k * period_s
        clock.sleep_until(max(deadline_s, earliest_s))
        work_s = clock.now()
        yield k, deadline_s, work_s
        earliest_s = work_s + min_interval_s
        k += 1


#: What a Streamer streams: a whole (N, J) array of ticks, or rows of J ticks handed over one at a time.
FrameSource = Union[ArrayLike, Iterable[ArrayLike]]


def tick_frames(frames: FrameSource, joint_count: int) -> Iterator[np.ndarray]:
    """The rows of ``frames`` as int64 tick arrays of ``joint_count``: a whole array is checked at once,
    rows from any other iterable (a live walk's frame source) one by one as they come."""
    if isinstance(frames, (np.ndarray, list, tuple)):
        return iter(as_tick_frames(frames, joint_count))
    return (as_tick_frames(np.asarray(row).reshape(1, -1), joint_count)[0] for row in frames)


def as_tick_frames(frames: ArrayLike, joint_count: int) -> np.ndarray:
    array = np.asarray(frames)
    if array.ndim != 2 or array.shape[1] != joint_count:
        raise ValueError(f"frames must have shape (N, {joint_count}), got {array.shape}")
    if array.size and not np.issubdtype(array.dtype, np.integer):
        if not np.all(np.isfinite(array)) or not np.all(array == np.rint(array)):
            raise ValueError("frames must hold whole ticks (integers)")
    return array.astype(np.int64)
