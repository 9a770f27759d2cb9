"""Walks are planned with a margin under the servos' limits, and generate, check and walk judge a walk alike.

- Every planner (the balanced walk's speed fit, the planar walk, the terrain walk) keeps its goals within
  PLANNED_SHARE of each joint's max_velocity_dps and max_acceleration_dps2, measured as the servos see
  them (gaitbot.robot.joint_motion): so a real-time send, whose frames come a little early or late, stays
  inside the limits that ``gaitbot check`` judges recordings by.
- One definition of velocity and acceleration and one preflight: ``generate`` (on what it wrote),
  ``check`` (on the file) and ``walk`` (``--trajectory`` the file, or the same options) give the same
  verdict and the same first error; a dry-run recording of a walk has the same peaks as its goals file.
- A refusal comes before any note (``walk --feedback`` on a robot without an IMU: one line).
"""

from __future__ import annotations

import json

import pytest

from gaitbot.gait.trajectory import Trajectory
from gaitbot.robot.config import shipped_config_names
from gaitbot.robot.motion_margin import PLANNED_SHARE
from gaitbot.robot.planar_fit import trajectory_share
from helpers import config, run_cli


def shares(robot: str, path) -> tuple[float, float]:
    v, a, _ = trajectory_share(config(robot), Trajectory.load(path))
    return v, a


@pytest.mark.parametrize("robot", sorted(shipped_config_names()))
def test_every_shipped_robots_walk_is_planned_within_the_margin(robot, capsys, tmp_path):
    """The default walk, its goals (the sag feedforward on balanced robots) and, for a planar robot, a walk
    asked at half its cycle: every joint within PLANNED_SHARE of its velocity and acceleration limits (planned at the
    full limits, the op3's goals reached 92% and a planar walk at a short cycle beyond 100%)."""
    robot_config = config(robot)
    walks = [("walk", ()), ("goals", ("--goals",))]
    if not robot_config.is_3d:  # the planar walker stretches the cycle (the balanced one says it cannot fit)
        walks.append(("fast", ("--cycle", str(robot_config.gait.cycle_s / 2))))
    for name, extra in walks:
        out = tmp_path / f"{name}.csv"
        code, _, err = run_cli(capsys, "generate", "--robot", robot, "--distance", "1", *extra, "-o", out)
        v, a = shares(robot, out)
        assert v <= PLANNED_SHARE and a <= PLANNED_SHARE, (name, v, a, err)
        assert code == 0, err


def test_a_planar_walk_too_fast_for_its_servos_gets_a_longer_cycle(capsys, tmp_path):
    out = tmp_path / "fast.csv"
    code, _, err = run_cli(capsys, "generate", "--robot", "xl430-biped", "--distance", "1", "--cycle", "1.5", "-o", out)
    assert code == 0
    assert "needed a longer cycle" in err and "instead of 1.5 s" in err
    assert max(shares("xl430-biped", out)) <= PLANNED_SHARE


def _first_error(capsys, *argv) -> tuple[int, str]:
    code, _, err = run_cli(capsys, *argv)
    lines = [line for line in err.splitlines() if "error:" in line]
    return code, lines[-1].split("error: ", 1)[1] if lines else ""


