"""The real-time loop: frames of servo ticks sent on absolute deadlines, with a safe stop.

This room knows servo ids, ticks, a :class:`~gaitbot.bus.base.Bus` and a clock; joint
names and angles were turned into ticks by the caller.

Pacing (``Streamer``)
    Frame k is due at ``start + k * period`` on the monotonic clock. Deadlines are never
    re-anchored, so sleep overshoot and bus jitter cannot add up into drift over long runs.
    A frame that misses its deadline is sent late and counted. No frame is ever skipped: every
    frame is part of a trajectory whose velocities and accelerations were limit-checked,
    and skipping one would double a step. No burst is sent to catch up either: two goals
    sent back to back would do the same. So frame k goes out at
    ``max(deadline_k, previous_send + min_frame_interval_s)``. The default is
    ``0.9 * period``: after a stall (say one 40 ms USB hiccup) the stream gets back onto its
    original deadlines at a tenth of a period per frame, and meanwhile the servos move at
    most 1/0.9 = 1.11 times the planned speed. Later frames keep their absolute deadlines,
    and the ones sent during recovery are counted as late against them.

Safe stop (``walk_session``)
    Every way out leaves the robot in a known pose and closes the bus (which flushes a
    recording) in a ``finally``. See :func:`walk_session`.
"""

from __future__ import annotations

import os
import signal
import threading
import time
from collections.abc import Callable, Iterable, Sequence
from contextlib import contextmanager
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike

from gaitbot.bus.base import Bus, BusError, PortError, RegisterWrite, ServoTimeout
from gaitbot.clock import Clock, MonotonicClock, VirtualClock
from gaitbot.ramp import brake_ticks, ramp_ticks, stop_ticks

__all__ = [
    "Clock", "MonotonicClock", "VirtualClock", "ramp_ticks", "brake_ticks", "stop_ticks",
    "StreamStats", "Streamer", "MissingServosError", "Terminated", "prepare", "write_settings", "paced_deadlines",
    "sigterm_raises_terminated",
    "SessionResult", "walk_session", "latency_timer_warning",
    "LATE_THRESHOLD_S", "EXIT_CODES",
]

#: A frame is late when it starts more than this after its deadline. 0.5 ms is 3 % of a
#: 60 Hz period. On an idle Linux machine the spin-wait sends within tens of microseconds,
#: so anything beyond 0.5 ms is the OS or the bus taking the time, and worth counting. It is
#: still far below anything a servo can show in its motion.
LATE_THRESHOLD_S = 0.5e-3

#: Exit codes by outcome, the shell's conventions (128 + SIGINT, 128 + SIGTERM).
EXIT_CODES = {"completed": 0, "interrupted": 130, "terminated": 143, "bus_error": 1}


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

    def summary(self) -> str:
        """One paragraph for people."""
        ms = 1e3
        rate_hz = 1.0 / self.period_s if self.period_s > 0 else float("nan")
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

    monitor() is called right after each write, inside the frame's bus time (``bus_call_s``
    covers both): walk_session reads the servos back there, so that a servo that stops
    answering or reports a fault ends the walk within a frame or two. It raises to stop.

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
                 monitor: Callable[[], None] | None = None) -> None:
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
        self.min_frame_interval_s = 0.9 * self.period_s if min_frame_interval_s is None else min_frame_interval_s
        self.cpu_time_s = cpu_time_s
        self.monitor = monitor
        self.stats = StreamStats(period_s=self.period_s, late_threshold_s=late_threshold_s)
        self.last_sent_ticks: np.ndarray | None = None
        self.previous_sent_ticks: np.ndarray | None = None

    def run(self, frames: ArrayLike, start_s: float | None = None) -> StreamStats:
        """Stream ``frames`` (N, len(ids)) of int ticks; return their timing.

        ``start_s`` is the first frame's deadline (default: now); a session passes the deadline
        after its previous run so consecutive runs keep one period apart on one absolute grid.
        ``next_deadline_s`` holds the deadline after the last frame sent (also when interrupted)."""
        frames = _as_tick_frames(frames, len(self.ids))
        count = frames.shape[0]
        stats = StreamStats(period_s=self.period_s, late_threshold_s=self.late_threshold_s,
                            lateness_s=np.zeros(count), bus_call_s=np.zeros(count))
        self.stats = stats
        clock, bus, ids, cpu, monitor = self.clock, self.bus, self.ids, self.cpu_time_s, self.monitor
        cpu_start = cpu()
        start_s = clock.now() if start_s is None else start_s
        self.next_deadline_s = start_s
        try:
            ticks = paced_deadlines(clock, self.period_s, start_s, self.min_frame_interval_s)
            for _, (k, deadline_s, send_s) in zip(range(count), ticks):
                work_cpu_start = cpu()
                self.previous_sent_ticks, self.last_sent_ticks = self.last_sent_ticks, frames[k]
                # Python ints (SDK packet builders want ints, not numpy scalars), one frame at a
                # time: converting a whole one-hour walk up front would take ~100 MB.
                bus.write_goal_ticks(dict(zip(ids, frames[k].tolist())))
                if monitor is not None:
                    monitor()
                done_s = clock.now()
                self.next_deadline_s = deadline_s + self.period_s
                stats._record(send_s - deadline_s, done_s - send_s)
                stats.wall_s = done_s - start_s
                if self.on_frame is not None:
                    self.on_frame(k, stats)
                stats.work_cpu_s += cpu() - work_cpu_start
        finally:
            stats.cpu_s = cpu() - cpu_start
        return stats


