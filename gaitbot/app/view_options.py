"""``--mcap FILE`` and ``--foxglove [HOST:PORT]`` (walk, drive): their options and the observer they make.

The command adds the options with :func:`add_view_options` and makes a :class:`WalkView` with
:func:`open_view` before its session; the view room does the work (gaitbot.view, docs/live-view.md).
Neither library is needed unless asked for: without ``gaitbot[view]`` installed the option fails in one line.
"""

from __future__ import annotations

import argparse
import sys

import numpy as np
from pathlib import Path

DEFAULT_FOXGLOVE = "127.0.0.1:8765"  # gaitbot.view.live's default: loopback only


def host_port(text: str) -> tuple[str, int]:
    """``--foxglove [HOST:]PORT`` or ``HOST`` (port 8765); PORT 0 picks a free port."""
    host, colon, port_text = text.rpartition(":")
    if not colon:
        host, port_text = ("", text) if text.isdigit() else (text, "8765")
    port = int(port_text) if port_text.isdigit() else -1
    if not 0 <= port <= 65535 or host.startswith("["):
        raise argparse.ArgumentTypeError(f"expected [HOST:]PORT with PORT 0..65535 (default {DEFAULT_FOXGLOVE}), "
                                         f"got {text!r}")
    return host or "127.0.0.1", port


def mcap_path(text: str) -> str:
    """``--mcap FILE``: a file that can be written, checked before any work is done."""
    from gaitbot.app.options import UsageError, file_option
    from gaitbot.app.outputs import output_path

    try:
        output_path(Path(file_option(text, "--mcap")), "--mcap")
    except UsageError as exc:
        raise argparse.ArgumentTypeError(str(exc).removeprefix("--mcap: ").removeprefix("--mcap ")) from None
    except OSError as exc:  # a name the OS refuses (too long, a loop)
        raise argparse.ArgumentTypeError(f"cannot write there ({exc.strerror or exc})") from None
    return text


def add_view_options(p) -> None:
    p.add_argument("--mcap", metavar="FILE", type=mcap_path, help="write the walk's telemetry (joints, transforms, CoM, ZMP, feet, "
                   "servo health) to this MCAP file (ROS 2 messages: Foxglove and ros2 bag open it)")
    p.add_argument("--foxglove", nargs="?", const=host_port(DEFAULT_FOXGLOVE), type=host_port, metavar="HOST:PORT",
                   help="serve the same telemetry live to Foxglove (default 127.0.0.1:8765; another HOST is reachable "
                   "from the network) and take its Teleop panel's Twists on /cmd_vel (drive)")


def felt_now(health=None, feedback=None, sim_robot=None):
    """What the robot's sensors gave this frame, gathered for the view's worker (gaitbot.view.felt.FeltSample):
    references and a few copies, no computation. ``health``: the session's HealthMonitor (its latest servo
    read-back); ``feedback``: the walk's gaitbot.feel.Feedback (its IMU reading and tilt estimate);
    ``sim_robot``: a simulation's robot (its measured centre of mass and pelvis pose), or None each."""
    from gaitbot.view.felt import FeltSample

    reading = getattr(feedback, "reading", None)
    tilt = (feedback.estimate.roll_deg, feedback.estimate.pitch_deg) if reading is not None else None
    com = pelvis = contacts = None
    if sim_robot is not None and hasattr(sim_robot, "torso_body"):
        data, body = sim_robot.data, sim_robot.torso_body
        com, pelvis = data.subtree_com[body].copy(), (data.xpos[body].copy(), data.xmat[body].reshape(3, 3).copy())
        contacts = _floor_contacts(sim_robot)
    return FeltSample(reading, tilt, getattr(health, "last_read_back", None), com, pelvis, contacts)


def _floor_contacts(sim_robot):
    """The simulated floor's contacts now: points (K, 3) and normal forces (K,) (MuJoCo's mj_contactForce), or
    None where the model has no floor geom the robot knows of."""
    floor = getattr(sim_robot, "floor_geom", None)
    if floor is None:
        return None
    mujoco, model, data = sim_robot.mujoco, sim_robot.model, sim_robot.data
    force = np.zeros(6)
    points, normals = [], []
    for i in range(data.ncon):
        contact = data.contact[i]
        if floor in (contact.geom1, contact.geom2):
            mujoco.mj_contactForce(model, data, i, force)
            points.append(contact.pos.copy())
            normals.append(force[0])
    return (np.array(points).reshape(-1, 3), np.array(normals))


class WalkView:
    """The observer of one walk (gaitbot.view.publisher.TelemetryPublisher over the asked-for sinks) and the
    planned frames it reads from; ``teleop`` is the Foxglove command source when --foxglove is on."""

    def __init__(self, publisher, frames, teleop=None) -> None:
        self.publisher, self.frames, self.teleop = publisher, frames, teleop
        self.health = None  # a HealthMonitor, summarised in each frame when set
        self.feedback = None  # the walk's gaitbot.feel.Feedback when it reads an IMU: /imu
        self.sim_robot = None  # --sim: the simulated robot, for the measured CoM and pelvis pose

    def on_frame(self, k: int, **extra) -> None:
        """Frame k of the planned walk (the session's walk-frame index), with what the session adds."""
        from gaitbot.view.telemetry import health_of

        felt = felt_now(self.health, self.feedback, self.sim_robot)
        self.publisher.on_frame(self.frames.frame(k, health=health_of(self.health), felt=felt, **extra))

    def chain(self, on_frame):
        """A session ``on_frame(k, stats)`` callback that also feeds the view."""
        def both(k: int, stats) -> None:
            self.on_frame(k)
            if on_frame is not None:
                on_frame(k, stats)
        return both

    def close(self) -> None:
        self.publisher.close()
        for note in self.publisher.notes:
            print(f"note: {note}", file=sys.stderr)


