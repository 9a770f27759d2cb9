"""The step envelope: the robot configs carry it, the planner and the course check share it, and a course
outside it is refused up front naming the tread and why (exit 2, one line); a course inside it plans."""


import pytest

from gaitbot.app.cli import main
from gaitbot.gait.terrain.envelope import REFERENCE_MARGIN_M, StepEnvelope, course_problems
from gaitbot.gait.terrain.model import Terrain, Tread
from gaitbot.robot.config import ConfigError, load_robot_config
from helpers import REPO_ROOT

ROOT = REPO_ROOT
# Terrain is walked by the planar walker: every shipped pitch-only robot states its step envelope.
ROBOTS = sorted(p for p in (ROOT / "config").glob("*.toml") if not load_robot_config(p).is_3d)
ENV = StepEnvelope.for_foot(0.12, 0.04, 0.035, 0.08, "test leg")


@pytest.mark.parametrize("path", ROBOTS, ids=lambda p: p.stem)
def test_every_shipped_robot_states_its_envelope(path):
    cfg = load_robot_config(path)
    reach = cfg.terrain
    leg = cfg.geometry.thigh_m + cfg.geometry.shank_m
    assert reach is not None
    assert 0.1 * leg <= reach.max_rise_m <= 0.3 * leg and 0.05 * leg <= reach.max_drop_m <= 0.3 * leg
    assert 0.0 < reach.max_gap_m < leg


def test_a_terrain_table_is_checked_like_the_rest(tmp_path):
    text = (ROOT / "config" / "xl430-biped.toml").read_text().replace("max_gap_m", "max_gaps_m")
    bad = tmp_path / "robot.toml"
    bad.write_text(text)
    with pytest.raises(ConfigError, match=r"terrain.max_gaps_m: unknown key"):
        load_robot_config(bad)


def test_step_limit_falls_from_the_level_to_the_largest_rise_and_drop():
    assert ENV.step_limit(0.0) == pytest.approx(0.12 + 2 * REFERENCE_MARGIN_M + 0.08)
    assert ENV.step_limit(0.02) == pytest.approx(0.14 + 0.08 * 0.25)
    assert ENV.step_limit(0.04) == pytest.approx(0.14) and ENV.step_limit(-0.035) == pytest.approx(0.14)
    assert ENV.step_limit(0.0401) < 0 and ENV.step_limit(-0.036) < 0


@pytest.mark.parametrize("treads, first_words", [
    ((Tread(0.4, 0.6, 0.04),), None),
    ((Tread(0.4, 0.14, 0.04), Tread(0.54, 0.6, 0.08)), None),
    ((Tread(0.4, 0.08, -0.1),), None),  # a ditch 8 cm wide: the widest on the level
    ((Tread(0.4, 0.081, -0.1),), "the ground after tread 1: a gap of 0.081 m"),
    ((Tread(0.4, 0.02, -0.1), Tread(0.42, 0.6, 0.02)), None),  # a quarter of the gap at half the rise
    ((Tread(0.4, 0.03, -0.1), Tread(0.43, 0.6, 0.02)), "tread 2: a gap of 0.03 m"),
    ((Tread(0.4, 0.6, 0.041),), "tread 1: rise 0.041 m exceeds"),
    ((Tread(0.4, 0.6, -0.036),), "tread 1: drop 0.036 m exceeds"),
    ((Tread(0.4, 0.13, 0.03), Tread(0.53, 0.6, 0.06)), "tread 2: rise 0.06 m exceeds"),
    ((Tread(0.4, 0.02, 0.05),), "tread 1: stands 0.05 m above its neighbours"),
])
def test_course_problems_name_the_first_place_and_why(treads, first_words):
    problem = course_problems(Terrain(treads), 0.0, 0.8, 0.12, 0.01, ENV)
    if first_words is None:
        assert problem is None
    else:
        assert problem is not None and problem.startswith(first_words), problem
        assert "\n" not in problem


def test_a_course_cannot_ask_for_more_than_the_robot_can(tmp_path, capsys):
    path = tmp_path / "course.toml"
    path.write_text("[course]\nstart_m = 0.0\nend_m = 1.0\nmax_rise_m = 0.09\n")
    assert main(["plan", "--terrain", str(path)]) == 2
    err = capsys.readouterr().err
    assert f"{path}: course.max_rise_m: 0.09 m is more than xl430-biped can step" in err
