"""The simulated IMU: MuJoCo's motion of the IMU's body, as the robot's IMU device answers it on the bus.

At every frame end the body's angular velocity (its own axes) and specific force (its velocity change over
the frame, less gravity, in its own axes) are taken from the physics, the config's noise figures applied
(``[imu]``: white noise per sample, a constant bias of the given size in a seeded random direction, a delay
of whole frames), and the reading written into the device's control table (gaitbot.servos.opencr's
encoding), where a READ of the simulated bus finds it, byte for byte as the OpenCR would answer. The
board's fused roll, pitch and yaw are the body's true angles, delayed like the rest.

``fault`` makes a broken IMU for the tests and docs: "frozen" (the registers stop changing), "noisy" (gyro
noise of NOISY_FAULT_DPS, 1 sigma) or "absent" (the device does not answer).
"""

from __future__ import annotations

import math
from collections import deque

import numpy as np

from gaitbot.robot.imu_settings import ImuSettings
from gaitbot.servos.opencr import IMU_BLOCK, STANDARD_GRAVITY_M_S2, encode_imu_block

FAULTS = ("frozen", "noisy", "absent")
NOISY_FAULT_DPS = 100.0
FAULT_AFTER_S = 1.0
"""A fault starts this long after the start (the walk is under way)."""


def rpy_from_matrix(r: np.ndarray) -> np.ndarray:
    """Z-Y-X roll, pitch, yaw (rad) of a rotation matrix."""
    return np.array([math.atan2(r[2, 1], r[2, 2]), math.asin(-max(-1.0, min(1.0, r[2, 0]))), math.atan2(r[1, 0], r[0, 0])])


class SimImu:
    """An observer of a SimRobot that keeps ``table`` (the device's control table) up to date every frame."""

    def __init__(self, robot, settings: ImuSettings, table: bytearray, body: int, seed: int = 0,
                 fault: str | None = None) -> None:
        self.robot, self.settings, self.table, self.body = robot, settings, table, body
        self.rng = np.random.default_rng(seed)
        direction = self.rng.normal(size=3)
        self.bias_dps = settings.gyro_bias_dps * direction / np.linalg.norm(direction)
        self.pending: deque = deque()
        self.fault = fault
        self.answering = True
        self._last_velocity = None
        self._mujoco = robot.mujoco
        self._buffer = np.zeros(6)

    def truth(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(body rates deg/s, specific force g, roll/pitch/yaw deg), noiseless, in the body's axes."""
        robot = self.robot
        rot = robot.data.xmat[self.body].reshape(3, 3)
        self._mujoco.mj_objectVelocity(robot.model, robot.data, self._mujoco.mjtObj.mjOBJ_BODY, self.body,
                                       self._buffer, 0)  # world frame: angular, then linear
        omega_world, velocity = self._buffer[:3].copy(), self._buffer[3:].copy()
        accel = np.zeros(3) if self._last_velocity is None else (velocity - self._last_velocity) / robot.frame_s
        self._last_velocity = velocity
        specific_force = rot.T @ (accel + np.array([0.0, 0.0, STANDARD_GRAVITY_M_S2])) / STANDARD_GRAVITY_M_S2
        return np.degrees(rot.T @ omega_world), specific_force, np.degrees(rpy_from_matrix(rot))

    def __call__(self, robot) -> None:
        gyro, acc, rpy = self.truth()
        s = self.settings
        noise_dps = s.gyro_noise_dps
        if self.fault == "noisy" and robot.time_s >= FAULT_AFTER_S:
            noise_dps = NOISY_FAULT_DPS
        gyro = gyro + self.bias_dps + noise_dps * self.rng.normal(size=3)
        acc = acc + s.acc_noise_g * self.rng.normal(size=3)
        self.pending.append(encode_imu_block(gyro, acc, rpy))
        if len(self.pending) <= s.delay_frames:
            return
        block = self.pending.popleft()
        if self.fault is not None and robot.time_s >= FAULT_AFTER_S:
            self.answering = self.fault != "absent"
            if self.fault == "frozen":
                return
        start, length = IMU_BLOCK
        self.table[start:start + length] = block
