"""The walk session: open, check, ramp to the first pose, walk, and leave the robot in a known pose.

This room knows servo ids, ticks, a :class:`~gaitbot.bus.base.Bus` and a clock; joint names and
angles were turned into ticks by the caller. Every way out leaves the robot in a known pose and
closes the bus (which flushes a recording) in a ``finally``: see :func:`walk_session` and
docs/bus-faults.md.
"""

from __future__ import annotations

import itertools
from collections.abc import Callable, Iterable, Iterator, Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from gaitbot.bus.base import Bus, BusError, PortError, RegisterWrite
from gaitbot.bus.log import RecordingFailed
from gaitbot.stream.clock import Clock, MonotonicClock
from gaitbot.stream.health import HealthMonitor, ServoHealthStop
from gaitbot.stream.pacing import StreamStats, Streamer, as_tick_frames
from gaitbot.stream.ramps import ramp_ticks, stop_ticks
from gaitbot.stream.readback import ReadBackMonitor
from gaitbot.stream.signals import Terminated, install_sigterm_handler, restore_sigterm_handler

#: Exit codes by outcome, the shell's conventions (128 + SIGINT, 128 + SIGTERM).
EXIT_CODES = {"completed": 0, "interrupted": 130, "terminated": 143, "bus_error": 1, "health_stop": 1}


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


def check_health(bus: Bus, ids: Sequence[int], health: HealthMonitor | None) -> None:
    """Read every servo's health once before anything moves (ServoHealthStop refuses the start)."""
    if health is None:
        return
    for servo_id in ids:
        health.observe(bus.read_health(int(servo_id)))


# --------------------------------------------------------------------------- the session

