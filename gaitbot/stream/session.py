"""The walk session: open, check, ramp to the first pose, walk, and leave the robot in a known pose.

This room knows servo ids, ticks, a :class:`~gaitbot.bus.base.Bus` and a clock; joint names and
angles were turned into ticks by the caller. :class:`WalkSession` holds the session's limits in one
record (:class:`SessionLimits`) and takes its frames from a frame source (a whole array, or an
iterator that plans each frame as it is due), on one thread, paced by the injected clock. Every way
out leaves the robot in a known pose and closes the bus (which flushes a recording) in a
``finally``; signals only set a flag that the loop acts on between bus exchanges, and a stop ramp,
once started, always finishes (docs/bus-faults.md).
"""

from __future__ import annotations

import itertools
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass
from enum import Enum

import signal

import numpy as np
from numpy.typing import ArrayLike

from gaitbot.bus.base import Bus, BusError, PortError, RegisterWrite
from gaitbot.bus.recording import RecordingFailed
from gaitbot.feel.feedback import RobotFell
from gaitbot.stream.clock import Clock, MonotonicClock
from gaitbot.stream.health import HealthMonitor, ServoHealthStop
from gaitbot.stream.pacing import FrameSource, StopRequestedError, StreamStats, Streamer, as_tick_frames, tick_frames
from gaitbot.stream.ramps import ramp_ticks, stop_ticks
from gaitbot.stream.readback import ReadBackMonitor
from gaitbot.stream.signals import StopSignals, Terminated, signals_deferred


class Outcome(str, Enum):
    """How a walk session ended; compares and hashes as its value ("completed", ...), which reports print."""

    COMPLETED = "completed"
    INTERRUPTED = "interrupted"  # Ctrl-C
    TERMINATED = "terminated"  # SIGTERM
    BUS_ERROR = "bus_error"
    HEALTH_STOP = "health_stop"  # a servo's temperature or voltage reached its stop threshold
    FELL = "fell"  # the IMU said the robot fell (gaitbot.feel): stepping stopped, the CoM lowered

    def __str__(self) -> str:
        return self.value

    def __hash__(self) -> int:
        return hash(self.value)

    @property
    def exit_code(self) -> int:
        """The shell's conventions: 128 + SIGINT, 128 + SIGTERM; 1 for a fault."""
        return {"completed": 0, "interrupted": 130, "terminated": 143}.get(self.value, 1)

    @classmethod
    def of_signal(cls, signum: int | None) -> Outcome:
        return cls.TERMINATED if signum == signal.SIGTERM else cls.INTERRUPTED


#: Exit codes by outcome.
EXIT_CODES = {outcome.value: outcome.exit_code for outcome in Outcome}


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
class SessionLimits:
    """What every motion the session plans itself (the start ramp, the stop ramps) keeps within, in
    ticks, and the frame period the session runs at (seconds)."""

    max_velocity_ticks_per_s: float
    max_accel_ticks_per_s2: float
    period_s: float = 1 / 60

    def ramp(self, from_ticks: np.ndarray, to_ticks: np.ndarray) -> np.ndarray:
        """Rest to rest (gaitbot.stream.ramps.ramp_ticks)."""
        return ramp_ticks(from_ticks, to_ticks, self.max_velocity_ticks_per_s, self.max_accel_ticks_per_s2,
                          self.period_s)

    def stop(self, previous_ticks: np.ndarray, last_ticks: np.ndarray, stand_ticks: np.ndarray) -> np.ndarray:
        """Brake from the motion under way, then ramp to ``stand_ticks`` (gaitbot.stream.ramps.stop_ticks)."""
        return stop_ticks(previous_ticks, last_ticks, stand_ticks, self.max_velocity_ticks_per_s,
                          self.max_accel_ticks_per_s2, self.period_s)


