"""Contact read back from angles (gait/footfall.py), checked against the walker and against the ground.

The walker plans its root and heel strikes; footfall.py must find nearly the same from the angles
alone, and the root it builds must keep a foot on the ground and the other never below it.
"""

from __future__ import annotations

import numpy as np
import pytest

from gaitbot.gait import generate_walk
from gaitbot.gait.footfall import ContactRoot, foot_heights_in_body, root_from_contact, swing_clearances
from gaitbot.gait.geometry import leg_points
from gaitbot.robot.walk_settings import leg_geometry, walk_settings
from gaitbot.app.options import load_robot

CFG = load_robot("xl430-biped")
LEG, SETTINGS = leg_geometry(CFG), walk_settings(CFG)


@pytest.fixture(scope="module")
def walker():
    return generate_walk(LEG, [0.03, 0.06, 0.09, 0.06, 0.04], SETTINGS)


def lowest_world_y(angles_rad, root):
    out = []
    for side in (0, 1):
        q = angles_rad[:, 3 * side:3 * side + 3]
        _, _, heel, toe = leg_points(LEG, q[:, 0], q[:, 1], q[:, 2])
        out.append(np.minimum(heel[:, 1], toe[:, 1]) + root[:, 1])
    return np.column_stack(out)


def test_the_root_from_contact_follows_the_walkers_own_root(walker):
    root, _ = root_from_contact(LEG, walker.angles_rad, walker.root_m[0])
    assert np.abs(root[:, 1] - walker.root_xz_m[:, 1]).max() < 1e-4  # heights: a tenth of a millimetre
    # the walker and the read-back hand the support over at different moments of double support, where
    # the walker's rear toe and front heel do not quite agree: 2.8 mm over this 0.28 m walk
    assert np.abs(root[:, 0] - walker.root_m[:, 0]).max() < 0.02 * walker.root_m[-1, 0]


def test_one_foot_is_always_on_the_ground_and_the_other_never_below_it(walker):
    root, stance = root_from_contact(LEG, walker.angles_rad, [0.0, 0.0])
    lows = lowest_world_y(walker.angles_rad, root)
    frames = np.arange(len(root))
    np.testing.assert_allclose(lows[frames, stance], 0.0, atol=1e-12)
    tol = 0.25 * 0.01 * LEG.leg_length  # ContactRoot's default hand-over tolerance
    assert lows.min() >= -tol - 1e-12
    assert np.abs(np.diff(root[:, 0])).max() < 0.01  # no jump at a hand-over (steps are ~1 mm per frame)


def test_frame_by_frame_equals_the_whole_motion_at_once(walker):
    whole, _ = root_from_contact(LEG, walker.angles_rad, [0.2, 0.0])
    tracker = ContactRoot(LEG, 0.2)
    one_by_one = np.array([tracker.update(q) for q in walker.angles_rad])
    np.testing.assert_array_equal(one_by_one, whole)


def test_foot_heights_in_body_are_the_lowest_sole_points(walker):
    heights = foot_heights_in_body(LEG, walker.angles_rad)
    np.testing.assert_allclose(heights, lowest_world_y(walker.angles_rad, np.zeros((len(walker), 2))), atol=1e-12)


def test_swing_clearance_of_the_walker_holds_its_configured_clearance(walker):
    found = swing_clearances(LEG, walker)
    assert len(found) == len(walker.heel_strikes)
    assert min(c for _, c in found) >= SETTINGS.clearance
    lower = walker.__class__(walker.t_s, walker.angles_rad, walker.root_m - [0.0, 0.0, 0.005], walker.heel_strikes)
    assert max(c for _, c in swing_clearances(LEG, lower)) < max(c for _, c in found)
