"""Dry-run benchmark of the 60 Hz loop on the real clock, without hardware.

Streams a smooth trajectory for ``--seconds`` to an in-memory bus (it keeps the last goal
of each servo and nothing else). Then it prints how late frames went out and how much CPU
each frame cost. The lateness is this machine's own: OS scheduling plus the spin-wait. A
real serial bus adds its write time on top, which shows up as "bus call" time.

    python tools/bench_stream.py                 # 60 s at 60 Hz, 12 servos
    python tools/bench_stream.py --seconds 10

The integrator can swap ``InMemoryBus`` for the mock bus (the recording port under the
Dynamixel packet code) to include packet building in the figures.
"""

from __future__ import annotations

import argparse
import os
import platform
import sys
from collections.abc import Iterable, Mapping

import numpy as np

try:
    from gaitbot.bus.base import Bus
except ImportError:  # run from a checkout without installing
    sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), os.pardir))
    from gaitbot.bus.base import Bus

from gaitbot.app.progress import progress
from gaitbot.stream.clock import MonotonicClock
from gaitbot.stream import Streamer


class InMemoryBus(Bus):
    """A bus that answers instantly: the loop's own overhead, nothing else."""

    def __init__(self, ids: Iterable[int]) -> None:
        self.goals = {i: 2048 for i in ids}

    def open(self) -> None:
        pass

    def close(self) -> None:
        pass

    def ping(self, servo_id: int) -> bool:
        return servo_id in self.goals

    def set_torque(self, ids: Iterable[int], enabled: bool) -> None:
        pass

    def write_goal_ticks(self, goals: Mapping[int, int]) -> None:
        self.goals.update(goals)

    def read_present_ticks(self, ids: Iterable[int]) -> dict[int, int]:
        return {i: self.goals[i] for i in ids}


def bench_frames(frame_count: int, joint_count: int, rate_hz: float) -> np.ndarray:
    """A 1 Hz sine of 200 ticks around mid-range on every joint, phase-shifted per joint."""
    t = np.arange(frame_count)[:, None] / rate_hz
    phase = np.arange(joint_count)[None, :] * 0.5
    return np.rint(2048 + 200 * np.sin(2 * np.pi * t + phase)).astype(np.int64)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seconds", type=float, default=60.0, help="length of the dry run (default 60)")
    parser.add_argument("--rate-hz", type=float, default=60.0, help="frame rate (default 60)")
    parser.add_argument("--joints", type=int, default=12, help="servos on the bus (default 12)")
    args = parser.parse_args(argv)
    if args.seconds <= 0 or args.rate_hz <= 0 or args.joints <= 0:
        parser.error("--seconds, --rate-hz and --joints must be positive")

    ids = list(range(1, args.joints + 1))
    frame_count = max(1, round(args.seconds * args.rate_hz))
    frames = bench_frames(frame_count, args.joints, args.rate_hz)
    clock = MonotonicClock()
    print(f"Streaming {frame_count} frames to {args.joints} in-memory servos at {args.rate_hz:g} Hz "
          f"({frame_count / args.rate_hz:.1f} s, spin {clock.spin_s * 1e3:.1f} ms) ...", flush=True)
    with progress("streaming in real time", total=frame_count, unit="frame") as bar:
        def on_frame(k: int, _stats) -> None:  # now and then: a bar drawn every frame would cost the loop
            if k % 30 == 0:
                bar.update(k + 1 - bar.n)

        stats = Streamer(InMemoryBus(ids), ids, 1.0 / args.rate_hz, clock, on_frame).run(frames)

    us = 1e6
    print(f"machine: {platform.platform()}, {platform.processor() or platform.machine()}, "
          f"{os.cpu_count()} CPUs, Python {platform.python_version()}")
    print(f"frames: {stats.frames}, late (> {stats.late_threshold_s * 1e3:.1f} ms): {stats.late_frames}, "
          f"wall {stats.wall_s:.3f} s")
    print(f"lateness    median {stats.lateness_median_s * us:8.1f} us   p99 {stats.lateness_p99_s * us:8.1f} us"
          f"   max {stats.max_lateness_s * us:8.1f} us")
    print(f"bus call    median {stats.bus_call_median_s * us:8.1f} us   p99 {stats.bus_call_p99_s * us:8.1f} us"
          f"   max {stats.bus_call_max_s * us:8.1f} us")
    print(f"CPU/frame   {stats.cpu_per_frame_s * us:8.1f} us in all (mostly the spin-wait), "
          f"{stats.work_cpu_per_frame_s * us:.1f} us of work")
    return 0


if __name__ == "__main__":
    sys.exit(main())
