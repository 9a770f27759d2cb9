"""Tests of the real-time loop, the ramp planner and the walk session.

No hardware and no wall-clock luck: time is a VirtualClock, and the bus is a fake that
charges each call's cost to that clock and records what it was sent and when.
Expected values come from hand computation or from properties (limits, end poses),
never from figures printed by the code under test.
"""

from __future__ import annotations

import math
import os
import signal

import numpy as np
import pytest

from gaitbot.bus.base import Bus, BusError, ServoTimeout
from gaitbot.stream.clock import MonotonicClock, VirtualClock
from gaitbot.stream.ramps import brake_ticks, ramp_ticks, stop_ticks
from gaitbot.bus.serial_latency import latency_timer_warning
from gaitbot.robot.motion_margin import MIN_SEND_INTERVAL_SHARE
from gaitbot.stream import (
    EXIT_CODES, MissingServosError, Streamer, prepare, walk_session,
)

PERIOD_S = 1 / 60
IDS = [1, 2, 3, 4]


class FakeBus(Bus):
    """Records every call with the virtual time it started at.

    on_write(attempt, goals) runs at the start of each write_goal_ticks (attempt counts
    calls from 0, including ones that raised) and may raise to simulate Ctrl-C, SIGTERM or a bus failure. After
    ``die()``, every call raises ServoTimeout (a dead bus); after ``max_calls`` calls in
    total a RuntimeError stops a runaway loop, so a hang shows up as a failure.
    """

    def __init__(self, clock: VirtualClock, present: dict[int, int] | None = None, missing=(),
                 on_write=None, max_calls: int = 100_000) -> None:
        self.clock = clock
        self.present = dict(present or {i: 2048 for i in IDS})
        self.missing = set(missing)
        self.on_write = on_write
        self.max_calls = max_calls
        self.calls: list[tuple[str, float, object]] = []
        self.writes: list[tuple[float, dict[int, int]]] = []
        self.dead = False
        self.closed = False
        self.write_attempts = 0

    def _call(self, name: str, arg: object = None) -> None:
        self.calls.append((name, self.clock.now(), arg))
        if len(self.calls) > self.max_calls:
            raise RuntimeError("runaway: too many bus calls")
        if self.dead and name != "close":
            raise ServoTimeout(f"{name}: no answer (dead bus)")

    def die(self) -> None:
        self.dead = True

    def open(self) -> None:
        self._call("open")

    def close(self) -> None:
        self._call("close")
        self.closed = True

    def ping(self, servo_id: int) -> bool:
        self._call("ping", servo_id)
        return servo_id not in self.missing

    def set_torque(self, ids, enabled: bool) -> None:
        self._call("set_torque", (list(ids), enabled))

    def write_goal_ticks(self, goals) -> None:
        start_s = self.clock.now()
        self._call("write", dict(goals))
        attempt = self.write_attempts
        self.write_attempts += 1
        if self.on_write is not None:
            self.on_write(attempt, goals)
        self.writes.append((start_s, dict(goals)))
        self.clock.charge_bus_call()

    def read_present_ticks(self, ids) -> dict[int, int]:
        self._call("read", list(ids))
        return {i: self.present[i] for i in ids if i not in self.missing}

    # helpers for assertions
    def write_times(self) -> np.ndarray:
        return np.array([t for t, _ in self.writes])

    def write_ticks(self, ids=IDS) -> np.ndarray:
        return np.array([[g[i] for i in ids] for _, g in self.writes], dtype=np.int64)

    def names(self) -> list[str]:
        return [name for name, _, _ in self.calls]


def assert_within_limits(frames: np.ndarray, before: np.ndarray, max_velocity: float, max_accel: float,
                         period_s: float = PERIOD_S, after: np.ndarray | None = None,
                         moving_from: np.ndarray | None = None) -> None:
    """Finite-difference velocity and acceleration of integer frames, starting from rest at ``before``
    (or, with ``moving_from``, in motion: ``moving_from`` then ``before`` were the two frames before)."""
    first = before if moving_from is None else moving_from
    padded = [first, before, *frames] + ([after, after] if after is not None else [])
    path = np.array(padded, dtype=np.float64)
    velocity = np.diff(path, axis=0) / period_s
    accel = np.diff(path, n=2, axis=0) / period_s**2
    assert np.abs(velocity).max() <= max_velocity + 1e-9
    assert np.abs(accel).max() <= max_accel + 1e-9


def min_time_s(distance: float, max_velocity: float, max_accel: float) -> float:
    """Rest-to-rest minimum time on one axis (bang-coast-bang), from the textbook formula."""
    if distance * max_accel >= max_velocity**2:
        return distance / max_velocity + max_velocity / max_accel
    return 2 * math.sqrt(distance / max_accel)


# --------------------------------------------------------------------------- clocks