@dataclass(frozen=True)
class SessionResult:
    """How a walk session ended.

    outcome: an :class:`Outcome`; exit_code its exit status (0, 130, 143, 1).
    error: the bus error that ended the walk (or stopped preparation), for the caller's message.
    walk_stats: timing of the walk itself (None if it never started).
    reached_stand: the last frame sent is within 1 tick of the stand pose (the ramp's own tolerance).
    torque_off: torque was switched off at the end.
    notes: what happened on the way out, one sentence each.
    """

    outcome: Outcome
    exit_code: int
    error: BaseException | None = None
    walk_stats: StreamStats | None = None
    reached_stand: bool = False
    torque_off: bool = False
    notes: tuple[str, ...] = ()

    def message(self) -> str:
        head = {"completed": "Walk completed", "interrupted": "Walk interrupted (Ctrl-C)",
                "terminated": "Walk terminated (SIGTERM)", "bus_error": "Walk stopped by a bus error",
                "health_stop": "Walk stopped to protect a servo", "fell": "Walk stopped: the robot fell"}
        parts = [head.get(self.outcome, str(self.outcome))]
        if isinstance(self.error, RecordingFailed):
            parts = ["Walk stopped because the recording failed (the serial port is fine)"]
        if self.error is not None:
            parts.append(f"error: {self.error}")
        parts.extend(self.notes)
        return "; ".join(parts) + "."


#: A stop ramp whose writes are interrupted by an exception (not a signal: signals never raise in a
#: session) is planned again from where it was, at most this many times, so that it ends in bounded time.
STOP_RAMP_RESTARTS = 10


