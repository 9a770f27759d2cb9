"""Clocks for the real-time loop: the real monotonic one and a virtual one for tests.

The streamer only ever asks a clock two things, ``now()`` and ``sleep_until(deadline_s)``,
so that tests can replace time itself and check deadlines exactly, without wall-clock luck.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from typing import Protocol, runtime_checkable

__all__ = ["Clock", "MonotonicClock", "VirtualClock"]


@runtime_checkable
class Clock(Protocol):
    """A monotonic time source in seconds that can wait for an absolute deadline."""

    def now(self) -> float:
        """Seconds on a monotonic scale (the origin is arbitrary)."""

    def sleep_until(self, deadline_s: float) -> None:
        """Return at or just after ``deadline_s``; return at once if it has passed."""


class MonotonicClock:
    """The real clock: ``time.perf_counter`` (monotonic, sub-microsecond on Linux).

    ``time.sleep`` alone wakes up late by the OS timer slack and scheduling (typically
    50-100 us on Linux, over a millisecond elsewhere), so we sleep until ``spin_s`` before
    the deadline and spin on the counter for the rest. The spin costs CPU (at most
    ``spin_s`` per frame, about 9 % of one core at 60 Hz with the default 1.5 ms) and buys
    sends within a few microseconds of their deadline.
    """

    def __init__(self, spin_s: float = 1.5e-3) -> None:
        if spin_s < 0:
            raise ValueError(f"spin_s must be >= 0, got {spin_s}")
        self.spin_s = spin_s

    def now(self) -> float:
        return time.perf_counter()

    def sleep_until(self, deadline_s: float) -> None:
        remaining_s = deadline_s - time.perf_counter()
        if remaining_s > self.spin_s:
            time.sleep(remaining_s - self.spin_s)
        while time.perf_counter() < deadline_s:
            pass


class VirtualClock:
    """Deterministic time for tests: sleeping jumps time forward, nothing else moves it.

    Work "costs" time only when someone says so: ``advance(dt_s)``, or
    ``charge_bus_call()`` which a fake bus calls inside each bus method so that a test can
    make bus calls slow, jittery, or make one particular frame late, deterministically.

    bus_call_cost_s: seconds charged per bus call, either a constant or a function of the
    call's index (0, 1, 2, ... in order of ``charge_bus_call`` calls).
    """

    def __init__(self, start_s: float = 0.0,
                 bus_call_cost_s: float | Callable[[int], float] = 0.0) -> None:
        self._now_s = float(start_s)
        self.bus_call_cost_s = bus_call_cost_s
        self.bus_calls = 0
        self.sleeps = 0

    def now(self) -> float:
        return self._now_s

    def sleep_until(self, deadline_s: float) -> None:
        self.sleeps += 1
        if deadline_s > self._now_s:
            self._now_s = float(deadline_s)

    def advance(self, dt_s: float) -> None:
        """Let ``dt_s`` seconds pass (work being done)."""
        if dt_s < 0:
            raise ValueError(f"time does not run backwards (dt_s={dt_s})")
        self._now_s += dt_s

    def charge_bus_call(self) -> float:
        """Advance by the cost of the next bus call; return that cost in seconds."""
        cost = self.bus_call_cost_s
        cost_s = float(cost(self.bus_calls) if callable(cost) else cost)
        self.bus_calls += 1
        self.advance(cost_s)
        return cost_s
