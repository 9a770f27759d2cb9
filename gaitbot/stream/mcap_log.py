"""Logs in MCAP (ROS 2's default bag format, Foxglove's own): a walk's channels as ROS 2 messages.

Why: a log that opens anywhere. Every channel here is a standard ROS 2 message (gaitbot.stream.ros2_messages),
CDR-encoded by the ``mcap-ros2-support`` library (the ``ecosystem`` extra), so ``ros2 bag`` and Foxglove read
it. The robot's URDF is on ``/robot_description`` (Foxglove's 3D panel draws it from there), its fixed frames
on ``/tf_static``; each call adds one message at time ``t_s`` after ``start_ns`` (Unix ns). The bus
recording stays the byte-exact record ``gaitbot check`` reads: this is a view of a walk, not its evidence.

Channels (topic: message): /joint_states and /joint_goals: sensor_msgs/JointState (read-back and goals);
/tf: tf2_msgs/TFMessage (odom -> base_link from the root's pose, and every walking joint's frame through the
exported frame table, gaitbot.robot.description.frames); /com/*, /zmp/*: geometry_msgs/PointStamped;
/support_polygon, /footprints: geometry_msgs/PolygonStamped; /cmd_vel: geometry_msgs/Twist; /diagnostics:
diagnostic_msgs/DiagnosticArray (servo health). A live walk should write from its own thread, off the 60 Hz
frame: a chunk is compressed when it fills.
"""

from __future__ import annotations

from itertools import count
from pathlib import Path

import numpy as np

from gaitbot.errors import UserError
from gaitbot.gait.mass import MassModel
from gaitbot.robot.config import RobotConfig
from gaitbot.robot.description.frames import ROOT_LINK, joint_frames
from gaitbot.robot.description.tree import matrix_quaternion, rpy_matrix
from gaitbot.robot.description.urdf_writer import urdf_text
from gaitbot.stream.ros2_messages import schema_name, schema_text

WORLD_FRAME = "odom"  # REP-105: the world frame a walk's odometry is in
JOINT_STATES, JOINT_GOALS, TF, TF_STATIC = "/joint_states", "/joint_goals", "/tf", "/tf_static"
ROBOT_DESCRIPTION, COM_PLANNED, CMD_VEL, DIAGNOSTICS = "/robot_description", "/com/planned", "/cmd_vel", "/diagnostics"
ECOSYSTEM_HINT = "pip install 'gaitbot[ecosystem]'"


class McapUnavailable(UserError):
    """The mcap libraries are not installed (the ecosystem extra)."""