@pytest.mark.parametrize("robot, options", [
    ("op3", ("--distance", "1", "--cycle", "0.5")),  # too fast even for the gentlest balanced walk
    ("op3", ("--distance", "1", "--max-step", "0.11")),
    ("op3", ("--distance", "0.5",)),
    ("xl430-biped", ("--distance", "0.5")),
    ("bioloid", ("--distance", "0.5", "--cycle", "0.6")),
])
def test_generate_check_and_walk_give_one_verdict(robot, options, capsys, tmp_path):
    """The file generate writes: generate's verdict, check's and walk --trajectory's agree, with the same first
    error; the goals file (what walk sends): check's verdict and first error are walk's."""
    for goals in ((), ("--goals",)):
        out = tmp_path / f"walk{len(goals)}.csv"
        code_gen, err_gen = _first_error(capsys, "generate", "--robot", robot, *options, *goals, "-o", out)
        assert out.is_file()  # written whatever the verdict
        code_check, stdout, _ = run_cli(capsys, "check", "--robot", robot, "--json", out)
        report = json.loads(stdout)
        if not goals:
            code_walk, err_walk = _first_error(capsys, "walk", "--robot", robot, "--dry-run", "--trajectory", out)
            assert code_gen == code_check == code_walk, (code_gen, code_check, code_walk, err_gen)
            if code_check:
                assert err_gen.endswith(report["first_error"]) and err_walk.endswith(report["first_error"])
        else:
            code_walk, err_walk = _first_error(capsys, "walk", "--robot", robot, "--dry-run", *options)
            joints_ok = all(v["kind"] not in ("velocity", "acceleration", "position") for v in report["violations"])
            assert (code_walk == 0) == (code_gen == 0)
            if code_walk:
                assert err_gen.endswith(err_walk.split(": ", 1)[1])
                assert not joints_ok or report["first_error"] is None or err_walk.endswith(report["first_error"])
        assert code_gen in (0, 1) and code_check in (0, 1)


def test_generate_exits_1_in_one_line_when_walk_would_refuse(capsys, tmp_path):
    out = tmp_path / "fast.csv"
    code, _, err = run_cli(capsys, "generate", "--robot", "op3", "--distance", "1", "--cycle", "0.5", "-o", out)
    assert code == 1 and out.is_file()
    errors = [line for line in err.splitlines() if "error" in line]
    assert errors == [f"gaitbot generate: error: wrote {out}, but gaitbot walk would refuse it: knee_pitch_left: "
                      f"velocity 268.9 deg/s at t=1.717 s exceeds max_velocity_dps 240.0"]


@pytest.mark.parametrize("robot", ["op3", "bioloid", "xl430-biped"])
def test_a_dry_run_recording_has_the_peaks_of_its_goals_file(robot, capsys, tmp_path):
    """One definition: the goal ticks at the frame times, whether read from a trajectory file or decoded from
    a recording (the simulated clock sends at the frame times)."""
    goals, record = tmp_path / "goals.csv", tmp_path / "run.jsonl"
    assert run_cli(capsys, "generate", "--robot", robot, "--distance", "0.5", "--goals", "-o", goals)[0] == 0
    assert run_cli(capsys, "walk", "--robot", robot, "--distance", "0.5", "--dry-run", "--record", record)[0] == 0
    peaks = []
    for path in (goals, record):
        # --boom: the goals overshoot the planned angles by the sag, so only their joint limits are judged
        code, stdout, _ = run_cli(capsys, "check", "--robot", robot, "--json", "--boom", path)
        assert code == 0
        doc = json.loads(stdout)
        joints = doc["joints"] if "joints" in doc else doc["joint_check"]["joints"]
        peaks.append({j["joint"]: j["worst_velocity_dps"] for j in joints})
    assert peaks[0] == pytest.approx(peaks[1], rel=1e-3)  # the recording's send times are kept to the us


@pytest.mark.parametrize("feedback", ["full", "gyro"])
def test_feedback_on_a_robot_without_an_imu_is_refused_before_any_note(feedback, capsys):
    code, out, err = run_cli(capsys, "walk", "--robot", "xl430-biped", "--dry-run", "--feedback", feedback)
    assert code == 2 and out == ""
    assert err.splitlines() == [f"gaitbot walk: error: --feedback {feedback}: robot xl430-biped has no IMU "
                                f"([imu] source = \"none\")"]


def test_without_an_imu_the_open_loop_note_comes_once_the_walk_is_accepted(capsys):
    code, _, err = run_cli(capsys, "walk", "--robot", "xl430-biped", "--dry-run", "--distance", "0.1")
    assert code == 0 and "no IMU ([imu]): walking open loop" in err
