"""Whole walks checked from the outside: only the emitted joint angles and root are used.

The forward kinematics below is written here from docs/gait-model.md section 1, independently of
gaitbot.gait.geometry: thigh direction h from the downward vertical, shank h - k, sole pitch
(h - k) + a from the horizontal (toe up positive); the sole lies ``ankle_height`` below the ankle,
perpendicular to the sole; the heel is ``heel_back`` behind the ankle's projection on the sole
(0 for seed 000's leg) and the toe is ``foot`` ahead of the heel along the sole. Both hips sit at the root point (sagittal plane).

The plan (step start/end times, the swinging leg, toe-off share) is read from ``plan_walk`` only to
know *when* each invariant applies; every position is recomputed here from angles and root.
"""

from __future__ import annotations

import glob
import math
import os
from dataclasses import dataclass

import numpy as np
import pytest

from gaitbot.gait import (TABLE1_LEG, LegGeometry, WalkSettings, generate_walk, perturb_steps,
                          steps_for_distance)
from gaitbot.gait.walker import plan_walk, trajectory_of
from gaitbot.robot.config import load_robot_config
from gaitbot.robot.walk_settings import leg_geometry, walk_settings
from helpers import CONFIG_DIR as REPO_CONFIG_DIR, swing_clearances

CONFIG_DIR = str(REPO_CONFIG_DIR)
CONFIG_FILES = sorted(glob.glob(os.path.join(CONFIG_DIR, "*.toml")))
LEGS = ("left", "right")


# --------------------------------------------------------------------------------------------
# independent forward kinematics
# --------------------------------------------------------------------------------------------
def fk_leg(q: np.ndarray, thigh: float, shank: float, foot: float, ankle_height: float,
           heel_back: float = 0.0) -> dict:
    """Knee, ankle, heel and toe relative to the hip for leg angles q (n, 3) = hip, knee, ankle flexion."""
    h, k, a = q[:, 0], q[:, 1], q[:, 2]
    knee = np.column_stack([thigh * np.sin(h), -thigh * np.cos(h)])
    ankle = knee + np.column_stack([shank * np.sin(h - k), -shank * np.cos(h - k)])
    p = (h - k) + a
    # unit vector along the sole (cos p, sin p); "down, perpendicular to the sole" is (sin p, -cos p)
    along_sole = np.column_stack([np.cos(p), np.sin(p)])
    heel = ankle + ankle_height * np.column_stack([np.sin(p), -np.cos(p)]) - heel_back * along_sole
    toe = heel + foot * along_sole
    return {"knee": knee, "ankle": ankle, "heel": heel, "toe": toe, "pitch": p}


@dataclass
class Walk:
    geometry: LegGeometry
    settings: WalkSettings
    steps: list
    walker: object
    traj: object
    pts: dict  # pts[leg][point] -> (N, 2) world positions
    rate: float

    @property
    def L(self) -> float:
        return self.geometry.thigh + self.geometry.shank

    def frame(self, t: float) -> int:
        i = round(t * self.rate)
        assert abs(i - t * self.rate) < 1e-6, f"time {t} does not fall on a frame"
        return i

    def lowest(self, leg: str) -> np.ndarray:
        return np.minimum(self.pts[leg]["heel"][:, 1], self.pts[leg]["toe"][:, 1])

    def real_steps(self):
        return [s for s in self.walker.planned_steps]

    def stance_leg_per_frame(self) -> list:
        """Leg locked on the ground at each frame: the non-swinging leg during each step;
        'both' before the first step (crouch from standing) and after the last (settle, stand)."""
        n = len(self.traj)
        out = ["both"] * n
        for s in self.walker.planned_steps:
            a, b = self.frame(s.start_s), self.frame(s.end_s)
            other = "left" if s.leg == "right" else "right"
            for i in range(a, b):
                out[i] = other
        return out

    def swing_windows(self):
        """(step, toe-off frame time, heel strike time) for each planned step."""
        u = self.walker.ctx.toe_off_u
        for s in self.walker.planned_steps:
            yield s, s.start_s + u * (s.end_s - s.start_s), s.end_s


