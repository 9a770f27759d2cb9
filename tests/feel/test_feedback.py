"""gaitbot.feel: the tilt estimate, the gyro damping's direction (checked with gaitbot's leg kinematics), and
that no correction ever takes a goal outside a joint's position, velocity or acceleration limits (checked from
the config's limits directly)."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from gaitbot.feel.estimate import TIME_CONSTANT_S, TiltEstimate
from gaitbot.feel.feedback import Feedback, RobotFell
from gaitbot.gait.kinematics6 import foot_pose
from gaitbot.robot.calibration import angles_to_ticks, ticks_to_angles
from gaitbot.servos.opencr import ImuReading
from helpers import config

PERIOD_S = 1 / 60


class StubReader:
    """An IMU reader that returns the readings it is given (the bus is not the point here)."""

    fault = None

    def __init__(self) -> None:
        self.next: ImuReading | None = None

    def read(self, deadline_s: float) -> ImuReading | None:
        return self.next


def strong_op3(**imu):
    cfg = config("op3")
    settings = dict(ankle_pitch_s=0.5, hip_pitch_s=0.5, ankle_roll_s=0.5, hip_roll_s=0.5, attitude_roll_gain=1.0,
                    attitude_pitch_gain=1.0, max_correction_deg=30.0, fall_tilt_deg=89.0, fall_tilt_rate_dps=2000.0,
                    attitude_roll_gain_by_servo_error=())
    return dataclasses.replace(cfg, imu=dataclasses.replace(cfg.imu, **{**settings, **imu}))


def reading(gyro_dps, acc_g=(0.0, 0.0, 1.0)) -> ImuReading:
    return ImuReading(np.asarray(gyro_dps, float), np.asarray(acc_g, float), np.zeros(3))


def test_a_still_tilted_torso_is_estimated_from_gravity_and_a_gyro_bias_errs_by_bias_times_tau():
    est = TiltEstimate(PERIOD_S)
    tilt = math.radians(10.0)
    for _ in range(600):  # 10 s still, pitched 10 deg forward, gyro biased 2 deg/s in pitch
        est.update(reading([0.0, 2.0, 0.0], [-math.sin(tilt), 0.0, math.cos(tilt)]))
    assert est.pitch_deg == pytest.approx(10.0 + 2.0 * TIME_CONSTANT_S, abs=0.05)
    assert est.roll_deg == pytest.approx(0.0, abs=1e-9)
    assert est.direction() == "forwards"


def true_up_in_torso(rotation) -> np.ndarray:
    """The world's up in the torso's frame for a torso at ``rotation`` (scipy Rotation: torso -> world)."""
    return rotation.inv().apply([0.0, 0.0, 1.0])


def test_a_torso_that_twists_while_it_leans_is_followed_as_a_rotation():
    # A fall as the simulation shows them: leaning 20 deg to the right, the torso pitches forward at 120 deg/s
    # while it yaws at -130 deg/s (body rates). The truth is integrated by scipy's rotations, independently.
    from scipy.spatial.transform import Rotation
    est = TiltEstimate(PERIOD_S)
    pose = Rotation.from_euler("x", 20.0, degrees=True)
    rates_dps = np.array([0.0, 120.0, -130.0])
    est.update(reading([0.0, 0.0, 0.0], true_up_in_torso(pose)))
    for _ in range(20):  # a third of a second; the accelerometer reads 1 g along the true up (no lag from it)
        pose = pose * Rotation.from_rotvec(np.radians(rates_dps) * PERIOD_S)
        est.update(reading(rates_dps, true_up_in_torso(pose)))
    truth = math.degrees(math.acos(true_up_in_torso(pose)[2]))
    assert truth > 40.0  # it fell past the op3's threshold
    assert est.tilt_deg == pytest.approx(truth, abs=0.5)


def test_a_falling_robots_accelerometer_does_not_pull_the_tilt_back():
    # Near free fall the specific force is small and says nothing of up: the gyro's 100 deg/s for 0.3 s is
    # the tilt (30 deg), not the 0.2 g that still points along the torso's z.
    est = TiltEstimate(PERIOD_S)
    est.update(reading([0.0, 0.0, 0.0]))
    for _ in range(18):
        est.update(reading([0.0, 100.0, 0.0], [0.0, 0.0, 0.2]))
    assert est.pitch_deg == pytest.approx(30.0, abs=0.01)
    assert est.tilt_deg == pytest.approx(30.0, abs=0.01)


def stance_torso_pitch_roll(cfg, angles_by_name: dict, side: str) -> tuple[float, float]:
    """The torso's world pitch and roll (deg) when ``side``'s foot is flat on the floor (gaitbot's kinematics)."""
    q = [angles_by_name[f"{k}_{side}"] for k in ("hip_yaw", "hip_roll", "hip_pitch", "knee_pitch", "ankle_pitch",
                                                  "ankle_roll")]
    _, foot = foot_pose(cfg.body.geometry, side, np.array(q))
    torso = foot.T  # the foot flat (identity in the world): the torso's rotation is the foot's inverse
    return math.degrees(math.atan2(-torso[2, 0], torso[2, 2])), math.degrees(math.atan2(torso[2, 1], torso[2, 2]))


def corrected_crouch(cfg, mode: str, imu: ImuReading):
    """A walking crouch (hip 30, knee 60, ankle 30 deg), one ``imu`` reading, and the goals ``mode`` corrects
    it to: (the crouch's angles, the corrected angles), by joint name (rad)."""
    names = [j.name for j in cfg.joints]
    crouch = {n: math.radians({"hip_pitch": 30, "knee_pitch": 60, "ankle_pitch": 30}.get(n.rsplit("_", 1)[0], 0))
              for n in names}
    row = angles_to_ticks(cfg, np.array([crouch[n] for n in names]))
    stub = StubReader()
    fb = Feedback(cfg, mode, stub, PERIOD_S, lambda: 0.0)
    stub.next = imu
    fb.sense(0.0)
    return crouch, dict(zip(names, ticks_to_angles(cfg, fb.correct(0, row))))


@pytest.mark.parametrize("gyro, index, sign", [([0.0, 50.0, 0.0], 0, -1), ([0.0, -50.0, 0.0], 0, 1),
                                               ([50.0, 0.0, 0.0], 1, -1), ([-50.0, 0.0, 0.0], 1, 1)])
def test_gyro_damping_turns_the_torso_against_its_rate_on_either_stance_leg(gyro, index, sign):
    cfg = strong_op3()
    crouch, corrected = corrected_crouch(cfg, "gyro", reading(gyro))
    for side in ("left", "right"):
        before = stance_torso_pitch_roll(cfg, crouch, side)[index]
        after = stance_torso_pitch_roll(cfg, corrected, side)[index]
        # gyro y > 0: pitching forward (pitch up); gyro x > 0: rolling right, which is roll (about x) up
        assert sign * (after - before) > 0.5


@pytest.mark.parametrize("axis, tilt_deg", [(1, 6.0), (1, -6.0), (0, 6.0), (0, -6.0)])
def test_the_attitude_term_turns_a_still_tilted_torso_back_and_only_on_its_own_axis(axis, tilt_deg):
    """A torso held still at a lean (gravity says so, no rate): "full" with a gain on that axis alone moves the
    goals so that, on either stance foot, the torso turns back towards upright about that axis, not the other."""
    gains = {"attitude_roll_gain": 1.0 if axis == 1 else 0.0, "attitude_pitch_gain": 1.0 if axis == 0 else 0.0}
    cfg = strong_op3(**gains)
    lean = math.radians(tilt_deg)
    # pitch (axis 0) forward: gravity along -x in the body; roll (axis 1) right: gravity along +y
    crouch, corrected = corrected_crouch(cfg, "full", reading([0.0, 0.0, 0.0], [-math.sin(lean), 0.0, math.cos(lean)]
                                                              if axis == 0 else [0.0, math.sin(lean), math.cos(lean)]))
    for side in ("left", "right"):
        before, after = stance_torso_pitch_roll(cfg, crouch, side), stance_torso_pitch_roll(cfg, corrected, side)
        assert -np.sign(tilt_deg) * (after[axis] - before[axis]) > 3.0  # turned back, by about the lean
        assert after[1 - axis] == pytest.approx(before[1 - axis], abs=0.2)  # the other axis left alone


@settings(max_examples=15, deadline=None)
@given(st.lists(st.tuples(st.floats(-2000, 2000), st.floats(-2000, 2000), st.floats(-0.6, 0.6), st.floats(-0.6, 0.6)),
                min_size=20, max_size=20), st.integers(0, 10_000))
def test_no_correction_breaks_a_limit(imu, seed):
    cfg = strong_op3()
    joints = cfg.joints
    rng = np.random.default_rng(seed)
    t = np.arange(len(imu)) / 60
    # a smooth plan well inside the limits, near the top of a joint's range for some
    mid = np.array([(j.min_deg + j.max_deg) / 2 for j in joints])
    span = np.array([(j.max_deg - j.min_deg) / 2 for j in joints])
    plan_deg = mid + 0.9 * span * np.sin(0.3 * t[:, None] + rng.uniform(0, 6, len(joints)))
    rows = angles_to_ticks(cfg, np.radians(plan_deg))
    stub = StubReader()
    fb = Feedback(cfg, "full", stub, PERIOD_S, lambda: 0.0)
    fb._check_fall = lambda: None  # wild readings integrate to any tilt: the limits are the point here
    sent = []
    for k, (gx, gy, ax, ay) in enumerate(imu):
        stub.next = reading([gx, gy, 0.0], [ax, ay, 1.0])
        fb.sense(k * PERIOD_S)
        sent.append(fb.correct(k, rows[k]))
    angles = np.degrees(ticks_to_angles(cfg, np.array(sent)))
    lo, hi = np.array([j.min_deg for j in joints]), np.array([j.max_deg for j in joints])
    tick_deg = np.array([360 / (2 * math.pi * j.model.ticks_per_rad) for j in joints])
    assert np.all(angles >= lo - tick_deg) and np.all(angles <= hi + tick_deg)
    # the ticks sent, as gaitbot check differentiates them: no slack beyond the limits themselves (a window
    # taken from unrounded goals once let a second difference exceed the acceleration limit by a tick)
    speed = np.abs(np.diff(angles, axis=0)) * 60
    assert np.all(speed <= np.array([j.max_velocity_dps for j in joints]) * (1 + 1e-9))
    accel = np.abs(np.diff(angles, 2, axis=0)) * 3600
    assert np.all(accel <= np.array([j.max_acceleration_dps2 for j in joints]) * (1 + 1e-9))


def test_a_tilt_beyond_the_threshold_is_a_fall_with_its_direction():
    cfg = config("op3")
    stub = StubReader()
    now = [0.0]
    fb = Feedback(cfg, "gyro", stub, PERIOD_S, lambda: now[0])
    row = angles_to_ticks(cfg, np.zeros(len(cfg.joints)))
    tilt = math.radians(cfg.imu.fall_tilt_deg + 2)
    stub.next = reading([0.0, 0.0, 0.0], [0.0, -math.sin(tilt), math.cos(tilt)])  # gravity says: leaning left
    now[0] = 1.25
    fb.sense(now[0])
    with pytest.raises(RobotFell) as fell:
        fb.correct(0, row)
    assert fell.value.direction == "sideways (left)" and fell.value.t_s == pytest.approx(1.25)


def feed(fb, now, readings, row, period_s=PERIOD_S):
    """Each reading (None: a missed read) sensed and the frame corrected, a frame apart (RobotFell propagates)."""
    for r in readings:
        now[0] += period_s
        fb.stub.next = r
        fb.sense(now[0])
        fb.correct(0, row)


def level(*g):
    return [None if v is None else reading([0.0] * 3, [0.0, 0.0, v]) for v in g]


@pytest.mark.parametrize("before, low, fell", [
    ([1.0] * 10, [0.15, 0.1, 0.05], True),    # loaded, then three readings (50 ms) under 0.2 g: dropped
    ([1.0] * 10, [0.15, 0.1, 1.0], False),    # two low readings then the feet carry it again: a jolt, not a fall
    ([1.0] * 10, [0.25] * 30, False),         # half a second at 0.25 g: light, but never under the threshold
    ([0.0] * 10, [0.1] * 3, False),           # an IMU's registers before its first measurement: never loaded
    ([1.0] * 10, [0.0] * 30, False),          # exactly 0 on all three axes: a dead accelerometer, not a drop
    ([1.0] * 10, [0.1, 0.1, None, 0.1, 0.1], False),  # a missed read: the 50 ms were not all seen
    ([1.0] * 10, [0.1, 0.1, None, 0.1, 0.1, 0.1], True),  # ... then three readings in a row again
])
def test_the_feet_load_lost_is_a_fall_said_to_go_down(before, low, fell):
    """The accelerometer's magnitude under [fall] load_lost_g (0.2) in every reading for load_lost_s (0.05 s:
    3 readings at 60 Hz), once a reading showed the feet carrying the robot (docs/feedback.md, "A fall")."""
    cfg = config("op3")
    assert (cfg.imu.fall_load_lost_g, cfg.imu.fall_load_lost_s) == (0.2, 0.05)
    now = [0.0]
    fb = Feedback(cfg, "none", StubReader(), PERIOD_S, lambda: now[0])
    fb.stub = fb.reader
    row = angles_to_ticks(cfg, np.zeros(len(cfg.joints)))
    feed(fb, now, level(*before), row)
    if not fell:
        feed(fb, now, level(*low), row)
        return
    with pytest.raises(RobotFell) as raised:
        feed(fb, now, level(*low), row)
    assert raised.value.direction == "down" and "the feet's load lost" in raised.value.reason
    assert raised.value.t_s == pytest.approx((len(before) + len(low)) * PERIOD_S)  # at the last low reading
    assert fb.least_load_g == pytest.approx(max(g for g in low[-3:]))


@pytest.mark.parametrize("rate_hz, readings", [(60.0, 3), (50.0, 3), (20.0, 2), (10.0, 2)])
def test_the_load_lost_window_covers_load_lost_s_in_two_readings_at_least(rate_hz, readings):
    """The window is whole readings covering at least load_lost_s (0.05 s): 3 at 60 Hz (exactly 50 ms), 3 at
    50 Hz (2.5 rounded up: 60 ms), and never one reading alone, however slow the frames (2 at 20 and 10 Hz)."""
    cfg = config("op3")
    now = [0.0]
    period_s = 1.0 / rate_hz
    fb = Feedback(cfg, "none", StubReader(), period_s, lambda: now[0])
    fb.stub = fb.reader
    row = angles_to_ticks(cfg, np.zeros(len(cfg.joints)))
    feed(fb, now, level(1.0, 1.0), row, period_s)
    feed(fb, now, level(*[0.1] * (readings - 1)), row, period_s)  # one reading short: no fall yet
    with pytest.raises(RobotFell) as raised:
        feed(fb, now, level(0.1), row, period_s)
    assert f"under 0.2 g for {1e3 * readings * period_s:.0f} ms" in raised.value.reason  # the span it covered


def test_the_least_load_held_is_the_lowest_window_maximum():
    """``least_load_g``: the lowest accelerometer magnitude held over a whole load_lost_s window (the walk's
    margin to the threshold), computed here by hand over sliding windows of 3."""
    cfg = config("op3")
    now = [0.0]
    fb = Feedback(cfg, "none", StubReader(), PERIOD_S, lambda: now[0])
    fb.stub = fb.reader
    row = angles_to_ticks(cfg, np.zeros(len(cfg.joints)))
    magnitudes = [1.0, 0.9, 0.5, 0.45, 0.8, 1.2, 0.6, 0.55, 0.7, 1.0]
    feed(fb, now, [reading([0.0] * 3, [0.6 * g, 0.0, 0.8 * g]) for g in magnitudes], row)  # |(0.6, 0, 0.8)| = 1
    assert fb.least_load_g == pytest.approx(min(max(magnitudes[i:i + 3]) for i in range(len(magnitudes) - 2)))


def test_without_a_reading_nothing_is_corrected():
    cfg = strong_op3()
    stub = StubReader()
    fb = Feedback(cfg, "full", stub, PERIOD_S, lambda: 0.0)
    row = angles_to_ticks(cfg, np.zeros(len(cfg.joints)))
    fb.sense(0.0)
    assert np.array_equal(fb.correct(0, row), row)


def test_the_ticks_sent_keep_the_acceleration_limit_exactly_through_a_wild_gyro():
    """The window of the next frame is taken from the ticks sent, not the unrounded goals: 600 frames of a
    plan at 90% of the velocity limit reversing every 0.2 s under a gyro jumping by hundreds of deg/s, and no
    second difference of the ticks sent exceeds the acceleration limit (in ticks: max accel x frame^2)."""
    cfg = strong_op3()
    joints = cfg.joints
    rng = np.random.default_rng(7)
    n = 600
    per_rad = np.array([j.model.ticks_per_rad for j in joints])
    speed = 0.9 * np.radians([j.max_velocity_dps for j in joints])
    t = np.arange(n) * PERIOD_S
    mid = np.radians([(j.min_deg + j.max_deg) / 2 for j in joints])
    plan = mid + speed * 0.1 * np.sin(2 * np.pi * t / 0.4)[:, None] / (2 * np.pi / 0.4 * 0.1)
    rows = angles_to_ticks(cfg, plan)
    stub = StubReader()
    fb = Feedback(cfg, "full", stub, PERIOD_S, lambda: 0.0)
    fb._check_fall = lambda: None
    sent = []
    for k in range(n):
        stub.next = reading(rng.normal(0, 300, 3), [*rng.normal(0, 0.3, 2), 1.0])
        fb.sense(k * PERIOD_S)
        sent.append(fb.correct(k, rows[k]))
    second = np.abs(np.diff(np.array(sent, dtype=float), 2, axis=0))
    limit = np.radians([j.max_acceleration_dps2 for j in joints]) * per_rad * PERIOD_S ** 2
    assert second.max() > 0.5 * limit.min()  # the window was reached
    assert np.all(second <= limit + 1e-9)


@pytest.mark.parametrize("error_deg, gain", [(3.0, 0.0), (6.0, 0.0), (8.0, 0.2), (10.0, 0.4), (13.6, 0.4)])
def test_the_roll_attitude_gain_follows_the_servos_stiffness(error_deg, gain):
    """config/op3.toml's [[6, 0], [10, 0.4]]: none for servos as stiff as it writes them, 0.4 for soft ones (factory
    gains, Menagerie's model), the straight line between (8 deg: half way), flat beyond the ends; the Feedback
    uses it on the roll joints, sign as the roll damping's."""
    cfg = config("op3")
    assert cfg.imu.roll_gain(error_deg) == pytest.approx(gain)
    fb = Feedback(cfg, "full", StubReader(), PERIOD_S, lambda: 0.0, servo_error_deg=error_deg)
    roll = fb.attitude[:, 0]
    for i, j in enumerate(cfg.joints):
        kind, _, side = j.name.rpartition("_")
        expected = gain * (1 if side == "left" else -1) if kind in ("hip_roll", "ankle_roll") else 0.0
        assert roll[i] == pytest.approx(expected)


def test_without_a_stiffness_the_feedback_takes_the_one_the_config_writes():
    """op3 asks for 6 deg ([servo] full_torque_error_deg): the stiff end of its table, no roll attitude; without
    that setting, the XM430-W350's factory gain (12.4 deg: soft, the full 0.4)."""
    fb = Feedback(config("op3"), "full", StubReader(), PERIOD_S, lambda: 0.0)
    assert fb.servo_error_deg == 6.0
    assert not fb.attitude.any()
    factory = dataclasses.replace(config("op3"), servo=dataclasses.replace(config("op3").servo, full_torque_error_deg=None))
    soft = Feedback(factory, "full", StubReader(), PERIOD_S, lambda: 0.0)
    assert soft.servo_error_deg == pytest.approx(12.4, abs=0.1)
    assert abs(soft.attitude[:, 0]).max() == pytest.approx(0.4)
