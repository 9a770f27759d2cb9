"""OnlineWalker (seed 000 Algorithm 2, frame by frame) against the offline generate_walk."""

from __future__ import annotations

import numpy as np
import pytest

from gaitbot.gait import TABLE1_LEG, LegGeometry, OnlineWalker, WalkSettings, generate_walk

ROBOT_LEG = LegGeometry(thigh=0.11, shank=0.11, foot=0.12, hip_width=0.07, ankle_height=0.0305)
ROBOT_SETTINGS = WalkSettings(cycle_s=2.4, rate_hz=60.0, clearance=0.012)


def drain(walker: OnlineWalker, limit: int = 100000):
    frames = []
    while True:
        f = walker.next_frame()
        if f is None:
            return frames
        frames.append(f)
        assert len(frames) < limit


def as_arrays(frames):
    t = np.array([f[0] for f in frames])
    q = np.array([f[1] for f in frames])
    r = np.array([f[2] for f in frames])
    return t, q, r


def assert_same_as_offline(frames, geometry, steps, settings):
    t, q, r = as_arrays(frames)
    off = generate_walk(geometry, steps, settings)
    assert len(t) == len(off)
    assert np.array_equal(q, off.angles_rad), f"angles differ by {np.abs(q - off.angles_rad).max():.3g} rad"
    assert np.array_equal(r, off.root_xz_m), f"root differs by {np.abs(r - off.root_xz_m).max():.3g}"
    np.testing.assert_allclose(t, off.t_s, rtol=0, atol=1e-12)
    np.testing.assert_allclose(np.diff(t), 1.0 / settings.rate_hz, atol=1e-12)


CASES = [
    (TABLE1_LEG, WalkSettings(), [0.3, 0.5, 0.1, 0.0, 0.75]),
    (ROBOT_LEG, ROBOT_SETTINGS, [0.05, 0.1, 0.02, 0.08]),
]


@pytest.mark.parametrize("geometry, settings, steps", CASES)
def test_steps_appended_one_at_a_time_equal_offline(geometry, settings, steps):
    walker = OnlineWalker(geometry, settings)
    for sl in steps:
        walker.append_step(sl)
    walker.finish()
    assert walker.finished
    assert_same_as_offline(drain(walker), geometry, steps, settings)
    assert walker.next_frame() is None


@pytest.mark.parametrize("geometry, settings, steps", CASES)
def test_steps_appended_while_walking(geometry, settings, steps):
    """Consume frames between appends (the queue never runs dry): still the offline walk, frame for frame."""
    walker = OnlineWalker(geometry, settings)
    frames = []
    walker.append_step(steps[0])
    for sl in steps[1:]:
        # take all but a few of the frames queued so far, then queue the next step
        queued = walker.ctx.settle_frames + walker.ctx.step_frames * len(walker.planned_steps) - len(frames)
        for _ in range(queued - 3):
            frames.append(walker.next_frame())
        walker.append_step(sl)
    walker.finish()
    frames += drain(walker)
    assert_same_as_offline(frames, geometry, steps, settings)
    heel = [(h.leg, h.x_m) for h in walker.heel_strikes]
    off = generate_walk(geometry, steps, settings)
    assert heel == [(h.leg, h.x_m) for h in off.heel_strikes]


def test_queue_running_dry_closes_and_stands():
    steps = [0.3, 0.4]
    walker = OnlineWalker(TABLE1_LEG)
    for sl in steps:
        walker.append_step(sl)
    frames = drain(walker)  # never call finish: the walker must close by itself
    assert walker.finished
    t, q, r = as_arrays(frames)
    np.testing.assert_allclose(q[-1], 0.0, atol=1e-12)  # standing
    assert r[-1, 1] == pytest.approx(TABLE1_LEG.leg_length, abs=1e-12)
    # closing step: the trailing foot comes beside the leading one at the last foothold
    closing = walker.planned_steps[-1]
    assert closing.closing and closing.length_m == 0.0 and closing.foothold_m == pytest.approx(0.7)
    assert_same_as_offline(frames, TABLE1_LEG, steps, WalkSettings())
    assert walker.next_frame() is None
    with pytest.raises(RuntimeError):
        walker.append_step(0.2)


def test_walker_with_no_steps_just_stands():
    walker = OnlineWalker(TABLE1_LEG)
    t, q, r = as_arrays(drain(walker))
    np.testing.assert_allclose(q[[0, -1]], 0.0, atol=1e-12)
    assert r[-1, 0] == pytest.approx(0.0, abs=1e-12)  # back over the feet, which never went anywhere
    assert [s.length_m for s in walker.planned_steps] == [0.0]
    assert [h.x_m for h in walker.heel_strikes] == [0.0]


def test_dry_queue_then_no_more_frames_and_finish_is_idempotent():
    walker = OnlineWalker(TABLE1_LEG)
    walker.append_step(0.2)
    n = len(drain(walker))
    walker.finish()
    assert walker.next_frame() is None
    assert n == len(generate_walk(TABLE1_LEG, [0.2]))