def make_walk(geometry: LegGeometry, steps, settings: WalkSettings | None = None) -> Walk:
    settings = settings or WalkSettings()
    walker = plan_walk(geometry, steps, settings)
    traj = trajectory_of(walker)
    g = geometry
    pts = {}
    for j, leg in enumerate(LEGS):
        rel = fk_leg(traj.angles_rad[:, 3 * j:3 * j + 3], g.thigh, g.shank, g.foot, g.ankle_height, g.heel_back)
        pts[leg] = {k: (v + traj.root_xz_m if k != "pitch" else v) for k, v in rel.items()}
    rate = 1.0 / (traj.t_s[1] - traj.t_s[0])
    return Walk(g, settings, list(steps), walker, traj, pts, rate)


# --------------------------------------------------------------------------------------------
# the walks under test
# --------------------------------------------------------------------------------------------
DITCH = [round(0.05 * i, 2) for i in range(1, 16)]  # seed 000's 15-step ditch crossing 0.05 .. 0.75
TABLE1_CASES = {
    "constant_0.3": [0.3] * 6,
    "mixed": [0.05, 0.75, 0.1, 0.6, 0.0, 0.4],
    "ditch_15": DITCH,
    "perturbed": perturb_steps(steps_for_distance(3.0, 0.5), 0.05, seed=7, max_step=0.75),
    "left_right_0.4_0.34": [0.4, 0.34] * 3,
}


def _robot(path):
    cfg = load_robot_config(path)
    return cfg, leg_geometry(cfg), walk_settings(cfg)


def _robot_cases():
    """Walks of every shipped robot the planar walker drives: the pitch-only ones. A robot whose legs roll
    (``is_3d``) walks with the balanced walker, checked in tests/gait/test_balance_*.py."""
    cases = {}
    for path in CONFIG_FILES:
        cfg, g, s = _robot(path)
        if cfg.is_3d:
            continue
        m = cfg.gait.max_step_m
        name = os.path.basename(path)[:-5]
        cases[f"{name}-constant"] = (g, s, [0.6 * m] * 6)
        cases[f"{name}-mixed"] = (g, s, [0.1 * m, m, 0.15 * m, 0.8 * m, 0.0, 0.5 * m])
        cases[f"{name}-perturbed"] = (g, s, perturb_steps(steps_for_distance(6 * m, m), 0.1 * m, seed=3, max_step=m))
    return cases


ROBOT_CASES = _robot_cases()
SETTINGS_CASES = {  # Table 1's leg with other settings: 50 Hz (1.346 s is not a whole number of frames), m = 0 and 5
    "rate_50hz": (TABLE1_LEG, WalkSettings(rate_hz=50.0), [0.3, 0.55, 0.15, 0.0, 0.25]),
    "intermediate_0": (TABLE1_LEG, WalkSettings(intermediate_steps=0), [0.1, 0.6, 0.2, 0.3]),
    "intermediate_5": (TABLE1_LEG, WalkSettings(intermediate_steps=5), [0.1, 0.6, 0.2, 0.3]),
}
ALL_CASES = {**{k: (TABLE1_LEG, WalkSettings(), v) for k, v in TABLE1_CASES.items()}, **SETTINGS_CASES, **ROBOT_CASES}
_CACHE: dict = {}


def walk_for(name: str) -> Walk:
    if name not in _CACHE:
        g, s, steps = ALL_CASES[name]
        _CACHE[name] = make_walk(g, steps, s)
    return _CACHE[name]


def test_shipped_configs_found():
    assert len(CONFIG_FILES) >= 3, CONFIG_FILES


def test_fk_self_check():
    """The FK above on hand poses: standing straight, hip 90 deg, knee 90 deg (shank and sole pointing
    back and down), ankle 90 deg (toe straight up)."""
    q = np.radians([[0, 0, 0], [90, 0, 0], [0, 90, 0], [0, 0, 90]])
    r = fk_leg(q, 0.4, 0.6, 0.2, 0.05)
    np.testing.assert_allclose(r["ankle"], [[0, -1.0], [1.0, 0], [-0.6, -0.4], [0, -1.0]], atol=1e-12)
    np.testing.assert_allclose(r["heel"], [[0, -1.05], [1.05, 0], [-0.65, -0.4], [0.05, -1.0]], atol=1e-12)
    np.testing.assert_allclose(r["toe"], [[0.2, -1.05], [1.05, 0.2], [-0.65, -0.6], [0.05, -0.8]], atol=1e-12)


