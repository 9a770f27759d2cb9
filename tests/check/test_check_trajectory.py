"""check_trajectory: each limit broken on purpose, by one joint at one time, is found there.

Trajectories are a still pose with one smooth shape added to one joint, so the expected value,
time and count of each violation can be worked out by hand (see the comment at each test).
The limits are pinned here (the xl430-biped config with these limits put in, so that retuning the
shipped file does not move the hand-worked numbers): hip -45..60, knee -5..110, ankle -45..45 deg,
300 deg/s, 6000 deg/s^2.
"""

from __future__ import annotations

import dataclasses
import json
import math

import numpy as np
import pytest

from gaitbot.check.trajectory import check_trajectory, trajectory_angles_deg
from gaitbot.robot.config import load_robot_config, resolve_config

RATE_HZ = 60.0
DT = 1.0 / RATE_HZ
#: Velocities and accelerations are measured on the goal ticks as sent (gaitbot.robot.joint_motion): an XL430's
#: tick is 360/4096 deg, so rounding moves a velocity by at most one tick per frame and an acceleration by two.
TICK_DEG = 360.0 / 4096
V_TICK = TICK_DEG / DT
A_TICK = 2 * TICK_DEG / DT ** 2
POSE_DEG = [10.0, 30.0, -10.0, 10.0, 30.0, -10.0]  # hip, knee, ankle (left, right): far from every limit
COL = {"hip_pitch_left": 0, "knee_pitch_left": 1, "ankle_pitch_left": 2,
       "hip_pitch_right": 3, "knee_pitch_right": 4, "ankle_pitch_right": 5}


@pytest.fixture(scope="module")
def xl430():
    return pinned(load_robot_config(resolve_config("xl430-biped")))


PINNED_DEG = {"hip": (-45.0, 60.0), "knee": (-5.0, 110.0), "ankle": (-45.0, 45.0)}


def pinned(config):
    """The config with the limits these tests were worked out for."""
    joints = tuple(dataclasses.replace(j, min_deg=PINNED_DEG[j.name.split("_")[0]][0],
                                       max_deg=PINNED_DEG[j.name.split("_")[0]][1], max_velocity_dps=300.0,
                                       max_acceleration_dps2=6000.0) for j in config.joints)
    return dataclasses.replace(config, joints=joints)


@pytest.fixture(scope="module")
def ax12a():
    return load_robot_config(resolve_config("ax12a-biped"))


def still(duration_s: float = 5.0):
    t = np.arange(int(round(duration_s * RATE_HZ)) + 1) / RATE_HZ
    return t, np.tile(POSE_DEG, (len(t), 1))


def bump(t, start_s, length_s, height_deg):
    """Raised-cosine bump: 0 outside [start, start + length], height at the middle."""
    s = (t - start_s) / length_s
    inside = (s >= 0) & (s <= 1)
    return np.where(inside, height_deg / 2 * (1 - np.cos(2 * np.pi * np.clip(s, 0, 1))), 0.0)


def rise(t, start_s, length_s, height_deg):
    """Half-cosine step from 0 to height over [start, start + length], then held."""
    s = np.clip((t - start_s) / length_s, 0, 1)
    return height_deg / 2 * (1 - np.cos(np.pi * s))


def of(report, joint=None, kind=None, severity=None):
    return [v for v in report.violations
            if (joint is None or v.joint == joint) and (kind is None or v.kind == kind)
            and (severity is None or v.severity == severity)]


# --- a clean gait passes --------------------------------------------------------------------------


