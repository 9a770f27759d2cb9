"""What the view costs the 60 Hz loop: one observer call per frame (docs/live-view.md).

    python tools/bench_view.py            # p50 / p99 / max microseconds per frame, op3, six steps

The planned walk's telemetry (gaitbot.view.walk_frames) is made once; then, paced at 60 Hz as a session
calls it, the observer takes each frame's record. "loop" rows: what the call costs the walk's loop (the
record queued for the worker thread, gaitbot.view.publisher.BackgroundPublisher); "worker" rows: the
worker's own cost per frame (every channel encoded to CDR and written). Sinks: none, an MCAP file, the
Foxglove server with no client, and with a loopback client subscribed to every channel (its own thread,
as Foxglove would be). "worker: drive record": a drive's frame made on the worker (gaitbot.view.
drive_telemetry: goals from the ticks, CoM, ZMP, soles and support over three frames) and encoded.
"+ sensors" rows: each frame also carries what the robot felt (an IMU reading with the walk's tilt
estimate, and one servo's read-back: gaitbot.app.view_options.felt_now in the loop, gaitbot.view.felt on
the worker). Machine-dependent figures.
"""

from __future__ import annotations

import asyncio
import json
import sys
import tempfile
import threading
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from gaitbot.app.options import load_robot  # noqa: E402
from gaitbot.app.view_options import felt_now  # noqa: E402
from gaitbot.bus.base import ReadBack, ReadBackOutcome  # noqa: E402
from gaitbot.feel.feedback import Feedback  # noqa: E402
from gaitbot.robot.calibration import standing_ticks  # noqa: E402
from gaitbot.servos.opencr import ImuReading  # noqa: E402
from gaitbot.gait.joints import LEG_JOINTS  # noqa: E402
from gaitbot.gait.trajectory import Trajectory  # noqa: E402
from gaitbot.robot.balanced_walk import plan_balanced  # noqa: E402
from gaitbot.robot.calibration import angles_to_ticks  # noqa: E402
from gaitbot.view.drive_telemetry import DriveSample, DriveTelemetry  # noqa: E402
from gaitbot.view.live import FoxgloveSink  # noqa: E402
from gaitbot.view.mcap_log import McapSink  # noqa: E402
from gaitbot.view.publisher import BackgroundPublisher, TelemetryPublisher  # noqa: E402
from gaitbot.view.telemetry import ServoHealth  # noqa: E402
from gaitbot.view.walk_frames import PlannedFrames  # noqa: E402

ROBOT, STEPS_M = "op3", [0.05] * 6


class NullSink:
    label = "none"

    def write(self, topic, type_name, data, log_time_ns) -> None:
        pass

    def close(self) -> None:
        pass


def subscriber(port: int, stop: threading.Event) -> threading.Thread:
    """A loopback client subscribing to every channel and reading all it is sent, on its own thread."""
    import websockets

    async def run() -> None:
        async with websockets.connect(f"ws://127.0.0.1:{port}", subprotocols=["foxglove.sdk.v1"]) as ws:
            next_id = 1
            while not stop.is_set():
                try:
                    message = await asyncio.wait_for(ws.recv(), 0.1)
                except asyncio.TimeoutError:
                    continue
                except websockets.ConnectionClosed:  # the walk ended and its server with it
                    return
                if isinstance(message, str) and json.loads(message)["op"] == "advertise":
                    subs = [{"id": next_id + i, "channelId": c["id"]} for i, c in enumerate(json.loads(message)["channels"])]
                    next_id += len(subs)
                    await ws.send(json.dumps({"op": "subscribe", "subscriptions": subs}))

    thread = threading.Thread(target=lambda: asyncio.run(run()), daemon=True)
    thread.start()
    return thread


class Sensors:
    """A walk's sensors as the loop finds them each frame: the feedback after an IMU reading (the OP3 standing,
    a little noise), and the health monitor's latest read-back (one servo a frame, in turn)."""

    def __init__(self, config) -> None:
        self.feedback = Feedback(config, "full", None, 1 / 60, time.perf_counter)
        self.rng = np.random.default_rng(1)
        self.answers = [ReadBack(i, ReadBackOutcome.ANSWERED, int(t)) for i, t in zip(config.ids, standing_ticks(config))]
        self.last_read_back = None

    def felt(self, k: int):
        reading = ImuReading(self.rng.normal(0, 0.5, 3), np.array([0.0, 0.0, 1.0]) + self.rng.normal(0, 0.02, 3),
                             np.zeros(3))
        self.feedback.reading = reading
        self.feedback.estimate.update(reading)
        self.last_read_back = self.answers[k % len(self.answers)]
        start = time.perf_counter()
        felt = felt_now(self, self.feedback)  # what the loop does (this object stands for the health monitor)
        return felt, time.perf_counter() - start