def paced_deadlines(clock: Clock, period_s: float, start_s: float, min_interval_s: float):
    """The pacing rule of the module docstring, for any per-frame work (sending goals, reading positions).

    Yields ``(k, deadline_s, start_s_of_work)`` for k = 0, 1, ...: waits until frame k's absolute
    deadline ``start_s + k * period_s`` but never less than ``min_interval_s`` after the previous
    frame's work started, then reports the time the work starts. Deadlines are never re-anchored;
    nothing is skipped. Stop iterating to stop (the generator sleeps only when asked for a frame)."""
    earliest_s = start_s
    k = 0
    while True:
        deadline_s = start_s + k * period_s
        clock.sleep_until(max(deadline_s, earliest_s))
        work_s = clock.now()
        yield k, deadline_s, work_s
        earliest_s = work_s + min_interval_s
        k += 1


def _as_tick_frames(frames: ArrayLike, joint_count: int) -> np.ndarray:
    array = np.asarray(frames)
    if array.ndim != 2 or array.shape[1] != joint_count:
        raise ValueError(f"frames must have shape (N, {joint_count}), got {array.shape}")
    if array.size and not np.issubdtype(array.dtype, np.integer):
        if not np.all(np.isfinite(array)) or not np.all(array == np.rint(array)):
            raise ValueError("frames must hold whole ticks (integers)")
    return array.astype(np.int64)


# --------------------------------------------------------------------------- before walking

class MissingServosError(BusError):
    """Servos that did not answer a ping; ``missing_ids`` names every one of them."""

    def __init__(self, missing_ids: Iterable[int], expected_ids: Iterable[int]) -> None:
        self.missing_ids = sorted(int(i) for i in missing_ids)
        self.expected_ids = [int(i) for i in expected_ids]
        names = ", ".join(str(i) for i in self.missing_ids)
        noun = "servo" if len(self.missing_ids) == 1 else "servos"
        super().__init__(
            f"{noun} {names} did not answer a ping (expected ids {self.expected_ids}); "
            "check power, cabling, baud rate and ids")


def prepare(bus: Bus, ids: Sequence[int]) -> np.ndarray:
    """Check every servo answers and return where they are (present ticks, in ``ids`` order).

    Raises MissingServosError naming all missing ids at once, so one trip to the robot
    fixes every cable.
    """
    ids = [int(i) for i in ids]
    answering = set(bus.scan(ids))
    missing = [i for i in ids if i not in answering]
    if missing:
        raise MissingServosError(missing, ids)
    present = bus.read_present_ticks(ids)
    unread = [i for i in ids if i not in present]
    if unread:
        raise MissingServosError(unread, ids)
    return np.array([int(present[i]) for i in ids], dtype=np.int64)


def write_settings(bus: Bus, writes: Iterable[RegisterWrite]) -> None:
    """Write the session's settings (the servos' gain registers), in order, each servo confirming its
    own; called before torque goes on, so a servo never moves with the stiffness it had before."""
    for write in writes:
        bus.write_register(write.ids, write.address, write.length, write.value)


# --------------------------------------------------------------------------- the session

class Terminated(BaseException):
    """Raised in the main thread by our SIGTERM handler during a walk session.

    A BaseException like KeyboardInterrupt, so that ``except Exception`` in lower layers
    cannot swallow it.
    """


