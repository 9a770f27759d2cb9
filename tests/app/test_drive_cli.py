"""``gaitbot drive`` as a user runs it: commands files (dry run and simulation), a pty keyboard, a UDP sender
and its watchdog, Ctrl-C mid-step, and the recordings ``gaitbot check`` reads."""

from __future__ import annotations

import json
import math
import os
import pty
import signal
import socket
import subprocess
import sys
import time
from pathlib import Path

import pytest

from helpers import REPO_ROOT, gaitbot, slow_except

from gaitbot.app.steer_walk import commanded_pose
from gaitbot.gait.steer.command import read_commands
from gaitbot.gait.steer.schedule import CommandSchedule


def commands_file(tmp_path: Path, name: str, lines: list[dict]) -> Path:
    path = tmp_path / f"{name}.jsonl"
    path.write_text("".join(json.dumps(line) + "\n" for line in lines))
    return path


def check_ok(record: Path) -> None:
    result = gaitbot("check", str(record))
    assert result.returncode == 0, result.stdout + result.stderr


CASES = {"turn": {"vx": 0.0, "vy": 0.0, "wz": 10.0}, "sidestep": {"vx": 0.0, "vy": -0.02, "wz": 0.0},
         "backwards": {"vx": -0.04, "vy": 0.0, "wz": 0.0}, "arc": {"vx": 0.04, "vy": 0.0, "wz": -8.0}}


@pytest.mark.parametrize("mode", slow_except(["--dry-run", "--sim"], "--dry-run"))
@pytest.mark.parametrize("case", slow_except(CASES))
def test_a_commands_file_drive_ends_where_the_commands_say(tmp_path, mode, case):
    """The report's pose (planned on the mock bus, measured in the free-floating simulation) against the
    commands integrated on their own, within 25% of the commanded displacement and turn; no fall; the
    recording passes gaitbot check."""
    if mode == "--sim":
        pytest.importorskip("mujoco")
    path = commands_file(tmp_path, case, [{"t": 0.0, **CASES[case]}, {"t": 8.0, "stop": True}])
    record = tmp_path / "drive.jsonl"
    result = gaitbot("drive", "--robot", "op3", mode, "--input", f"commands:{path}", "--json", "--record", str(record))
    assert result.returncode == 0, result.stderr
    report = json.loads(result.stdout)
    assert report["fell"] is False and report["exit_status"] == 0
    cx, cy, ch = commanded_pose(CommandSchedule.of(read_commands(path), str(path)))
    pose = report["pose"]
    size = math.hypot(cx, cy)
    if size > 0.01:
        assert math.hypot(pose["x_m"] - cx, pose["y_m"] - cy) <= 0.25 * size
    else:
        assert math.hypot(pose["x_m"], pose["y_m"]) <= 0.02
    assert abs(pose["heading_deg"] - ch) <= 0.25 * abs(ch) + 2.0
    check_ok(record)


@pytest.mark.slow
def test_identical_drives_give_byte_identical_recordings_and_commands_record_reads_back(tmp_path):
    path = commands_file(tmp_path, "arc", [{"t": 0.0, "vx": 0.03, "vy": 0.0, "wz": 6.0}, {"t": 4.0, "stop": True}])
    outputs = []
    for k in range(2):
        record, commands = tmp_path / f"r{k}.jsonl", tmp_path / f"c{k}.jsonl"
        result = gaitbot("drive", "--robot", "op3", "--dry-run", "--input", f"commands:{path}", "--record", str(record),
                         "--record-commands", str(commands))
        assert result.returncode == 0, result.stderr
        outputs.append((record.read_bytes(), commands))
    assert outputs[0][0] == outputs[1][0]
    assert read_commands(outputs[0][1]) == read_commands(path)  # the received commands, readable back


def test_an_out_of_limits_command_is_clipped_and_said_once(tmp_path):
    path = commands_file(tmp_path, "fast", [{"t": 0.0, "vx": 1.0}, {"t": 1.0, "vx": 2.0}, {"t": 3.0, "stop": True}])
    result = gaitbot("drive", "--robot", "op3", "--dry-run", "--input", f"commands:{path}", "--json")
    assert result.returncode == 0, result.stderr
    assert result.stderr.count("clipped") == 1
    assert json.loads(result.stdout)["clipped"] is True


def start_drive(*args: str, **popen) -> subprocess.Popen:
    return subprocess.Popen([sys.executable, "-m", "gaitbot.app.cli", "drive", "--robot", "op3", *args],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, cwd=REPO_ROOT, **popen)


def wait_for_first_command(received: Path, timeout_s: float = 40.0) -> None:
    """Until the drive has polled its input once (it records the still command it starts with)."""
    deadline = time.monotonic() + timeout_s
    while time.monotonic() < deadline:
        if received.exists() and received.read_text():
            return
        time.sleep(0.05)


def test_ctrl_c_mid_step_stands_exits_130_and_the_recording_passes_check(tmp_path):
    path = commands_file(tmp_path, "on", [{"t": 0.0, "vx": 0.05, "vy": 0.0, "wz": 5.0}])  # no stop entry
    record = tmp_path / "drive.jsonl"
    process = start_drive("--dry-run", "--input", f"commands:{path}", "--record", str(record), "--json",
                          "--max-time", "3600")
    time.sleep(4.0)  # mid-walk (on the simulated clock, far faster than real time: dozens of steps in)
    process.send_signal(signal.SIGINT)
    out, err = process.communicate(timeout=60)
    assert process.returncode == 130, err
    report = json.loads(out)
    assert report["outcome"] == "interrupted" and report["steps"] >= 1
    check_ok(record)