def test_virtual_clock_sleeps_forward_only_and_charges_bus_calls():
    clock = VirtualClock(start_s=5.0, bus_call_cost_s=lambda i: 0.001 * (i + 1))
    clock.sleep_until(7.0)
    assert clock.now() == 7.0
    clock.sleep_until(6.0)  # a passed deadline does not move time back
    assert clock.now() == 7.0
    assert clock.charge_bus_call() == pytest.approx(0.001)
    assert clock.charge_bus_call() == pytest.approx(0.002)
    assert clock.now() == pytest.approx(7.003)
    with pytest.raises(ValueError):
        clock.advance(-1.0)


def test_monotonic_clock_never_returns_before_the_deadline():
    clock = MonotonicClock()
    for delay_s in (0.0, 0.0005, 0.003):  # below and above the spin threshold
        deadline_s = clock.now() + delay_s
        clock.sleep_until(deadline_s)
        assert clock.now() >= deadline_s


# --------------------------------------------------------------------------- streamer pacing

def run_frames(costs_s, count: int, **kwargs):
    clock = VirtualClock(start_s=100.0, bus_call_cost_s=costs_s)
    bus = FakeBus(clock)
    frames = np.arange(count)[:, None] + np.zeros((1, len(IDS)), dtype=np.int64)
    stats = Streamer(bus, IDS, PERIOD_S, clock, **kwargs).run(frames)
    return bus, stats


def test_deadlines_are_absolute_no_drift_over_10000_frames_with_jittery_bus():
    rng = np.random.default_rng(3)
    costs_s = rng.uniform(0.0, 0.8 * PERIOD_S, size=10_000)
    bus, stats = run_frames(lambda i: costs_s[i], 10_000)
    expected_s = 100.0 + np.arange(10_000) * PERIOD_S
    # Sleeping a period after each write would drift by the sum of the costs (about 67 s).
    assert np.abs(bus.write_times() - expected_s).max() < 1e-9
    assert stats.frames == 10_000 and stats.late_frames == 0


def test_stalls_do_not_shift_later_deadlines():
    # A 2.3-period stall every 997 calls; between stalls the schedule must come back to
    # the original absolute deadlines (re-anchoring on the late send would not).
    rng = np.random.default_rng(4)
    costs_s = rng.uniform(0.0, 0.5 * PERIOD_S, size=10_000)
    costs_s[::997] = 2.3 * PERIOD_S
    bus, stats = run_frames(lambda i: costs_s[i], 10_000)
    lateness_s = bus.write_times() - (100.0 + np.arange(10_000) * PERIOD_S)
    assert lateness_s.min() > -1e-9                     # never early
    assert abs(lateness_s[-1]) < 1e-9                   # on the original grid at the end
    stall_frames = np.arange(0, 10_000, 997)
    for k in stall_frames[:-1]:
        # after a stall of 2.3 periods the next frame is 1.3 periods late and recovers
        # a twentieth of a period per frame (MIN_SEND_INTERVAL_SHARE 0.95): 26 late frames, then on the grid
        assert lateness_s[k + 1] == pytest.approx(1.3 * PERIOD_S, abs=1e-9)
        assert np.abs(lateness_s[k + 27: k + 997]).max() < 1e-9
    assert np.diff(bus.write_times()).min() >= MIN_SEND_INTERVAL_SHARE * PERIOD_S - 1e-9  # never a burst


def test_late_frame_is_counted_and_not_followed_by_a_catch_up_burst():
    # Frame 10's write takes 2.5 periods: frame 11 goes out 1.5 periods late; each later
    # frame waits at least 0.95 period (MIN_SEND_INTERVAL_SHARE), so lateness falls by 0.05 period a frame:
    # frames 11..40 are late by 1.5, 1.45, ..., 0.05 periods (30 frames), frame 41 is on time.
    assert MIN_SEND_INTERVAL_SHARE == 0.95
    costs = {10: 2.5 * PERIOD_S}
    bus, stats = run_frames(lambda i: costs.get(i, 0.1 * PERIOD_S), 60)
    times_s = bus.write_times()
    lateness_s = times_s - (100.0 + np.arange(60) * PERIOD_S)
    expected_periods = np.zeros(60)
    expected_periods[11:41] = 1.5 - 0.05 * np.arange(30)
    np.testing.assert_allclose(lateness_s / PERIOD_S, expected_periods, atol=1e-9)
    assert stats.late_frames == 30
    assert np.diff(times_s).min() >= 0.95 * PERIOD_S - 1e-9
    assert stats.frames == 60  # nothing skipped