def _time(ns: int) -> dict:
    return {"sec": ns // 1_000_000_000, "nanosec": ns % 1_000_000_000}


def _transform(parent: str, child: str, translation, rotation, ns: int) -> dict:
    w, x, y, z = matrix_quaternion(rotation)
    return {"header": {"stamp": _time(ns), "frame_id": parent}, "child_frame_id": child,
            "transform": {"translation": dict(zip("xyz", map(float, translation))),
                          "rotation": {"x": x, "y": y, "z": z, "w": w}}}


class McapLog:
    """An MCAP file of a robot's channels (module docstring); a context manager, closed by ``close()``."""

    def __init__(self, path: str | Path, config: RobotConfig, start_ns: int = 0, compress: bool = True) -> None:
        try:
            from mcap.writer import CompressionType
            from mcap_ros2.writer import Writer
        except ImportError:
            raise McapUnavailable(f"MCAP logs need the mcap libraries, which are not installed: {ECOSYSTEM_HINT}") \
                from None
        self._file = open(path, "wb")
        self._writer = Writer(self._file, compression=CompressionType.ZSTD if compress else CompressionType.NONE)
        self._schemas: dict[str, object] = {}
        self._sequence = count()
        self.start_ns = int(start_ns)
        self.frames = joint_frames(config)
        self._write(ROBOT_DESCRIPTION, "std_msgs/String", {"data": urdf_text(config)}, 0.0)
        self._write(TF_STATIC, "tf2_msgs/TFMessage", {"transforms": [
            _transform(f.parent, f.child, *f.transform(), self.start_ns) for f in self.frames if not f.moving]}, 0.0)

    def _ns(self, t_s: float) -> int:
        return self.start_ns + int(round(t_s * 1e9))

    def _write(self, topic: str, message: str, value: dict, t_s: float) -> None:
        schema = self._schemas.get(message)
        if schema is None:
            schema = self._schemas[message] = self._writer.register_msgdef(schema_name(message), schema_text(message))
        ns = self._ns(t_s)
        self._writer.write_message(topic, schema, value, log_time=ns, publish_time=ns, sequence=next(self._sequence))

    def _header(self, t_s: float, frame: str = "") -> dict:
        return {"stamp": _time(self._ns(t_s)), "frame_id": frame}

    def joint_states(self, t_s: float, names, positions_rad, velocities_rad_s=(), efforts_nm=(),
                     topic: str = JOINT_STATES) -> None:
        """Joint angles (rad), optionally speeds (rad/s) and torques (N m), by gaitbot's joint names."""
        self._write(topic, "sensor_msgs/JointState", {
            "header": self._header(t_s), "name": list(names), "position": [float(v) for v in positions_rad],
            "velocity": [float(v) for v in velocities_rad_s], "effort": [float(v) for v in efforts_nm]}, t_s)

    def transforms(self, t_s: float, angles_rad: dict[str, float], root_m=None, root_rotation=None) -> None:
        """/tf: every walking joint's frame at ``angles_rad`` (by name), and odom -> base_link when the root's
        place (m) and rotation (3 x 3; default upright) are given."""
        ns = self._ns(t_s)
        out = [_transform(f.parent, f.child, *f.transform(angles_rad.get(f.name, 0.0)), ns)
               for f in self.frames if f.moving]
        if root_m is not None:
            rotation = np.eye(3) if root_rotation is None else root_rotation
            out.insert(0, _transform(WORLD_FRAME, ROOT_LINK, root_m, rotation, ns))
        self._write(TF, "tf2_msgs/TFMessage", {"transforms": out}, t_s)

    def point(self, topic: str, t_s: float, xyz_m, frame: str = WORLD_FRAME) -> None:
        """A point (m): a centre of mass or a ZMP, planned or measured."""
        self._write(topic, "geometry_msgs/PointStamped", {"header": self._header(t_s, frame),
                                                          "point": dict(zip("xyz", map(float, xyz_m)))}, t_s)

    def polygon(self, topic: str, t_s: float, points_m, frame: str = WORLD_FRAME) -> None:
        """A polygon (m): a support polygon, a footprint."""
        self._write(topic, "geometry_msgs/PolygonStamped", {"header": self._header(t_s, frame), "polygon": {
            "points": [dict(zip("xyz", map(float, p))) for p in points_m]}}, t_s)

    def twist(self, t_s: float, forward_m_s: float, left_m_s: float, turn_rad_s: float, topic: str = CMD_VEL) -> None:
        """A velocity command (the drive's input)."""
        self._write(topic, "geometry_msgs/Twist", {"linear": {"x": forward_m_s, "y": left_m_s, "z": 0.0},
                                                   "angular": {"x": 0.0, "y": 0.0, "z": turn_rad_s}}, t_s)

    def diagnostics(self, t_s: float, statuses) -> None:
        """Servo health: ``statuses`` of (name, level 0 OK / 1 WARN / 2 ERROR, message, {key: value})."""
        self._write(DIAGNOSTICS, "diagnostic_msgs/DiagnosticArray", {"header": self._header(t_s), "status": [
            {"level": int(level), "name": name, "message": message, "hardware_id": name,
             "values": [{"key": k, "value": str(v)} for k, v in values.items()]}
            for name, level, message, values in statuses]}, t_s)

    def close(self) -> None:
        if not self._file.closed:
            self._writer.finish()
            self._file.close()

    def __enter__(self) -> "McapLog":
        return self

    def __exit__(self, *_exc) -> None:
        self.close()


def write_trajectory(path: str | Path, config: RobotConfig, trajectory, start_ns: int = 0) -> int:
    """A planned walk as MCAP: each frame's goals (/joint_goals), the robot's pose (/tf) and its planned centre
    of mass (/com/planned, from every link's mass). Returns the frames written."""
    mass = MassModel.of(config.body)
    names = [j.name for j in config.joints]
    held = {j.name: np.radians(j.hold_deg) for j in config.held_joints}
    leg = [f"{kind}_{side}" for side in ("left", "right") for kind in
           ("hip_yaw", "hip_roll", "hip_pitch", "knee_pitch", "ankle_pitch", "ankle_roll")]
    with McapLog(path, config, start_ns) as log:
        for k, t_s in enumerate(trajectory.t_s):
            angles = dict(held)
            angles.update(zip(trajectory.joints, trajectory.angles_rad[k]))
            rpy = trajectory.torso_rpy_rad[k] if trajectory.torso_rpy_rad is not None else (0.0, 0.0, 0.0)
            rotation = rpy_matrix(*rpy)
            log.joint_states(t_s, names, [angles.get(n, 0.0) for n in names], topic=JOINT_GOALS)
            log.transforms(t_s, angles, trajectory.root_m[k], rotation)
            com = mass.com_in_root(np.array([angles.get(n, 0.0) for n in leg]))
            log.point(COM_PLANNED, t_s, trajectory.root_m[k] + rotation @ com)
    return len(trajectory.t_s)