def test_smooth_gait_like_trajectory_passes(xl430):
    # Sinusoids at the gait cycle 1.346 s: knee 30 +- 25 deg. Peak speed 25 * 2pi/1.346 = 116.7 deg/s,
    # peak acceleration 25 * (2pi/1.346)^2 = 544.8 deg/s^2: far inside the limits.
    t = np.arange(0, 20, DT)
    w = 2 * np.pi / 1.346
    s = np.sin(w * t)
    angles = np.column_stack([10 + 20 * s, 30 + 25 * s, -5 + 10 * s] * 2)
    report = check_trajectory(xl430, t, angles)
    assert report.ok and report.violations == () and report.first_error is None
    assert [j.verdict for j in report.joints] == ["ok"] * 6
    knee = report.joints[1]
    assert knee.joint == "knee_pitch_left"
    assert knee.worst_velocity_dps == pytest.approx(25 * w, abs=V_TICK)
    assert knee.worst_acceleration_dps2 == pytest.approx(25 * w * w, abs=A_TICK)
    assert knee.used_min_deg == pytest.approx(5.0, abs=0.01) and knee.used_max_deg == pytest.approx(55.0, abs=0.01)
    # closest approach: 55 deg is 55 below max 110; 5 deg is 10 above min -5 -> 10
    assert knee.closest_to_limit_deg == pytest.approx(10.0, abs=0.01)


# --- position ---------------------------------------------------------------------------------------


def test_position_above_max_found_at_its_joint_and_time(xl430):
    # knee_pitch_left 30 + bump of 85 deg over [1, 3] s: peak 115 deg at t = 2.000 s, 5 above max 110.
    # Beyond 110 while 42.5 (1 - cos(pi s)) > 80, i.e. s > 0.844 -> samples t = 1.85 .. 2.15 (19).
    # Speed at most pi*85/2 = 133.5 deg/s, acceleration at most 2 pi^2 85 / 4 = 419 deg/s^2.
    t, angles = still()
    angles[:, COL["knee_pitch_left"]] += bump(t, 1.0, 2.0, 85.0)
    report = check_trajectory(xl430, t, angles)
    assert not report.ok
    assert len(report.violations) == 1
    (v,) = report.violations
    assert (v.kind, v.joint, v.severity, v.limit_name, v.limit) == ("position", "knee_pitch_left", "error",
                                                                     "max_deg", 110.0)
    assert abs(v.t_s - 2.0) <= DT and v.value == pytest.approx(115.0)
    assert v.t_start_s == pytest.approx(1.85) and v.t_end_s == pytest.approx(2.15) and v.n_samples == 19
    assert report.first_error.startswith("knee_pitch_left: position 115.0 deg at t=2.000 s exceeds max_deg 110.0")
    verdicts = {j.joint: j.verdict for j in report.joints}
    assert verdicts.pop("knee_pitch_left") == "fail" and set(verdicts.values()) == {"ok"}
    assert report.joints[1].closest_to_limit_deg == pytest.approx(-5.0)


def test_position_below_min_on_a_mirrored_joint(xl430):
    # ankle_pitch_right (direction -1): -10 + bump of -40 over [2, 4] s -> -50 at t = 3.000 s, below -45.
    t, angles = still()
    angles[:, COL["ankle_pitch_right"]] += bump(t, 2.0, 2.0, -40.0)
    report = check_trajectory(xl430, t, angles)
    (v,) = report.violations
    assert (v.kind, v.joint, v.limit_name, v.limit) == ("position", "ankle_pitch_right", "min_deg", -45.0)
    assert abs(v.t_s - 3.0) <= DT and v.value == pytest.approx(-50.0)
    assert "is below min_deg -45.0" in report.first_error


# --- velocity ---------------------------------------------------------------------------------------


