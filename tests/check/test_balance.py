"""The balance check: centre of mass and ZMP of a trajectory against the support polygon.

Expected values come from physics, not from the code: standing still, the ZMP is the centre of mass's
ground projection; a rigid robot accelerating uniformly by a puts its ZMP z_com a / g behind its centre
of mass (every mass has the same acceleration, so the multibody formula reduces to the cart-table's).
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from gaitbot.app.cli import main
from gaitbot.check.balance import balance_trace, signed_distance
from gaitbot.check.preflight import preflight, robot_angles_deg
from gaitbot.gait.trajectory import Trajectory
from gaitbot.robot.config import load_robot_config, resolve_config

OP3 = load_robot_config(resolve_config("op3"))
G = 9.81


def standing(config, n=90, accel_x=0.0, rate=60.0):
    """Straight legs, soles flat, the root moving as x = a t^2 / 2."""
    t = np.arange(n) / rate
    z = config.body.geometry.standing_root_height_m
    root = np.column_stack([0.5 * accel_x * t ** 2, np.zeros(n), np.full(n, z)])
    return Trajectory(t, np.zeros((n, len(config.walking_joint_names))), root, joints=config.walking_joint_names)


def test_standing_still_the_zmp_is_the_centre_of_mass_projection():
    walk = standing(OP3)
    trace = balance_trace(OP3, walk, robot_angles_deg(OP3, walk))
    np.testing.assert_allclose(trace.zmp_m, trace.com_m[:, :2], atol=1e-12)
    # the centre of mass from the config's own numbers: torso and both legs' links at the straight pose
    body = OP3.body
    total = body.total_kg
    assert total == pytest.approx(3.147470, abs=1e-4)  # the [mass] total_kg the file states
    # both feet flat: the polygon is the hull of two soles, and the ZMP lies well inside it
    assert len(trace.support[0]) == 4
    assert trace.margin_m.min() > 0.02


def test_uniform_acceleration_moves_the_zmp_back_by_z_a_over_g():
    a = 1.0  # m/s^2 forward
    walk = standing(OP3, accel_x=a)
    trace = balance_trace(OP3, walk, robot_angles_deg(OP3, walk))
    com_z = trace.com_m[:, 2]
    expected = trace.com_m[:, 0] - com_z * a / G
    np.testing.assert_allclose(trace.zmp_m[:, 0], expected, atol=1e-9)


def test_a_trajectory_that_tips_the_robot_is_refused_and_says_which_way():
    walk = standing(OP3, accel_x=4.0)  # the ZMP ends up some 10 cm behind the centre of mass: off the heels
    report = preflight(OP3, walk)
    assert not report.ok
    assert report.first_error.startswith("zmp: ") and "tip backwards" in report.first_error
    assert report.balance.frames_outside == len(walk)
    # a boom holds it up: the same trajectory is accepted, balance not checked
    on_boom = preflight(OP3, walk, on_boom=True)
    assert on_boom.ok and not on_boom.balance.checked


def test_the_cli_check_fails_a_tipping_file_and_walk_refuses_it_before_anything_moves(tmp_path, capsys):
    path = tmp_path / "tips.csv"
    standing(OP3, n=120, accel_x=4.0).save(path)
    assert main(["check", str(path), "--robot", "op3"]) == 1
    out = capsys.readouterr().out
    assert "tip backwards" in out and "balance:" in out
    record = tmp_path / "run.jsonl"
    assert main(["walk", "--dry-run", "--robot", "op3", "--trajectory", str(path), "--record", str(record)]) == 1
    err = capsys.readouterr().err
    assert "refused before anything moved" in err and "tip backwards" in err
    assert not record.exists() or "goal" not in record.read_text()
    assert main(["check", str(path), "--robot", "op3", "--boom"]) == 0


def test_robots_on_a_boom_are_not_checked_for_balance():
    xl = load_robot_config(resolve_config("xl430-biped"))
    assert xl.boom
    report = preflight(xl, standing(xl, accel_x=4.0))
    assert report.ok and not report.balance.checked and "boom" in report.balance.note
    # without the boom the same walk is judged, and this one tips
    free = dataclasses.replace(xl, boom=False)
    assert not preflight(free, standing(free, accel_x=4.0)).ok


def test_a_root_below_where_the_feet_allow_is_named():
    walk = standing(OP3)
    sunk = dataclasses.replace(walk, root_m=walk.root_m - [0.0, 0.0, 0.01])
    report = preflight(OP3, sunk)
    assert not report.ok and "below the floor" in report.first_error and "10.0 mm" in report.first_error


@pytest.mark.parametrize("point, expected", [((0.0, 0.0), 1.0), ((2.0, 0.0), -1.0), ((1.0, 3.0), -2.0),
                                             ((0.5, 0.25), 0.5)])
def test_signed_distance_to_a_square(point, expected):
    square = np.array([[-1.0, -1.0], [1.0, -1.0], [1.0, 1.0], [-1.0, 1.0]])  # counter-clockwise
    assert signed_distance(np.array(point), square) == pytest.approx(expected)
