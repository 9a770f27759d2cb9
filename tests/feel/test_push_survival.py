"""tools/push_survival.py's ``--walk``: another walk of the robot pushed, its figure named apart from the default
walk's, and a walk that refuses its arguments stopping the tool with one line and exit 2 (no traceback)."""

from __future__ import annotations

import re
import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "tools"))
import push_survival  # noqa: E402


def figure_names(argv: list[str], capsys) -> list[str]:
    """The figure regions ``--markdown`` prints (no push drawn: no walk is simulated)."""
    assert push_survival.main_([*argv, "--pushes", "0", "--markdown"]) == 0
    return re.findall(r"<!-- figure (\S+) -->", capsys.readouterr().out)


def test_another_walk_has_its_own_figure_names(capsys):
    default = figure_names([], capsys)
    assert default == ["push-op3", "push-op3-by-way", "push-op3-noticed"]
    # the default walk named explicitly is the default walk: the same figures
    assert figure_names(["--walk", push_survival.WALKS["op3"]], capsys) == default
    assert figure_names(["--walk=--distance 1"], capsys) == ["push-op3-walk", "push-op3-walk-by-way",
                                                              "push-op3-walk-noticed"]


@pytest.mark.parametrize("walk, reason", [
    ("--distance 1 --cycle 0.1", "--cycle must be"),  # gaitbot walk's own check
    ("--distance abc", "invalid float value: 'abc'"),  # its argument parser's
    ("--bogus", "unrecognized arguments: --bogus"),
    ("--distance 1 --robot bioloid", "--robot is set by this tool"),  # the table would name another robot
    ("--feedback=none", "--feedback is set by this tool"),  # the tool's --modes would override it
])
def test_a_walk_that_refuses_its_arguments_stops_with_one_line_and_exit_2(walk, reason, capsys):
    code = push_survival.main_([f"--walk={walk}", "--pushes", "1", "--modes", "full"])
    err = capsys.readouterr().err
    assert code == 2
    lines = err.strip().splitlines()
    assert len(lines) == 1 and "Traceback" not in err
    assert lines[0].startswith(f"push_survival.py: --walk {walk!r}")
    assert reason in lines[0]  # the reason, passed on