def test_velocity_over_limit_found_at_its_joint_and_time(xl430):
    # knee_pitch_right rises 50 deg by a half cosine over 0.25 s (15 frames) from t0 = 1 s: 30 -> 80 deg.
    # Forward difference k (t0 + k/60): 25*60*(cos(pi(k-1)/15) - cos(pi k/15)) = 3000 sin(pi/30) sin(pi(k-1/2)/15)
    #   k = 8: 3000 * 0.104528 * 1      = 313.6 deg/s  (the worst)
    #   k = 7, 9: 313.6 * sin(6.5pi/15) = 306.7 deg/s  (also over 300)
    #   k = 6, 10: 313.6 * 0.9135       = 286.5 deg/s  (under)
    # Accelerations stay under 3933 deg/s^2 and the position under 110.
    t, angles = still()
    t0 = 1.0
    angles[:, COL["knee_pitch_right"]] += rise(t, t0, 0.25, 50.0)
    report = check_trajectory(xl430, t, angles)
    (v,) = report.violations
    assert (v.kind, v.joint, v.limit_name, v.limit) == ("velocity", "knee_pitch_right", "max_velocity_dps", 300.0)
    assert abs(v.t_s - (t0 + 8 * DT)) <= DT
    assert v.value == pytest.approx(3000 * math.sin(math.pi / 30), abs=V_TICK)
    assert v.n_samples == 3
    assert v.t_start_s == pytest.approx(t0 + 7 * DT) and v.t_end_s == pytest.approx(t0 + 9 * DT)
    assert report.joints[COL["knee_pitch_right"]].worst_acceleration_dps2 < 6000


# --- acceleration -----------------------------------------------------------------------------------


def test_acceleration_over_limit_found_at_its_joint_and_time(xl430):
    # ankle_pitch_left + bump of 4 deg over 0.1 s (6 frames) from t0 = 1 s: samples 0, 1, 3, 4, 3, 1, 0 deg.
    # Velocities 60, 120, 60, -60, -120, -60 deg/s (under 300).
    # Second differences x 3600: at k = 0..6: 3600, 3600, -3600, -7200, -3600, 3600, 3600 deg/s^2.
    # Only the middle sample, t0 + 3/60 = 1.05 s, exceeds 6000: value 7200.
    t, angles = still()
    t0 = 1.0
    angles[:, COL["ankle_pitch_left"]] += bump(t, t0, 0.1, 4.0)
    report = check_trajectory(xl430, t, angles)
    (v,) = report.violations
    assert (v.kind, v.joint, v.limit_name, v.limit) == ("acceleration", "ankle_pitch_left",
                                                        "max_acceleration_dps2", 6000.0)
    assert v.t_s == pytest.approx(t0 + 3 * DT) and v.n_samples == 1
    assert v.value == pytest.approx(7200.0, abs=A_TICK)
    summary = report.joints[COL["ankle_pitch_left"]]
    assert summary.worst_velocity_dps == pytest.approx(120.0, abs=V_TICK)


def test_differences_use_the_files_own_non_uniform_times(xl430):
    # knee_pitch_left at t = 0, 0.05, 0.15, 0.2 s: 0, 1, 5, 5 deg.
    # velocities (at the later sample): 20 @0.05, 40 @0.15, 0 @0.2 deg/s
    # accelerations (at the middle sample): 2(40-20)/0.15 = 266.7 @0.05, 2(0-40)/0.15 = -533.3 @0.15 deg/s^2
    t = np.array([0.0, 0.05, 0.15, 0.2])
    angles = np.zeros((4, 6))
    angles[:, 1] = [0, 1, 5, 5]
    knee = check_trajectory(xl430, t, angles).joints[1]
    assert knee.worst_velocity_dps == pytest.approx(40.0, abs=TICK_DEG / 0.05) and knee.worst_velocity_t_s == pytest.approx(0.15)
    assert knee.worst_acceleration_dps2 == pytest.approx(1600 / 3, abs=2 * TICK_DEG / 0.05 / 0.075) and knee.worst_acceleration_t_s == pytest.approx(0.15)


def test_a_slow_rate_cannot_hide_a_jump(xl430):
    """Issue 13 case 4: frames 1000 s apart (rate 0.001 Hz) with a 45 deg change between them are a 45 deg jump
    that a position servo makes at full speed: measured over 0.1 s (the slowest rate, 10 Hz), 450 deg/s."""
    t = np.array([0.0, 1000.0, 2000.0])
    angles = np.zeros((3, 6))
    angles[:, 1] = [0, 45, 45]
    report = check_trajectory(xl430, t, angles)
    assert not report.ok
    assert report.joints[1].worst_velocity_dps == pytest.approx(450.0)


