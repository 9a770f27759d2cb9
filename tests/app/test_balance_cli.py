"""The command line picks the walker by robot: --cycle on plan/generate/walk, generate --goals, the
balanced plan's JSON, and what a balanced robot refuses (one line, exit 2)."""

from __future__ import annotations

import json

import numpy as np
import pytest

from gaitbot.gait.trajectory import Trajectory
from helpers import run_cli


def plan_json(capsys, *args) -> dict:
    code, out, _ = run_cli(capsys, "plan", "--json", *args)
    assert code == 0
    return json.loads(out)


@pytest.mark.parametrize("robot, cycle_s", [("xl430-biped", 3.0), ("op3", 1.0)])
def test_cycle_overrides_the_configs_cycle(robot, cycle_s, capsys):
    plan = plan_json(capsys, "--robot", robot, "--distance", "0.3", "--cycle", str(cycle_s))
    assert plan["cycle_s"] == pytest.approx(cycle_s)
    steps = plan["steps"]
    assert steps[1]["end_s"] - steps[0]["end_s"] == pytest.approx(cycle_s / 2)  # two steps a cycle


def test_a_balanced_plan_says_how_it_walks(capsys):
    plan = plan_json(capsys, "--robot", "op3", "--distance", "0.5")
    assert plan["walker"] == "balanced" and plan["sag_feedforward"] is True
    assert plan["total_distance_m"] == pytest.approx(0.5) and all(s["rv"] is None for s in plan["steps"])
    assert [h["y_m"] for h in plan["heel_strikes"][:2]] == pytest.approx([-0.0475, 0.0475])
    assert plan["preview_horizon_s"] == 1.0 and 0.2 < plan["com_height_m"] < 0.3
    assert plan["peak_joint_speed_dps"] < 240.0


@pytest.mark.parametrize("args, short", [((), False), (("--max-step", "0.07", "--cycle", "1.4"), False),
                                         (("--max-step", "0.05", "--cycle", "1.0"), True)])
def test_the_speed_fits_note_says_when_its_steps_will_land_short(args, short, capsys):
    """Only a walk whose swing moves the foot forward until it lands (the fit's progression at 100%) is told its
    steps land short (docs/walk-faster.md measures it); the shipped walk and the slow-cycle 0.1 m/s one keep 90%."""
    code, _, err = run_cli(capsys, "plan", "--robot", "op3", "--distance", "0.5", *args)
    assert code == 0
    notes = [line for line in err.splitlines() if line.startswith("note: ") and "gentler walk" in line]
    assert len(notes) == 1  # even the shipped walk is fitted (docs/balance.md)
    assert ("progression done at 100%" in notes[0]) == short
    assert ("steps land short" in notes[0]) == short


@pytest.mark.parametrize("walk", [("--distance", "1", "--max-step", "0.06"),
                                  ("--velocity", "0.15,0,0", "--duration", "4")])
def test_an_asked_clearance_is_walked_as_asked_or_refused_naming_it(walk, capsys):
    """The 0.15 m/s walk, straight or steered, needs the speed fit's fallbacks, which lower the op3's own 5 mm
    clearance to 3 mm; a clearance given with --clearance is kept (and the note says so), and one the servos
    cannot follow is refused before anything moves with the refusal naming it, not quietly lowered."""
    fast = ("--robot", "op3", "--cycle", "0.8", *walk)
    assert plan_json(capsys, *fast)["clearance_m"] == pytest.approx(0.003)
    code, out, err = run_cli(capsys, "plan", "--json", *fast, "--clearance", "0.005")
    assert code == 0 and json.loads(out)["clearance_m"] == pytest.approx(0.005)
    assert "clearance 5 mm (as --clearance asked: kept, not lowered)" in err
    code, _, err = run_cli(capsys, "walk", "--dry-run", *fast, "--clearance", "0.008")
    errors = [line for line in err.splitlines() if not line.startswith("note: ")]
    assert code == 1 and len(errors) == 1 and "walk refused before anything moved: knee_pitch" in errors[0]
    assert "--clearance 0.008 m is kept as asked" in errors[0]


def test_generate_goals_add_the_sag_feedforward_on_a_balanced_robot_only(capsys, tmp_path):
    for robot, differ in (("op3", True), ("xl430-biped", False)):
        planned, goals = tmp_path / f"{robot}.csv", tmp_path / f"{robot}-goals.csv"
        assert run_cli(capsys, "generate", "--robot", robot, "--distance", "0.3", "-o", planned)[0] == 0
        assert run_cli(capsys, "generate", "--robot", robot, "--distance", "0.3", "--goals", "-o", goals)[0] == 0
        a, b = Trajectory.load(planned), Trajectory.load(goals)
        assert a.joints == b.joints and np.array_equal(a.root_m, b.root_m)
        gap = np.degrees(np.abs(a.angles_rad - b.angles_rad)).max()
        assert (0.5 < gap < 3.0) if differ else gap == 0.0


@pytest.mark.parametrize("args, message, status", [
    (["plan", "--robot", "op3", "--distance", "1", "--cycle", "-1"], "--cycle must be 0.2..10 seconds", 2),
    (["plan", "--robot", "op3", "--distance", "1", "--cycle", "1e9"], "--cycle must be 0.2..10 seconds", 2),
    # a walk the servos cannot follow is the robot's failure, not bad input: exit 1 (docs/command-line.md)
    (["walk", "--dry-run", "--robot", "op3", "--distance", "0.5", "--cycle", "0.4"], "walk refused before anything moved", 1),
    (["plan", "--robot", "op3", "--terrain", "config/terrain/kerb.toml"], "walks on the flat only", 2),
    (["plan", "--robot", "op3", "--steps", "0.05,0.3"], "--steps: step 2 is 0.3 m", 2),
])
def test_what_a_balanced_walk_refuses_is_one_line(args, message, status, capsys):
    """One error line (a note on how the walk was fitted to the servos' speed may come before it)."""
    code, _, err = run_cli(capsys, *args)
    errors = [line for line in err.splitlines() if not line.startswith("note: ")]
    assert code == status and len(errors) == 1 and message in errors[0]
