"""``--feedback zmp``: the plan's steps walked online with the measured CoM error fed to the preview controller
(gaitbot.gait.balance.correction through gaitbot.drive.stepping): nothing felt walks exactly the online plan,
a felt lean moves the CoM by a bounded, decaying correction, and where the walk is not a balanced plan of
steps the mode is refused in one line."""

from __future__ import annotations

import numpy as np
import pytest

from gaitbot.gait.balance.correction import DEAD_BAND_M
from helpers import Felt, op3_stepping_plan


@pytest.fixture(scope="module")
def op3_plan():
    return op3_stepping_plan()


def test_nothing_felt_walks_the_online_plan_and_a_lean_moves_the_com_within_bounds(op3_plan):
    from gaitbot.drive.stepping import SteppingFrames

    cfg, plan = op3_plan
    online = np.array(list(SteppingFrames(cfg, plan, Felt(started=False), stepping=False)))
    quiet = SteppingFrames(cfg, plan, Felt(), stepping=False, correction=True)
    assert np.array_equal(np.array(list(quiet)), online)  # inside the dead band: nothing fed
    assert quiet.correction_log.max_offset_m == 0.0
    leaning = SteppingFrames(cfg, plan, Felt(pitch_deg=10.0), stepping=False, correction={"gain": -0.3})
    frames = np.array(list(leaning))
    assert frames.shape == online.shape and np.abs(frames - online).max() > 0
    log = leaning.correction_log
    # a steady forward lean: the correction settles at -g e = 0.3 (z_c x 10 deg - the dead band), forward (3.5
    # mm on the op3), after an overshoot of the controller's integral term (about half as much again)
    z = leaning.walker.com_height_m
    settled = 0.3 * (z * np.radians(10.0) - DEAD_BAND_M)
    assert leaning.walker.com_offset_m == pytest.approx((settled, 0.0), abs=2e-4)
    assert settled < log.max_offset_m <= 1.7 * settled
    assert not leaning.log.moved  # zmp alone never moves a foothold


def test_the_corrections_zmp_stays_inside_the_support_polygon_of_each_frame(op3_plan):
    from gaitbot.drive.stepping import SteppingFrames
    from gaitbot.gait.balance.correction import fraction_inside, support_polygon

    cfg, plan = op3_plan
    frames = SteppingFrames(cfg, plan, Felt(roll_deg=-8.0, rates=(-60.0, 40.0, 0.0)), stepping=False,
                            correction={"gain": 1.0, "jerk_weight": 1e-6})
    walker, corr = frames.walker, None
    seen = 0
    for _ in frames:
        corr = frames.correction
        k = walker._k - 1
        if walker._out <= walker.rise_frames or k >= walker.planned_frames:
            continue
        hull = support_polygon(cfg.body.geometry, walker._ext_at("ankles", k), walker._ext_at("yaw", k))
        ref = walker._ext_at("zmp", k)
        point = (ref[0] + corr.zmp_shift_m[0], ref[1] + corr.zmp_shift_m[1])
        assert fraction_inside(point, (0.0, 0.0), hull) == 1.0 or fraction_inside(ref, (0.0, 0.0), hull) == 0.0
        seen += 1
    assert seen > 100 and corr.clipped > 0  # the clip was needed, and held


@pytest.mark.parametrize("argv, words", [
    (("drive", "--robot", "op3", "--sim", "--feedback", "zmp"), "--feedback zmp: the live drive"),
    (("walk", "--robot", "op3", "--dry-run", "--feedback", "zmp", "--velocity", "0.05,0,0", "--duration", "2"),
     "--feedback zmp: only a balanced walk"),
])
def test_zmp_where_the_walk_is_not_walked_online_is_refused_in_one_line(capsys, argv, words):
    from helpers import run_cli

    code, out, err = run_cli(capsys, *argv)
    assert code == 2 and words in err and len(err.strip().splitlines()) == 1