# --------------------------------------------------------------------------------------------
# (a) .. (e), (g), (h) on every case
# --------------------------------------------------------------------------------------------
@pytest.mark.parametrize("name", list(ALL_CASES))
def test_locked_contact_point_never_slides(name):
    """(a) The stance foot's lower point (heel or toe) does not move while it stays the same point."""
    w = walk_for(name)
    stance = w.stance_leg_per_frame()
    worst = 0.0
    for i in range(len(w.traj) - 1):
        legs = LEGS if stance[i] == "both" else (stance[i],)
        for leg in legs:
            heel, toe = w.pts[leg]["heel"], w.pts[leg]["toe"]
            lower_now = "heel" if heel[i, 1] <= toe[i, 1] else "toe"
            lower_next = "heel" if heel[i + 1, 1] <= toe[i + 1, 1] else "toe"
            if lower_now != lower_next:
                continue
            p = w.pts[leg][lower_now]
            worst = max(worst, float(np.hypot(*(p[i + 1] - p[i]))))
    assert worst < 1e-9 * w.L, f"locked contact point moved {worst / w.L:.3g} leg lengths in one frame"


@pytest.mark.parametrize("name", list(ALL_CASES))
def test_rear_foot_pinned_until_toe_off(name):
    """Double support: the rear (about to swing) foot also stays put until its toe-off."""
    w = walk_for(name)
    worst = 0.0
    for s, t_off, _ in w.swing_windows():
        a, b = w.frame(s.start_s), int(math.floor(t_off * w.rate + 1e-9))
        heel, toe = w.pts[s.leg]["heel"], w.pts[s.leg]["toe"]
        for i in range(a, b):
            lower_now = "heel" if heel[i, 1] <= toe[i, 1] else "toe"
            lower_next = "heel" if heel[i + 1, 1] <= toe[i + 1, 1] else "toe"
            if lower_now == lower_next:
                p = w.pts[s.leg][lower_now]
                worst = max(worst, float(np.hypot(*(p[i + 1] - p[i]))))
            assert min(heel[i, 1], toe[i, 1]) < 1e-9 * w.L, f"rear foot off the ground before toe-off at frame {i}"
    assert worst < 1e-9 * w.L, f"rear foot slid {worst / w.L:.3g} leg lengths in one frame"


@pytest.mark.parametrize("name", list(ALL_CASES))
def test_nothing_below_ground_and_someone_on_it(name):
    """(b) no point of either leg below ground by more than 1e-4 L; (c) at every frame a foot is on the ground."""
    w = walk_for(name)
    deepest = min(float(w.pts[leg][p][:, 1].min()) for leg in LEGS for p in ("heel", "toe", "ankle", "knee"))
    assert deepest >= -1e-4 * w.L, f"a leg point is {-deepest / w.L:.3g} leg lengths below ground"
    lowest = np.minimum(w.lowest("left"), w.lowest("right"))
    assert float(np.abs(lowest).max()) <= 1e-9 * w.L, (
        f"lowest foot point {lowest[np.argmax(np.abs(lowest))] / w.L:.3g} L off the ground "
        f"at frame {int(np.argmax(np.abs(lowest)))}")


@pytest.mark.parametrize("name", list(ALL_CASES))
def test_stance_foot_on_ground(name):
    """The stance foot itself (not just some foot) touches the ground at every frame of its stance."""
    w = walk_for(name)
    stance = w.stance_leg_per_frame()
    for i, leg in enumerate(stance):
        legs = LEGS if leg == "both" else (leg,)
        for lg in legs:
            y = w.lowest(lg)[i]
            assert abs(y) <= 1e-9 * w.L, f"frame {i}: {lg} stance foot lowest point at {y / w.L:.3g} L"