@dataclass(frozen=True)
class SessionResult:
    """How a walk session ended.

    outcome: "completed" | "interrupted" | "terminated" | "bus_error" | "health_stop" (a servo's temperature
    or voltage reached its stop threshold: gaitbot.stream.health).
    exit_code: 0 | 130 | 143 | 1 | 1 respectively.
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
                "terminated": "Walk terminated (SIGTERM)", "bus_error": "Walk stopped by a bus error",
                "health_stop": "Walk stopped to protect a servo"}
        parts = [head.get(self.outcome, self.outcome)]
        if isinstance(self.error, RecordingFailed):
            parts = ["Walk stopped because the recording failed (the serial port is fine)"]
        if self.error is not None:
            parts.append(f"error: {self.error}")
        parts.extend(self.notes)
        return "; ".join(parts) + "."


def walk_session(bus: Bus, ids: Sequence[int], frames: ArrayLike | Iterator, stand_ticks: ArrayLike, *,
                 max_velocity_ticks_per_s: float, max_accel_ticks_per_s2: float,
                 period_s: float = 1 / 60, clock: Clock | None = None,
                 torque_off_on_exit: bool = False,
                 on_frame: Callable[[int, StreamStats], None] | None = None,
                 handle_sigterm: bool = True, monitor_servos: bool = True,
                 setup_writes: Sequence[RegisterWrite] = (), health: HealthMonitor | None = None) -> SessionResult:
    """Open, check, ramp to the first pose, walk, and leave the robot in a known pose.

    Sequence: ``bus.open()`` -> :func:`prepare` (ping all, read present) -> ``setup_writes`` (the
    servos' gains) -> present pose as goal, then torque on (a servo enabled with a stale goal register
    would jump to it) -> ramp to ``frames[0]`` -> stream ``frames`` -> end. Ways out (completed 0,
    interrupted 130, terminated 143, bus_error 1) and the safe stop (brake at the acceleration limit
    from the motion under way, then ramp to ``stand_ticks``) are in docs/bus-faults.md; in every case
    torque goes off if ``torque_off_on_exit`` and the bus is closed in a ``finally`` (which flushes a
    recording). A PortError (the port is gone) skips the stop ramp and the torque-off: nothing could
    reach the servos.

    ``monitor_servos``: after every frame of the start ramp, the walk and the final ramp one servo is
    read back within what is left of that frame (gaitbot.stream.readback: never waited on, never
    retried inside a frame), so a servo that stops answering or reports error bits ends the walk
    within ``len(ids)`` + READ_BACK_MISSES frames; the safe stop ramp is not read back (it must reach
    the healthy servos whatever the faulty one does). ``handle_sigterm``: SIGTERM raises
    :class:`~gaitbot.stream.signals.Terminated` (main thread only; the old handler is restored).

    ``health``: that read-back reads the servo's whole health block instead (position, temperature,
    voltage, load: the same one READ, ``Bus.set_read_back_blocks``) and hands it to the monitor, which warns or stops the
    walk (outcome "health_stop", the safe stop of a bus fault, exit 1); every servo is also read once
    before torque goes on, so a robot already too hot or on a flat battery does not start.
    """
    ids = [int(i) for i in ids]
    walk, rest = _first_frames(frames, len(ids))
    stand = as_tick_frames(np.asarray(stand_ticks).reshape(1, -1), len(ids))[0]
    clock = clock if clock is not None else MonotonicClock()

    def ramp(from_ticks: np.ndarray, to_ticks: np.ndarray) -> np.ndarray:
        return ramp_ticks(from_ticks, to_ticks, max_velocity_ticks_per_s, max_accel_ticks_per_s2, period_s)

    def stop(previous_ticks: np.ndarray, last_ticks: np.ndarray) -> np.ndarray:
        return stop_ticks(previous_ticks, last_ticks, stand, max_velocity_ticks_per_s, max_accel_ticks_per_s2,
                          period_s)

    read_back = None
    if monitor_servos:
        on_answer = None
        if health is not None:  # the read-back reads each servo's health block and the monitor judges it
            bus.set_read_back_blocks({i: (b.address, b.length) for i, b in health.blocks.items()})
            on_answer = health.observe_read_back
        read_back = ReadBackMonitor(bus, ids, clock, period_s, on_answer=on_answer)

    def streamer(callback=None, monitored: bool = False) -> Streamer:
        return Streamer(bus, ids, period_s, clock, callback, monitor=read_back if monitored else None)

    old_handler = install_sigterm_handler() if handle_sigterm else None
    state = _SessionState()
    try:
        try:
            state.opened = True  # close even if open fails halfway: a recording may already be started
            bus.open()
            present = prepare(bus, ids)
            check_health(bus, ids, health)
            write_settings(bus, setup_writes)
            # Already at the first pose (within a tick): that pose is the goal written before torque on,
            # and it counts as the walk's first frame, so a recording holds exactly the trajectory.
            at_start = int(np.max(np.abs(present - walk[0]))) <= 1
            first_goal = walk[0] if at_start else present
            first_sent_s = clock.now()
            bus.write_goal_ticks(dict(zip(ids, first_goal.tolist())))
            state.last_sent = first_goal
            state.last_send_s = first_sent_s
            state.torque_on = True  # before the call: a torque-on that fails halfway still gets its torque-off
            bus.set_torque(ids, True)
            state.next_deadline_s = first_sent_s + period_s
            if not at_start:
                state.run(streamer(monitored=True), ramp(present, walk[0]))
            if rest is None:
                state.run(streamer(on_frame, monitored=True), walk[1:] if at_start else walk, is_walk=True)
                state.run(streamer(monitored=True), stop(walk[-2] if len(walk) > 1 else walk[-1], walk[-1]))
            else:  # frames from an iterator (a live drive): the stop ramp starts from the last two sent
                state.run(streamer(on_frame, monitored=True), rest if at_start else itertools.chain([walk[0]], rest),
                          is_walk=True)
                previous = state.previous_sent if state.previous_sent is not None else state.last_sent
                state.run(streamer(monitored=True), stop(previous, state.last_sent))
            outcome, error = "completed", None
        except (KeyboardInterrupt, Terminated) as exc:
            outcome, error = ("terminated" if isinstance(exc, Terminated) else "interrupted"), None
            state.safe_stop(streamer, stop)
        except ServoHealthStop as exc:  # a servo too hot or under-powered: the safe stop of a bus fault
            outcome, error = "health_stop", exc
            state.safe_stop(streamer, stop)
        except BusError as exc:
            outcome, error = "bus_error", exc
            if isinstance(exc, PortError) and state.torque_on:
                state.port_lost = True
                state.notes.append("the port is gone, so no stop ramp or torque-off could be sent: "
                                   "the servos hold their last goal")
            else:
                state.safe_stop(streamer, stop)
                explain = getattr(bus, "explain_status_error", None)
                if callable(explain):  # the robot is safe now: time to read what the fault was
                    try:
                        error = explain(exc)
                    except (KeyboardInterrupt, Terminated):
                        pass
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
                restore_sigterm_handler(old_handler)
    return SessionResult(
        outcome=outcome, exit_code=EXIT_CODES[outcome], error=error, walk_stats=state.walk_stats,
        reached_stand=state.last_sent is not None and int(np.max(np.abs(state.last_sent - stand))) <= 1,
        torque_off=state.torque_off, notes=tuple(state.notes))


def _first_frames(frames, joint_count: int) -> tuple[np.ndarray, Iterator | None]:
    """(the frames as an array, None), or for an iterator (its first frame as a one-row array, the rest)."""
    if isinstance(frames, Iterator):
        first = next(frames, None)
        if first is None:
            raise ValueError("frames is empty: nothing to walk")
        return as_tick_frames(np.asarray(first).reshape(1, -1), joint_count), frames
    walk = as_tick_frames(frames, joint_count)
    if walk.shape[0] == 0:
        raise ValueError("frames is empty: nothing to walk")
    return walk, None


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
        self.last_send_s: float | None = None  # when the last frame went out: the pacing rule across runs

    def run(self, streamer: Streamer, frames: np.ndarray, is_walk: bool = False) -> None:
        try:
            stats = streamer.run(frames, self.next_deadline_s, self.last_send_s)
        finally:
            self.next_deadline_s = getattr(streamer, "next_deadline_s", self.next_deadline_s)
            self.last_send_s = getattr(streamer, "last_send_s", None) or self.last_send_s
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