@dataclass(frozen=True)
class SessionResult:
    """How a walk session ended.

    outcome: "completed" | "interrupted" | "terminated" | "bus_error".
    exit_code: 0 | 130 | 143 | 1 respectively.
    error: the bus error that ended the walk (or stopped preparation), for the caller's message.
    walk_stats: timing of the walk itself (None if it never started).
    reached_stand: the last frame sent is within 1 tick of ``stand_ticks`` (the ramp's own tolerance).
    torque_off: torque was switched off at the end.
    notes: what happened on the way out, one sentence each.
    """

    outcome: str
    exit_code: int
    error: BaseException | None = None
    walk_stats: StreamStats | None = None
    reached_stand: bool = False
    torque_off: bool = False
    notes: tuple[str, ...] = ()

    def message(self) -> str:
        head = {"completed": "Walk completed", "interrupted": "Walk interrupted (Ctrl-C)",
                "terminated": "Walk terminated (SIGTERM)", "bus_error": "Walk stopped by a bus error"}
        parts = [head.get(self.outcome, self.outcome)]
        if self.error is not None:
            parts.append(f"error: {self.error}")
        parts.extend(self.notes)
        return "; ".join(parts) + "."


def _raise_terminated(signum: int, _frame: object) -> None:
    raise Terminated(f"received signal {signum}")