def test_stats_against_hand_computation():
    # 100 frames; frame 20's write costs a period + 4 ms, every other write 1 ms.
    # Frame 21 is due at 21P but the bus is busy until 21P + 4 ms: late 4 ms.
    # Frame 22 waits until send21 + 0.95P = 22P + 4 ms - P/20: late 3.1667 ms; then 2.3333, 1.5 and
    # 0.6667 ms (> 0.5 ms threshold). Frame 26 would be 0.17 ms early: on time.
    p = PERIOD_S
    costs = {20: p + 0.004}
    bus, stats = run_frames(lambda i: costs.get(i, 0.001), 100)
    late_ms = [4.0 - k * p * 1e3 / 20 for k in range(5)]
    assert stats.frames == 100
    assert stats.late_frames == 5
    assert stats.max_lateness_s == pytest.approx(4e-3, abs=1e-12)
    assert stats.lateness_median_s == pytest.approx(0.0, abs=1e-12)
    # numpy linear percentile: position 0.99 * 99 = 98.01 between sorted[98] and sorted[99]
    assert stats.lateness_p99_s * 1e3 == pytest.approx(late_ms[1] + 0.01 * (late_ms[0] - late_ms[1]), abs=1e-9)
    assert stats.bus_call_median_s == pytest.approx(0.001, abs=1e-12)
    assert stats.bus_call_max_s == pytest.approx(p + 0.004, abs=1e-12)
    # sorted bus calls: 99 of 1 ms, then P + 4 ms; p99 position 98.01
    assert stats.bus_call_p99_s == pytest.approx(0.001 + 0.01 * (p + 0.003), abs=1e-12)
    # last frame (99) is on time, so the run lasts 99 periods plus its 1 ms write
    assert stats.wall_s == pytest.approx(99 * p + 0.001, abs=1e-9)
    assert stats.last_lateness_s == pytest.approx(0.0, abs=1e-12)
    d = stats.to_dict()
    assert d["frames"] == 100 and d["late_frames"] == 5
    assert d["lateness_max_s"] == pytest.approx(4e-3, abs=1e-12)
    assert 0.0 <= d["work_cpu_per_frame_s"] * 100 <= d["cpu_per_frame_s"] * 100 + 1e-9
    text = stats.summary()
    assert "100 frames" in text and "5 late" in text and "4.000 ms" in text


def test_bus_call_median_with_an_even_count():
    # costs 0..9 ms, ten of each, over 100 frames: the median is the mean of the 50th and
    # 51st sorted values, 4 ms and 5 ms.
    bus, stats = run_frames(lambda i: 0.001 * (i % 10), 100)
    assert stats.bus_call_median_s == pytest.approx(0.0045, abs=1e-12)
    assert stats.bus_call_p99_s == pytest.approx(0.009, abs=1e-12)
    assert stats.late_frames == 0


def test_cpu_time_is_taken_from_the_injected_counter():
    ticks = iter(range(1000))
    bus, stats = run_frames(0.001, 10, cpu_time_s=lambda: float(next(ticks)))
    # one reading at start and end of the run, two per frame: 22 readings, 21 units in all;
    # the frames account for 1 unit each.
    assert stats.cpu_s == 21.0
    assert stats.work_cpu_s == 10.0
    assert stats.cpu_per_frame_s == pytest.approx(2.1)


def test_on_frame_sees_every_frame_with_fresh_stats():
    seen = []
    clock = VirtualClock()
    bus = FakeBus(clock)
    streamer = Streamer(bus, IDS, PERIOD_S, clock, on_frame=lambda k, s: seen.append((k, s.frames)))
    streamer.run(np.zeros((5, len(IDS)), dtype=np.int64))
    assert seen == [(k, k + 1) for k in range(5)]


def test_each_frame_is_one_write_with_python_int_ticks_by_id():
    clock = VirtualClock()
    bus = FakeBus(clock)
    frames = np.array([[10, 20, 30, 40], [11, 21, 31, 41]], dtype=np.int32)
    Streamer(bus, IDS, PERIOD_S, clock).run(frames)
    assert [g for _, g in bus.writes] == [{1: 10, 2: 20, 3: 30, 4: 40}, {1: 11, 2: 21, 3: 31, 4: 41}]
    assert all(type(v) is int for _, g in bus.writes for v in g.values())


def test_streamer_rejects_bad_frames():
    clock = VirtualClock()
    streamer = Streamer(FakeBus(clock), IDS, PERIOD_S, clock)
    with pytest.raises(ValueError, match="shape"):
        streamer.run(np.zeros((3, 3), dtype=np.int64))
    with pytest.raises(ValueError, match="whole ticks"):
        streamer.run(np.full((3, 4), 0.5))
    empty = streamer.run(np.zeros((0, 4), dtype=np.int64))
    assert empty.frames == 0 and empty.lateness_p99_s == 0.0


# --------------------------------------------------------------------------- ramps