def _open_sinks(mcap, foxglove):
    """The asked-for sinks and, with --foxglove, the Teleop source over its server; one line if one cannot open."""
    from gaitbot.app.options import UsageError
    from gaitbot.view.live import ViewOptionError

    sinks, teleop = [], None
    try:
        if mcap is not None:
            from gaitbot.view.mcap_log import McapSink
            sinks.append(McapSink(mcap))
        if foxglove is not None:
            from gaitbot.view.live import FoxgloveSink
            from gaitbot.view.teleop import TeleopSource
            live = FoxgloveSink(*foxglove)
            print(f"foxglove: ws://{live.host}:{live.port} (open it in Foxglove: docs/live-view.md)", file=sys.stderr)
            sinks.append(live)
            teleop = TeleopSource(live.inbox)
        from gaitbot.view.ros2_messages import import_ros2_cdr
        import_ros2_cdr()  # the messages' library, missing: one line now rather than a traceback later
    except (ImportError, OSError, ViewOptionError) as exc:
        for sink in sinks:
            sink.close()
        raise UsageError(str(exc) if not isinstance(exc, OSError) else f"--mcap {mcap}: {exc.strerror or exc}") from None
    return sinks, teleop


def open_view(args, config, goals, planned=None, health=None, realtime: bool = True, feedback=None,
              sim_robot=None) -> WalkView | None:
    """The view of ``args.mcap`` / ``args.foxglove`` for this walk, or None when neither was asked for;
    ``realtime``: the walk runs on a real clock (a full telemetry queue then drops a frame, never waits);
    ``feedback`` and ``sim_robot`` as felt_now's."""
    mcap, foxglove = getattr(args, "mcap", None), getattr(args, "foxglove", None)
    if mcap is None and foxglove is None:
        return None
    sinks, teleop = _open_sinks(mcap, foxglove)
    from gaitbot.view.publisher import BackgroundPublisher, TelemetryPublisher
    from gaitbot.view.walk_frames import PlannedFrames

    publisher = BackgroundPublisher(TelemetryPublisher(config, sinks), lossless=not realtime)
    view = WalkView(publisher, PlannedFrames(config, goals, planned), teleop)
    view.health, view.feedback, view.sim_robot = health, feedback, sim_robot
    return view


# --- drive ------------------------------------------------------------------------------------------------
FOXGLOVE_INPUT = "foxglove"


def drive_input(args) -> str:
    """``drive --input``: as given; left out, the Teleop panel with --foxglove, else the keyboard."""
    if args.input is None:
        args.input = FOXGLOVE_INPUT if getattr(args, "foxglove", None) is not None else "keyboard"
    if args.input == FOXGLOVE_INPUT and getattr(args, "foxglove", None) is None:
        args.foxglove = host_port(DEFAULT_FOXGLOVE)  # the Teleop panel needs the server
    return args.input


class DriveView:
    """The sinks of one drive and, with --foxglove, its Teleop source; ``attach`` starts the telemetry once
    the drive's frames exist (gaitbot.view.drive_telemetry does the work off the loop)."""

    def __init__(self, config, sinks, teleop) -> None:
        self.config, self.sinks, self.teleop = config, sinks, teleop
        self.publisher = None

    def attach(self, frames, health, realtime: bool, on_frame=None, feedback=None, sim_robot=None):
        """A session ``on_frame(k, stats)`` callback feeding the view from ``frames`` (gaitbot.drive.frames),
        then calling ``on_frame``; ``realtime`` as open_view's; ``feedback``, ``sim_robot`` as felt_now's."""
        import math

        from gaitbot.view.drive_telemetry import DriveSample, DriveTelemetry
        from gaitbot.view.publisher import BackgroundPublisher, TelemetryPublisher
        from gaitbot.view.telemetry import health_of

        telemetry = DriveTelemetry(self.config, TelemetryPublisher(self.config, self.sinks))
        self.publisher = publisher = BackgroundPublisher(telemetry, lossless=not realtime)
        self.sinks = []

        def both(k: int, stats) -> None:
            ticks, body, root, yaw = frames.body_pose()
            c = frames.command
            publisher.on_frame(DriveSample(frames.k * frames.period_s, ticks.copy(), body.copy(), root, yaw,
                                           (c.vx_m_s, c.vy_m_s, math.radians(c.wz_deg_s)), health_of(health),
                                           felt_now(health, feedback, sim_robot)))
            if on_frame is not None:
                on_frame(k, stats)
        return both

    def close(self) -> None:
        for sink in self.sinks:  # never attached: a drive that ended before its first frame
            sink.close()
        self.sinks = []
        if self.publisher is not None:
            self.publisher.close()
            for note in self.publisher.notes:
                print(f"note: {note}", file=sys.stderr)
            self.publisher = None


def open_drive_view(args, config) -> DriveView | None:
    """The view of ``drive --mcap/--foxglove`` (None when neither was asked for); call ``drive_input`` first."""
    mcap, foxglove = getattr(args, "mcap", None), getattr(args, "foxglove", None)
    if mcap is None and foxglove is None:
        return None
    return DriveView(config, *_open_sinks(mcap, foxglove))