def walk_session(bus: Bus, ids: Sequence[int], frames: ArrayLike, stand_ticks: ArrayLike, *,
                 max_velocity_ticks_per_s: float, max_accel_ticks_per_s2: float,
                 period_s: float = 1 / 60, clock: Clock | None = None,
                 torque_off_on_exit: bool = False,
                 on_frame: Callable[[int, StreamStats], None] | None = None,
                 handle_sigterm: bool = True, monitor_servos: bool = True,
                 setup_writes: Sequence[RegisterWrite] = ()) -> SessionResult:
    """Open, check, ramp to the first pose, walk, and leave the robot in a known pose.

    Sequence: ``bus.open()`` -> :func:`prepare` (ping all, read present) -> ``setup_writes``
    (:func:`write_settings`: the servos' gains; none leaves them as they are) -> write present
    as goal, then torque on (a servo enabled with a stale goal register would jump to it)
    -> ramp from present to ``frames[0]`` -> stream ``frames`` -> end.

    Ways out:
      * completed (0): the trajectory should end standing. If its last frame is not
        ``stand_ticks``, a final ramp takes the robot there.
      * interrupted (130, Ctrl-C) / terminated (143, SIGTERM): streaming stops; the safe
        stop (:func:`~gaitbot.ramp.stop_ticks`) brakes the motion under way at the
        acceleration limit, then ramps to ``stand_ticks`` within the limits. A second
        Ctrl-C or SIGTERM during it abandons it.
      * bus_error (1): one attempt at the ramp to stand. The first failing bus call ends it,
        so a dead bus costs one bounded timeout, never a hang. The error is in ``error``.
        When the error is a :class:`~gaitbot.bus.base.PortError` (the port itself is gone),
        nothing can reach the servos: no stop ramp and no torque-off are tried, the servos hold
        their last goal, and a note says so.

    Servo faults during motion: with ``monitor_servos`` (the default) every frame of the start
    ramp, the walk and the final ramp is followed by a read-back of one servo, each in turn
    (``bus.read_present_ticks``), so that a servo that stops answering, answers late, sends
    damaged packets or reports error bits (overload, overheating, input voltage) raises a
    BusError naming it within ``len(ids)`` frames plus the bus's bounded retries. The bus retries reads as its fault policy says
    (see :class:`gaitbot.bus.sdk_bus.SdkBus`). The safe stop ramp is not read back: it must
    reach the healthy servos whatever the faulty one does.
    In every case, torque goes off if ``torque_off_on_exit``, and the bus is closed in a
    ``finally`` so that a recording made by the bus is flushed and readable. Other
    exceptions (bugs) get the same safe stop and are then re-raised.

    The stop starts from the motion under way: velocity from the last two frames sent.
    Braking each joint at the acceleration limit overshoots the last pose by v^2 / (2 a),
    which a trajectory checked against the same limits always has room for. Stopping dead
    at the last pose would decelerate at v / period instead, several times the limit at
    walking speeds.

    handle_sigterm: install a SIGTERM handler that raises :class:`Terminated` (main
    thread only; the previous handler is restored on return).
    """
    ids = [int(i) for i in ids]
    walk = _as_tick_frames(frames, len(ids))
    if walk.shape[0] == 0:
        raise ValueError("frames is empty: nothing to walk")
    stand = _as_tick_frames(np.asarray(stand_ticks).reshape(1, -1), len(ids))[0]
    clock = clock if clock is not None else MonotonicClock()

    def ramp(from_ticks: np.ndarray, to_ticks: np.ndarray) -> np.ndarray:
        return ramp_ticks(from_ticks, to_ticks, max_velocity_ticks_per_s, max_accel_ticks_per_s2, period_s)

    def stop(previous_ticks: np.ndarray, last_ticks: np.ndarray) -> np.ndarray:
        return stop_ticks(previous_ticks, last_ticks, stand, max_velocity_ticks_per_s, max_accel_ticks_per_s2,
                          period_s)

    next_checked = [0]

    def check_servos() -> None:
        """Read one servo back per frame, in turn: each servo is checked every len(ids) frames, and
        the frame's bus time grows by one status packet, not by len(ids) of them (protocols without
        sync read would otherwise ask every servo on its own every frame)."""
        servo_id = ids[next_checked[0] % len(ids)]
        next_checked[0] += 1
        if servo_id not in bus.read_present_ticks([servo_id]):
            raise ServoTimeout(f"servo {servo_id} stopped answering reads during the walk", servo_id=servo_id)

    def streamer(callback=None, monitored: bool = False) -> Streamer:
        monitor = check_servos if (monitored and monitor_servos) else None
        return Streamer(bus, ids, period_s, clock, callback, monitor=monitor)

    old_handler = _install_sigterm_handler() if handle_sigterm else None
    state = _SessionState()
    try:
        try:
            state.opened = True  # close even if open fails halfway: a recording may already be started
            bus.open()
            present = prepare(bus, ids)
            write_settings(bus, setup_writes)
            # Already at the first pose (within a tick): that pose is the goal written before torque on,
            # and it counts as the walk's first frame, so a recording holds exactly the trajectory.
            at_start = int(np.max(np.abs(present - walk[0]))) <= 1
            first_goal = walk[0] if at_start else present
            first_sent_s = clock.now()
            bus.write_goal_ticks(dict(zip(ids, first_goal.tolist())))
            state.last_sent = first_goal
            state.torque_on = True  # before the call: a torque-on that fails halfway still gets its torque-off
            bus.set_torque(ids, True)
            state.next_deadline_s = first_sent_s + period_s
            if not at_start:
                state.run(streamer(monitored=True), ramp(present, walk[0]))
            state.run(streamer(on_frame, monitored=True), walk[1:] if at_start else walk, is_walk=True)
            state.run(streamer(monitored=True), stop(walk[-2] if len(walk) > 1 else walk[-1], walk[-1]))
            outcome, error = "completed", None
        except (KeyboardInterrupt, Terminated) as exc:
            outcome, error = ("terminated" if isinstance(exc, Terminated) else "interrupted"), None
            state.safe_stop(streamer, stop)
        except BusError as exc:
            outcome, error = "bus_error", exc
            if isinstance(exc, PortError) and state.torque_on:
                state.port_lost = True
                state.notes.append("the port is gone, so no stop ramp or torque-off could be sent: "
                                   "the servos hold their last goal")
            else:
                state.safe_stop(streamer, stop)
        except Exception:
            state.safe_stop(streamer, stop)
            state.finish(bus, ids, torque_off_on_exit)
            raise
        state.finish(bus, ids, torque_off_on_exit)
    finally:
        try:
            state.close(bus)
        finally:
            if handle_sigterm:
                _restore_sigterm_handler(old_handler)
    return SessionResult(
        outcome=outcome, exit_code=EXIT_CODES[outcome], error=error, walk_stats=state.walk_stats,
        reached_stand=state.last_sent is not None and int(np.max(np.abs(state.last_sent - stand))) <= 1,
        torque_off=state.torque_off, notes=tuple(state.notes))


