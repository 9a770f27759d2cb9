"""The IMU read once a frame, after the frame's goals, within what is left of the frame; its faults noticed.

The read is the read-back's kind (gaitbot.stream.readback): one READ with a budget ending READ_MARGIN_S
before the next frame's deadline, never retried, never waited on beyond it. A reading that misses its
budget is simply absent for that frame. Faults, each said once, after which the reader stops reading (the
walk goes on open loop, as a robot without an IMU does; docs/feedback.md):

* absent: no answer for ABSENT_FRAMES frames in a row;
* frozen: the same 18 bytes for FROZEN_FRAMES frames in a row (a live sensor's noise moves the LSBs);
* noisy: the gyro jumps by more than NOISY_JUMP_DPS between frames on average over NOISY_FRAMES frames.
"""

from __future__ import annotations

from collections import deque
from collections.abc import Callable

import numpy as np

from gaitbot.bus.base import Bus
from gaitbot.robot.imu_settings import ImuSettings
from gaitbot.servos.opencr import IMU_BLOCK, ImuReading, decode_imu_block

READ_MARGIN_S = 2.0e-3
ABSENT_FRAMES = 6
FROZEN_FRAMES = 30
NOISY_FRAMES = 15
NOISY_JUMP_DPS = 60.0


def mount_rotation(rpy_deg) -> np.ndarray:
    """Torso-from-device rotation for the device's roll, pitch, yaw on the torso (Z-Y-X, degrees)."""
    r, p, y = np.radians(rpy_deg)
    cr, sr, cp, sp, cy, sy = np.cos(r), np.sin(r), np.cos(p), np.sin(p), np.cos(y), np.sin(y)
    return np.array([[cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr],
                     [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr],
                     [-sp, cp * sr, cp * cr]])


class ImuReader:
    """Reads ``settings``' IMU on ``bus`` once a frame; ``fault`` names the fault once one is noticed."""

    def __init__(self, bus: Bus, settings: ImuSettings, now: Callable[[], float], period_s: float,
                 on_fault: Callable[[str], None] | None = None) -> None:
        self.bus, self.settings, self.now, self.period_s = bus, settings, now, float(period_s)
        self.rotation = mount_rotation(settings.mount_rpy_deg)
        self.on_fault = on_fault
        self.fault: str | None = None
        self.reads = self.answers = 0
        self._missed = self._same = 0
        self._last: bytes | None = None
        self._last_gyro: np.ndarray | None = None
        self._jumps: deque = deque(maxlen=NOISY_FRAMES)

    def read(self, deadline_s: float) -> ImuReading | None:
        """This frame's reading in the torso's axes, or None (missed, or the IMU is faulty)."""
        if self.fault is not None:
            return None
        budget_s = deadline_s + self.period_s - READ_MARGIN_S - self.now()
        self.reads += 1
        data = self.bus.read_device(self.settings.device_id, IMU_BLOCK[0], IMU_BLOCK[1], budget_s)
        if data is None:
            self._missed += 1
            if self._missed >= ABSENT_FRAMES:
                self._fail(f"absent: no answer from id {self.settings.device_id} in {self._missed} frames")
            return None
        self._missed = 0
        self.answers += 1
        self._same = self._same + 1 if data == self._last else 0
        self._last = data
        if self._same >= FROZEN_FRAMES:
            self._fail(f"frozen: the same reading for {self._same} frames")
            return None
        raw = decode_imu_block(data)
        reading = ImuReading(self.rotation @ raw.gyro_dps, self.rotation @ raw.acc_g, raw.fused_rpy_deg)
        if self._last_gyro is not None:
            self._jumps.append(float(np.abs(reading.gyro_dps - self._last_gyro).max()))
        self._last_gyro = reading.gyro_dps
        if len(self._jumps) == NOISY_FRAMES and np.mean(self._jumps) > NOISY_JUMP_DPS:
            self._fail(f"noisy: the gyro jumps {np.mean(self._jumps):.0f} deg/s between frames on average")
            return None
        return reading

    def _fail(self, what: str) -> None:
        self.fault = what
        if self.on_fault is not None:
            self.on_fault(f"IMU (id {self.settings.device_id}) {what}: feedback and fall detection off, walking "
                          "open loop")