@pytest.mark.parametrize("seed", range(8))
def test_ramp_respects_limits_reaches_target_and_is_synchronised(seed):
    rng = np.random.default_rng(seed)
    joints = 12
    start = rng.integers(500, 3500, size=joints)
    target = rng.integers(500, 3500, size=joints)
    max_velocity = float(rng.uniform(300, 4000))      # ticks/s
    max_accel = float(rng.uniform(10_000, 80_000))    # ticks/s^2
    frames = ramp_ticks(start, target, max_velocity, max_accel, PERIOD_S)
    assert frames.dtype.kind == "i"
    np.testing.assert_array_equal(frames[-1], target)
    assert_within_limits(frames, start, max_velocity, max_accel, after=target)
    # synchronised: every joint has covered the same fraction of its way, up to rounding
    delta = (target - start).astype(float)
    lead = int(np.argmax(np.abs(delta)))
    fraction = (frames[:, lead] - start[lead]) / delta[lead]
    moving = np.abs(delta) > 0
    expected = start[moving] + fraction[:, None] * delta[moving]
    assert np.abs(frames[:, moving] - expected).max() <= 0.5 + 0.5 * np.abs(delta[moving]).max() / np.abs(delta[lead])
    # duration: not faster than physics allows, not much slower than the rounding margins require
    distance = np.abs(delta).max()
    duration_s = len(frames) * PERIOD_S
    assert duration_s >= min_time_s(distance, max_velocity, max_accel) - 1e-9
    assert duration_s <= min_time_s(distance, max_velocity - 1 / PERIOD_S, max_accel - 2 / PERIOD_S**2) + PERIOD_S


def test_ramp_short_move_is_a_triangle_within_limits():
    start, target = np.array([2000, 2000]), np.array([2030, 1990])
    frames = ramp_ticks(start, target, 5000.0, 40_000.0, PERIOD_S)
    np.testing.assert_array_equal(frames[-1], target)
    assert_within_limits(frames, start, 5000.0, 40_000.0, after=target)


def test_ramp_is_empty_when_already_within_one_tick():
    frames = ramp_ticks([100, 200, 300], [101, 200, 299], 1000.0, 20_000.0, PERIOD_S)
    assert frames.shape == (0, 3)
    assert ramp_ticks([100, 200], [102, 200], 1000.0, 20_000.0, PERIOD_S).shape[0] >= 1


def test_ramp_with_limits_below_tick_resolution_stays_within_one_tick_of_quantisation():
    # 30 ticks/s is half a tick per frame at 60 Hz: integer frames cannot be smoother than
    # one tick steps, so the promise is the limit plus one tick of quantisation.
    start, target = np.array([0, 0]), np.array([50, -20])
    max_velocity, max_accel = 30.0, 1000.0
    frames = ramp_ticks(start, target, max_velocity, max_accel, PERIOD_S)
    np.testing.assert_array_equal(frames[-1], target)
    assert_within_limits(frames, start, max_velocity + 1 / PERIOD_S, max_accel + 2 / PERIOD_S**2, after=target)


def test_brake_stops_each_joint_within_the_acceleration_limit():
    previous, last = np.array([1000, 3000, 2000, 500]), np.array([1020, 2970, 2000, 540])  # ticks per frame
    max_accel = 30_000.0
    frames = brake_ticks(previous, last, max_accel, PERIOD_S)
    # from the motion under way to rest, and rest held after
    assert_within_limits(frames, last, np.inf, max_accel, after=frames[-1], moving_from=previous)
    # each joint keeps going its own way and stops no further than v^2 / (2 a) (planned deceleration, + rounding)
    velocity = (last - previous) / PERIOD_S
    travel = (frames[-1] - last) * np.sign(velocity)
    assert (travel >= 0).all()
    assert (travel <= velocity**2 / (2 * (max_accel - 2 / PERIOD_S**2)) + 0.5).all()
    assert (frames[:, 2] == 2000).all()  # a joint at rest stays put


def test_brake_is_empty_at_rest_or_below_a_tick_of_motion():
    assert brake_ticks([5, 6], [5, 6], 30_000.0, PERIOD_S).shape == (0, 2)
    assert brake_ticks([5, 6], [6, 6], 30_000.0, PERIOD_S).shape == (0, 2)  # stops within a fraction of a tick


def test_stop_brakes_then_ramps_to_stand_within_limits():
    previous, last, stand = np.array([1500, 2500]), np.array([1530, 2480]), np.array([2048, 2048])
    frames = stop_ticks(previous, last, stand, VMAX, AMAX, PERIOD_S)
    np.testing.assert_array_equal(frames[-1], stand)
    assert_within_limits(frames, last, VMAX, AMAX, after=stand, moving_from=previous)


def test_ramp_rejects_bad_input():
    with pytest.raises(ValueError):
        ramp_ticks([0, 0], [10], 100.0, 100.0, PERIOD_S)
    with pytest.raises(ValueError):
        ramp_ticks([0], [10], 0.0, 100.0, PERIOD_S)


# --------------------------------------------------------------------------- prepare and the session

VMAX = 2000.0    # ticks/s
AMAX = 30_000.0  # ticks/s^2
STAND = np.array([2048, 2048, 2048, 2048])


