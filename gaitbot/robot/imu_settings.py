"""A robot's IMU and what the walk does with it: the optional ``[imu]``, ``[feedback]`` and ``[fall]`` tables.

    [imu]
    source = "opencr"          # "none" (no IMU: open loop) or "opencr" (the OP3's OpenCR on the servo bus)
    id = 200                   # its Dynamixel id (the OP3 firmware's)
    mount_rpy_deg = [0, 0, 0]  # the device's orientation on the torso (after its own board mounting)
    gyro_noise_dps = 0.5       # white noise of one gyro sample, 1 sigma (the simulation adds it)
    gyro_bias_dps = 1.0        # a constant gyro bias of this size, random direction (the simulation)
    acc_noise_g = 0.02         # accelerometer noise, 1 sigma (the simulation)
    delay_frames = 1           # whole frames between the motion and the reading (the simulation)

    [feedback]                 # gyro damping: goal correction in deg per deg/s of torso rate (= seconds)
    ankle_pitch_s = 0.02
    hip_pitch_s = 0.0
    ankle_roll_s = 0.02
    hip_roll_s = 0.01
    attitude_roll_gain = 0.0   # "full": extra correction per degree of estimated roll (deg/deg)
    # or, instead, the roll gain by the servos' stiffness (their full-torque error, deg), interpolated:
    # attitude_roll_gain_by_servo_error = [[6.0, 0.0], [10.0, 0.4]]
    attitude_pitch_gain = 0.0  # "full": and per degree of estimated pitch (deg/deg)
    max_correction_deg = 8.0   # no correction beyond this on any joint

    [fall]
    tilt_deg = 40.0            # estimated torso tilt beyond this is a fall
    tilt_rate_dps = 250.0      # or a tilt rate beyond this
    load_lost_g = 0.2          # or the accelerometer under this (g) for load_lost_s: the feet's load lost
    load_lost_s = 0.05
    response = "torque_off"    # after stopping and lowering the CoM: "hold" or "torque_off"

docs/robot-config.md and docs/feedback.md say what each does; gaitbot.feel applies them.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

IMU_SOURCES = ("none", "opencr")
FALL_RESPONSES = ("hold", "torque_off")
IMU_KEYS = ("source", "id", "mount_rpy_deg", "gyro_noise_dps", "gyro_bias_dps", "acc_noise_g", "delay_frames")
FEEDBACK_KEYS = ("ankle_pitch_s", "hip_pitch_s", "ankle_roll_s", "hip_roll_s", "attitude_roll_gain", "attitude_pitch_gain",
                 "max_correction_deg", "attitude_roll_gain_by_servo_error")
MAX_GAIN_POINTS = 16
MAX_ATTITUDE_GAIN = 2.0
FALL_KEYS = ("tilt_deg", "tilt_rate_dps", "load_lost_g", "load_lost_s", "response")
MAX_DELAY_FRAMES = 30
MAX_GAIN_S = 1.0


@dataclass(frozen=True)
class ImuSettings:
    """``[imu]``, ``[feedback]`` and ``[fall]`` of a config (defaults: no IMU, no feedback gains, the fall
    thresholds of docs/feedback.md)."""

    source: str = "none"
    device_id: int = 200
    mount_rpy_deg: tuple[float, float, float] = (0.0, 0.0, 0.0)
    gyro_noise_dps: float = 0.0
    gyro_bias_dps: float = 0.0
    acc_noise_g: float = 0.0
    delay_frames: int = 0
    ankle_pitch_s: float = 0.0
    hip_pitch_s: float = 0.0
    ankle_roll_s: float = 0.0
    hip_roll_s: float = 0.0
    attitude_roll_gain: float = 0.0
    attitude_pitch_gain: float = 0.0
    max_correction_deg: float = 8.0
    fall_tilt_deg: float = 40.0
    fall_tilt_rate_dps: float = 250.0
    fall_response: str = "torque_off"
    attitude_roll_gain_by_servo_error: tuple[tuple[float, float], ...] = ()
    fall_load_lost_g: float = 0.2
    fall_load_lost_s: float = 0.05

    def roll_gain(self, servo_error_deg: float) -> float:
        """The attitude roll gain for servos that give full torque at ``servo_error_deg`` of position error:
        ``attitude_roll_gain_by_servo_error`` interpolated (flat beyond its ends), else ``attitude_roll_gain``.
        Why by stiffness: soft servos let the torso lean under the stance leg's load faster than gyro
        damping holds it, and the lean's correction that carries them is too much ankle torque for stiff ones
        (docs/feedback.md, "Soft servos")."""
        table = self.attitude_roll_gain_by_servo_error
        if not table:
            return self.attitude_roll_gain
        errors, gains = zip(*table)
        return float(np.interp(servo_error_deg, errors, gains))

    @property
    def present(self) -> bool:
        return self.source != "none"

    @property
    def device_ids(self) -> tuple[int, ...]:
        """The bus ids this IMU answers at (none without an IMU on the bus)."""
        return (self.device_id,) if self.source == "opencr" else ()


def read_imu(fields: Any, data: dict, bus: Any) -> ImuSettings:
    """The three tables of a config (``fields``: its gaitbot.fields.Fields reader); ImuSettings() if absent."""
    imu = fields.optional_table(data, "imu", "imu", IMU_KEYS)
    feedback = fields.optional_table(data, "feedback", "feedback", FEEDBACK_KEYS)
    fall = fields.optional_table(data, "fall", "fall", FALL_KEYS)
    source = imu.get("source", "none")
    if source not in IMU_SOURCES:
        raise fields.fail("imu.source", f"unknown IMU source {source!r} (allowed: {', '.join(IMU_SOURCES)})")
    if source == "opencr" and getattr(bus, "backend", "dynamixel") != "dynamixel":
        raise fields.fail("imu.source", "the OpenCR answers on a Dynamixel bus (Protocol 2.0); this robot's bus is "
                                        f"{bus.backend}")
    device_id = fields.integer(imu, "id", "imu", "a Dynamixel id 0..252") if "id" in imu else 200
    if not 0 <= device_id <= 252:
        raise fields.fail("imu.id", f"{device_id} is out of range (allowed: 0..252)")
    mount = imu.get("mount_rpy_deg", [0.0, 0.0, 0.0])
    if not isinstance(mount, list) or len(mount) != 3:
        raise fields.fail("imu.mount_rpy_deg", "must be [roll, pitch, yaw] in degrees")
    mount = tuple(fields.check_number(v, "imu.mount_rpy_deg", within=(-180.0, 180.0, "deg")) for v in mount)
    noise = {k: fields.number(imu, k, "imu", non_negative=True, default=0.0, within=(0.0, 1000.0, ""))
             for k in ("gyro_noise_dps", "gyro_bias_dps", "acc_noise_g")}
    delay = fields.integer(imu, "delay_frames", "imu", "a whole number of frames") if "delay_frames" in imu else 0
    if not 0 <= delay <= MAX_DELAY_FRAMES:
        raise fields.fail("imu.delay_frames", f"{delay} is outside the allowed 0..{MAX_DELAY_FRAMES}")
    gains = {k: fields.number(feedback, k, "feedback", non_negative=True, default=0.0, within=(0.0, MAX_GAIN_S, "s"))
             for k in FEEDBACK_KEYS[:4]}
    attitude = [fields.number(feedback, k, "feedback", non_negative=True, default=0.0,
                              within=(0.0, MAX_ATTITUDE_GAIN, ""))
                for k in ("attitude_roll_gain", "attitude_pitch_gain")]
    by_error = _gain_table(fields, feedback)
    if by_error and "attitude_roll_gain" in feedback:
        raise fields.fail("feedback.attitude_roll_gain_by_servo_error", "give it or attitude_roll_gain, not both")
    max_corr = fields.number(feedback, "max_correction_deg", "feedback", positive=True, default=8.0,
                             within=(0.0, 45.0, "deg"))
    response = fall.get("response", "torque_off")
    if response not in FALL_RESPONSES:
        raise fields.fail("fall.response", f"unknown response {response!r} (allowed: {', '.join(FALL_RESPONSES)})")
    return ImuSettings(source, device_id, mount, noise["gyro_noise_dps"], noise["gyro_bias_dps"], noise["acc_noise_g"],
                       delay, gains["ankle_pitch_s"], gains["hip_pitch_s"], gains["ankle_roll_s"], gains["hip_roll_s"],
                       *attitude, max_corr,
                       fields.number(fall, "tilt_deg", "fall", positive=True, default=40.0, within=(5.0, 90.0, "deg")),
                       fields.number(fall, "tilt_rate_dps", "fall", positive=True, default=250.0,
                                     within=(10.0, 2000.0, "deg/s")),
                       response, by_error,
                       fields.number(fall, "load_lost_g", "fall", positive=True, default=0.2, within=(0.05, 0.5, "g")),
                       fields.number(fall, "load_lost_s", "fall", positive=True, default=0.05,
                                     within=(0.01, 1.0, "s")))


def _gain_table(fields: Any, feedback: dict) -> tuple[tuple[float, float], ...]:
    """``attitude_roll_gain_by_servo_error``: [[error_deg, gain], ...], errors rising (empty if absent)."""
    name = "feedback.attitude_roll_gain_by_servo_error"
    table = feedback.get("attitude_roll_gain_by_servo_error", [])
    allowed = (f"a list of 1 to {MAX_GAIN_POINTS} [servo error deg, gain] pairs, errors rising, gains "
               f"0..{MAX_ATTITUDE_GAIN:g}")
    if not isinstance(table, list) or len(table) > MAX_GAIN_POINTS or (table and not all(
            isinstance(pair, list) and len(pair) == 2 for pair in table)):
        raise fields.fail(name, f"must be {allowed}")
    pairs = tuple((fields.check_number(e, name, positive=True, within=(0.0, 90.0, "deg")),
                   fields.check_number(g, name, non_negative=True, within=(0.0, MAX_ATTITUDE_GAIN, "")))
                  for e, g in table)
    if any(b[0] <= a[0] for a, b in zip(pairs, pairs[1:])):
        raise fields.fail(name, f"must be {allowed}")
    return pairs
