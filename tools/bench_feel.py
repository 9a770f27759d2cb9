"""What the IMU feedback costs a frame: the estimate and the correction (gaitbot.feel), and the IMU read's wire time.

    python tools/bench_feel.py            # op3, 5000 frames

The IMU read itself goes over the bus (its wire time at 2 Mbaud is a fact of the packets: gaitbot.servos.opencr);
here the reader's bus is a stub that returns a recorded-like block at once, so the figures are the host's
work per frame: decoding the block, the complementary filter, the gyro damping, the attitude term and the
limit window. Three lines: the feedback alone (--frames frames of a sway), and the frame a walk with feedback
really does, the online balanced walker's ``next_frame`` (30 steps queued, as tools/bench_balance.py) with the
feedback on its goals; and ``--feedback zmp``'s CoM correction alone (its support polygon and one step). Both in wall time and in CPU time of this thread (time.thread_time): on a shared machine
the wall p99 is the host's scheduling, the CPU p99 is the code's. Last, ``--feedback step``'s frames by what
they do (queue a step, a stage of a moved step's check, queue the moved step, take a step back for a pause,
none of these), in CPU time.
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from gaitbot.feel.feedback import Feedback
from gaitbot.feel.imu_reader import ImuReader
from gaitbot.robot.balanced_walk import balanced_walker
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


def percentiles(label: str, wall, cpu, what: str) -> str:
    wall, cpu = np.array(wall) * 1e3, np.array(cpu) * 1e3
    return (f"{label}: wall p50 {np.percentile(wall, 50):.3f} ms, p99 {np.percentile(wall, 99):.3f} ms, max "
            f"{wall.max():.3f} ms; CPU p50 {np.percentile(cpu, 50):.3f} ms, p99 {np.percentile(cpu, 99):.3f} ms, "
            f"max {cpu.max():.3f} ms over {len(wall)} {what}")


def feedback_of(config, period: float, clock: list[float]) -> Feedback:
    reader = ImuReader(StubBus(), config.imu, lambda: clock[0], period)
    return Feedback(config, "full", reader, period, lambda: clock[0])


def feedback_alone(config, frames: int) -> str:
    period, clock = 1 / config.gait.rate_hz, [0.0]
    feedback = feedback_of(config, period, clock)
    t = np.arange(frames) * period
    plan = np.radians(10.0) * np.sin(2 * np.pi * t / config.gait.cycle_s)[:, None] * np.ones(len(config.joints))
    rows = angles_to_ticks(config, plan)
    wall, cpu = np.empty(frames), np.empty(frames)
    for k in range(frames):
        clock[0] = k * period
        w, c = time.perf_counter(), time.thread_time()
        feedback.sense(clock[0])
        feedback.correct(k, rows[k])
        wall[k], cpu[k] = time.perf_counter() - w, time.thread_time() - c
    return percentiles("IMU read + estimate + feedback", wall, cpu, "frames")


def walker_with_feedback(config) -> str:
    """The online walker's frame, its goals in ticks, and the feedback on them (a frame of a live walk)."""
    period, clock = 1 / config.gait.rate_hz, [0.0]
    feedback = feedback_of(config, period, clock)
    walker = balanced_walker(config)
    for _ in range(30):
        walker.append_step(0.05)
    names = [j.name for j in config.joints]
    from gaitbot.gait.joints import LEG_JOINTS
    column = [LEG_JOINTS.index(n) for n in names]
    wall, cpu, k = [], [], 0
    while True:
        w, c = time.perf_counter(), time.thread_time()
        frame = walker.next_frame()
        if frame is None:
            break
        row = angles_to_ticks(config, np.asarray(frame[2])[column][None])[0]
        feedback.sense(clock[0])
        feedback.correct(k, row)
        wall.append(time.perf_counter() - w)
        cpu.append(time.thread_time() - c)
        k += 1
        clock[0] = k * period
    return percentiles("walker next_frame + ticks + IMU read + estimate + feedback", wall, cpu, "frames")