def gait_frames(count: int = 120) -> np.ndarray:
    """A smooth gait-like trajectory from STAND to STAND, within the limits but fast.

    Peak speed 600 * pi / 2 s = 942 ticks/s (16 ticks a frame): stopping that dead in one
    frame would be 56,000 ticks/s^2, nearly twice AMAX, so the stop tests can tell braking
    from stopping dead.
    """
    t = np.arange(count) * PERIOD_S
    phase = 2 * np.pi * t / (count * PERIOD_S)
    amplitude = np.array([600, -500, 400, -600])
    return np.rint(STAND + amplitude * (1 - np.cos(phase))[:, None] / 2).astype(np.int64)


def session(bus, clock, frames=None, **kwargs):
    kwargs.setdefault("torque_off_on_exit", True)
    return walk_session(bus, IDS, gait_frames() if frames is None else frames, STAND,
                        max_velocity_ticks_per_s=VMAX, max_accel_ticks_per_s2=AMAX,
                        period_s=PERIOD_S, clock=clock, **kwargs)


def start_pose_bus(clock, **kwargs) -> FakeBus:
    present = {1: 1800, 2: 2300, 3: 2048, 4: 1900}
    return FakeBus(clock, present=present, **kwargs)


def test_prepare_names_every_missing_id():
    clock = VirtualClock()
    bus = FakeBus(clock, present={i: 0 for i in range(1, 7)}, missing={2, 5})
    with pytest.raises(MissingServosError) as info:
        prepare(bus, [1, 2, 3, 4, 5, 6])
    assert info.value.missing_ids == [2, 5]
    assert "servos 2, 5 did not answer" in str(info.value)


def test_session_closes_the_bus_even_when_open_fails():
    from gaitbot.bus.base import PortError

    clock = VirtualClock()

    class NoPort(FakeBus):
        def open(self):
            super().open()
            raise PortError("cannot open serial port /dev/ttyUSB9")

    bus = NoPort(clock)
    result = session(bus, clock)
    assert result.outcome == "bus_error" and result.exit_code == 1 and isinstance(result.error, PortError)
    assert bus.names() == ["open", "close"]


def test_prepare_returns_present_ticks_in_id_order():
    clock = VirtualClock()
    bus = FakeBus(clock, present={1: 11, 2: 22, 3: 33, 4: 44})
    np.testing.assert_array_equal(prepare(bus, [3, 1, 4, 2]), [33, 11, 44, 22])


def test_session_with_missing_servos_moves_nothing_and_closes():
    clock = VirtualClock()
    bus = FakeBus(clock, missing={3})
    result = session(bus, clock)
    assert result.outcome == "bus_error" and result.exit_code == 1
    assert isinstance(result.error, MissingServosError) and result.error.missing_ids == [3]
    assert "write" not in bus.names() and "set_torque" not in bus.names()
    assert bus.closed


def test_the_test_gait_is_within_limits():
    walk = gait_frames()
    assert_within_limits(walk, STAND, VMAX, AMAX, after=STAND)
    assert np.abs(np.diff(walk, axis=0)).max() / PERIOD_S > 900  # fast enough to need braking


def test_session_completed_ramps_in_walks_and_ends_standing():
    clock = VirtualClock(bus_call_cost_s=0.002)
    bus = start_pose_bus(clock)
    walk = gait_frames()
    result = session(bus, clock, frames=walk)
    assert result.outcome == "completed" and result.exit_code == 0 and result.error is None
    names = bus.names()
    # goal = present before torque on, so enabling torque moves nothing
    present = np.array([1800, 2300, 2048, 1900])
    first_write = names.index("write")
    assert names.index("set_torque") > first_write
    written = bus.write_ticks()
    np.testing.assert_array_equal(written[0], present)
    # the start ramp, then the walk verbatim, then nothing else (the walk ends standing)
    ramp_len = len(written) - 1 - len(walk)
    assert ramp_len > 0
    assert_within_limits(written[1: 1 + ramp_len], present, VMAX, AMAX, after=walk[0])
    np.testing.assert_array_equal(written[1 + ramp_len:], walk)
    assert result.reached_stand and result.walk_stats.frames == len(walk)
    assert names[-2:] == ["set_torque", "close"] and bus.calls[-2][2] == (IDS, False)
    assert result.torque_off


def test_session_keeps_torque_on_when_asked():
    clock = VirtualClock()
    bus = start_pose_bus(clock)
    result = session(bus, clock, torque_off_on_exit=False)
    assert result.outcome == "completed" and not result.torque_off
    assert [c[2] for c in bus.calls if c[0] == "set_torque"] == [(IDS, True)]


def test_session_ramps_to_stand_when_trajectory_ends_elsewhere():
    clock = VirtualClock()
    bus = start_pose_bus(clock)
    walk = gait_frames()[:45]  # ends away from STAND, still moving at 70 % of peak speed
    result = session(bus, clock, frames=walk)
    written = bus.write_ticks()
    np.testing.assert_array_equal(written[-1], STAND)
    tail = written[len(written) - 1 - np.flatnonzero((written[::-1] == walk[-1]).all(axis=1))[0] + 1:]
    assert_within_limits(tail, walk[-1], VMAX, AMAX, after=STAND, moving_from=walk[-2])
    assert result.reached_stand


