"""The goals of each frame corrected by what the IMU felt, inside every limit; a fall noticed.

Once a frame the stream calls ``sense(deadline_s)`` after the goals went out (the IMU read, in that frame's
budget) and ``correct(k, row)`` on the next frame's planned goals (ticks): the reading is one frame old
when it acts. Corrections (docs/feedback.md; gains per robot, ``[feedback]``):

* gyro damping ("gyro" and "full"): the torso's pitch rate w_p and roll rate w_r (rad/s) move the ankle and
  hip goals of both legs against the motion: ankle_pitch and hip_pitch by -k w_p; ankle_roll and hip_roll
  by +s k w_r (s = +1 left, -1 right). With the foot flat, the shank's lean is the ankle pitch and
  -s ankle roll, and the torso's pitch is hip - knee + ankle pitch (gaitbot.gait.kinematics6's
  conventions), so each term pushes against the tilting velocity: a damper in parallel with the servo.
* attitude ("full", "step" and "zmp"): the same joints by the estimated roll times the roll gain and pitch
  times ``attitude_pitch_gain`` (deg/deg): the torso's lean held against as well as its rate. The roll gain may
  depend on the servos' stiffness (``attitude_roll_gain_by_servo_error``): the stiffness the config writes
  to them, or, on another author's simulated model, its own actuators' (``servo_error_deg``).

Every correction is clipped to ``max_correction_deg``, then each goal to the window its joint's limits
allow from the last two goals sent: position limits, |step| <= max velocity x frame, |change of step| <=
max acceleration x frame^2. So no feedback can break a limit (``gaitbot check`` of the recording holds it).

A fall: the estimated tilt beyond ``[fall] tilt_deg``, or the tilt rate beyond ``tilt_rate_dps`` while the
tilt is past half the threshold (a push's jolt alone is not a fall), or the feet's load lost: the
accelerometer's magnitude (the specific force: 1 g while the feet carry the robot, 0 g falling freely) under
``load_lost_g`` in every reading for ``load_lost_s`` (a drop, a floor that gives way, a step off an edge:
nothing tilts, yet nothing holds the robot up). The window is whole readings, at least two, covering at least
``load_lost_s``; a missed reading starts it again, and a reading of exactly 0 on all three axes is no reading
(a dead accelerometer, or one not yet measuring: a falling one's noise still moves its low bits). RobotFell,
which the session answers by stopping the steps, lowering the CoM (``fall_pose``) and the config's response.
"""

from __future__ import annotations

import math
from collections import deque
from collections.abc import Callable

import numpy as np

from gaitbot.feel.estimate import TiltEstimate
from gaitbot.feel.imu_reader import ImuReader
from gaitbot.robot.calibration import tick_limits
from gaitbot.robot.config import RobotConfig

MODES = ("none", "gyro", "full", "step", "zmp")
FALL_CROUCH_DEG = {"knee_pitch": 25.0, "hip_pitch": 12.5, "ankle_pitch": 12.5}
"""How much further the legs fold when a fall is noticed (the CoM comes down: less height to fall from)."""
LOADED_G = 0.7
"""The feet's load counts as lost only after a reading of at least this (g) has shown them carrying the robot
(a walk starts standing on them); [fall] load_lost_g stays under it (gaitbot.robot.imu_settings)."""
DOWN_TILT_DEG = 10.0
"""A load-lost fall with the torso tilted less than this is said to go "down", not the way it leans."""


def servo_stiffness_deg(config: RobotConfig) -> float:
    """The servos' full-torque error (deg) the feedback's gains are chosen for: ``[servo] full_torque_error_deg``
    as the config asks it (the register's whole steps aside), else the mean of the leg servos' factory gains."""
    if config.servo.full_torque_error_deg is not None:
        return float(config.servo.full_torque_error_deg)
    return float(np.mean([j.model.full_torque_error_deg for j in config.joints if j.hold_deg is None]))


