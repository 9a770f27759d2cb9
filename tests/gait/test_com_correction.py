"""The measured CoM error fed to the preview controller (gaitbot.gait.balance.correction): its decay is the
controller's own closed loop (checked by running the controller twice, from states apart by the error), a
steady error settles where the derivation says, and the correction's ZMP never leaves the sole (checked
against the sole's rectangle from the robot's geometry directly)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from gaitbot.gait.balance.correction import ComCorrection, closed_loop, fraction_inside, support_polygon
from gaitbot.gait.balance.preview import PreviewController, preview_gains
from helpers import config

DT = 1 / 60
HORIZON = 60


def two_runs(gains, dz0, frames):
    """The CoM state difference (frames + 1, 3) of two preview controllers on one (stepping) reference, the
    second started dz0 = (x, x', x'') away from the first: the controller's closed loop, simulated."""
    reference = np.zeros((frames + HORIZON + 1, 2))
    reference[20:, 0], reference[45:, 1] = 0.03, -0.02
    plan, moved = PreviewController(gains, [0.0, 0.0]), PreviewController(gains, [0.0, 0.0])
    moved.state[:, 0] += dz0
    out = [moved.state[:, 0] - plan.state[:, 0]]
    for k in range(frames):
        future = reference[k + 1:k + 1 + HORIZON]
        plan.step(reference[k], future)
        moved.step(reference[k], future)
        out.append(moved.state[:, 0] - plan.state[:, 0])
    return np.array(out)


@pytest.mark.parametrize("jerk_weight", [1e-6, 1e-2])
def test_the_closed_loop_is_the_controllers_response_to_a_state_error(jerk_weight):
    gains = preview_gains(0.24, DT, HORIZON, jerk_weight)
    m = closed_loop(gains)
    dz0 = np.array([0.01, -0.05, 0.3])
    runs = two_runs(gains, dz0, 120)
    z = np.concatenate([[0.0], dz0])
    for k in range(121):
        assert runs[k] == pytest.approx(z[1:], abs=1e-12)
        z = m @ z
    assert np.abs(runs[-1]).max() < 1e-2 * np.abs(dz0).max()  # it decays (2 s)


def test_an_error_felt_once_decays_as_the_controllers_response_less_the_error_left_standing():
    # fed once (no rate), then nothing: dz_k = M^(k-1) (M - I) g e4 = d_k - d_(k-1), d the controller's
    # response to the state error g e (two_runs)
    g, e = -0.3, 0.02
    corr = ComCorrection(preview_gains(0.24, DT, HORIZON), gain=g, dead_band_m=0.0, jerk_weight=1e-2)
    d = two_runs(preview_gains(0.24, DT, HORIZON, 1e-2), np.array([g * e, 0.0, 0.0]), 100)[:, 0]
    offsets = [corr.step((e, 0.0), (0.0, 0.0))[0]] + [corr.step((0.0, 0.0), (0.0, 0.0))[0] for _ in range(99)]
    assert np.array(offsets) == pytest.approx(d[1:] - d[:-1], abs=1e-12)


@pytest.mark.parametrize("g", [-0.3, 0.5])
def test_a_steady_error_settles_at_minus_gain_times_the_error_and_the_dead_band_feeds_nothing(g):
    corr = ComCorrection(preview_gains(0.24, DT, HORIZON), gain=g, dead_band_m=0.0)
    for _ in range(600):
        offset = corr.step((0.01, -0.02), (0.0, 0.0))
    assert offset == pytest.approx((-g * 0.01, g * 0.02), abs=1e-6)
    quiet = ComCorrection(preview_gains(0.24, DT, HORIZON), gain=g, dead_band_m=0.015)
    for _ in range(100):
        assert quiet.step((0.008, 0.0), (0.02, 0.0)) == (0.0, 0.0)  # DCM error 0.008 + 0.02 / 6.4 < 0.015
    with pytest.raises(ValueError):
        ComCorrection(preview_gains(0.24, DT, HORIZON), gain=1.5)


def sole_rectangle(geometry, ankle_x, ankle_y, side, share):
    """(x_lo, x_hi, y_lo, y_hi) of a straight foot's sole shrunk to ``share`` about its centre, from the
    geometry's definitions (gaitbot.gait.body: the sole's centre foot/2 - heel_back ahead of the ankle and
    sole_outward outward)."""
    cx = ankle_x + geometry.foot_m / 2 - geometry.heel_back_m
    cy = ankle_y + (1 if side == "left" else -1) * geometry.sole_outward_m
    hl, hw = share * geometry.foot_m / 2, share * geometry.foot_width_m / 2
    return cx - hl, cx + hl, cy - hw, cy + hw


@settings(max_examples=60, deadline=None)
@given(st.lists(st.tuples(st.floats(-0.08, 0.08), st.floats(-0.08, 0.08), st.floats(-0.6, 0.6),
                          st.floats(-0.6, 0.6)), min_size=5, max_size=40),
       st.sampled_from([-1.0, -0.3, 0.3, 1.0]), st.floats(-0.02, 0.02), st.floats(-0.015, 0.015))
def test_the_corrections_zmp_stays_inside_the_stance_sole(errors, gain, ref_dx, ref_dy):
    geometry = config("op3").body.geometry
    h = geometry.ankle_height_m
    ankles = np.array([[0.0, 0.05, h], [0.03, -0.05, h + 0.02]])  # the right foot swings: the left one stands
    hull = support_polygon(geometry, ankles, (0.0, 0.0), 0.8)
    x_lo, x_hi, y_lo, y_hi = sole_rectangle(geometry, 0.0, 0.05, "left", 0.8)
    ref = ((x_lo + x_hi) / 2 + ref_dx, (y_lo + y_hi) / 2 + ref_dy)  # the planned ZMP, inside the sole
    corr = ComCorrection(preview_gains(0.24, DT, HORIZON), gain=gain, dead_band_m=0.0, jerk_weight=1e-6)
    for ex, ey, vx, vy in errors:
        corr.step((ex, ey), (vx, vy), ref, hull)
        zx, zy = ref[0] + corr.zmp_shift_m[0], ref[1] + corr.zmp_shift_m[1]
        assert x_lo - 1e-9 <= zx <= x_hi + 1e-9 and y_lo - 1e-9 <= zy <= y_hi + 1e-9
        # the shift said is the correction's own: x - (z_c / g) x''
        for axis in range(2):
            s = corr.state[axis]
            assert corr.zmp_shift_m[axis] == pytest.approx(s[1] - corr.z_over_g * s[3], abs=1e-12)


def test_the_support_polygon_is_both_soles_in_double_support_and_a_point_outside_is_not_entered():
    geometry = config("op3").body.geometry
    h = geometry.ankle_height_m
    hull = support_polygon(geometry, np.array([[0.0, 0.05, h], [0.06, -0.05, h]]), (0.0, 0.0), 1.0)
    assert len(hull) >= 6  # two offset rectangles: a hexagon
    middle = (0.03 + geometry.foot_m / 2 - geometry.heel_back_m, 0.0)
    assert fraction_inside(middle, (0.0, 0.0), hull) == 1.0
    assert fraction_inside(middle, (1.0, 0.0), hull) < 0.1
    assert fraction_inside((1.0, 1.0), (0.0, 0.0), hull) == 0.0
    assert math.isclose(fraction_inside((0.5, 0.0), (0.0, 2.0), [(0, -1), (1, -1), (1, 1), (0, 1)]), 0.5)
