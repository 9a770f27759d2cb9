"""What the robot felt this frame, handed over by the loop as it is and turned into telemetry on the view's worker.

The 60 Hz loop only gathers references and a few copies into a :class:`FeltSample`: the IMU reading the walk's
feedback took this frame (gaitbot.feel: body rates in deg/s and specific force in g, torso axes) with the
roll and pitch its complementary filter made of it, the servo read-back the session got last (one servo a
frame, in turn: gaitbot.stream.readback), and in a simulation the measured centre of mass, pelvis pose and
floor contacts.
:class:`Felt`, called on the worker thread (gaitbot.view.publisher), makes the ROS 2 quantities of them:

* the IMU in SI units (rad/s, m/s^2 with gravity in it, as sensor_msgs/Imu wants), its orientation from the
  walk's own roll and pitch, yaw 0 (the walk estimates no yaw; its variance says "unknown"), and each
  diagonal variance from the config's ``[imu]`` noise figures;
* a simulation's measured ZMP: the centre of pressure of its floor contacts;
* the read-back angles of every joint, each the latest its servo gave (a joint is read every
  ``len(joints)`` frames), through the calibration: from the frame where every servo has answered once.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

import numpy as np

from gaitbot.feel.estimate import TIME_CONSTANT_S
from gaitbot.robot.calibration import ticks_to_angles
from gaitbot.robot.config import RobotConfig
from gaitbot.servos.opencr import STANDARD_GRAVITY_M_S2
from gaitbot.view.link_frames import quaternion_rpy
from gaitbot.view.telemetry import FrameTelemetry, ImuSample

UNKNOWN_YAW_VARIANCE_RAD2 = math.pi ** 2 / 3
"""The variance of an angle known only to lie on the circle (uniform on -pi..pi): the yaw the walk does not estimate."""


@dataclass(frozen=True, eq=False)
class FeltSample:
    """The loop's hand-over (no computation): ``imu`` a gaitbot.servos.opencr.ImuReading in the torso's axes
    (None: no reading this frame), ``tilt_deg`` the walk's (roll, pitch) estimate after it, ``read_back`` the
    session's latest answered gaitbot.bus.base.ReadBack (servo id, present ticks), ``com_m`` (3,) and
    ``pelvis`` (position (3,), rotation (3, 3)) measured by a simulation, world frame, and its floor contacts
    (points (K, 3) m, normal forces (K,) N)."""

    imu: object | None = None
    tilt_deg: tuple[float, float] | None = None
    read_back: object | None = None
    com_m: np.ndarray | None = None
    pelvis: tuple[np.ndarray, np.ndarray] | None = None
    contacts: tuple[np.ndarray, np.ndarray] | None = None


def centre_of_pressure(contacts) -> np.ndarray | None:
    """(x, y) of the floor's reaction (m): its contact points weighted by their normal forces; on flat ground the
    ZMP (Vukobratovic and Borovac, "Zero-moment point: thirty five years of its life", 2004). None in the air."""
    if contacts is None:
        return None
    points, forces = contacts
    total = float(np.sum(forces))
    if not total > 0.0:
        return None
    return (np.asarray(forces) @ np.asarray(points)[:, :2]) / total


class Felt:
    """Turns each frame's FeltSample into its FrameTelemetry fields (on the worker; keeps the read-back)."""

    def __init__(self, config: RobotConfig) -> None:
        self.config = config
        self.index = {servo_id: i for i, servo_id in enumerate(config.ids)}
        self.ticks = np.full(len(config.ids), np.nan)
        s = config.imu
        self.gyro_variance = math.radians(s.gyro_noise_dps) ** 2
        self.acc_variance = (s.acc_noise_g * STANDARD_GRAVITY_M_S2) ** 2
        tilt_variance = math.radians(s.gyro_bias_dps * TIME_CONSTANT_S) ** 2  # the filter's error: bias x time constant
        self.orientation_variance = (tilt_variance, tilt_variance, UNKNOWN_YAW_VARIANCE_RAD2)

    def imu(self, reading, tilt_deg) -> ImuSample:
        """The IMU in SI units, with the walk's roll and pitch as its orientation (module docstring)."""
        roll, pitch = (math.radians(a) for a in tilt_deg) if tilt_deg is not None else (None, None)
        return ImuSample(
            angular_velocity_rad_s=tuple(float(math.radians(w)) for w in reading.gyro_dps),
            linear_acceleration_m_s2=tuple(float(a * STANDARD_GRAVITY_M_S2) for a in reading.acc_g),
            orientation_xyzw=quaternion_rpy(roll, pitch, 0.0) if roll is not None else None,
            orientation_variance=self.orientation_variance if roll is not None else None,
            angular_velocity_variance=(self.gyro_variance,) * 3,
            linear_acceleration_variance=(self.acc_variance,) * 3)

    def read_back_rad(self, answer) -> np.ndarray | None:
        """Every joint's latest read-back angle (rad), or None until every servo has answered once."""
        if answer is not None and answer.ticks is not None and answer.servo_id in self.index:
            self.ticks[self.index[answer.servo_id]] = answer.ticks
        if np.isnan(self.ticks).any():
            return None
        return ticks_to_angles(self.config, self.ticks)

    def resolve(self, frame: FrameTelemetry) -> FrameTelemetry:
        """``frame`` with its ``felt`` sample turned into ``imu``, ``read_back_rad`` and the measured fields."""
        felt = frame.felt
        if felt is None:
            return frame
        extra = {"felt": None}
        if felt.imu is not None:
            extra["imu"] = self.imu(felt.imu, felt.tilt_deg)
        read_back = self.read_back_rad(felt.read_back)
        if read_back is not None:
            extra["read_back_rad"] = read_back
        if felt.com_m is not None:
            extra["measured_com_m"] = felt.com_m
        if felt.pelvis is not None:
            extra["measured_pelvis"] = felt.pelvis
        zmp = centre_of_pressure(felt.contacts)
        if zmp is not None:
            extra["measured_zmp_m"] = zmp
        return dataclasses.replace(frame, **extra)