class WalkSession:
    """One walk on one bus: :meth:`start` (open, check, gains, torque on, ramp to the first pose),
    :meth:`stream` (the frames, from a frame source), :meth:`stop` (the stop ramp to the stand pose, torque
    off if asked, close); :meth:`run` does all three and every way out.

    The bus must not be opened yet; the session closes it. ``health``: the per-frame read-back reads
    each servo's health block and the monitor judges it (gaitbot.stream.health), and every servo is
    read once before torque on. ``monitor_servos``: read one servo back after each frame of the start
    ramp, the walk and the final ramp (gaitbot.stream.readback); a stop ramp after a fault is not read
    back (it must reach the healthy servos whatever the faulty one does). ``handle_signals``: SIGINT and
    SIGTERM only set a flag while the session runs (main thread only; the old handlers come back after).
    ``feedback`` (gaitbot.feel.Feedback): during the walk, the IMU is read after the read-back in the same
    frame's budget and each frame's goals are corrected from it; a fall it notices (RobotFell) stops the
    stepping and brakes into the fall pose (the CoM lowered), then the config's response (docs/feedback.md).
    """

    def __init__(self, bus: Bus, ids: Sequence[int], stand_ticks: ArrayLike, limits: SessionLimits, *,
                 clock: Clock | None = None, torque_off_on_exit: bool = False,
                 setup_writes: Sequence[RegisterWrite] = (), health: HealthMonitor | None = None,
                 monitor_servos: bool = True, handle_signals: bool = True, feedback=None) -> None:
        self.bus = bus
        self.feedback = feedback
        self.ids = [int(i) for i in ids]
        self.stand = as_tick_frames(np.asarray(stand_ticks).reshape(1, -1), len(self.ids))[0]
        self.limits = limits
        self.clock = clock if clock is not None else MonotonicClock()
        self.torque_off_on_exit = torque_off_on_exit
        self.setup_writes = tuple(setup_writes)
        self.health = health
        self.handle_signals = handle_signals
        self.read_back: ReadBackMonitor | None = None
        if monitor_servos:
            on_answer = None
            if health is not None:  # the read-back reads each servo's health block and the monitor judges it
                bus.set_read_back_blocks({i: (b.address, b.length) for i, b in health.blocks.items()})
                on_answer = health.observe_read_back
            self.read_back = ReadBackMonitor(bus, self.ids, self.clock, limits.period_s, on_answer=on_answer)
        self.signals: StopSignals | None = None  # set while run() defers signals
        self.state = _SessionState()

    # ------------------------------------------------------------------ the three phases

    def start(self, first_ticks: ArrayLike) -> bool:
        """Open, check every servo (ping, present position, health), write the gains, write the present pose
        as goal, torque on, and ramp to ``first_ticks``. True when the servos were already there (within a
        tick): that pose was the goal written before torque on, and counts as the walk's first frame."""
        first = as_tick_frames(np.asarray(first_ticks).reshape(1, -1), len(self.ids))[0]
        bus, ids, state = self.bus, self.ids, self.state
        state.opened = True  # close even if open fails halfway: a recording may already be started
        bus.open()
        present = prepare(bus, ids)
        check_health(bus, ids, self.health)
        write_settings(bus, self.setup_writes)
        self._act_on_signals()
        at_start = int(np.max(np.abs(present - first))) <= 1
        first_goal = first if at_start else present
        first_sent_s = self.clock.now()
        bus.write_goal_ticks(dict(zip(ids, first_goal.tolist())))  # a servo enabled with a stale goal would jump
        state.last_sent, state.last_send_s = first_goal, first_sent_s
        state.torque_on = True  # before the call: a torque-on that fails halfway still gets its torque-off
        bus.set_torque(ids, True)
        state.next_deadline_s = first_sent_s + self.limits.period_s
        if not at_start:
            self._run(self._streamer(monitored=True), self.limits.ramp(present, first), watch_signals=True)
        return at_start

    def stream(self, frames: FrameSource, on_frame: Callable[[int, StreamStats], None] | None = None) -> StreamStats:
        """Stream the frames, each when it is due; a deferred signal stops it between two frames."""
        self._run(self._streamer(on_frame, monitored=True, felt=True), frames, is_walk=True, watch_signals=True)
        return self.state.walk_stats

    def stop(self, monitored: bool = False) -> bool:
        """Ramp from the motion under way (the last two frames sent) to the stand pose, and finish it whatever
        signals arrive. ``monitored``: read the servos back meanwhile (the end of a healthy walk). False
        when nothing had moved (torque never went on)."""
        state = self.state
        if not state.torque_on or state.last_sent is None:
            return False  # nothing moved: the robot is where it was
        previous = state.previous_sent if state.previous_sent is not None else state.last_sent
        ramp = self.limits.stop(previous, state.last_sent, self.stand)
        for _ in range(STOP_RAMP_RESTARTS):
            streamer = self._streamer(monitored=monitored)
            try:
                self._run(streamer, ramp)
                return True
            except (KeyboardInterrupt, Terminated):  # raised by a bus, not by a signal of ours (those never raise)
                # that frame's write was cut short: the ramp goes on with it
                ramp = ramp[streamer.stats.frames:]
                state.notes_once("a stop ramp write was interrupted, and the ramp went on")
        state.notes.append("stop ramp given up after repeated interrupted writes")
        return True

    def finish(self) -> None:
        """Torque off if asked (not when the port is gone)."""
        state = self.state
        if not (self.torque_off_on_exit and state.torque_on) or state.port_lost:
            return
        try:
            self.bus.set_torque(self.ids, False)
            state.torque_off = True
            state.notes.append("torque off")
        except (KeyboardInterrupt, Terminated):
            state.notes.append("torque off abandoned on an interrupt")
        except BusError as exc:
            state.notes.append(f"torque off failed: {exc}")

    def close(self) -> None:
        """Close once, whatever happens: a failure or an interrupt becomes a note (closing flushes a
        recording made by the bus room, so it is never skipped, and must not hide how the walk ended)."""
        if not self.state.opened:
            return
        self.state.opened = False
        try:
            self.bus.close()
        except (KeyboardInterrupt, Terminated):
            self.state.notes.append("closing the bus was interrupted")
        except Exception as exc:  # noqa: BLE001 - reported to the caller in the notes
            self.state.notes.append(f"closing the bus failed: {exc}")

    # ------------------------------------------------------------------ the whole session

    def run(self, frames: FrameSource, on_frame: Callable[[int, StreamStats], None] | None = None) -> SessionResult:
        """Start, stream, stop, with every way out (docs/bus-faults.md): completed 0, interrupted 130,
        terminated 143, bus_error and health_stop 1. A PortError (the port is gone) skips the stop ramp and
        the torque-off: nothing could reach the servos. Other exceptions (bugs) get the safe stop and are
        raised again."""
        if isinstance(frames, (np.ndarray, list, tuple)):
            frames = as_tick_frames(frames, len(self.ids))  # checked before anything is opened
            if frames.shape[0] == 0:
                raise ValueError("frames is empty: nothing to walk")
        deferring = signals_deferred() if self.handle_signals else _no_signals()
        try:
            with deferring as self.signals:
                outcome, error = self._walk(frames, on_frame)
                self.finish()
        finally:
            self.close()
        if outcome is Outcome.COMPLETED and self.signals is not None and self.signals.pending:
            outcome = Outcome.of_signal(self.signals.pending[0])  # arrived during the final ramp, which finished
        state = self.state
        return SessionResult(outcome=outcome, exit_code=outcome.exit_code, error=error, walk_stats=state.walk_stats,
                             reached_stand=state.last_sent is not None
                             and int(np.max(np.abs(state.last_sent - self.stand))) <= 1,
                             torque_off=state.torque_off, notes=tuple(state.notes))

    def _first_and_rest(self, frames: FrameSource) -> tuple[np.ndarray, FrameSource]:
        """The first frame (checked: the start ramp goes there) and the others (a whole array is checked at
        once; a frame source's rows are checked by the Streamer as they come)."""
        if isinstance(frames, (np.ndarray, list, tuple)):
            walk = as_tick_frames(frames, len(self.ids))
            if walk.shape[0] == 0:
                raise ValueError("frames is empty: nothing to walk")
            return walk[0], walk[1:]
        source = iter(frames)
        first = next(source, None)
        if first is None:
            raise ValueError("the frame source is empty: nothing to walk")
        return next(tick_frames([np.asarray(first).reshape(-1)], len(self.ids))), source

    def _walk(self, frames: FrameSource, on_frame) -> tuple[Outcome, BaseException | None]:
        """The phases, and the way out each exception takes; returns (outcome, error)."""
        first, rest = self._first_and_rest(frames)
        try:
            at_start = self.start(first)
            if not at_start:  # the ramp went to the first frame; the walk starts with it
                rest = np.asarray(frames) if isinstance(rest, np.ndarray) else itertools.chain([first], rest)
            self.stream(rest, on_frame)
            self.stop(monitored=True)
            return Outcome.COMPLETED, None
        except StopRequestedError:
            outcome, error = Outcome.of_signal(self.signals.pending[0] if self.signals else None), None
        except (KeyboardInterrupt, Terminated) as exc:  # raised by a bus or off the main thread
            outcome, error = (Outcome.TERMINATED if isinstance(exc, Terminated) else Outcome.INTERRUPTED), None
        except ServoHealthStop as exc:  # a servo too hot or under-powered: the safe stop of a bus fault
            outcome, error = Outcome.HEALTH_STOP, exc
        except RobotFell as exc:  # stop stepping, lower the CoM, then the config's response (gaitbot.feel)
            self._fall_stop()
            return Outcome.FELL, exc
        except BusError as exc:
            if isinstance(exc, PortError) and self.state.torque_on:
                self.state.port_lost = True
                self.state.notes.append("the port is gone, so no stop ramp or torque-off could be sent: "
                                        "the servos hold their last goal")
                return Outcome.BUS_ERROR, exc
            self._safe_stop()
            return Outcome.BUS_ERROR, self._explain(exc)
        except Exception:
            self._safe_stop()
            self.finish()
            raise
        self._safe_stop()
        return outcome, error

    def _safe_stop(self) -> None:
        try:
            if self.stop():
                self.state.notes.append("ramped to the stand pose")
        except BusError as exc:
            self.state.notes.append(f"stop ramp abandoned: {exc}")

    def _fall_stop(self) -> None:
        """A fall: brake from the motion under way into the fall pose (the legs folded: the CoM lower), then
        torque off if the robot's [fall] response says so (the ramp finishes whatever signals arrive)."""
        state, feedback = self.state, self.feedback
        if feedback.settings.fall_response == "torque_off":
            self.torque_off_on_exit = True
        if not state.torque_on or state.last_sent is None:
            return
        previous = state.previous_sent if state.previous_sent is not None else state.last_sent
        ramp = self.limits.stop(previous, state.last_sent, feedback.fall_pose(state.last_sent))
        try:
            self._run(self._streamer(), ramp)
            state.notes.append(f"{feedback.settings.fall_response.replace('_', ' ')} after lowering the CoM")
        except BusError as exc:
            state.notes.append(f"fall stop abandoned: {exc}")

    def _explain(self, exc: BusError) -> BaseException:
        """The fault in words, read once the robot is safe (a bus may read the servo's error register)."""
        try:
            return self.bus.explain_status_error(exc)
        except (KeyboardInterrupt, Terminated):
            return exc

    # ------------------------------------------------------------------ helpers

    def _act_on_signals(self) -> None:
        if self.signals is not None and self.signals.pending:
            raise StopRequestedError

    def _stop_requested(self) -> bool:
        return bool(self.signals is not None and self.signals.pending)

    def _streamer(self, on_frame=None, monitored: bool = False, felt: bool = False) -> Streamer:
        monitor = self.read_back if monitored else None
        feedback = self.feedback if felt else None
        if feedback is not None:  # the IMU read after the read-back, in the same frame's budget
            monitor = _both(monitor, feedback.sense)
        return Streamer(self.bus, self.ids, self.limits.period_s, self.clock, on_frame, monitor=monitor,
                        feedback=feedback)

    def _run(self, streamer: Streamer, frames: FrameSource, is_walk: bool = False, watch_signals: bool = False) -> None:
        self.state.run(streamer, frames, is_walk, self._stop_requested if watch_signals else None)