class RobotFell(Exception):
    """The IMU says the robot is falling: when (session seconds), which way, and why."""

    def __init__(self, t_s: float, direction: str, reason: str) -> None:
        self.t_s, self.direction, self.reason = t_s, direction, reason
        super().__init__(f"the robot fell {direction} at {t_s:.2f} s ({reason})")


class Feedback:
    """Per-frame corrections of a walk's goal rows (ticks, in ``config.joints`` order)."""

    def __init__(self, config: RobotConfig, mode: str, reader: ImuReader | None, period_s: float,
                 now: Callable[[], float], servo_error_deg: float | None = None) -> None:
        if mode not in MODES:
            raise ValueError(f"mode must be one of {MODES}, got {mode!r}")
        self.config, self.mode, self.reader, self.now = config, mode, reader, now
        self.settings = s = config.imu
        self.estimate = TiltEstimate(period_s)
        self.start_s = now()  # a fall's time is said from here (the session's start; the simulation's t = 0)
        joints = config.joints
        self.names = [j.name for j in joints]
        per_rad = np.array([j.model.ticks_per_rad for j in joints], dtype=float)
        self.ticks_per_rad = per_rad * np.array([j.direction for j in joints], dtype=float)
        limits = tick_limits(config)
        self.low = np.array([min(limits[j.id]) for j in joints], dtype=float)
        self.high = np.array([max(limits[j.id]) for j in joints], dtype=float)
        self.max_step = np.radians([j.max_velocity_dps for j in joints]) * per_rad * period_s
        self.max_change = np.radians([j.max_acceleration_dps2 for j in joints]) * per_rad * period_s ** 2
        self.rate_gain_s = np.zeros((len(joints), 2))  # columns: roll rate, pitch rate
        gains = {"ankle_pitch": (0, -s.ankle_pitch_s), "hip_pitch": (0, -s.hip_pitch_s),
                 "ankle_roll": (1, s.ankle_roll_s), "hip_roll": (1, s.hip_roll_s)}
        for i, name in enumerate(self.names):
            kind, _, side = name.rpartition("_")
            if kind in gains and joints[i].hold_deg is None:
                roll, k = gains[kind]
                if roll:
                    self.rate_gain_s[i, 0] = (1.0 if side == "left" else -1.0) * k
                else:
                    self.rate_gain_s[i, 1] = k
        if servo_error_deg is None:
            servo_error_deg = servo_stiffness_deg(config)
        self.servo_error_deg = float(servo_error_deg)
        self.attitude = np.sign(self.rate_gain_s) * [s.roll_gain(self.servo_error_deg), s.attitude_pitch_gain]
        self.max_correction_rad = math.radians(s.max_correction_deg)
        self.last: np.ndarray | None = None
        self.previous: np.ndarray | None = None
        self.correction_rad = np.zeros(len(joints))
        self.fresh = False
        self.reading = None  # the last sense()'s reading (None: missed), for whoever watches the walk
        self.load_window = max(2, math.ceil(s.fall_load_lost_s / period_s - 1e-9))  # readings it must stay lost
        self.recent_g: deque[float] = deque(maxlen=self.load_window)  # the accelerometer's last magnitudes (g)
        self.loaded = False  # a reading of LOADED_G or more seen
        self.least_load_g: float | None = None  # the lowest magnitude held over a whole window: the margin

    @property
    def active(self) -> bool:
        return self.mode != "none" and self.reader is not None and self.reader.fault is None

    def sense(self, deadline_s: float) -> None:
        """Read the IMU in this frame's budget and update the estimate (a missed read changes nothing)."""
        if self.reader is None:
            return
        reading = self.reader.read(deadline_s)
        self.fresh = reading is not None
        self.reading = reading
        if reading is not None:
            self.estimate.update(reading)
        self._track_load(0.0 if reading is None else self.estimate.acc_norm_g)

    def _track_load(self, magnitude_g: float) -> None:
        """The accelerometer's magnitude (g; 0: a missed reading) kept for the load-lost test (module
        docstring), once the feet have carried the robot; a missed or all-zero reading starts the window again."""
        if magnitude_g == 0.0:
            self.recent_g.clear()
            return
        self.loaded = self.loaded or magnitude_g >= LOADED_G
        if not self.loaded:
            return
        self.recent_g.append(magnitude_g)
        if len(self.recent_g) == self.load_window:
            held = max(self.recent_g)
            self.least_load_g = held if self.least_load_g is None else min(self.least_load_g, held)

    def correct(self, k: int, row) -> np.ndarray:
        """Frame ``k``'s planned goals (ticks) corrected and kept inside every limit; RobotFell on a fall."""
        row = np.asarray(row, dtype=float)
        if self.reader is not None and self.reader.fault is None and self.estimate.started:
            self._check_fall()
        wanted = np.zeros(len(row))
        if self.active and self.estimate.started:
            rates = np.radians(self.estimate.rates_dps[:2])
            wanted = self.rate_gain_s @ rates
            if self.mode in ("full", "step", "zmp"):  # step, zmp: full, and the walk moved (gaitbot.drive.stepping)
                wanted = wanted + self.attitude @ np.radians([self.estimate.roll_deg, self.estimate.pitch_deg])
            wanted = np.clip(wanted, -self.max_correction_rad, self.max_correction_rad)
        # whole ticks, as sent: the next frame's window is taken from these (a window from the unrounded goals
        # let the sent ticks' second difference exceed the acceleration limit by a tick)
        goal = np.rint(self.within_limits(row + wanted * self.ticks_per_rad))
        self.correction_rad = (goal - row) / self.ticks_per_rad
        self.previous, self.last = self.last, goal
        return goal.astype(np.int64)

    def within_limits(self, goal: np.ndarray) -> np.ndarray:
        """``goal`` clipped to what the limits allow after the last two goals sent (module docstring)."""
        low, high = self.low, self.high
        if self.last is not None:
            step = self.last - self.previous if self.previous is not None else np.zeros_like(goal)
            low = np.maximum(low, np.maximum(self.last - self.max_step, self.last + step - self.max_change))
            high = np.minimum(high, np.minimum(self.last + self.max_step, self.last + step + self.max_change))
            empty = low > high  # braking at a position limit: the position limit wins
            low, high = np.where(empty, self.low, low), np.where(empty, self.high, high)
        return np.clip(goal, np.ceil(low), np.floor(high))

    def _check_fall(self) -> None:
        s, e = self.settings, self.estimate
        tilt, rate = e.tilt_deg, float(np.hypot(*e.rates_dps[:2]))
        reason, direction = None, e.direction()
        if tilt > s.fall_tilt_deg:
            reason = f"torso tilted {tilt:.0f} deg, beyond {s.fall_tilt_deg:g}"
        elif rate > s.fall_tilt_rate_dps and tilt > 0.5 * s.fall_tilt_deg:
            reason = f"tilting at {rate:.0f} deg/s, beyond {s.fall_tilt_rate_dps:g}, at {tilt:.0f} deg"
        elif len(self.recent_g) == self.load_window and (held := max(self.recent_g)) < s.fall_load_lost_g:
            reason = (f"the feet's load lost: the accelerometer under {s.fall_load_lost_g:g} g for "
                      f"{1e3 * self.load_window * e.period_s:.0f} ms, {held:.2f} g at most")
            direction = "down" if tilt < DOWN_TILT_DEG else direction
        if reason is not None:
            raise RobotFell(self.now() - self.start_s, direction, reason)

    def fall_pose(self, last_ticks) -> np.ndarray:
        """The last goals with the legs folded by FALL_CROUCH_DEG, inside the position limits."""
        pose = np.asarray(last_ticks, dtype=float).copy()
        for i, name in enumerate(self.names):
            kind = name.rpartition("_")[0]
            if kind in FALL_CROUCH_DEG and self.config.joints[i].hold_deg is None:
                pose[i] += math.radians(FALL_CROUCH_DEG[kind]) * self.ticks_per_rad[i]
        return np.rint(np.clip(pose, self.low, self.high)).astype(np.int64)
