"""What the robot felt, in the view: /imu where the walk reads an IMU, the servos' read-back, and in a simulation
the measured centre of mass and pelvis pose; each checked against a physical fact, not against the code."""

import math
import xml.etree.ElementTree as ET

import numpy as np
import pytest

pytest.importorskip("mcap_ros2")
from gaitbot.robot.calibration import angles_to_ticks  # noqa: E402
from gaitbot.robot.description.tree import rpy_matrix  # noqa: E402
from gaitbot.robot.description.urdf_writer import urdf_text  # noqa: E402
from gaitbot.servos.opencr import ImuReading  # noqa: E402
from gaitbot.view.felt import Felt, FeltSample, centre_of_pressure  # noqa: E402
from gaitbot.view.telemetry import FrameTelemetry  # noqa: E402
from helpers import config, run_cli  # noqa: E402
from test_mcap_log import read_back  # noqa: E402

G = 9.80665  # standard gravity (m/s^2, CGPM 1901), what the OpenCR's g are


def test_the_imu_in_si_units_with_the_walk_tilt_as_orientation():
    felt = Felt(config("op3"))
    reading = ImuReading(np.array([90.0, -45.0, 0.0]), np.array([0.0, 0.5, math.sqrt(0.75)]), np.zeros(3))
    imu = felt.imu(reading, (30.0, -10.0))
    assert imu.angular_velocity_rad_s == pytest.approx((math.pi / 2, -math.pi / 4, 0.0))
    assert np.linalg.norm(imu.linear_acceleration_m_s2) == pytest.approx(G)
    # the quaternion turns the torso's z axis as roll 30 deg, pitch -10 deg (Z-Y-X, REP-103) do
    x, y, z, w = imu.orientation_xyzw
    q_matrix = np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                         [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                         [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]])
    assert np.allclose(q_matrix, rpy_matrix(math.radians(30), math.radians(-10), 0.0), atol=1e-12)
    # variances: the config's gyro noise (0.5 deg/s), and a yaw the walk does not estimate (uniform on the circle)
    assert imu.angular_velocity_variance[0] == pytest.approx(math.radians(0.5) ** 2)
    assert imu.orientation_variance[2] == pytest.approx((2 * math.pi) ** 2 / 12)


def test_read_back_once_every_servo_answered_and_each_its_latest():
    cfg = config("op3")
    felt = Felt(cfg)
    angles = np.random.default_rng(3).uniform(-0.5, 0.5, len(cfg.joints))
    ticks = angles_to_ticks(cfg, angles[:cfg.calibration.n_walking], cfg.walking_joint_names)
    angles[cfg.calibration.n_walking:] = [math.radians(j.hold_deg or 0.0) for j in cfg.joints[cfg.calibration.n_walking:]]

    class Answer:
        def __init__(self, servo_id, ticks):
            self.servo_id, self.ticks = servo_id, int(ticks)

    results = [felt.read_back_rad(Answer(i, t)) for i, t in zip(cfg.ids, ticks)]
    assert all(r is None for r in results[:-1])  # a joint never read is not guessed
    half_tick = 0.5 / np.array([j.model.ticks_per_rad for j in cfg.joints])
    assert np.all(np.abs(results[-1] - angles) <= half_tick + 1e-12)


def test_centre_of_pressure_weighs_the_contacts_by_their_normal_force():
    points = np.array([[0.0, 0.0, 0.0], [0.1, 0.0, 0.0], [0.1, 0.2, 0.0]])
    assert centre_of_pressure((points, np.array([1.0, 1.0, 2.0]))) == pytest.approx((0.075, 0.1))
    assert centre_of_pressure((points[:0], np.zeros(0))) is None  # in the air: no ZMP


def test_a_frame_without_sensors_is_left_as_it_is():
    frame = FrameTelemetry(0.0, ("a",), np.zeros(1), np.zeros(3), felt=FeltSample())
    resolved = Felt(config("op3")).resolve(frame)
    assert resolved.imu is None and resolved.read_back_rad is None and resolved.measured_com_m is None


def _quaternion_roll_pitch(q) -> tuple[float, float]:
    x, y, z, w = q.x, q.y, q.z, q.w
    return math.atan2(2 * (w * x + y * z), 1 - 2 * (x * x + y * y)), math.asin(2 * (w * y - z * x))


