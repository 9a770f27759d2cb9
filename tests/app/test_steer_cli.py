"""--velocity/--duration and --commands on plan, generate and walk: the walk they plan, and one line (exit 2,
nothing written or sent) for every bad combination."""

import json

import numpy as np
import pytest

from gaitbot.gait.trajectory import Trajectory
from helpers import run_cli


def test_plan_json_gives_each_footstep_and_the_end_poses(capsys):
    code, out, _ = run_cli(capsys, "plan", "--robot", "op3", "--velocity", "0,0.03,0", "--duration", "4", "--json")
    plan = json.loads(out)
    assert code == 0 and plan["steps"][0]["leg"] == "left"  # a sidestep left leads with the left foot
    assert plan["commanded"]["y_m"] == pytest.approx(0.12, abs=1e-6)
    assert abs(plan["planned"]["y_m"] - 0.12) <= 0.25 * 0.12
    assert abs(plan["planned"]["x_m"]) < 1e-9 and abs(plan["planned"]["heading_deg"]) < 1e-9


def test_generate_writes_hip_yaw_and_torso_yaw_and_the_file_checks(capsys, tmp_path):
    commands = tmp_path / "turn.jsonl"
    commands.write_text('{"t": 0, "vx": 0.0, "vy": 0.0, "wz": 10}\n{"t": 4.5, "stop": true}\n')
    out = tmp_path / "turn.csv"
    code, _, _ = run_cli(capsys, "generate", "--robot", "op3", "--commands", commands, "-o", out)
    assert code == 0
    t = Trajectory.load(out)
    assert t.torso_rpy_rad is not None and abs(np.degrees(t.torso_rpy_rad[-1, 2]) - 45.0) <= 0.25 * 45.0
    assert np.degrees(np.abs(t.angles_of(["hip_yaw_left"]))).max() > 3.0
    code, text, _ = run_cli(capsys, "check", out, "--robot", "op3")
    assert code == 0 and "the soles at least" in text


@pytest.mark.parametrize("argv, words", [
    (["--velocity", "0.05,0,0"], ("--duration",)),
    (["--velocity", "0.05,0,10", "--distance", "1"], ("--distance", "straight")),
    (["--velocity", "0.05,0", "--duration", "3"], ("--velocity", "VX,VY,WZ")),
    (["--velocity", "0.05,0,0", "--duration", "-1"], ("--duration",)),
    (["--velocity", "0.05,0,0", "--duration", "1e9"], ("--duration", "3600")),
])
def test_bad_steering_options_are_one_line(capsys, tmp_path, argv, words):
    out = tmp_path / "w.csv"
    code, _, err = run_cli(capsys, "generate", "--robot", "op3", *argv, "-o", out)
    assert code == 2 and err.count("\n") == 1 and not out.exists()
    for word in words:
        assert word in err


def test_a_commands_file_that_never_stops_is_refused(capsys, tmp_path):
    commands = tmp_path / "go.jsonl"
    commands.write_text('{"t": 0, "vx": 0.05}\n')
    code, _, err = run_cli(capsys, "plan", "--robot", "op3", "--commands", commands)
    assert code == 2 and "stop" in err and str(commands) in err


def test_a_robot_without_steering_says_so(capsys):
    code, _, err = run_cli(capsys, "plan", "--robot", "xl430-biped", "--velocity", "0.05,0,10", "--duration", "3")
    assert code == 2 and "walks straight" in err
