"""The observer that turns each frame into ROS 2 messages once and hands the bytes to its sinks, and the
thread that does it away from the walk's loop.

:class:`BackgroundPublisher` is what a session gets: ``on_frame`` only queues the record (tens of
microseconds, tools/bench_view.py); a worker thread encodes and writes. On a real-time walk a full queue
drops the frame (counted, said at the end) rather than wait; on a simulated clock, which runs as fast as
the CPU allows, the walk waits for the log instead, so the log holds every frame. A sink is an MCAP file (gaitbot.view.mcap_log) or a live Foxglove server (gaitbot.view.live): anything
with ``write(topic, type_name, data, log_time_ns)`` and ``close()``. A sink that fails (a full disk, a
closed server) is dropped with a note and the walk goes on: telemetry never stops the robot.
"""

from __future__ import annotations

import queue
import threading
import time

from gaitbot.robot.config import RobotConfig
from gaitbot.robot.description.urdf_writer import urdf_text
from gaitbot.view.channels import CHANNELS, frame_messages, static_messages
from gaitbot.view.felt import Felt
from gaitbot.view.link_frames import LinkTransforms
from gaitbot.view.ros2_messages import encoder
from gaitbot.view.telemetry import FrameTelemetry

STATIC_EVERY_S = 2.0  # how often a live server gets the static channels again


class TelemetryPublisher:
    """A :class:`~gaitbot.view.telemetry.Telemetry` observer writing every channel to every sink.

    ``start_ns``: the wall-clock time (ns since the Unix epoch) of the walk's t = 0, so that logs and live
    messages carry real stamps (default: now). The static channels (gaitbot.view.channels.STATIC_CHANNELS)
    go to every sink with the first frame, and again every ``STATIC_EVERY_S`` (and at the frame after a client
    subscribes to one: the sink's ``static_wanted`` event) to a sink whose
    ``repeats_static`` is true (a live server: a client may connect at any time)."""

    def __init__(self, config: RobotConfig, sinks, start_ns: int | None = None) -> None:
        self.links = LinkTransforms(config)
        self.urdf = urdf_text(config)
        self.felt = Felt(config)  # the sensors' raw readings, made telemetry here (on the worker)
        self._static_due_s = 0.0
        self.sinks = list(sinks)
        self.start_ns = time.time_ns() if start_ns is None else int(start_ns)
        self.encoders = {name: encoder(name) for name in set(CHANNELS.values())}  # built before the first frame
        self.notes: list[str] = []
        self.frames = 0

    def _static_asked(self) -> bool:
        """A live sink's new client subscribed to a static channel (its ``static_wanted`` event), now taken."""
        asked = False
        for sink in self.sinks:
            wanted = getattr(sink, "static_wanted", None)
            if wanted is not None and wanted.is_set():
                wanted.clear()
                asked = True
        return asked

    def on_frame(self, frame: FrameTelemetry) -> None:
        if not self.sinks:
            return
        frame = self.felt.resolve(frame)
        stamp_ns = self.start_ns + round(frame.t_s * 1e9)
        messages = frame_messages(frame, stamp_ns, self.links)
        asked = self._static_asked()
        if self.frames == 0 or frame.t_s >= self._static_due_s or asked:
            first = self.frames == 0
            self._static_due_s = frame.t_s + STATIC_EVERY_S
            messages += [(topic, message, first) for topic, message in static_messages(stamp_ns, self.links, self.urdf)]
        for topic, message, *first in messages:
            type_name = CHANNELS[topic]
            data = self.encoders[type_name](message)
            sinks = (self.sinks if not first or first[0]
                     else [s for s in self.sinks if getattr(s, "repeats_static", False)])
            for sink in list(sinks):
                try:
                    sink.write(topic, type_name, data, stamp_ns)
                except Exception as exc:  # noqa: BLE001 - a log or a viewer must never stop the walk
                    self.sinks.remove(sink)
                    self.notes.append(f"{sink.label} stopped at {frame.t_s:.2f} s: {exc}")
                    _close_quietly(sink)
        self.frames += 1

    def close(self) -> None:
        for sink in self.sinks:
            try:
                sink.close()
            except Exception as exc:  # noqa: BLE001 - said, the walk's outcome stands
                self.notes.append(f"{sink.label}: closing failed: {exc}")
            else:
                note = getattr(sink, "closing_note", None)
                if note:
                    self.notes.append(note)
        self.sinks = []


def _close_quietly(sink) -> None:
    try:
        sink.close()
    except Exception:  # noqa: BLE001 - already reported by the caller
        pass


QUEUED_FRAMES = 120  # 2 s at 60 Hz: a stalled disk or a slow moment of the CPU, absorbed
CLOSE_WAIT_S = 10.0  # the most the end of a walk waits for the log to be written


class BackgroundPublisher:
    """A TelemetryPublisher on its own thread (the module docstring says when a frame may be dropped)."""

    def __init__(self, publisher: TelemetryPublisher, lossless: bool = False) -> None:
        self.publisher = publisher
        self.lossless = lossless
        self.dropped = 0
        self._queue: queue.Queue = queue.Queue(maxsize=QUEUED_FRAMES)
        self._thread = threading.Thread(target=self._work, name="gaitbot-view", daemon=True)
        self._thread.start()
        self._closed = False

    def _work(self) -> None:
        while True:
            frame = self._queue.get()
            if frame is None:
                return
            try:
                self.publisher.on_frame(frame)
            except Exception as exc:  # noqa: BLE001 - a frame that cannot be encoded: said, the walk goes on
                if len(self.publisher.notes) < 10:
                    self.publisher.notes.append(f"telemetry: a frame at {frame.t_s:.2f} s was not written: {exc}")

    def on_frame(self, frame: FrameTelemetry) -> None:
        if self._closed:
            return
        if self.lossless:
            self._queue.put(frame)
            return
        try:
            self._queue.put_nowait(frame)
        except queue.Full:
            self.dropped += 1

    def close(self) -> None:
        if self._closed:
            return
        self._closed = True
        try:
            self._queue.put(None, timeout=CLOSE_WAIT_S)
        except queue.Full:
            pass
        self._thread.join(CLOSE_WAIT_S)
        if self._thread.is_alive():
            self.publisher.notes.append(f"telemetry: not all written within {CLOSE_WAIT_S:g} s")
        else:
            self.publisher.close()
        if self.dropped:
            self.publisher.notes.append(f"telemetry: {self.dropped} frames dropped (the log or viewer fell behind)")

    @property
    def notes(self) -> list[str]:
        return self.publisher.notes
