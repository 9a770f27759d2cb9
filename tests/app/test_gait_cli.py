"""The gait side of the command line: gaitbot plan / generate, and one-line errors with status 2.

The default robot is xl430-biped (leg 0.11 + 0.11 m, max_step_m 0.100, 60 Hz).
"""

from __future__ import annotations

import json

import numpy as np
import pytest

from gaitbot.app.cli import main
from gaitbot.gait import Trajectory
from gaitbot.gait.step_length import boulic_step_length
from gaitbot.robot.config import load_robot_config, resolve_config
from gaitbot.robot.walk_settings import leg_geometry

HEADER = ("t_s,hip_pitch_left_deg,knee_pitch_left_deg,ankle_pitch_left_deg,"
          "hip_pitch_right_deg,knee_pitch_right_deg,ankle_pitch_right_deg,root_x_m,root_y_m,root_z_m")
XL430 = load_robot_config(resolve_config("xl430-biped"))
XL430_LEG = leg_geometry(XL430)


def test_plan_json(capsys):
    assert main(["plan", "--steps", "0.05,0.08", "--json"]) == 0
    out = capsys.readouterr().out
    plan = json.loads(out)
    steps = plan["steps"]
    assert [s["length_m"] for s in steps] == pytest.approx([0.05, 0.08], abs=1e-12)
    assert [s["foothold_m"] for s in steps] == pytest.approx([0.05, 0.13], abs=1e-12)
    rvs = [s["rv"] for s in steps]
    assert 0.0 < rvs[0] < rvs[1] < 0.5
    # each RV realises its step length with the robot's leg and cycle (seed 000 section 2.3)
    cycle = plan["cycle_s"]
    assert cycle == pytest.approx(XL430.gait.cycle_s, abs=1e-12)  # a whole number of 60 Hz frames per step
    for s in steps:
        assert float(boulic_step_length(XL430_LEG, s["rv"], cycle)[0]) == pytest.approx(s["length_m"], abs=1e-9)
    assert plan["total_distance_m"] == pytest.approx(0.13, abs=1e-12)


def test_plan_table(capsys):
    assert main(["plan", "--distance", "0.25"]) == 0
    out = capsys.readouterr().out
    # fewest equal steps of at most 0.100 m for 0.25 m: three of 0.0833 m
    assert "3 steps" in out and "0.2500 m" in out
    assert out.count("0.0833") >= 3


def test_generate_csv(tmp_path, capsys):
    out = tmp_path / "x.csv"
    assert main(["generate", "--steps", "0.05,0.08", "-o", str(out)]) == 0
    assert "wrote" in capsys.readouterr().out
    lines = out.read_text().splitlines()
    assert lines[0].startswith("# gaitbot trajectory 2 origin: {") and lines[1] == HEADER
    walk = Trajectory.load(out)
    np.testing.assert_allclose(walk.angles_rad[[0, -1]], 0.0, atol=1e-9)
    # the root travels the 0.13 m of the steps (it starts over the ankles, heel_back ahead of the heels at 0)
    assert walk.root_m[-1, 0] - walk.root_m[0, 0] == pytest.approx(0.13, abs=1e-8)
    np.testing.assert_allclose(np.diff(walk.t_s), 1 / 60, atol=1e-8)


def test_generate_npz(tmp_path, capsys):
    out = tmp_path / "x.npz"
    assert main(["generate", "--distance", "0.2", "-o", str(out)]) == 0
    walk = Trajectory.load(out)
    assert [h.x_m for h in walk.heel_strikes][:2] == pytest.approx([0.1, 0.2])


@pytest.mark.parametrize("args, needle", [
    (["--steps", "0.03,-1"], "-1"),
    (["--steps", "0.03,0.5"], "0.5"),       # past xl430-biped's max_step_m 0.100
    (["--steps", "nan"], "nan"),
    (["--steps", "0.05,inf"], "inf"),
    (["--steps", "0.05,abc"], "abc"),
    (["--steps", ""], "empty"),
    (["--distance", "0"], "distance"),
    (["--distance", "-1"], "-1"),
])
@pytest.mark.parametrize("command", ["plan", "generate"])
def test_bad_input_one_line_status_2(tmp_path, capsys, command, args, needle):
    argv = [command, *args] + (["-o", str(tmp_path / "x.csv")] if command == "generate" else [])
    assert main(argv) == 2
    captured = capsys.readouterr()
    lines = captured.err.strip().splitlines()
    assert len(lines) == 1, captured.err
    assert needle in lines[0], lines[0]
    assert "Traceback" not in captured.err
    if command == "generate":
        assert not (tmp_path / "x.csv").exists()


def test_distance_zero_names_the_distance(capsys):
    assert main(["plan", "--distance", "0"]) == 2
    err = capsys.readouterr().err
    assert "--distance" in err and "0" in err