def test_simulated_walk_logs_the_imu_every_frame_and_it_feels_gravity(tmp_path, capsys):
    mcap = tmp_path / "sim.mcap"
    code, out, err = run_cli(capsys, "walk", "--sim", "--robot", "op3", "--distance", "0.2", "--mcap", mcap)
    assert code == 0, err
    log = read_back(mcap)
    walk_frames = int(out.split("Sent ")[1].split()[0])
    imu = [m for *_, m in log["/imu"]]
    assert len(imu) == len(log["/joint_goals"]) == walk_frames  # at the frame rate: one reading a frame
    assert np.allclose(np.diff([t for t, *_ in log["/imu"]]), 1e9 / 60, atol=1)
    links = {link.get("name") for link in ET.fromstring(urdf_text(config("op3"))).iter("link")}
    assert {m.header.frame_id for m in imu} == {"torso"} <= links  # a frame of the exported URDF
    imu = imu[2:]  # the first readings are the board's zeroed registers (the IMU's delay, a frame)
    acc = np.array([(m.linear_acceleration.x, m.linear_acceleration.y, m.linear_acceleration.z) for m in imu])
    gyro = np.array([(m.angular_velocity.x, m.angular_velocity.y, m.angular_velocity.z) for m in imu])
    # a walk that starts and ends standing: the torso's mean acceleration is ~0, so the mean specific force is
    # gravity, up the (nearly upright) torso; the mean rate is ~0 but for the simulated bias (1 deg/s)
    assert np.allclose(acc.mean(axis=0), (0.0, 0.0, G), atol=0.15)
    assert np.linalg.norm(gyro.mean(axis=0)) < math.radians(1.0) + 0.01
    # the orientation (the walk's filtered roll and pitch) follows the simulated torso's, measured by the
    # physics: the pitch (which swings 2 deg a step) moves with it and agrees on average; the filter's own
    # error in a walk (the sway's accelerations read as tilt, gaitbot.feel.estimate) stays small in both
    pose = {t: m.pose.orientation for t, *_, m in log["/pose_measured"]}
    felt = np.degrees([_quaternion_roll_pitch(m.orientation) for m in imu])
    truth = np.degrees([_quaternion_roll_pitch(pose[t]) for t, *_ in log["/imu"][2:]])
    assert np.corrcoef(felt[:, 1], truth[:, 1])[0, 1] > 0.8
    assert np.allclose(felt.mean(axis=0), truth.mean(axis=0), atol=0.3)
    assert np.sqrt(np.mean((felt - truth) ** 2, axis=0)).max() < 1.5
    # the measured centre of mass starts at the planned one (the robot is placed in the plan's first pose) and
    # travels the distance the walk measured
    com, measured = log["/com"][0][-1].point, log["/com_measured"][0][-1].point
    assert np.allclose((com.x, com.y, com.z), (measured.x, measured.y, measured.z), atol=2e-3)
    travelled = float(out.split("travelled ")[1].split(" m")[0])
    assert log["/com_measured"][-1][-1].point.x - measured.x == pytest.approx(travelled, abs=0.02)
    # the measured ZMP (the floor contacts' centre of pressure) averages to the measured CoM's ground point: the
    # CoM's horizontal acceleration, which sets them apart (p = c - z/g c''), averages ~0 from rest to rest
    zmp = np.array([(m.point.x, m.point.y) for *_, m in log["/zmp_measured"]])
    com_xy = np.array([(m.point.x, m.point.y) for *_, m in log["/com_measured"]])
    assert len(zmp) == walk_frames
    assert np.allclose(zmp.mean(axis=0), com_xy.mean(axis=0), atol=0.01)


def test_a_robot_without_an_imu_has_no_imu_channel(tmp_path, capsys):
    assert not config("xl430-biped").imu.present
    mcap = tmp_path / "no-imu.mcap"
    code, _, err = run_cli(capsys, "walk", "--sim", "--robot", "xl430-biped", "--distance", "0.05", "--mcap", mcap)
    assert code == 0, err
    log = read_back(mcap)
    assert "/imu" not in log
    assert {"/joint_goals", "/joint_states", "/com_measured", "/pose_measured"} <= set(log)
