"""Torso roll and pitch from the IMU: a complementary filter (stated choice; docs/feedback.md).

Each frame the gyro's roll and pitch rates (small-angle: body rates as Euler rates) advance the angles and
the accelerometer's tilt pulls them back with time constant TIME_CONSTANT_S: the gyro's bias then leaves an
error of bias x TIME_CONSTANT_S (1 deg/s -> 0.5 deg), and the accelerometer's swing accelerations are
filtered out over that time. The board's fused angles are not used: their frame and filter are the
firmware's, unknown to the walk.
"""

from __future__ import annotations

import math

import numpy as np

from gaitbot.servos.opencr import ImuReading

TIME_CONSTANT_S = 0.5


class TiltEstimate:
    """Roll (positive: leaning right) and pitch (positive: leaning forward), degrees, and their rates."""

    def __init__(self, period_s: float) -> None:
        self.period_s = float(period_s)
        self.alpha = TIME_CONSTANT_S / (TIME_CONSTANT_S + self.period_s)
        self.roll_deg = self.pitch_deg = 0.0
        self.rates_dps = np.zeros(3)
        self.started = False

    def update(self, reading: ImuReading) -> None:
        ax, ay, az = reading.acc_g
        roll_acc = math.degrees(math.atan2(ay, az))
        pitch_acc = math.degrees(math.atan2(-ax, math.hypot(ay, az)))
        self.rates_dps = np.asarray(reading.gyro_dps, dtype=float)
        if not self.started:  # the first reading: the accelerometer's tilt as it is
            self.roll_deg, self.pitch_deg, self.started = roll_acc, pitch_acc, True
            return
        a, dt = self.alpha, self.period_s
        self.roll_deg = a * (self.roll_deg + self.rates_dps[0] * dt) + (1 - a) * roll_acc
        self.pitch_deg = a * (self.pitch_deg + self.rates_dps[1] * dt) + (1 - a) * pitch_acc

    @property
    def tilt_deg(self) -> float:
        """The torso's tilt from upright (small-angle: the two angles' hypotenuse)."""
        return math.hypot(self.roll_deg, self.pitch_deg)

    def direction(self) -> str:
        """Which way it leans, in the robot's heading (the sim's words, gaitbot.sim.metrics)."""
        if abs(self.pitch_deg) >= abs(self.roll_deg):
            return "forwards" if self.pitch_deg > 0 else "backwards"
        return "sideways (right)" if self.roll_deg > 0 else "sideways (left)"