# --- ticks and the wrap seam ------------------------------------------------------------------------


@pytest.fixture()
def wide_xl430(tmp_path):
    """xl430-biped with hip_pitch_left allowed -170..170 deg (ticks 114..3982 around 2048)."""
    text = resolve_config("xl430-biped").read_text()
    i = text.index("[joints.hip_pitch_left]")
    j = text.index("[joints.knee_pitch_left]")
    block = text[i:j].replace("min_deg = -45.0", "min_deg = -170.0").replace("max_deg = 60.0", "max_deg = 170.0")
    path = tmp_path / "wide.toml"
    path.write_text(text[:i] + block + text[j:])
    return load_robot_config(path)


def test_wrap_seam_jump_is_a_violation(wide_xl430):
    # hip_pitch_left holds 165 deg then jumps to -165 deg at sample 120 (t = 2.000 s), as an angle file
    # wrapped at +-180 would: ticks 2048 + 165*4096/360 = 3925 -> 2048 - 1877 = 171, 3754 ticks apart,
    # more than half a turn (2048): the short way between them crosses 4095/0.
    t, angles = still()
    angles[:, 0] = np.where(np.arange(len(t)) < 120, 165.0, -165.0)
    report = check_trajectory(wide_xl430, t, angles)
    seam = of(report, "hip_pitch_left", "wrap_seam")
    assert len(seam) == 1 and seam[0].t_s == pytest.approx(2.0) and seam[0].severity == "error"
    assert of(report, "hip_pitch_left", "position") == []
    assert not report.ok


def test_tick_beyond_range_of_a_wrapping_servo_is_a_seam_violation(xl430):
    # hip_pitch_left 190 deg at one sample (t = 1.000 s): tick 2048 + 190*4096/360 = 4209.8 -> 4210 > 4095.
    t, angles = still()
    angles[60, 0] = 190.0
    report = check_trajectory(xl430, t, angles)
    (seam,) = of(report, "hip_pitch_left", "wrap_seam")
    assert seam.t_s == pytest.approx(1.0) and seam.value == 4210 and seam.limit == 4095
    assert of(report, "hip_pitch_left", "position")[0].t_s == pytest.approx(1.0)
    assert of(report, kind="tick_range") == []


def test_non_wrapping_servo_reports_tick_range_not_seam(ax12a):
    # AX-12A hip_pitch_left 160 deg at t = 1.000 s: tick 512 + 160*1023/300 = 1057.6 -> 1058 > 1023.
    t, angles = still()
    angles[60, 0] = 160.0
    report = check_trajectory(ax12a, t, angles)
    (tick,) = of(report, "hip_pitch_left", "tick_range")
    assert tick.t_s == pytest.approx(1.0) and tick.value == 1058 and tick.limit == 1023
    assert of(report, kind="wrap_seam") == []


def test_big_jump_on_a_non_wrapping_servo_is_not_a_seam_crossing(tmp_path):
    # AX-12A has no seam: 140 -> -140 deg is a (too fast) move, not a wrap.
    text = resolve_config("ax12a-biped").read_text()
    i = text.index("[joints.hip_pitch_left]")
    j = text.index("[joints.knee_pitch_left]")
    block = text[i:j].replace("min_deg = -45.0", "min_deg = -145.0").replace("max_deg = 60.0", "max_deg = 145.0")
    path = tmp_path / "wide_ax.toml"
    path.write_text(text[:i] + block + text[j:])
    config = load_robot_config(path)
    t, angles = still()
    angles[:, 0] = np.where(np.arange(len(t)) < 120, 140.0, -140.0)
    report = check_trajectory(config, t, angles)
    assert of(report, kind="wrap_seam") == [] and of(report, kind="tick_range") == []
    assert of(report, "hip_pitch_left", "velocity")[0].t_s == pytest.approx(2.0)


# --- margin -----------------------------------------------------------------------------------------


