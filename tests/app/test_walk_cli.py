"""gaitbot walk --dry-run end to end, checked with a packet decoder written here from the protocol
documents (not gaitbot's): ROBOTIS protocol 1.0 / Feetech checksum = ~(sum of id..params) & 0xFF;
protocol 2.0 CRC-16 with polynomial 0x8005, initial value 0, no reflection (ROBOTIS e-Manual).
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest

from gaitbot.app.cli import main
from gaitbot.gait.trajectory import Trajectory
from gaitbot.robot.config import load_robot_config
from helpers import CONFIG_DIR, parse_packet

CONFIGS = sorted(CONFIG_DIR.glob("*.toml"))
SYNC_WRITE = 0x83


def goal_frames(recording: Path, protocol: float, goal_len: int, big_endian: bool):
    lines = recording.read_text().splitlines()
    header = json.loads(lines[0])
    assert header["format"] == "gaitbot-bus-log"
    times, frames = [], []
    for line in lines[1:]:
        packet = json.loads(line)
        if packet["dir"] != "tx":
            continue
        _, instruction, params = parse_packet(bytes.fromhex(packet["hex"]), protocol)
        if instruction != SYNC_WRITE:
            continue
        head = 4 if protocol == 2.0 else 2
        data_len = params[2] | params[3] << 8 if protocol == 2.0 else params[1]
        assert data_len == goal_len
        frame = {}
        for k in range(head, len(params), 1 + data_len):
            value = int.from_bytes(params[k + 1:k + 1 + data_len], "big" if big_endian else "little")
            frame[params[k]] = value
        times.append(packet["t"])
        frames.append(frame)
    return header, np.array(times), frames


@pytest.mark.parametrize("config_path", [c if c.stem == "xl430-biped" else pytest.param(c, marks=pytest.mark.slow) for c in CONFIGS], ids=lambda p: p.stem)
def test_dry_run_recording_matches_generate(config_path, tmp_path, capsys):
    config = load_robot_config(config_path)
    record, csv = tmp_path / "run.jsonl", tmp_path / "walk.csv"
    assert main(["walk", "--robot", str(config_path), "--distance", "1.0", "--dry-run", "--record", str(record)]) == 0
    # the goals a walk sends: the planned angles, plus the servo-sag feedforward on balanced robots
    assert main(["generate", "--robot", str(config_path), "--distance", "1.0", "--goals", "-o", str(csv)]) == 0
    model = config.joints[0].model
    protocol = config.bus.protocol if config.bus.backend == "dynamixel" else 1.0
    header, times, frames = goal_frames(record, protocol, model.len_goal_position, model.byte_order == "big")
    ids = [j.id for j in config.joints]
    assert all(sorted(f) == sorted(ids) for f in frames), "every sync write addresses exactly the configured ids"
    ticks = np.array([[f[i] for i in ids] for f in frames], dtype=float)
    # ticks inside each joint's limits (hand calibration: zero + direction * angle * ticks/deg)
    for col, joint in enumerate(config.joints):
        per_deg = joint.model.ticks_per_rad * math.pi / 180
        bounds = sorted(joint.zero_tick + joint.direction * np.array([joint.min_deg, joint.max_deg]) * per_deg)
        assert bounds[0] - 0.5 <= ticks[:, col].min() and ticks[:, col].max() <= bounds[1] + 0.5, joint.name
    periods = np.diff(times)
    assert abs(periods.mean() - 1 / 60) < 0.01 / 60
    trajectory = Trajectory.load(csv)
    # Before the walk the session ramps every servo from where it is to the walk's first pose. The mock's
    # servos start where the robot stands (gaitbot/bus/factory.py: walking joints at 0 deg, held joints at
    # their hold_deg, in the config's ticks), and a pose at most 1 tick away is not worth a ramp
    # (gaitbot/stream/ramps.py): so a ramp only where the walk's first pose is not the stand pose.
    first_deg = {j.name: j.hold_deg for j in config.held_joints}
    first_deg.update({j.name: trajectory.angles_deg[0, c] for c, j in enumerate(config.walking_joints)})
    first_ticks = np.array([j.zero_tick + j.direction * first_deg[j.name] * j.model.ticks_per_rad * math.pi / 180
                            for j in config.joints])
    stand_deg = {j.name: (j.hold_deg if j in config.held_joints else 0.0) for j in config.joints}
    centre_ticks = np.rint([j.zero_tick + j.direction * stand_deg[j.name] * j.model.ticks_per_rad * math.pi / 180
                            for j in config.joints])  # where the mock's servos start
    ramp_frames = len(frames) - len(trajectory)
    assert (ramp_frames > 0) == (np.abs(np.rint(first_ticks) - centre_ticks).max() > 1), ramp_frames
    if ramp_frames:
        ramp = ticks[:ramp_frames + 1]  # the ramp, and the walk's first frame
        assert np.abs(ramp[-2] - first_ticks).max() <= 0.5 + 1e-9, "the ramp ends at the walk's first pose"
        towards = np.sign(np.rint(first_ticks) - centre_ticks)  # 0: a servo already there stays
        moves = np.diff(np.vstack([centre_ticks, ramp]), axis=0)
        assert (moves * towards >= 0).all() and (moves[:, towards == 0] == 0).all(), \
            "the ramp moves every servo from the stand pose straight to the first pose"
    # after it, decoded angles equal generate's for the same plan to within one tick
    for col, joint in enumerate(config.walking_joints):
        per_deg = joint.model.ticks_per_rad * math.pi / 180
        decoded_deg = (ticks[ramp_frames:, col] - joint.zero_tick) / (joint.direction * per_deg)
        assert np.abs(decoded_deg - trajectory.angles_deg[:, col]).max() <= 1.0 / per_deg + 1e-9, joint.name


@pytest.mark.parametrize("edit, field", [
    ('backend = "dynamixel"', "bus.backend"),
    ("id = 2\n", "joints.knee_pitch_left"),
    ("min_deg = -5.0", "min_deg"),
])
def test_walk_with_bad_config_exits_2_and_sends_nothing(edit, field, tmp_path, capsys):
    source = (CONFIG_DIR / "xl430-biped.toml").read_text()
    replacement = {'backend = "dynamixel"': 'backend = "herkulex"', "id = 2\n": "id = 1\n",
                   "min_deg = -5.0": "min_deg = 200.0"}[edit]
    assert edit in source
    bad = tmp_path / "bad.toml"
    bad.write_text(source.replace(edit, replacement, 1))
    record = tmp_path / "run.jsonl"
    code = main(["walk", "--robot", str(bad), "--distance", "0.3", "--dry-run", "--record", str(record)])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2
    assert len(err) == 1 and str(bad) in err[0] and field.split(".")[0] in err[0]
    assert not record.exists(), "nothing may be sent (or recorded) for a bad config"


def test_walk_refuses_a_plan_that_breaks_a_limit(tmp_path, capsys):
    source = (CONFIG_DIR / "xl430-biped.toml").read_text()
    tight = tmp_path / "tight.toml"
    # knees may bend at most 20 degrees: the walk's knee flexion (crouch 25 degrees) breaks it
    tight.write_text(source.replace("max_deg = 110.0", "max_deg = 20.0"))
    record = tmp_path / "run.jsonl"
    code = main(["walk", "--robot", str(tight), "--distance", "0.3", "--dry-run", "--record", str(record)])
    err = capsys.readouterr().err
    assert code == 1 and "knee_pitch" in err and "20" in err and "refused" in err  # the check failed: 1
    assert not record.exists()


def test_default_demo_walk_runs(tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    assert main(["walk", "--dry-run", "--record", "run.jsonl"]) == 0
    assert "Walk completed" in capsys.readouterr().out
    packets = [json.loads(line) for line in (tmp_path / "run.jsonl").read_text().splitlines()[1:]]
    assert sum(p["dir"] == "tx" for p in packets) > 100