def raise_at_walk_frames(raisers: dict):
    """on_write hook raising ``raisers[j]()`` at the write attempt walk-start + j.

    The walk starts with the attempt after the first write equal to walk[0] (the start
    ramp ends on walk[0] and the walk begins with it again). Offsets past the last walk
    frame that was attempted fall on the stop ramp.
    """
    walk = gait_frames()
    state = {"walk_start": None}

    def hook(attempt, goals):
        if state["walk_start"] is None and [goals[i] for i in IDS] == walk[0].tolist():
            state["walk_start"] = attempt + 1
        start = state["walk_start"]
        if start is not None and attempt - start in raisers:
            raisers[attempt - start]()
    hook.state = state
    return hook, walk


def interrupt_at_walk_frame(k: int, exc_factory):
    return raise_at_walk_frames({k: exc_factory})


def check_stop_ramp(previous_ticks: np.ndarray, interrupted_ticks: np.ndarray, stop_writes: np.ndarray) -> None:
    """Writes after the interruption: within limits from the motion under way (the last two
    frames), ending at STAND, each joint between where it was and STAND except for the braking
    overshoot v^2 / (2 a) (so no further walk frames)."""
    np.testing.assert_array_equal(stop_writes[-1], STAND)
    assert_within_limits(stop_writes, interrupted_ticks, VMAX, AMAX, after=STAND, moving_from=previous_ticks)
    velocity = (interrupted_ticks - previous_ticks) / PERIOD_S
    overshoot = velocity**2 / (2 * (AMAX - 2 / PERIOD_S**2)) + 1  # the planner's deceleration, plus rounding
    low = np.minimum(interrupted_ticks, STAND) - overshoot
    high = np.maximum(interrupted_ticks, STAND) + overshoot
    assert ((stop_writes >= low) & (stop_writes <= high)).all()


def test_ctrl_c_ramps_to_stand_and_exits_130():
    k = 40

    def ctrl_c():
        raise KeyboardInterrupt

    hook, walk = interrupt_at_walk_frame(k, ctrl_c)
    clock = VirtualClock(bus_call_cost_s=0.001)
    bus = start_pose_bus(clock, on_write=hook)
    result = session(bus, clock)
    assert result.outcome == "interrupted" and result.exit_code == 130
    assert result.walk_stats.frames == k
    # the interrupted write did not reach the fake bus; the stop starts from that frame
    stop_writes = split_at_interrupt(bus, walk, k)
    check_stop_ramp(walk[k - 1], walk[k], stop_writes)
    assert result.reached_stand and result.torque_off
    assert bus.names()[-2:] == ["set_torque", "close"]


def split_at_interrupt(bus: FakeBus, walk: np.ndarray, k: int) -> np.ndarray:
    """Writes after walk frame k-1 (frame k raised before being recorded)."""
    written = bus.write_ticks()
    for i in range(k, len(written)):
        if (written[i - k: i] == walk[:k]).all():
            return written[i:]
    raise AssertionError("walk frames not found in the writes")


def test_sigterm_ramps_to_stand_exits_143_and_restores_the_old_handler():
    k = 25
    called = []

    def sentinel(signum, frame):
        called.append(signum)

    def sigterm():
        os.kill(os.getpid(), signal.SIGTERM)

    hook, walk = interrupt_at_walk_frame(k, sigterm)
    clock = VirtualClock(bus_call_cost_s=0.001)
    bus = start_pose_bus(clock, on_write=hook)
    previous = signal.signal(signal.SIGTERM, sentinel)
    try:
        result = session(bus, clock)
        assert signal.getsignal(signal.SIGTERM) is sentinel
    finally:
        signal.signal(signal.SIGTERM, previous)
    assert called == []  # our handler took it, not the sentinel
    assert result.outcome == "terminated" and result.exit_code == 143
    # the signal only set the session's flag: the write it landed in went out whole, and the loop stopped
    # before the next frame, braking from the motion of frames k-1 and k
    assert result.walk_stats.frames == k + 1
    check_stop_ramp(walk[k - 1], walk[k], split_at_interrupt(bus, walk, k + 1))
    assert result.torque_off and bus.closed


def test_a_second_interrupt_does_not_abandon_the_stop_ramp():
    """A KeyboardInterrupt raised by the bus inside a stop-ramp write (signals of the session's own never
    raise: see the next test) does not end the ramp: it goes on, braking from where it was, to STAND."""
    k = 30

    def ctrl_c():
        raise KeyboardInterrupt

    # first Ctrl-C at walk frame k; the second at the third stop-ramp frame (attempt k + 3)
    hook, walk = raise_at_walk_frames({k: ctrl_c, k + 3: ctrl_c})
    clock = VirtualClock()
    bus = start_pose_bus(clock, on_write=hook)
    result = session(bus, clock, frames=walk)
    assert result.outcome == "interrupted" and result.exit_code == 130
    assert result.reached_stand
    np.testing.assert_array_equal(bus.write_ticks()[-1], STAND)
    # the interrupted ramp frame never went out and is sent again: the writes are the one planned stop ramp
    check_stop_ramp(walk[k - 1], walk[k], split_at_interrupt(bus, walk, k))
    assert result.torque_off and bus.names()[-2:] == ["set_torque", "close"]


