"""The channels of a walk's telemetry: topic, ROS 2 message type, and the messages of one frame.

The same channels go to an MCAP log and to a live Foxglove server (docs/live-view.md lists them). A channel
whose data a walk lacks (no read-back on a dry run, no IMU, no command) carries nothing; every other
channel carries one message a frame, stamped with the frame's time.
"""

from __future__ import annotations

import math

from gaitbot.robot.description.frames import TORSO_LINK
from gaitbot.view.link_frames import WORLD_FRAME, LinkTransforms, rotation_xyzw
from gaitbot.view.telemetry import FrameTelemetry

CHANNELS = {
    "/joint_goals": "sensor_msgs/msg/JointState",
    "/joint_states": "sensor_msgs/msg/JointState",
    "/tf": "tf2_msgs/msg/TFMessage",
    "/walk_command": "geometry_msgs/msg/Twist",
    "/imu": "sensor_msgs/msg/Imu",
    "/com": "geometry_msgs/msg/PointStamped",
    "/zmp": "geometry_msgs/msg/PointStamped",
    "/com_measured": "geometry_msgs/msg/PointStamped",
    "/zmp_measured": "geometry_msgs/msg/PointStamped",
    "/pose_measured": "geometry_msgs/msg/PoseStamped",
    "/support_polygon": "geometry_msgs/msg/PolygonStamped",
    "/footprints": "geometry_msgs/msg/PoseArray",
    "/diagnostics": "diagnostic_msgs/msg/DiagnosticArray",
    "/tf_static": "tf2_msgs/msg/TFMessage",
    "/robot_description": "std_msgs/msg/String",
}
"""Topic -> ROS 2 message type, every channel the view can write."""

STATIC_CHANNELS = ("/tf_static", "/robot_description")
"""Written once at the start of a log, and again every few seconds to a live server (a client that connects
later gets them too): the fixed frames, and the URDF the 3D panel draws (``gaitbot robot export --urdf``)."""

IMU_FRAME = TORSO_LINK  # the exported URDF's torso frame (on base_link): the readings are in the torso's axes
_NO_ESTIMATE = [-1.0] + [0.0] * 8  # sensor_msgs/Imu: element 0 = -1 means "no estimate"


def _covariance(variances) -> list[float]:
    """A 3 x 3 covariance, row major, of diagonal ``variances`` (all zeros, sensor_msgs' "unknown", without)."""
    out = [0.0] * 9
    for i, v in enumerate(variances or ()):
        out[4 * i] = float(v)
    return out


def header(stamp_ns: int, frame_id: str = "") -> dict:
    return {"stamp": {"sec": stamp_ns // 1_000_000_000, "nanosec": stamp_ns % 1_000_000_000}, "frame_id": frame_id}


def _xyz(v) -> dict:
    return {"x": float(v[0]), "y": float(v[1]), "z": float(v[2]) if len(v) > 2 else 0.0}


def _quaternion(q) -> dict:
    return {"x": q[0], "y": q[1], "z": q[2], "w": q[3]}


def joint_state(stamp_ns: int, joints, angles_rad) -> dict:
    """Joints whose angle is known (NaN: not read this frame) with their positions in radians."""
    pairs = [(n, float(a)) for n, a in zip(joints, angles_rad) if math.isfinite(a)]
    return {"header": header(stamp_ns), "name": [n for n, _ in pairs], "position": [a for _, a in pairs],
            "velocity": [], "effort": []}


def _diagnostics(stamp_ns: int, health) -> dict:
    values = [(key, value) for key, value in (("hottest_c", health.hottest_c), ("lowest_voltage_v", health.lowest_voltage_v),
                                              ("peak_load_pct", health.peak_load_pct)) if value is not None]
    return {"header": header(stamp_ns), "status": [{
        "level": int(health.level), "name": "gaitbot: servos", "message": health.message, "hardware_id": "servos",
        "values": [{"key": k, "value": f"{v:g}"} for k, v in values]}]}


def _imu(stamp_ns: int, imu) -> dict:
    orientation = imu.orientation_xyzw
    return {"header": header(stamp_ns, IMU_FRAME),
            "orientation": _quaternion(orientation if orientation is not None else (0.0, 0.0, 0.0, 1.0)),
            "orientation_covariance": _covariance(imu.orientation_variance) if orientation is not None else _NO_ESTIMATE,
            "angular_velocity": _xyz(imu.angular_velocity_rad_s),
            "angular_velocity_covariance": _covariance(imu.angular_velocity_variance),
            "linear_acceleration": _xyz(imu.linear_acceleration_m_s2),
            "linear_acceleration_covariance": _covariance(imu.linear_acceleration_variance)}


def _transform(stamp_ns: int, t) -> dict:
    return {"header": header(stamp_ns, t.parent), "child_frame_id": t.child,
            "transform": {"translation": _xyz(t.translation), "rotation": _quaternion(t.rotation_xyzw)}}


def static_messages(stamp_ns: int, links: LinkTransforms, urdf: str) -> list[tuple[str, dict]]:
    """(topic, message) of the STATIC_CHANNELS: every fixed joint's transform, and the robot's URDF."""
    return [("/tf_static", {"transforms": [_transform(stamp_ns, t) for t in links.static]}),
            ("/robot_description", {"data": urdf})]


def frame_messages(frame: FrameTelemetry, stamp_ns: int, links: LinkTransforms) -> list[tuple[str, dict]]:
    """(topic, message) of every channel that has data this frame (messages as nested dicts)."""
    out = [("/joint_goals", joint_state(stamp_ns, frame.joints, frame.goals_rad))]
    if frame.read_back_rad is not None:
        out.append(("/joint_states", joint_state(stamp_ns, frame.joints, frame.read_back_rad)))
    out.append(("/tf", {"transforms": [_transform(stamp_ns, t) for t in links.transforms(
        frame.joints, frame.goals_rad, frame.root_m, frame.root_rpy_rad)]}))
    if frame.command is not None:
        vx, vy, wz = frame.command
        out.append(("/walk_command", {"linear": _xyz((vx, vy, 0.0)), "angular": _xyz((0.0, 0.0, wz))}))
    if frame.imu is not None:
        out.append(("/imu", _imu(stamp_ns, frame.imu)))
    for topic, point in (("/com", frame.com_m), ("/zmp", frame.zmp_m), ("/com_measured", frame.measured_com_m),
                         ("/zmp_measured", frame.measured_zmp_m)):
        if point is not None:
            out.append((topic, {"header": header(stamp_ns, WORLD_FRAME), "point": _xyz(point)}))
    if frame.measured_pelvis is not None:
        position, rotation = frame.measured_pelvis
        out.append(("/pose_measured", {"header": header(stamp_ns, WORLD_FRAME), "pose": {
            "position": _xyz(position), "orientation": _quaternion(rotation_xyzw(rotation))}}))
    if frame.support_m is not None:
        out.append(("/support_polygon", {"header": header(stamp_ns, WORLD_FRAME), "polygon": {
            "points": [{"x": float(x), "y": float(y), "z": 0.0} for x, y in frame.support_m]}}))
    if frame.soles_m is not None:
        out.append(("/footprints", {"header": header(stamp_ns, WORLD_FRAME), "poses": [
            {"position": _xyz(centre), "orientation": _quaternion(rotation_xyzw(rotation))}
            for centre, rotation in frame.soles_m.values()]}))
    if frame.health is not None:
        out.append(("/diagnostics", _diagnostics(stamp_ns, frame.health)))
    return out
