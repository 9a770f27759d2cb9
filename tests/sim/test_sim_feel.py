"""The IMU in the simulated walk: read byte-exact on the bus, a fall noticed within 100 ms and handled (exit 1,
when and which way, the recording checks), a broken IMU noticed and the walk finished open loop."""

from __future__ import annotations

import json
import math
import struct

import pytest

from gaitbot.sim import SimUnavailable, import_mujoco  # noqa: E402  (picks the offscreen GL first)

try:
    import_mujoco()
except SimUnavailable:
    pytest.skip("the sim extra (MuJoCo) is not installed", allow_module_level=True)

from gaitbot.robot.config import load_robot_config, resolve_config  # noqa: E402
from gaitbot.sim.metrics import WalkMeter  # noqa: E402
from gaitbot.sim.physics import SimRobot  # noqa: E402
from gaitbot.sim.walk import SimWalk  # noqa: E402
from helpers import crc16, parse_packet, read_lines, run_cli  # noqa: E402

OPENCR_ID = 200


def imu_exchanges(path):
    """(instruction bytes, status bytes) of every exchange with id 200, parsed here from the raw packets."""
    rows = read_lines(path)[1:]
    out = []
    for tx, rx in zip(rows, rows[1:]):
        if tx["dir"] == "tx" and rx["dir"] == "rx" and bytes.fromhex(tx["hex"])[4] == OPENCR_ID:
            out.append((bytes.fromhex(tx["hex"]), bytes.fromhex(rx["hex"])))
    return out


def test_the_imu_is_read_every_frame_byte_exact_and_the_recording_checks(tmp_path, capsys):
    record = tmp_path / "walk.jsonl"
    code, out, err = run_cli(capsys, "walk", "--sim", "--json", "--robot", "op3", "--distance", "0.3", "--record", record)
    assert code == 0, err
    exchanges = imu_exchanges(record)
    report = json.loads(out)
    assert len(exchanges) >= 0.9 * report["simulated_s"] * 60 - 120  # every walk frame (not the ramps)
    # READ (0x02) of 18 bytes from address 32, Protocol 2.0 with its CRC: the packet built by hand
    body = bytes([0xFF, 0xFF, 0xFD, 0x00, OPENCR_ID, 0x07, 0x00, 0x02, 32, 0, 18, 0])
    expected = body + crc16(body).to_bytes(2, "little")
    standing = []
    for tx, rx in exchanges:
        assert tx == expected
        packet_id, instruction, params = parse_packet(rx, 2.0)
        assert (packet_id, instruction, params[0], len(params)) == (OPENCR_ID, 0x55, 0, 19)
        gyro = struct.unpack("<3h", params[1:7])
        acc = struct.unpack("<3h", params[7:13])
        standing.append((gyro, acc))
    # walking upright: the board's z accelerometer near +1 g (16384 LSB), gyro within +-100 deg/s (1640 LSB)
    accs_z = [a[2] for _, a in standing]
    assert 0.9 * 16384 < sum(accs_z) / len(accs_z) < 1.1 * 16384
    assert all(abs(g) < 1640 for gyro, _ in standing for g in gyro)
    assert run_cli(capsys, "check", record)[0] == 0


def test_a_fall_that_twists_as_it_tips_is_noticed_within_100_ms(capsys):
    # Push 30 of tools/push_survival.py, 2 N s forward and to the left late in a swing, with feedback none (full
    # survives it): the robot turns at up to 190 deg/s about its own vertical while it tips over to the right.
    # (On the push walk before its steps landed where planned, with full, a tilt integrated from the roll and
    # pitch rates alone lagged a fall like it by 12 deg and noticed it 183 ms late.)
    code, out, err = run_cli(capsys, "walk", "--sim", "--json", "--robot", "op3", "--distance", "1", "--cycle", "0.8",
                             "--max-step", "0.06", "--feedback", "none", "--imu-seed", "30", "--push", "1.988@51.8",
                             "--push-phase", "0.667529")
    assert code == 1, err
    report = json.loads(out)
    assert report["max_abs_yaw_deg"] > 45  # it twists as it falls
    fall = report["fall_noticed"]
    assert fall["direction"] == "sideways (right)"
    assert 0 <= fall["t_s"] - fall["true_tilt_crossed_s"] <= 0.1


def test_a_slow_fall_leaning_both_ways_is_noticed_within_100_ms(capsys):
    # Push 67 of tools/push_survival.py with feedback none: the torso leans 24 deg to the side and 31 forward and
    # hovers near the threshold for 100 ms before it goes over (docs/feedback.md, "A fall"): the slowest crossing
    # of the 100 pushes, timed against the true tilt.
    code, out, err = run_cli(capsys, "walk", "--sim", "--json", "--robot", "op3", "--distance", "1", "--cycle", "0.8",
                             "--max-step", "0.06", "--feedback", "none", "--imu-seed", "67", "--push", "1.398@98.0",
                             "--push-phase", "0.330787")
    assert code == 1, err
    fall = json.loads(out)["fall_noticed"]
    assert fall["direction"] == "forwards"
    assert 0 <= fall["t_s"] - fall["true_tilt_crossed_s"] <= 0.1


