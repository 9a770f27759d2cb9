"""Velocity commands: the JSON Lines format round-trips, and bad entries are refused naming line and field."""

import io
import math

import pytest
from hypothesis import given, strategies as st

from gaitbot.errors import UserError
from gaitbot.gait.steer.command import (TimedCommand, VelocityCommand, parse_commands, parse_velocity,
                                        read_commands, write_commands)

finite = st.floats(min_value=-2.0, max_value=2.0, allow_nan=False)


@given(st.lists(st.tuples(st.floats(0, 100), finite, finite, st.floats(-90, 90)), min_size=1, max_size=20))
def test_commands_round_trip_through_json_lines(rows):
    times = sorted(r[0] for r in rows)
    commands = [TimedCommand(t, VelocityCommand(vx, vy, wz)) for t, (_, vx, vy, wz) in zip(times, rows)]
    commands.append(TimedCommand(times[-1] + 1.0, stop=True))
    text = io.StringIO()
    write_commands(text, commands)
    assert parse_commands(text.getvalue().splitlines(), "f") == commands


def test_velocity_argument_in_its_units():
    assert parse_velocity("0.1,-0.05,30") == VelocityCommand(0.1, -0.05, 30.0)


@pytest.mark.parametrize("line, words", [
    ('{"vx": 0.1}', "missing field 't'"),
    ('{"t": 0, "vx": "fast"}', "vx (m/s) must be a number"),
    ('{"t": 0, "vx": 1e300}', "within"),
    ('{"t": -1}', "t (s) must be >= 0"),
    ('{"t": 0, "speed": 1}', "unknown field 'speed'"),
    ('{"t": 0, "stop": true, "vx": 0.1}', "carries no vx"),
    ('[1, 2]', "expected a JSON object"),
    ('{"t": 0', "not a JSON object"),
])
def test_bad_entries_name_the_line_and_field(line, words):
    with pytest.raises(UserError, match="f line 2: .*" + words.replace("(", r"\(").replace(")", r"\)")):
        parse_commands(['{"t": 0}', line], "f")


def test_times_must_not_go_back_and_nothing_follows_a_stop():
    with pytest.raises(UserError, match="line 2: t 1 s is before"):
        parse_commands(['{"t": 2}', '{"t": 1}'], "f")
    with pytest.raises(UserError, match="line 2: an entry after the stop"):
        parse_commands(['{"t": 2, "stop": true}', '{"t": 3}'], "f")


def test_files_are_bounded_and_regular(tmp_path):
    big = tmp_path / "big.jsonl"
    big.write_bytes(b" " * (5 * 1024 * 1024))
    with pytest.raises(UserError, match="larger than"):
        read_commands(big)
    with pytest.raises(UserError, match="not a regular file"):
        read_commands(tmp_path)
    assert not math.isnan(parse_velocity("0,0,0").wz_deg_s)