@pytest.mark.slow
def test_keys_on_a_pty_drive_the_robot(tmp_path):
    """W (forward) written to the pty that is the drive's standard input walks it forward; space stands it."""
    main, secondary = pty.openpty()
    received = tmp_path / "received.jsonl"
    process = start_drive("--dry-run", "--input", "keyboard", "--json", "--max-time", "7", "--record-commands",
                          str(received), stdin=secondary)
    os.close(secondary)
    try:
        wait_for_first_command(received)
        os.write(main, b"w")
        time.sleep(4.0)
        os.write(main, b" ")
        out, err = process.communicate(timeout=60)
    finally:
        os.close(main)
    assert process.returncode == 0, err
    report = json.loads(out)
    assert report["pose"]["x_m"] > 0.02 and abs(report["pose"]["heading_deg"]) < 1.0


def test_a_udp_sender_drives_and_its_silence_stands_the_robot(tmp_path):
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as probe:
        probe.bind(("127.0.0.1", 0))
        port = probe.getsockname()[1]
    received = tmp_path / "received.jsonl"
    process = start_drive("--dry-run", "--input", f"udp:127.0.0.1:{port}", "--json", "--max-time", "8",
                          "--record-commands", str(received))
    sender = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    try:
        wait_for_first_command(received)
        for _ in range(60):  # 3 s at 20 Hz, then silence
            sender.sendto(b'{"vx": 0.05, "vy": 0, "wz": 0}', ("127.0.0.1", port))
            time.sleep(0.05)
        out, err = process.communicate(timeout=60)
    finally:
        sender.close()
    assert process.returncode == 0, err
    assert "no command for 0.5 s: standing" in err
    report = json.loads(out)
    assert report["pose"]["x_m"] > 0.02


@pytest.mark.parametrize("args, words", [
    (["--input", "bogus"], "--input"),
    (["--input", "commands:/nonexistent/c.jsonl"], "/nonexistent/c.jsonl"),
    (["--max-time", "-1", "--input", "commands:config/commands/drive-demo.jsonl"], "--max-time"),
    (["--robot", "xl430-biped", "--input", "commands:config/commands/drive-demo.jsonl"], "[steer]"),
    (["--push", "1", "--input", "commands:config/commands/drive-demo.jsonl"], "--push: only with --sim"),
    (["--robot", "bioloid", "--feedback", "gyro", "--input", "commands:config/commands/drive-demo.jsonl"],
     "has no IMU"),
])
def test_bad_input_is_one_line_and_exit_2(args, words):
    result = gaitbot("drive", "--dry-run", *(["--robot", "op3"] if "--robot" not in args else []), *args)
    assert result.returncode == 2, result.stderr
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1 and words in lines[0] and "Traceback" not in result.stderr


def test_a_fall_in_a_drive_is_noticed_stops_and_exits_1_with_when_and_which_way(tmp_path):
    """A 3 N s push to the left 3 s into a simulated drive (IMU feedback on, as by default): the IMU notices the
    fall within 100 ms of the true tilt crossing the threshold, the drive stops stepping, lowers the CoM and
    exits 1 saying when and which way, in --json too; the recording up to the fall passes gaitbot check."""
    pytest.importorskip("mujoco")
    path = commands_file(tmp_path, "forward", [{"t": 0.0, "vx": 0.04, "vy": 0.0, "wz": 0.0}, {"t": 8.0, "stop": True}])
    record = tmp_path / "fall.jsonl"
    result = gaitbot("drive", "--robot", "op3", "--sim", "--input", f"commands:{path}", "--push", "3", "--push-at",
                     "3", "--json", "--record", str(record))
    assert result.returncode == 1, result.stderr
    report = json.loads(result.stdout)
    assert report["outcome"] == "fell" and report["fell"] is True and report["exit_status"] == 1
    assert report["feedback"] == "full"
    fall = report["fall_noticed"]
    assert fall["direction"] == "sideways (left)" and 3.0 < fall["t_s"] < 4.0
    assert 0 <= fall["t_s"] - fall["true_tilt_crossed_s"] <= 0.1
    check_ok(record)
    result = gaitbot("drive", "--robot", "op3", "--sim", "--input", f"commands:{path}", "--push", "3", "--push-at", "3")
    assert result.returncode == 1
    assert "The robot fell sideways (left) at" in result.stdout and "noticed by the IMU" in result.stdout


@pytest.mark.parametrize("robot, feedback", [("op3", "full"), ("bioloid", "none")])
def test_a_simulated_drive_reports_pose_distance_heading_and_no_fall(tmp_path, robot, feedback):
    """``drive --sim --input commands:FILE --json`` on both robots: the measured final pose, the distance, the
    heading and the fall flag; the IMU feedback as the robot allows (the bioloid has no IMU: said once)."""
    pytest.importorskip("mujoco")
    path = commands_file(tmp_path, "arc", [{"t": 0.0, "vx": 0.03, "vy": 0.0, "wz": 8.0}, {"t": 6.0, "stop": True}])
    result = gaitbot("drive", "--robot", robot, "--sim", "--input", f"commands:{path}", "--json")
    assert result.returncode == 0, result.stderr
    report = json.loads(result.stdout)
    assert report["fell"] is False and report["fall_noticed"] is None and report["feedback"] == feedback
    assert set(report["pose"]) == {"x_m", "y_m", "heading_deg"} and report["distance_m"] > 0.05
    cx, cy, ch = commanded_pose(CommandSchedule.of(read_commands(path), str(path)))
    assert math.hypot(report["pose"]["x_m"] - cx, report["pose"]["y_m"] - cy) <= 0.25 * math.hypot(cx, cy)
    assert abs(report["pose"]["heading_deg"] - ch) <= 0.25 * abs(ch) + 2.0
    assert result.stderr.count("has no IMU") == (1 if feedback == "none" else 0)