def test_margin_turns_near_misses_into_warnings(xl430):
    # knee_pitch_left 30 + bump of 78 deg: peak 108 at t = 2.000 s, 2 deg inside max 110.
    t, angles = still()
    angles[:, COL["knee_pitch_left"]] += bump(t, 1.0, 2.0, 78.0)
    assert check_trajectory(xl430, t, angles).violations == ()
    assert check_trajectory(xl430, t, angles, margin_deg=1.0).violations == ()  # 108 < 110 - 1
    report = check_trajectory(xl430, t, angles, margin_deg=5.0)
    assert report.ok and report.first_error is None
    (v,) = report.violations
    assert (v.kind, v.joint, v.severity, v.limit) == ("position", "knee_pitch_left", "warning", 110.0)
    assert abs(v.t_s - 2.0) <= DT and v.value == pytest.approx(108.0)
    assert report.joints[1].verdict == "warn"


def test_margin_does_not_soften_a_real_violation(xl430):
    t, angles = still()
    angles[:, COL["knee_pitch_left"]] += bump(t, 1.0, 2.0, 85.0)  # peak 115 > 110
    report = check_trajectory(xl430, t, angles, margin_deg=10.0)
    assert not report.ok
    assert of(report, "knee_pitch_left", "position", "error")[0].value == pytest.approx(115.0)


# --- held joints, reports, input errors -----------------------------------------------------------


def test_walking_only_angles_take_held_joints_at_hold(ax12a):
    t, angles = still()
    report = check_trajectory(ax12a, t, angles)
    assert report.ok and len(report.joints) == 8
    assert report.joints[6].joint == "hip_roll_left" and report.joints[6].used_max_deg == 0.0


def test_a_held_joint_is_checked_too(ax12a):
    # every joint given: hip_roll_right at 35 deg from t = 1 s on, beyond its max 30.
    t, angles6 = still()
    angles = trajectory_angles_deg(ax12a, np.radians(angles6))
    assert angles.shape == (len(t), 8)
    angles[60:, 7] = 35.0
    report = check_trajectory(ax12a, t, angles)
    pos = of(report, "hip_roll_right", "position")
    assert pos[0].t_start_s == pytest.approx(1.0) and pos[0].limit == 30.0


def test_report_text_and_json(xl430):
    # knee_pitch_left steps by 10 deg in one frame every 30 samples (0.5 s; up, down, up ...): 600 deg/s
    # each time. Samples 0..600 (t = 0..10 s) hold steps at samples 30, 60, ..., 600: 20 velocity violations.
    t, angles = still(10.0)
    steps = ((np.arange(len(t)) // 30) % 2) * 10.0
    angles[:, 1] += steps
    report = check_trajectory(xl430, t, angles)
    velocity = of(report, "knee_pitch_left", "velocity")
    assert len(velocity) == 20 and all(v.value == pytest.approx(600.0, abs=V_TICK) for v in velocity)
    text = report.format_text(max_per_kind=5)
    assert "knee_pitch_left" in text and "velocity (20):" in text and "... and 15 more" in text
    assert "forward differences" in text and "second differences" in text
    data = json.loads(json.dumps(report.to_dict()))
    assert data["ok"] is False and len(data["joints"]) == 6
    assert data["first_error"] == report.first_error
    times = [v.t_start_s for v in report.violations]
    assert times == sorted(times)


@pytest.mark.parametrize("t, angles", [
    (np.array([0.0, 0.1, 0.1]), np.zeros((3, 6))),      # time not increasing
    (np.array([0.0, 0.1, 0.2]), np.zeros((2, 6))),      # rows do not match times
    (np.array([0.0, 0.1, 0.2]), np.zeros((3, 5))),      # neither 6 nor n_joints columns
    (np.array([0.0, 0.1, 0.2]), np.full((3, 6), np.nan)),
])
def test_malformed_input_is_refused(xl430, t, angles):
    with pytest.raises(ValueError):
        check_trajectory(xl430, t, angles)