@pytest.mark.parametrize("signals", [[signal.SIGINT, signal.SIGINT], [signal.SIGTERM, signal.SIGINT, signal.SIGTERM]])
def test_signals_during_the_stop_ramp_only_set_the_flag_and_the_ramp_finishes(signals):
    """Real signals while a session runs (the first at walk frame k, the others in the stop ramp): none raises
    inside a bus exchange, the stop ramp goes out whole to STAND, and the outcome is the first signal's."""
    k = 30
    raisers = {k + i * 2: (lambda s=s: os.kill(os.getpid(), s)) for i, s in enumerate(signals)}
    hook, walk = raise_at_walk_frames(raisers)
    clock = VirtualClock()
    bus = start_pose_bus(clock, on_write=hook)
    result = session(bus, clock, frames=walk)
    expected = "terminated" if signals[0] == signal.SIGTERM else "interrupted"
    assert result.outcome == expected and result.reached_stand and result.torque_off
    assert result.walk_stats.frames == k + 1
    check_stop_ramp(walk[k - 1], walk[k], split_at_interrupt(bus, walk, k + 1))
    assert bus.write_attempts == len(bus.writes)  # no write was cut short


def test_dead_bus_gives_exit_1_without_hanging():
    k = 10
    hook_state = {}

    def fail():
        hook_state["bus"].die()
        hook_state["failed_call"] = len(hook_state["bus"].calls) - 1
        raise ServoTimeout("servo 3 did not answer", servo_id=3)

    hook, walk = interrupt_at_walk_frame(k, fail)
    clock = VirtualClock()
    bus = start_pose_bus(clock, on_write=hook, max_calls=10_000)
    hook_state["bus"] = bus
    result = session(bus, clock)
    assert result.outcome == "bus_error" and result.exit_code == 1
    assert isinstance(result.error, ServoTimeout) and result.error.servo_id == 3
    # after the failure: one write attempt (the stop ramp gives up at once), one torque-off attempt, close
    failure = hook_state["failed_call"]
    assert bus.calls[failure][2] == dict(zip(IDS, walk[k].tolist()))
    assert bus.names()[failure + 1:] == ["write", "set_torque", "close"]
    assert not result.torque_off and not result.reached_stand
    assert "servo 3" in result.message()


def test_transient_bus_error_still_ramps_to_stand():
    k = 20

    def fail():
        raise BusError("checksum error")

    hook, walk = interrupt_at_walk_frame(k, fail)
    clock = VirtualClock()
    bus = start_pose_bus(clock, on_write=hook)
    result = session(bus, clock)
    assert result.outcome == "bus_error" and result.exit_code == 1
    check_stop_ramp(walk[k - 1], walk[k], split_at_interrupt(bus, walk, k))
    assert result.reached_stand and result.torque_off and bus.closed


def test_unexpected_error_still_stops_safely_closes_and_reraises():
    k = 5

    def bug():
        raise ZeroDivisionError("bug in a lower layer")

    hook, walk = interrupt_at_walk_frame(k, bug)
    clock = VirtualClock()
    bus = start_pose_bus(clock, on_write=hook)
    with pytest.raises(ZeroDivisionError):
        session(bus, clock)
    np.testing.assert_array_equal(bus.write_ticks()[-1], STAND)
    assert bus.names()[-2:] == ["set_torque", "close"]


def test_exit_codes_are_the_shell_conventions():
    assert EXIT_CODES == {"completed": 0, "interrupted": 128 + signal.SIGINT,
                          "terminated": 128 + signal.SIGTERM, "bus_error": 1, "health_stop": 1,
                          "fell": 1}  # the IMU noticed a fall (gaitbot.feel)


# --------------------------------------------------------------------------- latency timer

def fake_sysfs(tmp_path, device: str, content: str):
    directory = tmp_path / "sys" / "bus" / "usb-serial" / "devices" / device
    directory.mkdir(parents=True)
    (directory / "latency_timer").write_text(content)
    return str(tmp_path / "sys")


def test_latency_timer_warning_at_the_default_16_ms(tmp_path):
    root = fake_sysfs(tmp_path, "ttyUSB0", "16\n")
    warning = latency_timer_warning("/dev/ttyUSB0", sysfs_root=root)
    assert warning is not None and "\n" not in warning
    assert "16 ms" in warning
    assert "echo 1 | sudo tee" in warning and "ttyUSB0/latency_timer" in warning
    assert "udev" in warning


