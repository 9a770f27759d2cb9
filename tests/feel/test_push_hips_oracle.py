"""tools/push_hips_oracle.py: the burst's shape and signs, and that it acts in the simulation (its direction too)."""

import math
import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "tools"))
import push_hips_oracle as ho  # noqa: E402
from helpers import config  # noqa: E402

PUSH_1 = ho.DRAWS[0]
"""Push 1 of tools/push_survival.py: 1.39 N s backwards and to the right, early in a swing; feedback full loses
it (docs/feedback.md), and the bound needs the hips to catch it (docs/capturability.md)."""


def test_the_burst_holds_then_returns_linearly_and_is_zero_outside():
    start = 5.0
    assert ho.burst_share(start - 1e-3, start) == 0.0
    assert ho.burst_share(start, start) == 1.0
    assert ho.burst_share(start + ho.HOLD_S - 1e-6, start) == 1.0
    assert ho.burst_share(start + ho.HOLD_S + ho.RETURN_S / 4, start) == pytest.approx(0.75)
    assert ho.burst_share(start + ho.HOLD_S + ho.RETURN_S, start) == 0.0


def test_a_forward_burst_flexes_both_hips_and_a_leftward_one_turns_the_pelvis_about_either_hip():
    names = [j.name for j in config("op3").joints]
    size = math.radians(ho.BURST_DEG)
    forward = dict(zip(names, ho.burst_rad(names, 0.0, 1.0)))
    assert forward["hip_pitch_left"] == forward["hip_pitch_right"] == pytest.approx(size)
    assert forward["hip_roll_left"] == pytest.approx(0.0, abs=1e-12)
    left = dict(zip(names, ho.burst_rad(names, 90.0, 0.5)))
    # abduction positive on both sides: the left hip opens and the right one closes by the same angle, so the
    # pelvis turns the same way about whichever foot stands
    assert left["hip_roll_left"] == pytest.approx(size / 2) and left["hip_roll_right"] == pytest.approx(-size / 2)
    assert abs(left["hip_pitch_left"]) < 1e-12
    others = [n for n in names if n not in ("hip_pitch_left", "hip_pitch_right", "hip_roll_left", "hip_roll_right")]
    assert not np.any(ho.burst_rad(others, 37.0, 1.0))


def test_the_oracles_burst_catches_a_push_the_feedback_loses_and_a_burst_away_from_it_does_not(monkeypatch):
    assert PUSH_1[0] > ho.OVER_N_S
    assert not ho._walk((None, ho.OVER_N_S, 1, PUSH_1))
    assert ho._walk((ho.LATENCY_FRAMES[0], ho.OVER_N_S, 1, PUSH_1))
    monkeypatch.setattr(ho, "BURST_DEG", -ho.BURST_DEG)  # the same burst, turned away from the push
    assert not ho._walk((ho.LATENCY_FRAMES[0], ho.OVER_N_S, 1, PUSH_1))