def test_a_fall_is_noticed_within_100_ms_and_the_walk_stops_with_exit_1(tmp_path, capsys):
    record = tmp_path / "fall.jsonl"
    code, out, err = run_cli(capsys, "walk", "--sim", "--json", "--robot", "op3", "--distance", "0.6", "--push", "3",
                             "--feedback", "gyro", "--record", record)
    assert code == 1, err
    report = json.loads(out)
    fall = report["fall_noticed"]
    assert fall["direction"] == "sideways (left)"  # pushed to the left
    assert 0 <= fall["t_s"] - fall["true_tilt_crossed_s"] <= 0.1
    assert report["outcome"] == "fell"
    assert run_cli(capsys, "check", record)[0] == 0  # the goals up to the fall and the fall stop obey every limit
    code, out, err = run_cli(capsys, "walk", "--sim", "--robot", "op3", "--distance", "0.6", "--push", "3")
    assert code == 1
    assert "The robot fell sideways (left) at" in out and "noticed by the IMU" in out


@pytest.mark.parametrize("fault, words", [("frozen", "frozen"), ("noisy", "noisy"), ("absent", "absent")])
def test_a_broken_imu_is_said_once_and_the_walk_goes_on_open_loop(fault, words, capsys):
    code, out, err = run_cli(capsys, "walk", "--sim", "--robot", "op3", "--distance", "0.4", "--imu-fault", fault)
    assert code == 0, err
    warnings = [line for line in err.splitlines() if line.startswith("warning: IMU")]
    assert len(warnings) == 1 and words in warnings[0] and "walking open loop" in warnings[0]


def test_a_robot_without_an_imu_says_so_once_and_refuses_feedback(capsys):
    code, out, err = run_cli(capsys, "walk", "--dry-run", "--robot", "xl430-biped", "--distance", "0.2")
    assert code == 0
    assert err.count("has no IMU") == 1
    code, out, err = run_cli(capsys, "walk", "--dry-run", "--robot", "xl430-biped", "--distance", "0.2",
                             "--feedback", "gyro")
    assert code == 2 and "--feedback gyro: robot xl430-biped has no IMU" in err


def test_the_yardstick_is_the_true_tilt_not_the_hypot_of_roll_and_pitch():
    # A torso rolled 30 deg and pitched 30 deg leans acos(cos 30 cos 30) = 41.4 deg from upright (its z axis
    # against the world's up, the measure of the IMU estimate's tilt), not hypot(30, 30) = 42.4: the yardstick
    # a fall's notice is timed against must measure the same angle, or a fall leaning both ways looks noticed late.
    mujoco = import_mujoco()
    robot = SimRobot(load_robot_config(resolve_config("op3")), 60.0, support="free")
    roll = pitch = math.radians(30)
    cr, sr, cp, sp = math.cos(roll / 2), math.sin(roll / 2), math.cos(pitch / 2), math.sin(pitch / 2)
    robot.data.qpos[3:7] = (cp * cr, cp * sr, sp * cr, -sp * sr)  # R = Ry(pitch) Rx(roll): the quaternions' product
    mujoco.mj_forward(robot.model, robot.data)
    rpy = robot.torso_rpy_rad()
    assert math.degrees(rpy[0]) == pytest.approx(30, abs=0.01) and math.degrees(rpy[1]) == pytest.approx(30, abs=0.01)
    assert WalkMeter._tilt_deg(robot) == pytest.approx(math.degrees(math.acos(math.cos(roll) * math.cos(pitch))), abs=0.01)

    class Meter:  # 42.4 deg by the hypot at 1 s, 41.4 by the tilt: only the tilt's crossing of 42 counts (at 2 s)
        times_s = [1.0, 2.0]
        rpy_deg = [(30.0, 30.0, 0.0), (31.0, 31.0, 0.0)]
        tilt_deg = [41.4, 42.9]

    walk = SimWalk.__new__(SimWalk)
    walk.meter = Meter()
    assert walk.tilt_crossed_s(42.0) == 2.0


def test_a_floor_that_gives_way_is_the_feet_load_lost_noticed_within_100_ms(monkeypatch, tmp_path, capsys):
    """When the push would start, the floor stops holding anything up (its contacts switched off): the robot
    falls freely and level, which no tilt threshold sees. The accelerometer reads about 0 g, and the walk
    notices the feet's load lost ([fall] load_lost_g 0.2 held for 50 ms) within 100 ms of the floor going:
    it says it fell down, exits 1, and its recording passes gaitbot check."""
    from gaitbot.sim import walk as sim_walk

    gone_s = []

    def floor_gives_way(self, robot) -> None:
        if robot.time_s + 1e-9 >= self.push.start_s and not gone_s:
            floor = robot.floor_geom
            robot.model.geom_contype[floor] = robot.model.geom_conaffinity[floor] = 0
            gone_s.append(robot.time_s)

    monkeypatch.setattr(sim_walk.Pusher, "__call__", floor_gives_way)
    record = tmp_path / "drop.jsonl"
    code, out, err = run_cli(capsys, "walk", "--sim", "--json", "--robot", "op3", "--distance", "0.6",
                             "--push", "0.1", "--record", record)
    assert code == 1, err
    fall = json.loads(out)["fall_noticed"]
    assert fall["direction"] == "down" and fall["reason"].startswith("the feet's load lost")
    assert 0 < fall["t_s"] - gone_s[0] <= 0.1
    assert run_cli(capsys, "check", record)[0] == 0