def correction_alone(config, frames: int) -> str:
    """``--feedback zmp``'s own work a frame (gaitbot.gait.balance.correction): the support polygon of the
    frame's grounded soles and one ComCorrection step, on errors beyond the dead band (always fed)."""
    from gaitbot.gait.balance.correction import ComCorrection, support_polygon

    walker = balanced_walker(config)
    correction = ComCorrection(walker.gains)
    rng = np.random.default_rng(0)
    h = config.body.geometry.ankle_height_m
    ankles = np.array([[0.0, 0.05, h], [0.03, -0.05, h]])
    errors = rng.normal(0.0, 0.03, (frames, 4))
    wall, cpu = np.empty(frames), np.empty(frames)
    for k in range(frames):
        ankles[1, 2] = h + (0.02 if k % 40 < 30 else 0.0)  # single support three frames of four
        w, c = time.perf_counter(), time.thread_time()
        hull = support_polygon(config.body.geometry, ankles, (0.0, 0.0))
        correction.step(errors[k, :2], errors[k, 2:], (0.02, 0.04), hull)
        wall[k], cpu[k] = time.perf_counter() - w, time.thread_time() - c
    return percentiles("zmp correction (support polygon + ComCorrection.step)", wall, cpu, "frames")


class LeaningFrom:
    """A tilt estimate (what the stepping source reads) that feels nothing until ``frame``, then a lean to the
    left: a push felt in the middle of a walk."""

    def __init__(self, frame: int) -> None:
        self.frame, self.frames, self.started = frame, 0, True
        self.roll_deg, self.pitch_deg, self.rates_dps = 0.0, 0.0, np.zeros(3)

    def tick(self) -> None:
        self.frames += 1
        if self.frames >= self.frame:
            self.roll_deg, self.rates_dps = -4.0, np.array([-30.0, 0.0, 0.0])


def stepping_frames(config, repeats: int = 5) -> list[str]:
    """``--feedback step``'s frames (gaitbot.drive.stepping) of six 6 cm steps with a lean felt from frame
    110, by what they do: queue a step (with its capture decision), one stage of a moved step's check, queue
    the moved step in place of the queued one, take the queued step back for a pause, none of these; CPU
    time of the thread."""
    from gaitbot.drive.stepping import SteppingFrames
    from gaitbot.robot.balanced_walk import balanced_gait_settings, plan_balanced

    plan = plan_balanced(config, [0.06] * 6, balanced_gait_settings(config, cycle_s=0.8, max_step_m=0.06))
    kinds = ("queue a step", "a stage of a check", "queue a moved step", "pause", "other")
    cpu: dict[str, list[float]] = {kind: [] for kind in kinds}
    for _ in range(repeats):
        felt = LeaningFrom(110)
        frames = SteppingFrames(config, plan, felt)
        frames_iter = iter(frames)
        while True:
            steps, moved, paused = frames.log.steps, len(frames.log.moved), len(frames.log.paused_s)
            checking = frames._checking is not None
            c = time.thread_time()
            try:
                next(frames_iter)
            except StopIteration:
                break
            took = time.thread_time() - c
            if len(frames.log.paused_s) > paused:
                kind = "pause"
            elif frames.log.steps > steps:
                kind = "queue a step"
            elif len(frames.log.moved) > moved:
                kind = "queue a moved step"
            elif checking or frames._checking is not None:
                kind = "a stage of a check"
            else:
                kind = "other"
            cpu[kind].append(took)
            felt.tick()
    return [f"--feedback step, {kind}: CPU p50 {np.median(v) * 1e3:.2f} ms, max {max(v) * 1e3:.2f} ms over "
            f"{len(v)} frames" for kind, v in cpu.items() if v]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--robot", default="op3")
    parser.add_argument("--frames", type=int, default=5000)
    args = parser.parse_args()
    config = load_robot_config(resolve_config(args.robot))
    print(f"{config.name}: {feedback_alone(config, args.frames)}")
    print(f"{config.name}: {walker_with_feedback(config)}")
    print(f"{config.name}: {correction_alone(config, args.frames)}")
    for line in stepping_frames(config):
        print(f"{config.name}: {line}")
    print(f"{config.name}: the IMU READ's wire time at 2 Mbaud: {IMU_READ_WIRE_S * 1e3:.3f} ms (43 bytes)")


if __name__ == "__main__":
    main()