@pytest.mark.parametrize("name", list(ALL_CASES))
def test_heel_strikes_at_planned_footholds(name):
    """(d) at each heel strike the landing heel is at (foothold, 0), footholds = cumulative step sums,
    and the rear foot is still on the ground (true double support)."""
    w = walk_for(name)
    x0 = w.pts["left"]["heel"][0, 0]
    expected = x0 + np.cumsum(w.steps)
    strikes = [s for s in w.walker.planned_steps if not s.closing]
    assert len(strikes) == len(w.steps)
    assert [s.length_m for s in strikes] == pytest.approx(list(w.steps), abs=1e-12)
    legs = [s.leg for s in strikes]
    assert legs == [("right", "left")[i % 2] for i in range(len(legs))], "legs must alternate, right first"
    for s, x in zip(strikes, expected):
        assert s.foothold_m == pytest.approx(x, abs=1e-9 * w.L)
        i = w.frame(s.end_s)
        heel = w.pts[s.leg]["heel"][i]
        assert abs(heel[0] - x) <= 1e-6 * w.L and abs(heel[1]) <= 1e-6 * w.L, (
            f"step {s.index}: {s.leg} heel at ({heel[0]:.9f}, {heel[1]:.3g}), foothold {x:.9f}")
        rear = "left" if s.leg == "right" else "right"
        assert abs(w.lowest(rear)[i]) <= 1e-9 * w.L, f"step {s.index}: rear foot not on the ground at heel strike"
    # the trajectory reports the same heel strikes
    got = [(h.leg, h.x_m) for h in w.traj.heel_strikes]
    assert [g[0] for g in got[:len(strikes)]] == legs
    np.testing.assert_allclose([g[1] for g in got[:len(strikes)]], expected, atol=1e-9 * w.L)


def swing_clearance_failures(w: Walk) -> list:
    out = []
    c = w.settings.clearance
    for s, t_off, t_end in w.swing_windows():
        dur = t_end - t_off
        lo, hi = t_off + 0.2 * dur, t_off + 0.8 * dur
        idx = [i for i in range(len(w.traj)) if lo - 1e-9 <= w.traj.t_s[i] <= hi + 1e-9]
        assert idx, "no frames in the swing window"
        y = w.lowest(s.leg)[idx]
        if y.min() < c - 1e-9 * w.L:
            out.append(f"step {s.index} ({s.leg}, {s.length_m:g}): swing sole {y.min():.6g} above ground, clearance {c:g}")
    return out


@pytest.mark.parametrize("name", ALL_CASES)
def test_swing_clearance(name):
    """(e) whole swing sole at least the configured clearance above ground from 20% to 80% of each swing."""
    w = walk_for(name)
    failures = swing_clearance_failures(w)
    assert not failures, "; ".join(failures)


@pytest.mark.parametrize("name", ROBOT_CASES)
def test_swing_keeps_the_clearance_while_the_foot_moves_forward(name):
    """docs/gait.md's rule, the one terrain walks answer to too (tests/helpers.py ``swing_clearances``, own FK):
    the whole sole at least the configured clearance above the ground while the ankle covers 10% to 90% of
    its travel, and off the ground within 5% of the swing's time."""
    cfg = load_robot_config(os.path.join(CONFIG_DIR, name.rsplit("-", 1)[0] + ".toml"))
    w = walk_for(name)
    found = swing_clearances(cfg, w.traj)
    assert len(found) >= 4
    for travel, least, lift_off in found:
        assert least >= cfg.gait.clearance_m * (1 - 1e-3), f"a swing of {travel:.3f} m lifts only {least * 1000:.1f} mm"
        assert lift_off <= 0.05


@pytest.mark.parametrize("name", list(ALL_CASES))
def test_starts_and_ends_standing_feet_together(name):
    """(g) all joint angles 0 at the first and last frame, heels side by side; ends at the last foothold."""
    w = walk_for(name)
    q = w.traj.angles_rad
    np.testing.assert_allclose(q[0], 0.0, atol=1e-12)
    np.testing.assert_allclose(q[-1], 0.0, atol=1e-12)
    for i in (0, -1):
        assert w.pts["left"]["heel"][i, 0] == pytest.approx(w.pts["right"]["heel"][i, 0], abs=1e-12)
        assert w.traj.root_xz_m[i, 1] == pytest.approx(w.geometry.leg_length + w.geometry.ankle_height, abs=1e-12)
    x0 = w.pts["left"]["heel"][0, 0]
    assert w.pts["left"]["heel"][-1, 0] == pytest.approx(x0 + sum(w.steps), abs=1e-9 * w.L)


def second_difference_dps2(w: Walk) -> np.ndarray:
    q = np.degrees(w.traj.angles_rad)
    return (q[2:] - 2 * q[1:-1] + q[:-2]) * w.rate**2


