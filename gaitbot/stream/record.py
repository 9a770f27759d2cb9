"""Recording a motion a person makes with the robot's legs: torque off, present positions read at the frame rate.

This module knows servo ids, ticks, a :class:`~gaitbot.bus.base.Bus` and a clock (the stream room's
vocabulary); what a sample becomes (angles, a root, a CSV row) is the ``sink``'s business
(gaitbot/app/record.py). Sequence (:func:`record_session`): open, ping and read every servo (a missing
one stops here, nothing written), ask ``confirm(n)`` (a refusal sends nothing), open the sink, torque
off, then read every present position on the streamer's absolute-deadline grid
(:func:`gaitbot.stream.pacing.paced_deadlines`) and hand each sample to ``sink.add(t_s, ticks)``.

Ways out: completed or stopped by Ctrl-C (0), terminated (143), bus_error (1), file_error (1: the
sink cannot write). Torque stays off at every exit (the person holding the legs keeps them) unless
``hold_at_end``: the pose is then read once more, the settings written, the pose written as goals
(through the caller's LimitGuard) and torque turned on, in the order a walk starts; any failure there
turns torque off again. docs/recording.md has the whole story.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from contextlib import nullcontext
from dataclasses import dataclass, field
from typing import Protocol

import numpy as np

from gaitbot.bus.base import Bus, BusError, RegisterWrite
from gaitbot.stream.clock import Clock, MonotonicClock
from gaitbot.stream.health import HealthMonitor, ServoHealthStop
from gaitbot.stream.pacing import LATE_THRESHOLD_S, paced_deadlines
from gaitbot.stream.session import EXIT_CODES, prepare, write_settings
from gaitbot.stream.signals import Terminated, sigterm_raises_terminated

#: Exit status of each outcome: a stopped recording (Ctrl-C) is a normal end.
RECORD_EXIT_CODES = {"declined": 0, "completed": 0, "stopped": 0, "terminated": EXIT_CODES["terminated"],
                     "bus_error": EXIT_CODES["bus_error"], "health_stop": EXIT_CODES["health_stop"], "file_error": 1}
#: fsync the sink about once a second (every row is flushed to the OS as it is written anyway).
SYNC_EVERY_S = 1.0


class SampleSink(Protocol):
    """Where samples go: opened after consent, before torque off; closed at every exit."""

    def open(self) -> None: ...

    def add(self, t_s: float, ticks: np.ndarray) -> None:
        """One sample: ``t_s`` its planned time from the first sample, ``ticks`` in the ``ids`` order."""

    def sync(self) -> None: ...

    def close(self) -> None: ...


@dataclass
class ReadTiming:
    """Lateness of each read (start - deadline) and how long each took, seconds."""

    period_s: float
    lateness_s: list[float] = field(default_factory=list)
    read_s: list[float] = field(default_factory=list)

    @property
    def samples(self) -> int:
        return len(self.read_s)

    def summary(self, simulated_clock: bool = False) -> str:
        """One line for people; on a simulated clock (a dry run) reads are on time by construction: not said."""
        if not self.read_s:
            return "no samples read"
        if simulated_clock:
            return f"Read {self.samples} samples at {1.0 / self.period_s:.0f} Hz on a simulated clock."
        late, read, ms = np.array(self.lateness_s), np.array(self.read_s), 1e3
        n_late = int(np.sum(late > LATE_THRESHOLD_S))
        return (f"Read {self.samples} samples at {1.0 / self.period_s:.0f} Hz; {n_late} started more than "
                f"{LATE_THRESHOLD_S * ms:.1f} ms late (max {late.max() * ms:.3f} ms; rows keep their planned times). "
                f"Read time median {np.median(read) * ms:.3f} ms, p99 {np.percentile(read, 99) * ms:.3f} ms, "
                f"max {read.max() * ms:.3f} ms.")


@dataclass(frozen=True)
class RecordResult:
    """How a recording ended: outcome (see the module docstring), exit code, samples read,
    the bus error if any, whether torque is off or holding at the end, and notes for people."""

    outcome: str
    exit_code: int
    samples: int
    timing: ReadTiming
    error: BaseException | None = None
    torque: str = "unchanged"  # "unchanged" | "off" | "holding"
    notes: tuple[str, ...] = ()

    def message(self) -> str:
        head = {"declined": "Recording cancelled: nothing was sent, torque left as it was",
                "completed": "Recording completed", "stopped": "Recording stopped (Ctrl-C)",
                "terminated": "Recording terminated (SIGTERM)", "bus_error": "Recording stopped by a bus error",
                "health_stop": "Recording stopped to protect a servo",
                "file_error": "Recording stopped: the file could not be written"}
        parts = [head[self.outcome]]
        if self.error is not None:
            parts.append(f"error: {self.error}")
        parts.extend(self.notes)
        return "; ".join(parts) + "."


def record_session(bus: Bus, ids: Sequence[int], period_s: float, sink: SampleSink, *,
                   confirm: Callable[[int], bool], n_samples: int | None = None, clock: Clock | None = None,
                   hold_at_end: bool = False, handle_sigterm: bool = True,
                   setup_writes: Sequence[RegisterWrite] = (), health: HealthMonitor | None = None) -> RecordResult:
    """Record until ``n_samples`` are read, Ctrl-C, SIGTERM or a bus error (see the module docstring).

    ``health``: after each sample one servo's health block is read, in turn, and handed to the monitor
    (warnings; a stop threshold ends the recording as "health_stop", exit 1, torque left off).

    ``confirm(n)`` asks the person whether ``n`` servos may go limp. ``bus`` should be wrapped in a
    LimitGuard when ``hold_at_end`` is set, so a pose outside the limits is never sent as a goal.
    """
    ids = [int(i) for i in ids]
    if n_samples is not None and n_samples < 1:
        raise ValueError(f"n_samples must be 1 or more, got {n_samples}")
    clock = clock if clock is not None else MonotonicClock()
    timing = ReadTiming(period_s)
    notes: list[str] = []
    state = {"torque": "unchanged", "sink_open": False, "opened": False}
    outcome, error = "completed", None
    with sigterm_raises_terminated() if handle_sigterm else nullcontext():
        try:
            try:
                state["opened"] = True
                bus.open()
                prepare(bus, ids)
                if not confirm(len(ids)):
                    return RecordResult("declined", RECORD_EXIT_CODES["declined"], 0, timing)
                sink.open()
                state["sink_open"] = True
                state["torque"] = "off"  # before the call: a torque-off that fails halfway is still off where it took
                bus.set_torque(ids, False)
                _read_loop(bus, ids, period_s, sink, clock, timing, n_samples, health)
            except KeyboardInterrupt:  # before torque off (at the question) it is a refusal
                outcome = "stopped" if state["torque"] == "off" else "declined"
            except Terminated:
                outcome = "terminated"
            except ServoHealthStop as exc:
                outcome, error = "health_stop", exc
            except BusError as exc:
                outcome, error = "bus_error", exc
            except OSError as exc:  # the sink's file; the bus's own OS errors arrive as PortError
                outcome, error = "file_error", exc
            if hold_at_end and outcome in ("completed", "stopped", "terminated") and state["torque"] == "off":
                state["torque"] = _hold_present_pose(bus, ids, notes, setup_writes)
            elif state["torque"] == "off":
                notes.append("torque stays off")
        finally:
            if state["sink_open"]:
                try:
                    sink.close()
                except OSError as exc:
                    notes.append(f"closing the file failed: {exc}")
            if state["opened"]:
                try:
                    bus.close()
                except Exception as exc:  # noqa: BLE001 - reported, must not hide how the recording ended
                    notes.append(f"closing the bus failed: {exc}")
    return RecordResult(outcome, RECORD_EXIT_CODES[outcome], timing.samples, timing, error, state["torque"],
                        tuple(notes))


def _read_loop(bus: Bus, ids: list[int], period_s: float, sink: SampleSink, clock: Clock, timing: ReadTiming,
               n_samples: int | None, health: HealthMonitor | None = None) -> None:
    start_s = clock.now()
    sync_every = max(1, int(round(SYNC_EVERY_S / period_s)))
    for k, deadline_s, read_start_s in paced_deadlines(clock, period_s, start_s, 0.9 * period_s):
        if n_samples is not None and k >= n_samples:
            return
        present = bus.read_present_ticks(ids)
        done_s = clock.now()
        timing.lateness_s.append(read_start_s - deadline_s)
        timing.read_s.append(done_s - read_start_s)
        sink.add(k * period_s, np.array([int(present[i]) for i in ids], dtype=np.int64))
        if health is not None:
            health.observe(bus.read_health(ids[k % len(ids)]))
        if (k + 1) % sync_every == 0:
            sink.sync()


def _hold_present_pose(bus: Bus, ids: list[int], notes: list[str], setup_writes: Sequence[RegisterWrite]) -> str:
    """Settings, present pose as goal, then torque on (the order a walk starts in); on any failure torque off again."""
    try:
        present = bus.read_present_ticks(ids)
        write_settings(bus, setup_writes)
        bus.write_goal_ticks({i: int(present[i]) for i in ids})
        bus.set_torque(ids, True)
        notes.append("torque on, holding the pose read last")
        return "holding"
    except (BusError, KeyboardInterrupt, Terminated) as exc:
        reason = "interrupted" if not isinstance(exc, BusError) else str(exc)
        try:
            bus.set_torque(ids, False)
            notes.append(f"pose not held ({reason}); torque stays off")
        except (BusError, KeyboardInterrupt, Terminated) as again:
            notes.append(f"pose not held ({reason}); torque off failed too: {again}")
        return "off"