def measure(frames: PlannedFrames, config, sinks, threaded: bool = True, repeats: int = 3,
            sensors: bool = False) -> np.ndarray:
    """Microseconds per observer call: the call the loop makes (threaded: what walk and drive use), or the
    encoding and writing itself (not threaded: the worker thread's own cost per frame). ``sensors``: each
    frame carries what the robot felt, gathered as the loop gathers it (that gathering timed too)."""
    publisher = TelemetryPublisher(config, sinks)
    if threaded:
        publisher = BackgroundPublisher(publisher)
    health = ServoHealth(0, "servo health over 100 reads", 31.0, 12.0, 20.0)
    robot = Sensors(config) if sensors else None
    cost = []
    for _ in range(repeats):
        for k in range(len(frames)):
            felt, gathering_s = robot.felt(k) if robot is not None else (None, 0.0)
            start = time.perf_counter() - gathering_s
            publisher.on_frame(frames.frame(k, health=health, command=(0.1, 0.0, 0.0), felt=felt))
            cost.append(time.perf_counter() - start)
            time.sleep(max(0.0, 1 / 60 - (time.perf_counter() - start)))  # a 60 Hz loop's pace
    publisher.close()
    return np.array(cost) * 1e6


def main() -> None:
    config = load_robot(ROBOT)
    plan = plan_balanced(config, STEPS_M)
    goals = Trajectory(plan.walk.t_s, plan.walk.goals_rad, plan.walk.root_m, plan.walk.heel_strikes, LEG_JOINTS)
    frames = PlannedFrames(config, goals, plan.walk.trajectory())
    print(f"{ROBOT}, {len(frames)} frames at 60 Hz x 3, microseconds per frame: p50 / p99 / max")
    with tempfile.TemporaryDirectory() as tmp:
        rows = [("worker: encode only", [NullSink()], False),
                ("worker: encode + --mcap", [McapSink(Path(tmp) / "a.mcap")], False),
                ("loop: --mcap", [McapSink(Path(tmp) / "b.mcap")], True),
                ("loop: --foxglove, no client", [FoxgloveSink("127.0.0.1", 0)], True)]
        for name, sinks, threaded in rows:
            _row(name, measure(frames, config, sinks, threaded))
        _row("worker: encode only + sensors", measure(frames, config, [NullSink()], False, sensors=True))
        _row("loop: --mcap + sensors", measure(frames, config, [McapSink(Path(tmp) / "s.mcap")], True, sensors=True))
        _row("worker: drive record + encode", measure_drive(config, plan.walk))
        live = FoxgloveSink("127.0.0.1", 0)
        stop = threading.Event()
        client = subscriber(live.port, stop)
        time.sleep(0.5)
        _row("loop: --foxglove + client, --mcap", measure(frames, config, [live, McapSink(Path(tmp) / "c.mcap")]))
        stop.set()
        client.join(2.0)


def measure_drive(config, walk, repeats: int = 3) -> np.ndarray:
    """Microseconds per DriveTelemetry.on_frame (the worker's work for a drive's frame), NullSink."""
    ticks = angles_to_ticks(config, walk.goals_rad, LEG_JOINTS)
    cost = []
    for _ in range(repeats):
        telemetry = DriveTelemetry(config, TelemetryPublisher(config, [NullSink()]))
        for k in range(len(walk.t_s)):
            sample = DriveSample(float(walk.t_s[k]), ticks[k], walk.q_rad[k], walk.root_m[k], 0.0, (0.1, 0.0, 0.0))
            start = time.perf_counter()
            telemetry.on_frame(sample)
            cost.append(time.perf_counter() - start)
    return np.array(cost) * 1e6


def _row(name: str, c: np.ndarray) -> None:
    print(f"  {name:36s} {np.percentile(c, 50):7.0f} {np.percentile(c, 99):7.0f} {c.max():7.0f}")

if __name__ == "__main__":
    main()