class _no_signals:  # noqa: N801 - a context manager standing in for signals_deferred
    def __enter__(self):
        return None

    def __exit__(self, *exc) -> bool:
        return False


def walk_session(bus: Bus, ids: Sequence[int], frames: FrameSource, stand_ticks: ArrayLike, *,
                 max_velocity_ticks_per_s: float, max_accel_ticks_per_s2: float,
                 period_s: float = 1 / 60, clock: Clock | None = None,
                 torque_off_on_exit: bool = False,
                 on_frame: Callable[[int, StreamStats], None] | None = None,
                 handle_sigterm: bool = True, monitor_servos: bool = True,
                 setup_writes: Sequence[RegisterWrite] = (), health: HealthMonitor | None = None,
                 feedback=None) -> SessionResult:
    """One :class:`WalkSession` run, in one call (the public API's shape: ``gaitbot.walk_session``).

    ``handle_sigterm``: SIGINT and SIGTERM set the session's stop flag while it runs (main thread only);
    the rest is :class:`WalkSession`'s."""
    limits = SessionLimits(max_velocity_ticks_per_s, max_accel_ticks_per_s2, period_s)
    session = WalkSession(bus, ids, stand_ticks, limits, clock=clock, torque_off_on_exit=torque_off_on_exit,
                          setup_writes=setup_writes, health=health, monitor_servos=monitor_servos,
                          handle_signals=handle_sigterm, feedback=feedback)
    return session.run(frames, on_frame)


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

    def notes_once(self, note: str) -> None:
        if note not in self.notes:
            self.notes.append(note)

    def run(self, streamer: Streamer, frames: FrameSource, is_walk: bool = False,
            stop_requested: Callable[[], bool] | None = None) -> None:
        try:
            stats = streamer.run(frames, self.next_deadline_s, self.last_send_s, stop_requested)
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


def _both(first: Callable[[float], None] | None, second: Callable[[float], None]) -> Callable[[float], None]:
    """Two per-frame monitors, one after the other (the read-back, then the IMU read)."""
    if first is None:
        return second

    def both(deadline_s: float) -> None:
        first(deadline_s)
        second(deadline_s)

    return both
