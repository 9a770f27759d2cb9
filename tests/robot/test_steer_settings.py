"""The [steer] table: read with every key, each bounded, one line naming the field when it is wrong."""

import pytest

from gaitbot.gait.steer.limits import SteerLimits
from test_robot_config_3d import OP3_TEXT, expect  # tests/robot is on the path (pytest prepend import mode)


def with_steer_line(key: str, value: str | None) -> str:
    lines = OP3_TEXT.splitlines()
    start = lines.index("[steer]")
    out = []
    for i, line in enumerate(lines):
        if i > start and line.startswith(f"{key} ="):
            if value is not None:
                out.append(f"{key} = {value}")
            continue
        out.append(line)
    return "\n".join(out) + "\n"


def test_the_op3_and_bioloid_have_steering_limits():
    from helpers import config

    for robot in ("op3", "bioloid"):
        steer = config(robot).steer
        assert isinstance(steer, SteerLimits)
        g = config(robot).body.geometry
        # the soles' own gap side by side leaves room for the least gap the walk keeps
        assert steer.min_gap_m < g.hip_width_m - g.foot_width_m + 2 * g.sole_outward_m
        assert steer.max_forward_m <= config(robot).gait.max_step_m


@pytest.mark.parametrize("key, value, words", [
    ("max_turn_deg", "90.0", ("outside", "60")),
    ("min_gap_m", "-0.01", ("outside",)),
    ("max_side_m", "\"wide\"", ("number",)),
    ("max_forward_m", None, ("missing",)),
])
def test_a_bad_steer_key_is_one_line_naming_it(tmp_path, capsys, key, value, words):
    expect(tmp_path, capsys, with_steer_line(key, value), f"steer.{key}", *words)


def test_an_unknown_steer_key_is_refused(tmp_path, capsys):
    text = OP3_TEXT.replace("[steer]\n", "[steer]\nmax_speed = 1.0\n")
    expect(tmp_path, capsys, text, "steer.max_speed", "unknown key")