@pytest.mark.parametrize("name", list(ROBOT_CASES))
def test_robot_joint_acceleration_under_servo_limit(name):
    """(h) velocities continuous: for robot walks within max_step_m, the frame-to-frame change of
    joint velocity stays under the shipped configs' max_acceleration_dps2 = 12000 deg/s^2 (times dt).

    A velocity jump of dv deg/s at one frame would show as a second difference of dv * rate, i.e.
    any jump above 12000 / 60 = 200 deg/s is caught."""
    w = walk_for(name)
    acc = np.abs(second_difference_dps2(w))
    i, j = np.unravel_index(int(np.argmax(acc)), acc.shape)
    assert acc.max() < 12000.0, f"joint {j} accelerates {acc.max():.0f} deg/s^2 at frame {i + 1}"


def velocity_jumps(angles_deg: np.ndarray, rate: float) -> np.ndarray:
    """J_i = |dv_i - (dv_(i-2) + dv_(i+2)) / 2|, dv_i the frame-to-frame change of joint velocity (deg/s).

    If the velocity is continuous and |acceleration| <= A everywhere, |dv_i| <= A dt for every i, so
    J <= 2 A dt. A velocity jump of size V at one instant adds V to one dv_i (or splits it between two
    neighbours) and shows as J ~ V whatever the frame rate, while smooth motion gives J -> 0 as dt -> 0."""
    v = np.diff(angles_deg, axis=0) * rate
    dv = np.diff(v, axis=0)
    return np.abs(dv[2:-2] - 0.5 * (dv[:-4] + dv[4:]))


CONTINUITY_RATE_HZ = 960.0  # 16 x the 60 Hz stream: any true velocity jump stands out of the smooth part
CONTINUITY_CASES = ["constant_0.3"] + [k for k in ROBOT_CASES if not k.endswith("perturbed")]


@pytest.mark.parametrize("name", CONTINUITY_CASES)
def test_joint_velocity_continuous(name):
    """(h) joint velocities continuous, judged at 960 Hz with the same cycle: J (see velocity_jumps) must
    stay under 2 A dt, with A = 12000 deg/s^2 (the shipped configs' max_acceleration_dps2) for robots
    and the same limit scaled to Table 1's 1.346 s cycle, 12000 (2.4 / 1.346)^2, for the human leg
    (angles do not depend on leg size and accelerations scale with 1 / cycle^2)."""
    g, s, steps = ALL_CASES[name]
    fine = WalkSettings(cycle_s=s.cycle_s, rate_hz=CONTINUITY_RATE_HZ, clearance=s.clearance)
    w = make_walk(g, steps, fine)
    a_max = 12000.0 * (2.4 / s.cycle_s) ** 2 if g == TABLE1_LEG else 12000.0
    bound = 2 * a_max / CONTINUITY_RATE_HZ
    j = velocity_jumps(np.degrees(w.traj.angles_rad), w.rate)
    i, k = np.unravel_index(int(np.argmax(j)), j.shape)
    assert j.max() < bound, f"joint {k} velocity jumps {j.max():.1f} deg/s at frame {i + 3} of {len(w.traj)} (bound {bound:.1f})"


def test_velocity_jump_measure():
    """The measure flags a kink and passes smooth motion of high acceleration."""
    rate = 960.0
    t = np.arange(2000) / rate
    smooth = 40.0 * np.sin(2 * np.pi * 2.0 * t)  # peak acceleration 40 (4 pi)^2 = 6317 deg/s^2
    assert velocity_jumps(smooth[:, None], rate).max() < 0.1
    kink = smooth + np.where(t < 1.0, 0.0, 30.0 * (t - 1.0))  # plus a 30 deg/s velocity jump
    assert velocity_jumps(kink[:, None], rate).max() > 25.0


def test_velocity_jump_would_be_caught():
    """The acceleration check can fail: a kink (velocity jump of 300 deg/s) in a smooth ramp is flagged."""
    rate = 60.0
    t = np.arange(120) / rate
    q = np.where(t < 1.0, 0.0, 300.0 * (t - 1.0))  # deg, velocity jumps from 0 to 300 deg/s
    acc = np.abs(q[2:] - 2 * q[1:-1] + q[:-2]) * rate**2
    assert acc.max() > 12000.0


