"""Boulic model, step length and its inverse, Bezier blending (docs/gait-model.md sections 2, 4, 5).

Expected values come from seed 000 (Table 3; Appendix A's Hermite blend), from the keyframe table
of docs/gait-model.md section 2 (written out again here, independently of gaitbot.gait.boulic), and from
hand computation.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from gaitbot.gait import TABLE1_LEG, LegGeometry, StepLengthError, StepLengthInverse
from gaitbot.gait.blend import BoulicBlend, bernstein_weights
from gaitbot.gait.boulic import hermite_periodic, keyframes_deg, pose_rad, toe_off_phase
from gaitbot.gait.step_length import boulic_step_length, step_length_to_rv_bisection

# seed 000, Table 3: given step length SL -> the RV Algorithm 1 found (tolerance 0.01)
TABLE3 = [
    (0.05, 0.03), (0.10, 0.061), (0.15, 0.091), (0.20, 0.1213), (0.25, 0.1591),
    (0.30, 0.1895), (0.35, 0.2273), (0.40, 0.2577), (0.45, 0.2878), (0.50, 0.3183),
    (0.55, 0.3486), (0.60, 0.3789), (0.65, 0.4244), (0.70, 0.4547), (0.75, 0.4812),
]
DC = 1.346  # seed 000, Table 2


@pytest.fixture(scope="module")
def inverse():
    return StepLengthInverse.build(TABLE1_LEG, DC)


# --------------------------------------------------------------------------------------------
# the keyframe table of docs/gait-model.md section 2, written out independently
# --------------------------------------------------------------------------------------------
def table_keyframes(rv: float, ds_dc: float) -> dict:
    if rv < 0.5:
        return {
            "hip": [(0.5, -30 * rv), (0.9, 50 * rv)],
            "knee": [(0.0, 3), (0.17, 3), (0.4, 3), (0.75, 140 * rv)],
            "ankle": [(0, -3), (0.08, -30 * rv - 3), (0.5, 22 * rv - 3), (ds_dc, -34 * rv - 3), (0.85, -3)],
        }
    if rv < 1.3:
        return {
            "hip": [(0.5, -15), (0.9, 25)],
            "knee": [(0.0, 3), (0.17, 3), (0.4, 3), (0.75, 70)],
            "ankle": [(0, -3), (0.08, -18), (0.5, 8), (ds_dc, -20), (0.85, -3)],
        }
    r = (rv - 1.3) / 1.7
    return {
        "hip": [(0.5, -15), (0.9, 25 + 6 * r), (0.9 + 0.2 * r, 25 + 5 * r)],
        "knee": [(0.0 - 0.03 * r, 3 + 3 * r), (0.17 - 0.05 * r, 3 + 22 * r), (0.4, 3), (0.75 - 0.05 * r, 70 - 5 * r)],
        "ankle": [(0, 5 * r - 3), (0.08, 4 * r - 18), (0.5 - 0.1 * r, 8 - 3 * r), (ds_dc, -20 - 8 * r), (0.85, 5 * r - 3)],
    }


def my_hermite(t: float, keys) -> float:
    """Seed 000 Appendix A between the two keyframes around t, periodic in t."""
    keys = sorted(((p % 1.0, v) for p, v in keys))
    t = t % 1.0
    ext = [(p - 1.0, v) for p, v in keys] + keys + [(p + 1.0, v) for p, v in keys]
    for (p0, v0), (p1, v1) in zip(ext, ext[1:]):
        if p0 <= t < p1:
            s = (t - p0) / (p1 - p0)
            return v0 * (2 * s**3 - 3 * s**2 + 1) + v1 * (-2 * s**3 + 3 * s**2)
    raise AssertionError("no bracket")


def my_leg_deg(rv, phase, ds_dc):
    k = table_keyframes(rv, ds_dc)
    return [my_hermite(phase, k[j]) for j in ("hip", "knee", "ankle")]


def my_step_length(rv: float, g: LegGeometry = TABLE1_LEG) -> float:
    """Realised step length (section 4): at the left heel strike (phase 0) the left heel is in front,
    the right leg (phase 0.5) rests on its lower point, heel if its toe is up, toe otherwise; rolling
    without slip, its flat-foot heel position (the anchor) is that heel, or that toe less the foot."""
    ds_dc = (0.752 * DC - 0.143) / DC

    def heel_toe(hip, knee, ankle):
        h, k, a = map(math.radians, (hip, knee, ankle))
        ax = g.thigh * math.sin(h) + g.shank * math.sin(h - k)
        p = h - k + a
        return ax, ax + g.foot * math.cos(p), p

    front_heel, _, _ = heel_toe(*my_leg_deg(rv, 0.0, ds_dc))
    rear_heel, rear_toe, p = heel_toe(*my_leg_deg(rv, 0.5, ds_dc))
    anchor = rear_heel if p >= 0 else rear_toe - g.foot
    return front_heel - anchor


# --------------------------------------------------------------------------------------------
# 1. Table 3 and the inverse
# --------------------------------------------------------------------------------------------
def test_toe_off_phase_with_table2_cycle():
    """Ds/Dc = (0.752 * 1.346 - 0.143) / 1.346 = 0.64576 (docs/gait-model.md: 0.6458)."""
    assert toe_off_phase(DC) == pytest.approx(0.6458, abs=1e-4)


@pytest.mark.parametrize("sl, rv_paper", TABLE3)
def test_table3_fast_inverse(inverse, sl, rv_paper):
    rv = inverse.rv(sl)
    assert abs(rv - rv_paper) <= 0.015, f"SL {sl}: RV {rv:.4f}, paper {rv_paper}"


@pytest.mark.parametrize("sl, rv_paper", TABLE3)
def test_table3_paper_bisection(sl, rv_paper):
    rv, iterations = step_length_to_rv_bisection(TABLE1_LEG, sl, tolerance=0.01)
    assert abs(rv - rv_paper) <= 0.015, f"SL {sl}: bisection RV {rv:.4f}, paper {rv_paper}"
    assert abs(float(boulic_step_length(TABLE1_LEG, rv)[0]) - sl) <= 0.01
    # bisection on [0, 0.5] to 0.01 in SL: 0.5 / 2^k below the RV slack in at most ~10 halvings
    assert 1 <= iterations <= 12


@pytest.mark.parametrize("rv", [0.0, 0.03, 0.1213, 0.25, 0.3789, 0.4812, 0.499])
def test_step_length_matches_independent_computation(rv):
    """boulic_step_length equals the one computed here from the table, Appendix A and our own FK."""
    assert float(boulic_step_length(TABLE1_LEG, rv, DC)[0]) == pytest.approx(my_step_length(rv), abs=1e-12)


def test_fast_inverse_agrees_with_tight_bisection(inverse):
    for sl in np.linspace(0.0, inverse.max_step_length, 23):
        rv_fast = inverse.rv(sl)
        rv_bis, _ = step_length_to_rv_bisection(TABLE1_LEG, float(sl), tolerance=1e-13)
        sl_fast = float(boulic_step_length(TABLE1_LEG, rv_fast, DC)[0])
        sl_bis = float(boulic_step_length(TABLE1_LEG, rv_bis, DC)[0])
        assert abs(sl_fast - sl_bis) <= 1e-9, f"SL {sl}: fast {sl_fast!r}, bisection {sl_bis!r}"
        assert abs(sl_fast - sl) <= 1e-9, f"SL {sl}: fast inverse realises {sl_fast!r}"
    # Table 1's leg steps slightly backwards at RV 0 (SL(0) < 0), so a zero step needs RV > 0
    assert float(boulic_step_length(TABLE1_LEG, 0.0, DC)[0]) < 0
    assert inverse.rv(0.0) > 0


def test_step_length_monotonic_in_region_a():
    rv = np.linspace(0.0, 0.5 - 1e-9, 2001)
    sl = boulic_step_length(TABLE1_LEG, rv, DC)
    assert np.all(np.diff(sl) > 0), f"SL falls near RV {rv[int(np.argmin(np.diff(sl)))]:.4f}"


def test_reachable_range(inverse):
    lo, hi = inverse.reachable_range
    assert lo == 0.0
    assert hi >= 0.75
    # the top of the range is the step length at the top of region A
    assert hi == pytest.approx(my_step_length(0.5 - 1e-12), abs=1e-6)
    assert inverse.rv(0.75) < 0.5
    with pytest.raises(StepLengthError):
        inverse.rv(hi * 1.01)


# --------------------------------------------------------------------------------------------
# 2. keyframes and the Hermite blend
# --------------------------------------------------------------------------------------------
@pytest.mark.parametrize("rv", [0.0, 0.2, 0.49, 0.5, 0.9, 1.29, 1.3, 2.0, 3.0])
def test_keyframes_match_the_table(rv):
    ds_dc = toe_off_phase(DC)
    got = keyframes_deg(rv, ds_dc)
    want = table_keyframes(rv, ds_dc)
    for joint in ("hip", "knee", "ankle"):
        phases, values = got[joint]
        pairs = sorted(zip(np.asarray(phases).tolist(), np.asarray(values).tolist()))
        expected = sorted(((p % 1.0, float(v)) for p, v in want[joint]))
        assert len(pairs) == len(expected)
        for (p, v), (pe, ve) in zip(pairs, expected):
            assert p == pytest.approx(pe, abs=1e-12) and v == pytest.approx(ve, abs=1e-12), (joint, pairs, expected)


@pytest.mark.parametrize("border", [0.5, 1.3])
def test_curves_continuous_across_region_borders(border):
    ds_dc = toe_off_phase(DC)
    phase = np.linspace(0.0, 1.0, 1001, endpoint=False)
    below, above = keyframes_deg(border - 1e-9, ds_dc), keyframes_deg(border + 1e-9, ds_dc)
    for joint in ("hip", "knee", "ankle"):
        a = hermite_periodic(phase, *below[joint])
        b = hermite_periodic(phase, *above[joint])
        worst = float(np.abs(a - b).max())
        assert worst <= 1e-5, f"{joint} jumps {worst:.3g} deg at RV {border}"


@pytest.mark.parametrize("rv", [0.1, 0.35, 0.8, 2.2])
def test_hermite_passes_through_keyframes_and_matches_appendix_a(rv):
    ds_dc = toe_off_phase(DC)
    frames = keyframes_deg(rv, ds_dc)
    for joint in ("hip", "knee", "ankle"):
        phases, values = frames[joint]
        got = hermite_periodic(np.asarray(phases), phases, values)
        np.testing.assert_allclose(got, values, atol=1e-12)
        grid = np.linspace(0, 1, 97, endpoint=False)
        mine = [my_hermite(t, table_keyframes(rv, ds_dc)[joint]) for t in grid]
        np.testing.assert_allclose(hermite_periodic(grid, phases, values), mine, atol=1e-9)


def test_hermite_hand_values():
    """Two keyframes (0.2, 10) and (0.6, 30): midway the blend is 20, a quarter of the way
    10 + 20 * (-2/64 + 3/16) = 13.125; wrapping from 0.6 to 1.2, at phase 0.9 it is 20 again."""
    p, v = np.array([0.2, 0.6]), np.array([10.0, 30.0])
    np.testing.assert_allclose(hermite_periodic([0.4, 0.3, 0.9, 0.2, 0.6], p, v), [20, 13.125, 20, 10, 30], atol=1e-12)


def test_right_leg_half_a_cycle_behind():
    phase = np.linspace(0.0, 1.0, 200, endpoint=False)
    for rv in (0.2, 0.9):
        both = pose_rad(rv, phase, DC)
        shifted = pose_rad(rv, (phase + 0.5) % 1.0, DC)
        np.testing.assert_allclose(both[:, 3:], shifted[:, :3], atol=1e-12)
        # and the left leg is the table's curve, in radians
        mine = np.radians([my_leg_deg(rv, t, toe_off_phase(DC)) for t in phase[::20]])
        np.testing.assert_allclose(both[::20, :3], mine, atol=1e-9)


# --------------------------------------------------------------------------------------------
# 3. Bezier (Bernstein) weighting
# --------------------------------------------------------------------------------------------
def test_bernstein_hand_values():
    np.testing.assert_allclose(bernstein_weights(2, 0.5)[0], [0.25, 0.5, 0.25], atol=1e-15)
    np.testing.assert_allclose(bernstein_weights(3, 1 / 3)[0], [8 / 27, 12 / 27, 6 / 27, 1 / 27], atol=1e-15)


@pytest.mark.parametrize("degree", [1, 2, 3, 5, 8])
def test_bernstein_weights_sum_to_one(degree):
    u = np.random.default_rng(degree).random(200)
    w = bernstein_weights(degree, np.concatenate([[0.0, 1.0], u]))
    assert w.shape == (202, degree + 1)
    np.testing.assert_allclose(w.sum(axis=1), 1.0, atol=1e-13)
    assert np.all(w >= 0)
    np.testing.assert_array_equal(w[0], np.eye(degree + 1)[0])
    np.testing.assert_array_equal(w[1], np.eye(degree + 1)[-1])


@pytest.mark.parametrize("rvs", [(0.1, 0.3), (0.05, 0.2, 0.35, 0.48), (0.4, 0.0, 0.2, 0.1, 0.3)])
def test_bezier_keeps_end_poses(rvs):
    blend = BoulicBlend(rvs, DC)
    phase = np.linspace(0.0, 1.0, 101)
    for u, rv in ((0.0, rvs[0]), (1.0, rvs[-1])):
        got = blend.leg(phase, np.full_like(phase, u))
        want = pose_rad(rv, phase, DC)[:, :3]
        np.testing.assert_allclose(got, want, atol=1e-12)
    # in between, a weighted mean: each joint within the range of the poses it blends
    mid = blend.leg(phase, np.full_like(phase, 0.5))
    stack = np.stack([pose_rad(rv, phase, DC)[:, :3] for rv in rvs])
    assert np.all(mid >= stack.min(axis=0) - 1e-12) and np.all(mid <= stack.max(axis=0) + 1e-12)
