"""Torso roll and pitch from the IMU: a complementary filter (stated choice; docs/feedback.md).

The filter tracks the world's up direction seen in the torso's frame. Each frame the gyro's three body
rates turn it (du/dt = -w x u: exact for any attitude, so a torso that twists while it leans, as a falling
robot does, is followed; integrating roll and pitch rates as Euler rates left a fall's tilt 12 deg behind
and noticed up to 180 ms late), and the accelerometer's direction pulls it back with time constant
TIME_CONSTANT_S, less as its reading leaves 1 g or the torso spins (the reading is then not gravity): the
gyro's bias leaves an error of bias x TIME_CONSTANT_S (1 deg/s -> 0.5 deg), and the accelerometer's swing
accelerations are filtered out over that time. Roll and pitch are read from it as from an accelerometer at
rest. The board's fused angles are not used: their frame and filter are the firmware's, unknown to the walk.
"""

from __future__ import annotations

import math

import numpy as np

from gaitbot.servos.opencr import ImuReading

TIME_CONSTANT_S = 0.5
ACCELERATION_TRUST_G = 0.3
"""The accelerometer's pull fades to nothing as its magnitude leaves 1 g by this much: a robot falling (or
landing hard) is accelerating, and the specific force then does not point up (a fall measured 0.24 g)."""
SPIN_TRUST_DPS = 150.0
"""... and as the torso turns this fast (deg/s): a torso rotating about a foot's edge feels its own centripetal
and tangential acceleration. Walking turns it at up to about 60 deg/s (55 on gaitbot's op3 at 0.15 m/s, 63 on
Menagerie's at 0.2); with it a slow fall on the threshold's edge was noticed 67 ms after the true tilt crossed
it instead of 133 (push 29 of python tools/push_survival.py, feedback none)."""


class TiltEstimate:
    """Roll (positive: leaning right) and pitch (positive: leaning forward), degrees, and their rates."""

    def __init__(self, period_s: float) -> None:
        self.period_s = float(period_s)
        self.alpha = TIME_CONSTANT_S / (TIME_CONSTANT_S + self.period_s)
        self.up = (0.0, 0.0, 1.0)  # the world's up in the torso's frame (unit)
        self.roll_deg = self.pitch_deg = 0.0
        self.rates_dps = np.zeros(3)
        self.acc_norm_g = 0.0  # the last reading's accelerometer magnitude (specific force, g)
        self.started = False

    def update(self, reading: ImuReading) -> None:
        self.rates_dps = np.asarray(reading.gyro_dps, dtype=float)
        ax, ay, az = (float(v) for v in reading.acc_g)  # floats: a frame's few dozen operations, no arrays
        self.acc_norm_g = norm = math.sqrt(ax * ax + ay * ay + az * az)
        if not self.started:  # the first reading: the accelerometer's tilt as it is
            x, y, z = (ax, ay, az) if norm > 0.0 else (0.0, 0.0, 1.0)
            self.started = True
        else:
            p, q, r = (math.radians(float(v)) * self.period_s for v in self.rates_dps)
            ux, uy, uz = self.up
            x, y, z = ux - (q * uz - r * uy), uy - (r * ux - p * uz), uz - (p * uy - q * ux)  # u - (w x u) dt
            length = math.sqrt(x * x + y * y + z * z)
            spin_dps = math.degrees(math.sqrt(p * p + q * q + r * r)) / self.period_s
            pull = (1.0 - self.alpha) * max(0.0, 1.0 - abs(norm - 1.0) / ACCELERATION_TRUST_G) if norm > 0.0 else 0.0
            pull *= max(0.0, 1.0 - spin_dps / SPIN_TRUST_DPS)
            keep = (1.0 - pull) / length
            pull = pull / norm if pull else 0.0
            x, y, z = keep * x + pull * ax, keep * y + pull * ay, keep * z + pull * az
        length = math.sqrt(x * x + y * y + z * z)
        self.up = (x / length, y / length, z / length)
        self.roll_deg = math.degrees(math.atan2(self.up[1], self.up[2]))
        self.pitch_deg = math.degrees(math.atan2(-self.up[0], math.hypot(self.up[1], self.up[2])))

    @property
    def tilt_deg(self) -> float:
        """The torso's tilt from upright: the angle between its z axis and the world's up."""
        return math.degrees(math.acos(min(max(float(self.up[2]), -1.0), 1.0)))

    def direction(self) -> str:
        """Which way it leans, in the robot's heading (the sim's words, gaitbot.sim.metrics)."""
        if abs(self.pitch_deg) >= abs(self.roll_deg):
            return "forwards" if self.pitch_deg > 0 else "backwards"
        return "sideways (right)" if self.roll_deg > 0 else "sideways (left)"
