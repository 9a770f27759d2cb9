"""What the IMU feedback costs a frame: the estimate and the correction (gaitbot.feel), and the IMU read's wire time.

    python tools/bench_feel.py            # op3, 5000 frames

The IMU read itself goes over the bus (its wire time at 2 Mbaud is a fact of the packets: gaitbot.servos.opencr);
here the reader's bus is a stub that returns a recorded-like block at once, so the figures are the host's
work per frame: decoding the block, the complementary filter, the gyro damping and the limit window.
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from gaitbot.feel.feedback import Feedback
from gaitbot.feel.imu_reader import ImuReader
from gaitbot.robot.calibration import angles_to_ticks
from gaitbot.robot.config import load_robot_config, resolve_config
from gaitbot.servos.opencr import IMU_READ_WIRE_S, encode_imu_block


class StubBus:
    """Answers every IMU read at once with a slightly different block (a live sensor's noise)."""

    def __init__(self) -> None:
        self.rng = np.random.default_rng(0)

    def read_device(self, device_id, address, length, budget_s):
        return encode_imu_block(self.rng.normal(0, 20, 3), [0.0, 0.0, 1.0] + self.rng.normal(0, 0.02, 3),
                                [0.0, 0.0, 0.0])


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--robot", default="op3")
    parser.add_argument("--frames", type=int, default=5000)
    args = parser.parse_args()
    config = load_robot_config(resolve_config(args.robot))
    period = 1 / config.gait.rate_hz
    clock = [0.0]
    reader = ImuReader(StubBus(), config.imu, lambda: clock[0], period)
    feedback = Feedback(config, "full", reader, period, lambda: clock[0])
    t = np.arange(args.frames) * period
    plan = np.radians(10.0) * np.sin(2 * np.pi * t / config.gait.cycle_s)[:, None] * np.ones(len(config.joints))
    rows = angles_to_ticks(config, plan)
    costs = np.empty(args.frames)
    for k in range(args.frames):
        clock[0] = k * period
        start = time.perf_counter()
        feedback.sense(clock[0])
        feedback.correct(k, rows[k])
        costs[k] = time.perf_counter() - start
    print(f"{config.name}: IMU read + estimate + feedback per frame over {args.frames} frames: median "
          f"{np.median(costs) * 1e3:.3f} ms, p99 {np.percentile(costs, 99) * 1e3:.3f} ms, max {costs.max() * 1e3:.3f} ms "
          f"(host work; the read's wire time at 2 Mbaud is {IMU_READ_WIRE_S * 1e3:.3f} ms)")


if __name__ == "__main__":
    main()