def test_latency_timer_of_1_ms_is_fine(tmp_path):
    root = fake_sysfs(tmp_path, "ttyUSB0", "1\n")
    assert latency_timer_warning("/dev/ttyUSB0", sysfs_root=root) is None


def test_latency_timer_unknown_device_or_unreadable_gives_no_warning(tmp_path):
    root = fake_sysfs(tmp_path, "ttyUSB1", "garbage")
    assert latency_timer_warning("/dev/ttyUSB1", sysfs_root=root) is None
    assert latency_timer_warning("/dev/ttyACM0", sysfs_root=root) is None
    assert latency_timer_warning("COM3", sysfs_root=root) is None


def test_latency_timer_follows_by_id_symlinks(tmp_path):
    root = fake_sysfs(tmp_path, "ttyUSB2", "16")
    (tmp_path / "dev").mkdir()
    (tmp_path / "dev" / "ttyUSB2").write_text("")
    link = tmp_path / "dev" / "usb-FTDI_FT232R_A1B2C3-if00-port0"
    link.symlink_to(tmp_path / "dev" / "ttyUSB2")
    warning = latency_timer_warning(str(link), sysfs_root=root)
    assert warning is not None and "ttyUSB2" in warning


@pytest.mark.parametrize("close_exc", [KeyboardInterrupt, OSError])
def test_a_failing_close_is_reported_and_the_sigterm_handler_still_restored(close_exc):
    clock = VirtualClock()

    class ClosingFails(FakeBus):
        def close(self):
            super().close()
            raise close_exc("flush failed")

    bus = ClosingFails(clock, present={i: 2048 for i in IDS})

    def sentinel(signum, frame):
        pass

    previous = signal.signal(signal.SIGTERM, sentinel)
    try:
        result = session(bus, clock)
        assert signal.getsignal(signal.SIGTERM) is sentinel
    finally:
        signal.signal(signal.SIGTERM, previous)
    assert result.outcome == "completed" and bus.closed
    assert any("closing the bus" in note for note in result.notes)


# --------------------------------------------------------------------------- WalkSession and frame sources

def test_a_frame_source_is_pulled_one_frame_at_a_time_and_sends_what_the_array_sends():
    """A live walk hands the session an iterator: each frame is taken only when it is due (after the frame
    before it went out), and the writes, their times and the stop are those of the same frames as an array."""
    from gaitbot.stream.session import SessionLimits, WalkSession

    walk = gait_frames()
    clock_a = VirtualClock(bus_call_cost_s=0.001)
    bus_a = start_pose_bus(clock_a)
    by_array = session(bus_a, clock_a, frames=walk)

    clock_b = VirtualClock(bus_call_cost_s=0.001)
    bus_b = start_pose_bus(clock_b)
    writes_when_pulled = []

    def frame_source():
        for frame in walk:
            writes_when_pulled.append(len(bus_b.writes))
            yield frame.tolist()  # any row of ticks will do

    live = WalkSession(bus_b, IDS, STAND, SessionLimits(VMAX, AMAX, PERIOD_S), clock=clock_b, torque_off_on_exit=True)
    by_source = live.run(frame_source())
    assert by_source.outcome == by_array.outcome == "completed" and by_source.exit_code == 0
    assert [(t, g) for t, g in bus_b.writes] == [(t, g) for t, g in bus_a.writes]
    assert by_source.walk_stats.frames == by_array.walk_stats.frames
    # frame k (k >= 2) is pulled after frame k - 1 was written: never ahead of the stream
    start = writes_when_pulled[1]
    assert writes_when_pulled[1:] == list(range(start, start + len(walk) - 1))


def test_a_frame_source_that_ends_early_still_ends_standing():
    """A live walk that stops producing frames (its planner ended the walk anywhere) gets the final ramp."""
    from gaitbot.stream.session import SessionLimits, WalkSession

    clock = VirtualClock()
    bus = start_pose_bus(clock)
    result = WalkSession(bus, IDS, STAND, SessionLimits(VMAX, AMAX, PERIOD_S), clock=clock).run(iter(gait_frames()[:45]))
    assert result.outcome == "completed" and result.reached_stand
    np.testing.assert_array_equal(bus.write_ticks()[-1], STAND)


def test_session_limits_are_one_record_and_outcomes_compare_as_their_names():
    from gaitbot.stream.session import Outcome, SessionLimits

    limits = SessionLimits(VMAX, AMAX, PERIOD_S)
    ramp = limits.ramp(np.full(4, 1000), STAND)
    np.testing.assert_array_equal(ramp, ramp_ticks(np.full(4, 1000), STAND, VMAX, AMAX, PERIOD_S))
    assert Outcome.TERMINATED == "terminated" and {"terminated": 1}[Outcome.TERMINATED] == 1
    assert [o.exit_code for o in Outcome] == [0, 128 + signal.SIGINT, 128 + signal.SIGTERM, 1, 1, 1]  # the last: fell