# --------------------------------------------------------------------------------------------
# (f) no climbing, no drift over 100 steps
# --------------------------------------------------------------------------------------------
def test_hundred_steps_same_height_no_drift():
    steps = [0.3] * 100
    w = make_walk(TABLE1_LEG, steps)
    strikes = [s for s in w.walker.planned_steps if not s.closing]
    assert len(strikes) == 100
    frames = [w.frame(s.end_s) for s in strikes]
    y = w.traj.root_xz_m[frames, 1]
    # the same pose at every heel strike of a constant walk: the body is exactly as high after 100 steps
    assert float(y.max() - y.min()) <= 1e-9, f"root height at heel strikes varies by {y.max() - y.min():.3g} L"
    # no drift: the hip sits the same distance behind the landing heel at every strike
    behind = w.traj.root_m[frames, 0] - w.pts["left"]["heel"][0, 0] - np.cumsum(steps)
    assert float(behind.max() - behind.min()) <= 1e-9
    # steady state: step 50 and step 98 have the same whole root path, relative to their footholds
    a0, b0 = w.frame(strikes[49].start_s), w.frame(strikes[49].end_s)
    a1, b1 = w.frame(strikes[97].start_s), w.frame(strikes[97].end_s)
    r0 = w.traj.root_xz_m[a0:b0] - [strikes[49].foothold_m, 0]
    r1 = w.traj.root_xz_m[a1:b1] - [strikes[97].foothold_m, 0]
    np.testing.assert_allclose(r0, r1, atol=1e-9)


# --------------------------------------------------------------------------------------------
# 5. every step length from 0 to the reachable maximum walks, and no jitter near zero
# --------------------------------------------------------------------------------------------
SWEEP = [round(0.05 * i, 2) for i in range(16)]  # 0, 0.05, ..., 0.75


@pytest.mark.parametrize("sl", SWEEP)
def test_sweep_constant_walks(sl):
    """Every step length from 0 to 0.75 walks: ground contact, no penetration, footholds, standing ends."""
    w = sweep_walk(sl)
    L = w.L
    lowest = np.minimum(w.lowest("left"), w.lowest("right"))
    assert float(np.abs(lowest).max()) <= 1e-9 * L
    deepest = min(float(w.pts[leg][p][:, 1].min()) for leg in LEGS for p in ("heel", "toe"))
    assert deepest >= -1e-4 * L
    x0 = w.pts["left"]["heel"][0, 0]
    for k, s in enumerate([s for s in w.walker.planned_steps if not s.closing]):
        heel = w.pts[s.leg]["heel"][w.frame(s.end_s)]
        assert heel[0] == pytest.approx(x0 + sl * (k + 1), abs=1e-6 * L)
        assert heel[1] == pytest.approx(0.0, abs=1e-6 * L)
    np.testing.assert_allclose(w.traj.angles_rad[[0, -1]], 0.0, atol=1e-12)


_SWEEP_CACHE: dict = {}


def sweep_walk(sl: float) -> Walk:
    if sl not in _SWEEP_CACHE:
        _SWEEP_CACHE[sl] = make_walk(TABLE1_LEG, [sl] * 4)
    return _SWEEP_CACHE[sl]


@pytest.mark.parametrize("sl", SWEEP)
def test_sweep_clearance(sl):
    failures = swing_clearance_failures(sweep_walk(sl))
    assert not failures, "; ".join(failures)


def ground_intervals(w: Walk):
    """(leg, first frame, last frame) of every time a foot is on the ground: from the start (or its
    heel strike) to its next toe-off, or to the end of the walk (the closing step, settle and stand)."""
    u = w.walker.ctx.toe_off_u
    for leg in LEGS:
        start = 0
        for s in w.walker.planned_steps:
            if s.leg != leg:
                continue
            t_off = s.start_s + u * (s.end_s - s.start_s)
            yield leg, start, int(math.floor(t_off * w.rate + 1e-9))
            start = w.frame(s.end_s)
        yield leg, start, len(w.traj) - 1


def contact_sequence(w: Walk, leg: str, a: int, b: int, eps: float) -> list:
    """Heel ('H') or toe ('T') down at each frame, skipping frames where the sole is level within eps."""
    dy = w.pts[leg]["toe"][a:b + 1, 1] - w.pts[leg]["heel"][a:b + 1, 1]
    seq = []
    for d in dy:
        state = "H" if d > eps else ("T" if d < -eps else None)
        if state and (not seq or seq[-1] != state):
            seq.append(state)
    return seq


