"""tools/push_margin.py's scan: the impulses walked from the smallest up, stopping at the first that falls, and
what a cell says. A made-up walk that falls above a known impulse stands in for the simulation (the figure itself
is rerun by tools/figures.py --check)."""

from __future__ import annotations

import sys

import pytest

from gaitbot.sim import SimUnavailable, import_mujoco

try:
    import_mujoco()
except SimUnavailable:
    pytest.skip("the sim extra (MuJoCo) is not installed", allow_module_level=True)

from helpers import REPO_ROOT  # noqa: E402

sys.path.insert(0, str(REPO_ROOT / "tools"))
import push_margin  # noqa: E402


def scan(falls_from=None, falls_only=None):
    walked = []

    def falls(impulse):
        walked.append(impulse)
        return (falls_from is not None and impulse >= falls_from) or impulse == falls_only

    return push_margin.held_impulse(falls), walked


def test_the_scan_walks_up_the_grid_and_stops_at_the_first_fall():
    (held, fell), walked = scan(falls_from=1.1)
    assert (held, fell) == (1.0, 1.25)
    assert walked == [0.25, 0.5, 0.75, 1.0, 1.25]  # nothing past the first fall
    assert push_margin.cell(held, fell) == "1.00 (falls at 1.25)"


def test_a_walk_that_never_falls_holds_the_whole_grid_and_one_that_always_falls_holds_nothing():
    (held, fell), walked = scan()
    assert (held, fell) == (2.0, None) and len(walked) == 8 and push_margin.cell(held, fell) == "2.00+"
    (held, fell), walked = scan(falls_from=0.0)
    assert (held, fell) == (0.0, 0.25) and walked == [0.25] and push_margin.cell(held, fell) == "- (falls at 0.25)"


def test_a_push_held_above_the_first_fall_is_not_looked_for():
    (held, fell), walked = scan(falls_only=0.5)  # 0.75 and up would hold: the scan does not say so
    assert (held, fell) == (0.25, 0.5) and walked == [0.25, 0.5]


def test_the_grid_is_the_issue_range_in_quarter_steps():
    assert push_margin.GRID_N_S[0] == 0.25 and push_margin.GRID_N_S[-1] == 2.0
    assert all(b - a == pytest.approx(0.25) for a, b in zip(push_margin.GRID_N_S, push_margin.GRID_N_S[1:]))
