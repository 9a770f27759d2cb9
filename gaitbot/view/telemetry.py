"""One frame of a walk as the view room sees it, and the observer a session calls with it.

The session (or the app around it) fills a :class:`FrameTelemetry` once a frame and calls
``observer.on_frame(record)``; it never waits on what the observer does with it (an observer must
return within a small fraction of a frame: tools/bench_view.py measures it). Angles are radians,
lengths metres, times seconds on the walk's clock from its start; positions are in the world frame ``odom``
(REP-103: x forward, y left, z up, the floor at z = 0).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Protocol

import numpy as np

NEEDS_VIEW_EXTRA = "needs pip install 'gaitbot[view]'"
"""The end of the one-line error when mcap or foxglove-sdk is missing (the hardware install lacks them)."""


@dataclass(frozen=True)
class ImuSample:
    """An IMU reading in the IMU's (the torso's) frame: angular velocity (rad/s) and linear acceleration (m/s^2,
    gravity included, as sensor_msgs/Imu); orientation (x, y, z, w) where the IMU estimates it, else None;
    each one's variances about x, y, z (rad^2, (rad/s)^2, (m/s^2)^2: the covariances' diagonals) where known."""

    angular_velocity_rad_s: tuple[float, float, float]
    linear_acceleration_m_s2: tuple[float, float, float]
    orientation_xyzw: tuple[float, float, float, float] | None = None
    orientation_variance: tuple[float, float, float] | None = None
    angular_velocity_variance: tuple[float, float, float] | None = None
    linear_acceleration_variance: tuple[float, float, float] | None = None


@dataclass(frozen=True)
class ServoHealth:
    """The servos' health so far: level 0 ok, 1 warning, 2 stopped (diagnostic_msgs' OK, WARN, ERROR), the
    latest warning or summary in words, and the worst readings (None before any)."""

    level: int = 0
    message: str = ""
    hottest_c: float | None = None
    lowest_voltage_v: float | None = None
    peak_load_pct: float | None = None


@dataclass(frozen=True, eq=False)
class FrameTelemetry:
    """What one frame of a walk carries (the module docstring gives units and frames).

    joints: the names of the angle columns (config joint names); goals_rad: the angles sent this frame;
    read_back_rad: angles read back from the servos where the session has them (None otherwise; a joint not
    read this frame is NaN). root_m and root_rpy_rad: the pelvis (base_link) pose, roll, pitch, yaw.
    com_m (3,) and zmp_m (2,): the planned centre of mass and ZMP; measured_com_m / measured_zmp_m where a
    simulation or a sensor gives them; measured_pelvis: the pelvis's (position (3,), rotation (3, 3)) a
    simulation measured. soles_m: each foot's sole box, side -> (centre (3,), rotation (3, 3))
    of its underside; support_m: the support polygon (K, 2), counter-clockwise, on the floor.
    command: (vx m/s, vy m/s, wz rad/s) in force (None for a walk without one). felt: what the robot's
    sensors gave this frame, as the loop handed it over (gaitbot.view.felt.FeltSample); the worker turns it
    into ``imu``, ``read_back_rad`` and the measured fields before the channels are made."""

    t_s: float
    joints: tuple[str, ...]
    goals_rad: np.ndarray
    root_m: np.ndarray
    root_rpy_rad: np.ndarray = field(default_factory=lambda: np.zeros(3))
    read_back_rad: np.ndarray | None = None
    com_m: np.ndarray | None = None
    zmp_m: np.ndarray | None = None
    measured_com_m: np.ndarray | None = None
    measured_zmp_m: np.ndarray | None = None
    measured_pelvis: tuple[np.ndarray, np.ndarray] | None = None
    soles_m: dict | None = None
    support_m: np.ndarray | None = None
    imu: ImuSample | None = None
    health: ServoHealth | None = None
    command: tuple[float, float, float] | None = None
    felt: object | None = None


class Telemetry(Protocol):
    """An observer of a walk: called once a frame, must not block; ``close`` once at the end (flushes a log)."""

    def on_frame(self, frame: FrameTelemetry) -> None:
        """Take one frame (never raises into the walk: a failing sink stops itself and says so in ``notes``)."""

    def close(self) -> None:
        """Finish (write an MCAP's summary, stop a server); idempotent."""


def health_of(monitor) -> ServoHealth | None:
    """The summary of a gaitbot.stream.health.HealthMonitor (None without one)."""
    if monitor is None:
        return None
    extreme = lambda e: None if e is None else float(e.value)  # noqa: E731
    return ServoHealth(level=1 if monitor.status else 0, message=monitor.status or monitor.summary(),
                       hottest_c=extreme(monitor.hottest), lowest_voltage_v=extreme(monitor.lowest_voltage),
                       peak_load_pct=extreme(monitor.peak_load))