def jitter_failures(w: Walk) -> list:
    """Jitter measured: while a foot is on the ground it rolls heel -> toe at most once and never back
    (contact sequence one of [], H, T, H T; level within 1e-9 L counts as neither), and it never lifts off
    and lands again (its lowest point stays on the ground)."""
    out = []
    for leg, a, b in ground_intervals(w):
        seq = contact_sequence(w, leg, a, b, 1e-9 * w.L)
        if seq not in ([], ["H"], ["T"], ["H", "T"]):
            dy = w.pts[leg]["toe"][a:b + 1, 1] - w.pts[leg]["heel"][a:b + 1, 1]
            back = a + int(np.argmax(np.minimum.accumulate(dy) < -1e-9 * w.L))  # first frame toe-down
            after = dy[back - a:]
            peak = back + int(np.argmax(after))
            out.append(f"{leg} foot on the ground frames {a}-{b} rolls {'->'.join(seq)}: toe down from frame {back}, "
                       f"then toe up again by {after.max() / w.L:.3g} L at frame {peak}")
        low = w.lowest(leg)[a:b + 1]
        if float(np.abs(low).max()) > 1e-9 * w.L:
            out.append(f"{leg} foot leaves the ground within frames {a}-{b} ({low.max() / w.L:.3g} L)")
    return out


@pytest.mark.parametrize("sl", [0.0, 0.01, 0.02])
def test_no_jitter_near_zero_step_length(sl):
    """The paper's jitter near zero step length is gone (measure: see jitter_failures)."""
    w = make_walk(TABLE1_LEG, [sl] * 6)
    intervals = list(ground_intervals(w))
    assert len(intervals) >= 8
    failures = jitter_failures(w)
    assert not failures, "; ".join(failures)


@pytest.mark.parametrize("name", list(ALL_CASES))
def test_feet_roll_heel_to_toe_without_rocking(name):
    """Every walk: each time a foot is on the ground it rolls heel -> toe at most once, never back."""
    failures = jitter_failures(walk_for(name))
    assert not failures, "; ".join(failures)


@pytest.mark.parametrize("geometry_name, last", [
    ("table1", 0.3), ("table1", 0.5), ("table1", 0.75), ("xl430-biped", 0.06), ("xl430-biped", 0.1),
])
def test_rear_foot_settles_flat_without_overshoot(geometry_name, last):
    """After the closing step the rear foot, on its toe, rolls down to level and stops there: its pitch
    never passes level to toe-up (which would switch its pivot to the heel and rock the foot)."""
    if geometry_name == "table1":
        g, s = TABLE1_LEG, WalkSettings()
    else:
        _, g, s = _robot(os.path.join(CONFIG_DIR, geometry_name + ".toml"))
    w = make_walk(g, [last] * 3, s)
    closing = w.walker.planned_steps[-1]
    assert closing.closing
    rear = "left" if closing.leg == "right" else "right"
    e = w.frame(closing.end_s)
    pitch = w.pts[rear]["pitch"][e:]
    assert pitch[0] < 0, "the rear foot should be on its toe at the closing heel strike"
    assert float(pitch.max()) <= 1e-9, f"rear foot pitch reaches {np.degrees(pitch.max()):+.4f} deg toe-up"
    assert abs(pitch[-1]) <= 1e-12


FINE_RATE_HZ = 15360.0  # 256 x 60 Hz


@pytest.mark.parametrize("name", [
    "constant_0.3", "ditch_15", "xl430-biped-mixed", "xl430-biped-perturbed",
])
def test_joint_velocity_continuous_fine(name):
    """(h) as test_joint_velocity_continuous but at 15360 Hz, where the bound 2 A dt is 1.56 deg/s for the
    robots and 4.97 deg/s for Table 1's leg: a velocity jump bigger than that, anywhere in the walk
    (steps, closing step, settle, stand), fails."""
    g, s, steps = ALL_CASES[name]
    w = make_walk(g, steps, WalkSettings(cycle_s=s.cycle_s, rate_hz=FINE_RATE_HZ, clearance=s.clearance))
    a_max = 12000.0 * (2.4 / s.cycle_s) ** 2 if g == TABLE1_LEG else 12000.0
    bound = 2 * a_max / FINE_RATE_HZ
    j = velocity_jumps(np.degrees(w.traj.angles_rad), w.rate)
    i, k = np.unravel_index(int(np.argmax(j)), j.shape)
    assert j.max() < bound, (f"joint {k} velocity jumps {j.max():.2f} deg/s at frame {i + 3} of {len(w.traj)} "
                             f"(bound {bound:.2f})")


