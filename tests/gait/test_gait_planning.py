"""Planning (steps for a distance, perturbations, unequal left/right steps) and bad step input."""

from __future__ import annotations

import math

import numpy as np
import pytest

from gaitbot.gait import (TABLE1_LEG, LegGeometry, OnlineWalker, StepLengthError, StepLengthInverse,
                          WalkSettings, generate_walk, perturb_steps, steps_for_distance)
from gaitbot.gait.walker import plan_walk


# --------------------------------------------------------------------------------------------
# 7. planning
# --------------------------------------------------------------------------------------------
@pytest.mark.parametrize("distance, max_step, expected", [
    (1.0, 0.3, [0.25] * 4),        # 3 steps reach only 0.9: 4 equal steps
    (0.9, 0.3, [0.3] * 3),         # exactly 3 maximal steps (0.9 / 0.3 is 3.0000000000000004 in floats)
    (0.1, 0.3, [0.1]),             # one short step
    (0.61, 0.3, [0.61 / 3] * 3),   # just over 2 steps: 3
    (0.75, 0.75, [0.75]),
    (3.0, 0.75, [0.75] * 4),
    (0.5, 0.1, [0.1] * 5),         # xl430-biped: half a metre at max_step_m
])
def test_steps_for_distance_hand_cases(distance, max_step, expected):
    got = steps_for_distance(distance, max_step)
    assert len(got) == len(expected)
    np.testing.assert_allclose(got, expected, atol=1e-12)
    assert math.fsum(got) == pytest.approx(distance, abs=1e-12)
    assert max(got) <= max_step * (1 + 1e-12)


@pytest.mark.parametrize("distance", [0.0, -1.0, float("nan"), float("inf")])
def test_steps_for_distance_bad_distance(distance):
    with pytest.raises(StepLengthError, match="distance"):
        steps_for_distance(distance, 0.3)


def test_steps_for_distance_bad_max():
    with pytest.raises(StepLengthError):
        steps_for_distance(1.0, 0.0)


def test_perturb_reproducible_and_keeps_distance():
    steps = [0.3] * 10
    a = perturb_steps(steps, 0.02, seed=11, max_step=0.75)
    b = perturb_steps(steps, 0.02, seed=11, max_step=0.75)
    c = perturb_steps(steps, 0.02, seed=12, max_step=0.75)
    assert a == b
    assert a != c
    assert len(a) == 10
    assert math.fsum(a) == pytest.approx(3.0, abs=1e-12)
    assert all(0.0 <= x <= 0.75 for x in a)
    assert np.std(np.array(a) - 0.3) > 0.002  # actually perturbed
    assert perturb_steps(steps, 0.0, seed=1, max_step=0.75) == steps
    with pytest.raises(StepLengthError):
        perturb_steps(steps, -0.1, seed=1, max_step=0.75)


@pytest.mark.parametrize("steps, sigma", [
    (steps_for_distance(3.0, 0.75), 0.05),  # steps at the maximum (what --distance plans by default)
    ([0.01] * 10, 0.05),                     # steps near zero
])
def test_perturb_within_range(steps, sigma):
    for seed in range(20):
        got = perturb_steps(steps, sigma, seed=seed, max_step=0.75)
        assert all(0.0 <= x <= 0.75 for x in got), got


@pytest.mark.parametrize("steps, sigma", [
    (steps_for_distance(3.0, 0.75), 0.05),
    ([0.01] * 10, 0.05),
])
def test_perturb_keeps_distance_when_clipping(steps, sigma):
    for seed in range(20):
        got = perturb_steps(steps, sigma, seed=seed, max_step=0.75)
        assert math.fsum(got) == pytest.approx(math.fsum(steps), abs=1e-9), f"seed {seed}: {got}"


def test_left_and_right_steps_may_differ():
    """Seed 000's third experiment: right 0.4, left 0.34."""
    steps = [0.4, 0.34] * 3
    walker = plan_walk(TABLE1_LEG, steps)
    planned = [s for s in walker.planned_steps if not s.closing]
    assert [s.leg for s in planned] == ["right", "left"] * 3
    np.testing.assert_allclose([s.length_m for s in planned], steps, atol=1e-15)
    np.testing.assert_allclose([s.foothold_m for s in planned], [0.4, 0.74, 1.14, 1.48, 1.88, 2.22], atol=1e-12)
    rvs = [s.rv for s in planned]
    np.testing.assert_allclose(rvs[0::2], rvs[0], atol=1e-9)
    np.testing.assert_allclose(rvs[1::2], rvs[1], atol=1e-9)
    assert rvs[0] > rvs[1] + 0.02
    # steps follow each other without gaps, one step duration each
    for a, b in zip(walker.planned_steps, walker.planned_steps[1:]):
        assert b.start_s == pytest.approx(a.end_s, abs=1e-12)
        assert b.end_s - b.start_s == pytest.approx(walker.ctx.step_frames / walker.ctx.rate_hz, abs=1e-12)


# --------------------------------------------------------------------------------------------
# 8. bad input
# --------------------------------------------------------------------------------------------
@pytest.mark.parametrize("steps, needle", [
    ([-0.1], "-0.1"),
    ([0.3, -0.25], "-0.25"),
    ([float("nan")], "nan"),
    ([float("inf")], "inf"),
    ([0.3, float("-inf")], "-inf"),
    ([0.8], "0.8"),
    ([0.2, 0.3, 1.5], "1.5"),
])
def test_bad_step_lengths_raise_naming_the_value(steps, needle):
    with pytest.raises(StepLengthError) as err:
        generate_walk(TABLE1_LEG, steps)
    assert needle in str(err.value), str(err.value)
    assert isinstance(err.value, ValueError)


def test_bad_step_names_its_position():
    with pytest.raises(StepLengthError, match="step 2"):
        generate_walk(TABLE1_LEG, [0.3, -0.25])


def test_too_long_message_names_the_maximum():
    inverse = StepLengthInverse.build(TABLE1_LEG)
    with pytest.raises(StepLengthError) as err:
        generate_walk(TABLE1_LEG, [0.8])
    assert f"{inverse.max_step_length:.4g}" in str(err.value)


def test_reachable_maximum_itself_walks():
    inverse = StepLengthInverse.build(TABLE1_LEG)
    walk = generate_walk(TABLE1_LEG, [inverse.max_step_length])
    assert walk.heel_strikes[0].x_m == pytest.approx(inverse.max_step_length, abs=1e-12)


@pytest.mark.parametrize("steps", [[], ()])
def test_empty_step_list_raises(steps):
    with pytest.raises(StepLengthError):
        generate_walk(TABLE1_LEG, steps)


@pytest.mark.parametrize("value, needle", [(-0.01, "-0.01"), (float("nan"), "nan"), (0.9, "0.9"), ("abc", "abc")])
def test_online_walker_rejects_bad_steps(value, needle):
    walker = OnlineWalker(TABLE1_LEG)
    with pytest.raises(StepLengthError) as err:
        walker.append_step(value)
    assert needle in str(err.value)
    # the walker is still usable after a rejected step
    walker.append_step(0.2)
    assert walker.planned_steps[-1].foothold_m == pytest.approx(0.2)


def test_robot_leg_too_long_step():
    leg = LegGeometry(thigh=0.11, shank=0.11, foot=0.12, hip_width=0.07, ankle_height=0.0305)
    settings = WalkSettings(cycle_s=2.4, clearance=0.012)
    with pytest.raises(StepLengthError, match="0.2"):
        generate_walk(leg, [0.05, 0.2], settings)
