"""The ROS 2 message definitions gaitbot's logs use, as the text an MCAP file carries for each schema.

Why ROS 2 messages: where a standard message exists (joint states, transforms, points, polygons, velocity
commands, diagnostics), a log in it opens in ``ros2 bag`` and Foxglove as any robot's would. The fields
are those of ros2/common_interfaces (sensor_msgs, geometry_msgs, std_msgs, diagnostic_msgs), tf2_msgs
(ros2/geometry2) and builtin_interfaces (ros2/rcl_interfaces); a schema's text is its definition followed
by every definition it uses, each after a line of '=' and ``MSG: package/Name`` (rosbag2's layout).
"""

from __future__ import annotations

#: name -> (definition, the messages it uses)
DEFINITIONS: dict[str, tuple[str, tuple[str, ...]]] = {
    "builtin_interfaces/Time": ("int32 sec\nuint32 nanosec", ()),
    "std_msgs/Header": ("builtin_interfaces/Time stamp\nstring frame_id", ("builtin_interfaces/Time",)),
    "std_msgs/String": ("string data", ()),
    "geometry_msgs/Vector3": ("float64 x\nfloat64 y\nfloat64 z", ()),
    "geometry_msgs/Point": ("float64 x\nfloat64 y\nfloat64 z", ()),
    "geometry_msgs/Point32": ("float32 x\nfloat32 y\nfloat32 z", ()),
    "geometry_msgs/Quaternion": ("float64 x 0\nfloat64 y 0\nfloat64 z 0\nfloat64 w 1", ()),
    "geometry_msgs/Transform": ("geometry_msgs/Vector3 translation\ngeometry_msgs/Quaternion rotation",
                                ("geometry_msgs/Vector3", "geometry_msgs/Quaternion")),
    "geometry_msgs/TransformStamped": ("std_msgs/Header header\nstring child_frame_id\n"
                                       "geometry_msgs/Transform transform",
                                       ("std_msgs/Header", "geometry_msgs/Transform")),
    "geometry_msgs/PointStamped": ("std_msgs/Header header\ngeometry_msgs/Point point",
                                   ("std_msgs/Header", "geometry_msgs/Point")),
    "geometry_msgs/Polygon": ("geometry_msgs/Point32[] points", ("geometry_msgs/Point32",)),
    "geometry_msgs/PolygonStamped": ("std_msgs/Header header\ngeometry_msgs/Polygon polygon",
                                     ("std_msgs/Header", "geometry_msgs/Polygon")),
    "geometry_msgs/Twist": ("geometry_msgs/Vector3 linear\ngeometry_msgs/Vector3 angular", ("geometry_msgs/Vector3",)),
    "sensor_msgs/JointState": ("std_msgs/Header header\nstring[] name\nfloat64[] position\nfloat64[] velocity\n"
                               "float64[] effort", ("std_msgs/Header",)),
    "tf2_msgs/TFMessage": ("geometry_msgs/TransformStamped[] transforms", ("geometry_msgs/TransformStamped",)),
    "diagnostic_msgs/KeyValue": ("string key\nstring value", ()),
    "diagnostic_msgs/DiagnosticStatus": ("byte OK=0\nbyte WARN=1\nbyte ERROR=2\nbyte STALE=3\nbyte level\n"
                                         "string name\nstring message\nstring hardware_id\n"
                                         "diagnostic_msgs/KeyValue[] values", ("diagnostic_msgs/KeyValue",)),
    "diagnostic_msgs/DiagnosticArray": ("std_msgs/Header header\ndiagnostic_msgs/DiagnosticStatus[] status",
                                        ("std_msgs/Header", "diagnostic_msgs/DiagnosticStatus")),
}


def _closure(name: str) -> list[str]:
    """Every message ``name`` uses, directly or not, each once, in the order first met."""
    seen: list[str] = []
    stack = list(DEFINITIONS[name][1])
    while stack:
        dep = stack.pop(0)
        if dep not in seen:
            seen.append(dep)
            stack.extend(DEFINITIONS[dep][1])
    return seen


def schema_name(name: str) -> str:
    """``sensor_msgs/JointState`` -> ``sensor_msgs/msg/JointState`` (the name ROS 2 tools look for)."""
    package, message = name.split("/")
    return f"{package}/msg/{message}"


def schema_text(name: str) -> str:
    """The schema text of message ``name`` (module docstring)."""
    parts = [DEFINITIONS[name][0]]
    for dep in _closure(name):
        parts.append("=" * 80 + f"\nMSG: {dep}\n{DEFINITIONS[dep][0]}")
    return "\n".join(parts) + "\n"