def test_jitter_measure_can_fail():
    """The contact-sequence measure flags a foot rocking heel -> toe -> heel."""

    class Fake:
        pts = {"left": {"heel": np.array([[0, 0.0], [0, 0.0], [0, 0.01], [0, 0.0]]),
                        "toe": np.array([[0.2, 0.01], [0.2, 0.0], [0.2, 0.0], [0.2, 0.02]])}}

    assert contact_sequence(Fake, "left", 0, 3, 1e-9) == ["H", "T", "H"]


def test_generate_walk_equals_plan_walk_frames():
    steps = [0.2, 0.3]
    a = generate_walk(TABLE1_LEG, steps)
    b = trajectory_of(plan_walk(TABLE1_LEG, steps))
    assert np.array_equal(a.angles_rad, b.angles_rad) and np.array_equal(a.root_m, b.root_m)
    assert np.array_equal(a.t_s, b.t_s)


# --------------------------------------------------------------------------------------------
# the checks above can fail: each is run on a walk corrupted on purpose
# --------------------------------------------------------------------------------------------
def _corrupt(name: str, root_fn=None, angles_fn=None) -> str:
    from gaitbot.gait import Trajectory

    w = walk_for(name)
    root, angles = w.traj.root_xz_m.copy(), w.traj.angles_rad.copy()
    if root_fn:
        root_fn(w, root)
    if angles_fn:
        angles_fn(w, angles)
    traj = Trajectory.sagittal(w.traj.t_s, angles, root, w.traj.heel_strikes)
    g = w.geometry
    pts = {}
    for j, leg in enumerate(LEGS):
        rel = fk_leg(angles[:, 3 * j:3 * j + 3], g.thigh, g.shank, g.foot, g.ankle_height, g.heel_back)
        pts[leg] = {k: (v + root if k != "pitch" else v) for k, v in rel.items()}
    key = f"corrupt-{len(_CACHE)}"
    _CACHE[key] = Walk(g, w.settings, w.steps, w.walker, traj, pts, w.rate)
    return key


def _mid_step(w: Walk, k: int = 2) -> int:
    s = w.walker.planned_steps[k]
    return (w.frame(s.start_s) + w.frame(s.end_s)) // 2


def _slide(w, root):
    root[_mid_step(w):, 0] += 1e-7 * w.L  # the whole body (and so the stance foot) slides 1e-7 L once


def _slide_far(w, root):
    root[_mid_step(w):, 0] += 1e-5 * w.L  # past the 1e-6 L foothold tolerance


def _sink(w, root):
    root[_mid_step(w), 1] -= 2e-4 * w.L


def _swing_low(w, root):
    s = w.walker.planned_steps[2]
    a, b = w.frame(s.start_s), w.frame(s.end_s)
    root[a:b, 1] -= w.settings.clearance  # whole body lower by the clearance over one step


def _not_standing(w, angles):
    angles[-1, 1] += 1e-9


def _kink(w, angles):
    i = _mid_step(w)
    angles[i:, 1] += np.radians(300.0 / w.rate) * np.arange(len(angles) - i)  # knee gains 300 deg/s at once


@pytest.mark.parametrize("check, corruption", [
    (test_locked_contact_point_never_slides, {"root_fn": _slide}),
    (test_nothing_below_ground_and_someone_on_it, {"root_fn": _sink}),
    (test_stance_foot_on_ground, {"root_fn": _sink}),
    (test_heel_strikes_at_planned_footholds, {"root_fn": _slide_far}),
    (test_swing_clearance, {"root_fn": _swing_low}),
    (test_starts_and_ends_standing_feet_together, {"angles_fn": _not_standing}),
])
def test_checks_catch_corrupted_walks(check, corruption):
    key = _corrupt("constant_0.3", **corruption)
    with pytest.raises(AssertionError):
        check(key)


def test_robot_acceleration_check_catches_a_kink():
    key = _corrupt("xl430-biped-constant", angles_fn=_kink)
    ROBOT_CASES[key] = ROBOT_CASES["xl430-biped-constant"]
    try:
        with pytest.raises(AssertionError):
            test_robot_joint_acceleration_under_servo_limit(key)
    finally:
        del ROBOT_CASES[key]