class _SessionState:
    """What the session has done so far, so that each way out knows what to undo."""

    def __init__(self) -> None:
        self.opened = False
        self.port_lost = False
        self.torque_on = False
        self.torque_off = False
        self.last_sent: np.ndarray | None = None
        self.previous_sent: np.ndarray | None = None
        self.walk_stats: StreamStats | None = None
        self.notes: list[str] = []
        self.next_deadline_s: float | None = None  # keeps consecutive runs on one frame grid

    def run(self, streamer: Streamer, frames: np.ndarray, is_walk: bool = False) -> None:
        try:
            stats = streamer.run(frames, self.next_deadline_s)
        finally:
            self.next_deadline_s = getattr(streamer, "next_deadline_s", self.next_deadline_s)
            if streamer.last_sent_ticks is not None:
                before = streamer.previous_sent_ticks
                self.previous_sent = before if before is not None else self.last_sent
                self.last_sent = streamer.last_sent_ticks
            if is_walk:
                self.walk_stats = streamer.stats
        if is_walk:
            self.walk_stats = stats

    def safe_stop(self, streamer: Callable[[], Streamer],
                  stop: Callable[[np.ndarray, np.ndarray], np.ndarray]) -> None:
        """Brake and ramp from the last sent pose to stand, once; give up on a bus error or a second signal."""
        if not self.torque_on or self.last_sent is None:
            return  # nothing moved: the robot is where it was
        previous = self.previous_sent if self.previous_sent is not None else self.last_sent
        try:
            self.run(streamer(), stop(previous, self.last_sent))
            self.notes.append("ramped to the stand pose")
        except (KeyboardInterrupt, Terminated):
            self.notes.append("stop ramp abandoned on a second interrupt")
        except BusError as exc:
            self.notes.append(f"stop ramp abandoned: {exc}")

    def finish(self, bus: Bus, ids: list[int], torque_off_on_exit: bool) -> None:
        if not (torque_off_on_exit and self.torque_on) or self.port_lost:
            return
        try:
            bus.set_torque(ids, False)
            self.torque_off = True
            self.notes.append("torque off")
        except (KeyboardInterrupt, Terminated):
            self.notes.append("torque off abandoned on an interrupt")
        except BusError as exc:
            self.notes.append(f"torque off failed: {exc}")

    def close(self, bus: Bus) -> None:
        """Close once, whatever happens: a failure or a further interrupt becomes a note.

        Closing flushes a recording made by the bus room, so it must not be skipped, and an
        error here must not hide how the walk ended.
        """
        if not self.opened:
            return
        try:
            bus.close()
        except (KeyboardInterrupt, Terminated):
            self.notes.append("closing the bus was interrupted")
        except Exception as exc:  # noqa: BLE001 - reported to the caller in the notes
            self.notes.append(f"closing the bus failed: {exc}")


_NOT_INSTALLED = object()


@contextmanager
def sigterm_raises_terminated():
    """Within the block, SIGTERM raises :class:`Terminated` in the main thread (elsewhere: no change)."""
    old_handler = _install_sigterm_handler()
    try:
        yield
    finally:
        _restore_sigterm_handler(old_handler)


def _install_sigterm_handler() -> object:
    """Install ``_raise_terminated`` for SIGTERM; return the previous handler, or _NOT_INSTALLED."""
    if threading.current_thread() is not threading.main_thread():
        return _NOT_INSTALLED  # signal handlers can only be set from the main thread
    return signal.signal(signal.SIGTERM, _raise_terminated)


def _restore_sigterm_handler(old_handler: object) -> None:
    if old_handler is _NOT_INSTALLED:
        return
    # None means the previous handler was not set from Python; the default is the best we can do.
    signal.signal(signal.SIGTERM, signal.SIG_DFL if old_handler is None else old_handler)


# --------------------------------------------------------------------------- the serial adapter

def latency_timer_warning(port_name: str, sysfs_root: str = "/sys") -> str | None:
    """A one-line warning if the USB-serial adapter of ``port_name`` buffers reads for over 1 ms.

    FTDI adapters (``/dev/ttyUSB*``) hold received bytes for their latency timer, 16 ms by
    default. Every servo reply then arrives up to 16 ms late, which is a whole frame at 60 Hz.
    Returns None when the timer is 1 ms or less, or when it cannot be read (not Linux, not a
    usb-serial device, no such port). Symlinks such as ``/dev/serial/by-id/...`` are resolved.
    ``sysfs_root`` is for tests.
    """
    device = os.path.basename(os.path.realpath(port_name))
    path = os.path.join(sysfs_root, "bus", "usb-serial", "devices", device, "latency_timer")
    try:
        with open(path, encoding="ascii") as f:
            latency_ms = int(f.read().strip())
    except (OSError, ValueError):
        return None
    if latency_ms <= 1:
        return None
    return (f"{port_name}: USB latency timer is {latency_ms} ms, so every servo read waits up to "
            f"{latency_ms} ms (about {latency_ms / (1000 / 60):.1f} frames at 60 Hz); lower it with "
            f"`echo 1 | sudo tee {path}` or permanently with a udev rule such as "
            '`ACTION=="add", SUBSYSTEM=="usb-serial", DRIVER=="ftdi_sio", ATTR{latency_timer}="1"`')
