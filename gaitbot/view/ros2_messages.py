"""The ROS 2 message types the view writes, their definitions, and CDR encoders and decoders for them.

Every channel uses a standard ROS 2 message (common_interfaces and geometry2, as in ROS 2 Humble:
https://github.com/ros2/common_interfaces, https://github.com/ros2/geometry2), so that ``ros2 bag``,
RViz and Foxglove open the log without any gaitbot schema. A schema is the message's definition followed
by those it uses, in the concatenated ``ros2msg`` form that rosbag2 stores in an MCAP (constants and
comments left out: they change nothing on the wire). The CDR (de)serialisation is mcap-ros2-support's
(imported on the view's paths only).
"""

from __future__ import annotations

from functools import lru_cache

from gaitbot.view.telemetry import NEEDS_VIEW_EXTRA

# Each definition, fields only; types in another package are written with their package.
DEFINITIONS = {
    "builtin_interfaces/Time": "int32 sec\nuint32 nanosec",
    "std_msgs/Header": "builtin_interfaces/Time stamp\nstring frame_id",
    "geometry_msgs/Vector3": "float64 x\nfloat64 y\nfloat64 z",
    "geometry_msgs/Point": "float64 x\nfloat64 y\nfloat64 z",
    "geometry_msgs/Point32": "float32 x\nfloat32 y\nfloat32 z",
    "geometry_msgs/Quaternion": "float64 x 0\nfloat64 y 0\nfloat64 z 0\nfloat64 w 1",
    "geometry_msgs/Pose": "geometry_msgs/Point position\ngeometry_msgs/Quaternion orientation",
    "geometry_msgs/Transform": "geometry_msgs/Vector3 translation\ngeometry_msgs/Quaternion rotation",
    "geometry_msgs/TransformStamped": "std_msgs/Header header\nstring child_frame_id\ngeometry_msgs/Transform transform",
    "geometry_msgs/Polygon": "geometry_msgs/Point32[] points",
    "diagnostic_msgs/KeyValue": "string key\nstring value",
    "diagnostic_msgs/DiagnosticStatus": "byte level\nstring name\nstring message\nstring hardware_id\n"
                                        "diagnostic_msgs/KeyValue[] values",
    # the channels' own types
    "sensor_msgs/msg/JointState": "std_msgs/Header header\nstring[] name\nfloat64[] position\nfloat64[] velocity\n"
                                  "float64[] effort",
    "tf2_msgs/msg/TFMessage": "geometry_msgs/TransformStamped[] transforms",
    "geometry_msgs/msg/Twist": "geometry_msgs/Vector3 linear\ngeometry_msgs/Vector3 angular",
    "sensor_msgs/msg/Imu": "std_msgs/Header header\ngeometry_msgs/Quaternion orientation\n"
                           "float64[9] orientation_covariance\ngeometry_msgs/Vector3 angular_velocity\n"
                           "float64[9] angular_velocity_covariance\ngeometry_msgs/Vector3 linear_acceleration\n"
                           "float64[9] linear_acceleration_covariance",
    "geometry_msgs/msg/PointStamped": "std_msgs/Header header\ngeometry_msgs/Point point",
    "geometry_msgs/msg/PoseStamped": "std_msgs/Header header\ngeometry_msgs/Pose pose",
    "geometry_msgs/msg/PolygonStamped": "std_msgs/Header header\ngeometry_msgs/Polygon polygon",
    "geometry_msgs/msg/PoseArray": "std_msgs/Header header\ngeometry_msgs/Pose[] poses",
    "diagnostic_msgs/msg/DiagnosticArray": "std_msgs/Header header\ndiagnostic_msgs/DiagnosticStatus[] status",
    "std_msgs/msg/String": "string data",
}
_SEPARATOR = "=" * 80


def _uses(name: str) -> list[str]:
    """The message types a definition uses, depth first, each once."""
    out: list[str] = []
    for line in DEFINITIONS[name].splitlines():
        kind = line.split()[0].split("[")[0]
        if "/" in kind:
            for used in _uses(kind) + [kind]:
                if used not in out:
                    out.append(used)
    return out


@lru_cache(maxsize=None)
def schema_text(name: str) -> str:
    """The concatenated ``ros2msg`` definition of ``name`` (what an MCAP's Schema record holds)."""
    parts = [DEFINITIONS[name]]
    for used in _uses(name):
        parts.append(f"{_SEPARATOR}\nMSG: {used}\n{DEFINITIONS[used]}")
    return "\n".join(parts) + "\n"


def import_ros2_cdr():
    """mcap-ros2-support's dynamic (de)serialisers, or one line saying how to install them."""
    try:
        from mcap_ros2 import _dynamic  # the library's own encoder builder (its Writer uses the same)
    except ImportError:
        raise ImportError(f"ROS 2 messages (--mcap, --foxglove) {NEEDS_VIEW_EXTRA}") from None
    return _dynamic


@lru_cache(maxsize=None)
def encoder(name: str):
    """A function from a message (nested dicts or objects with the fields) to its CDR bytes."""
    return import_ros2_cdr().serialize_dynamic(name, schema_text(name))[name]


@lru_cache(maxsize=None)
def decoder(name: str):
    """A function from CDR bytes to a message object (attributes named as the fields)."""
    return import_ros2_cdr().generate_dynamic(name, schema_text(name))[name]
