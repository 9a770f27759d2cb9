"""tools/push_capturability.py, the capturability bound on push survival, against closed forms it does not use:
standing on both feet, a push is caught by the ankles alone iff the capture point it moves stays in the soles'
rectangle (J / (m omega) along the push, or for a push of duration T the same with the ZMP held on the edge
during it); the planned walk unpushed is always capturable; a larger push in the same direction at the same
moment is never easier to catch; and against a forward integration of the capture point (its own ZMP rule,
footholds on a grid or at random): what the bound loses no simulated step catches, what it catches with one step
or none a simulated one catches too."""

from __future__ import annotations

import math
import sys
from pathlib import Path

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "tools"))
import push_capturability as pc  # noqa: E402
from helpers import config  # noqa: E402

G = 9.81


def standing(cfg, z_c: float = 0.235) -> pc.Situation:
    """Both feet down side by side, the CoM still above their middle (ankle points at y = +-hip_width / 2)."""
    g = cfg.body.geometry
    half = g.hip_width_m / 2
    sole_x, sole_y = pc.sole_edges(g)
    return pc.Situation(t_s=0.0, xi0_m=(0.0, 0.0), omega=math.sqrt(G / z_c), mass_kg=cfg.body.total_kg,
                        feet_m={"left": (0.0, half), "right": (0.0, -half)}, stance="left", lift_s=math.inf,
                        land_s=None, step_s=0.4, double_s=0.0, speedup=1.0, sole_x_m=sole_x, sole_y_m=sole_y)


def ankle_threshold_n_s(cfg, z_c: float, direction_deg: float, duration_s: float) -> float:
    """The largest push the ankles hold standing, from the sole's rectangle (the geometry's own numbers): the
    distance from the capture point (the feet's middle) to the rectangle's edge along the push, times m omega;
    for a push of duration T with the ZMP held at the edge e, xi(T) - e = (xi0 - e) e^(wT) + F/(m w^2)(e^(wT) - 1)
    <= 0 gives J <= (e - xi0) m w (wT) / (1 - e^(-wT))."""
    g = cfg.body.geometry
    front = g.foot_m - g.heel_back_m  # the heel is as far behind the ankle: both edges equally far
    side = g.hip_width_m / 2 + g.sole_outward_m + g.foot_width_m / 2
    a = math.radians(direction_deg)
    reach = min(front / abs(math.cos(a)) if abs(math.cos(a)) > 1e-12 else math.inf,
                side / abs(math.sin(a)) if abs(math.sin(a)) > 1e-12 else math.inf)
    w = math.sqrt(G / z_c)
    factor = 1.0 if duration_s == 0 else w * duration_s / (1 - math.exp(-w * duration_s))
    return reach * cfg.body.total_kg * w * factor


@settings(max_examples=40, deadline=None)
@given(direction=st.floats(0, 360), duration=st.sampled_from([0.0, 0.1]), z_c=st.floats(0.15, 0.3))
def test_standing_the_ankles_alone_catch_a_push_iff_its_capture_point_stays_on_the_soles(direction, duration, z_c):
    cfg = config("op3")
    sit = standing(cfg, z_c)
    box = pc.StepBox(0.05, 0.03, 0.063, 0.11)  # no step is planned standing: the limits are not used
    limit = ankle_threshold_n_s(cfg, z_c, direction, duration)
    assert pc.capturable(sit, 0.99 * limit, direction, box, duration_s=duration)["ok"]
    assert not pc.capturable(sit, 1.01 * limit, direction, box, duration_s=duration)["ok"]


@pytest.fixture(scope="module")
def walk():
    from push_survival import WALKS

    return pc.plan_walk("op3", WALKS["op3"])


@pytest.mark.parametrize("phase", [i / 20 for i in range(21)])
def test_the_planned_walk_unpushed_is_always_capturable(walk, phase):
    sit = pc.situation_at(walk, pc.push_time_s(walk, phase))
    for box in (pc.steer_box(walk), pc.reach_box(walk)):
        assert pc.capturable(sit, 0.0, 0.0, box)["ok"]


@settings(max_examples=25, deadline=None)
@given(direction=st.floats(0, 360), phase=st.floats(0, 1), small=st.floats(0, 2.5), more=st.floats(0, 1.5))
def test_a_larger_push_the_same_way_at_the_same_moment_is_never_easier(walk, direction, phase, small, more):
    sit = pc.situation_at(walk, pc.push_time_s(walk, phase))
    for box in (pc.steer_box(walk), pc.reach_box(walk)):
        if pc.capturable(sit, small + more, direction, box)["ok"]:
            assert pc.capturable(sit, small, direction, box)["ok"]


def test_looser_limits_never_catch_fewer(walk):
    # (b) contains (a), and letting the feet cross or land at once contains both; the hips only add: a
    # relaxation never loses a push
    for impulse, direction, phase in pc.draws(30, 23, 2.0):
        sit = pc.situation_at(walk, pc.push_time_s(walk, phase))
        a = pc.capturable(sit, impulse, direction, pc.steer_box(walk))["ok"]
        hips = pc.capturable(sit, impulse, direction, pc.steer_box(walk), hip_m=pc.hip_allowance_m(walk.config,
                                                                                                   sit.omega))["ok"]
        assert not a or hips
        b = pc.capturable(sit, impulse, direction, pc.reach_box(walk))["ok"]
        free = pc.capturable(sit, impulse, direction, pc.crossing(pc.reach_box(walk)), immediate=True)["ok"]
        assert (not a or b) and (not b or free)


def test_the_step_boxes_follow_the_config(walk):
    cfg = walk.config
    g, lim = cfg.body.geometry, cfg.steer
    a = pc.steer_box(walk)
    # soles 17 mm apart side by side (hip width 70 mm, soles 78 mm wide, 12.5 mm outward): 7 mm of slack inward
    assert a.spread_min_m == pytest.approx(g.hip_width_m - (0.017 - lim.min_gap_m), abs=1e-9)
    assert a.spread_max_m == pytest.approx(g.hip_width_m + lim.max_side_m)
    assert a.backward_m == lim.max_backward_m and a.forward_m >= lim.max_forward_m
    r = pc.reach_m(walk)
    assert 0 < r < g.thigh_m + g.shank_m


def test_the_hip_allowance_is_the_flywheel_bound():
    # without the servos' speed limit the torso swings bang-bang to HIP_LEAN_DEG (no coast) and the capture point
    # moves back by tau / (m g) (1 - e^(-w t))^2, t = sqrt(lean I / tau) (Pratt et al.'s flywheel); with the limit,
    # the pivot moves only while the torso speeds up or stops, so the allowance is smaller
    from dataclasses import replace

    cfg = config("op3")
    omega = math.sqrt(G / 0.235)
    fast = replace(cfg, joints=tuple(replace(j, max_velocity_dps=1e9, max_acceleration_dps2=1e12) for j in cfg.joints))
    torso, hip = cfg.body.torso, cfg.body.geometry.hip_below_root_m
    dx, dz = torso.com_m[0], torso.com_m[2] + hip
    inertia = torso.inertia_kg_m2[1, 1] + torso.mass_kg * (dx * dx + dz * dz)
    tau = 2 * next(j for j in cfg.joints if j.name == "hip_pitch_left").model.stall_torque_nm
    t = math.sqrt(math.radians(pc.HIP_LEAN_DEG) * inertia / tau)
    expected = tau / (cfg.body.total_kg * G) * (1 - math.exp(-omega * t)) ** 2
    assert pc.hip_allowance_m(fast, omega)[0] == pytest.approx(expected, rel=1e-9)
    limited = pc.hip_allowance_m(cfg, omega)
    assert 0 < limited[0] < expected and 0 < limited[1]


def simulate_caught(sit: pc.Situation, impulse: float, direction: float, lands: list, footholds: list,
                    dt: float = 5e-4) -> bool:
    """An independent check: the capture point stepped forward in time (xi_dot = w (xi - p) + F / (m w), small
    steps), the ZMP on the support's edge nearest to xi (the most it can pull xi back toward the middle), the
    feet landing at ``lands`` on ``footholds`` ((x, y) ankle points) and the old stance foot lifting after the
    plan's double support; caught when xi is in the hull of the last two feet once the last foot is down and
    the push is over."""
    w, m = sit.omega, sit.mass_kg
    a = math.radians(direction)
    force = (impulse / pc.PUSH_DURATION_S) * math.cos(a), (impulse / pc.PUSH_DURATION_S) * math.sin(a)
    swing = "right" if sit.stance == "left" else "left"
    feet = [(sit.stance, sit.feet_m[sit.stance])]  # (side, ankle) of the feet down, the next to lift first
    if sit.lift_s is not None:  # both down at the push: the other foot lifts first
        feet.insert(0, (swing, sit.feet_m[swing]))
    sides = [swing if k % 2 == 0 else sit.stance for k in range(len(lands))]
    xi = list(sit.xi0_m)
    t, k, lift_at = sit.t_s, 0, sit.lift_s if sit.lift_s is not None else -1.0
    end = max([sit.t_s + pc.PUSH_DURATION_S, *lands])
    while True:
        if k < len(lands) and t >= lands[k] - 1e-12:
            feet.append((sides[k], footholds[k]))
            lift_at = t + sit.double_s
            k += 1
        if len(feet) == 2 and t >= lift_at - 1e-12 and k < len(lands) and lift_at >= 0:
            feet.pop(0)
        lo = [min(f[i] + (sit.sole_x_m[0] if i == 0 else sit.sole_y_m[s][0]) for s, f in feet) for i in (0, 1)]
        hi = [max(f[i] + (sit.sole_x_m[1] if i == 0 else sit.sole_y_m[s][1]) for s, f in feet) for i in (0, 1)]
        if t >= end - 1e-12:
            return all(lo[i] - 1e-6 <= xi[i] <= hi[i] + 1e-6 for i in (0, 1))
        pushing = t < sit.t_s + pc.PUSH_DURATION_S
        for i in (0, 1):
            p = lo[i] if xi[i] < 0.5 * (lo[i] + hi[i]) else hi[i]
            xi[i] += dt * (w * (xi[i] - p) + (force[i] / (m * w) if pushing else 0.0))
        t += dt


def test_no_simulated_controller_catches_a_push_the_bound_says_is_lost(walk):
    # footholds drawn at random inside the step limits (and the soles' gap), landing times from the earliest
    # the servos allow to the planned one, the ZMP on the edge nearest the capture point: never
    # caught where the analysis says nothing catches it; and a push it catches with no step is caught so too
    import random

    rng = random.Random(5)
    box = pc.steer_box(walk)
    checked = {"lost": 0, "held": 0}
    for impulse, direction, phase in pc.draws(40, 23, 2.0):
        sit = pc.situation_at(walk, pc.push_time_s(walk, phase))
        verdict = pc.capturable(sit, impulse, direction, box)
        if verdict["ok"] and verdict["steps"] == 0:
            assert simulate_caught(sit, impulse, direction, [], [])
            checked["held"] += 1
        if verdict["ok"]:
            continue
        checked["lost"] += 1
        earliest, planned = pc.landing_times(sit)[0], sit.land_s
        for _ in range(80):
            n = rng.randint(1, pc.MAX_STEPS)
            first = rng.uniform(earliest, planned)
            lands = [first + j * sit.step_s for j in range(n)]
            stance = sit.feet_m[sit.stance]
            holds, side = [], sit.swing
            for _ in range(n):
                s = 1.0 if side == "left" else -1.0
                if rng.random() < 0.5:  # the limits' corners, where a step reaches furthest
                    x = stance[0] + rng.choice((-box.backward_m, box.forward_m))
                    y = stance[1] + s * rng.choice((box.spread_min_m, box.spread_max_m))
                else:
                    x = stance[0] + rng.uniform(-box.backward_m, box.forward_m)
                    y = stance[1] + s * rng.uniform(box.spread_min_m, box.spread_max_m)
                holds.append((x, y))
                stance, side = (x, y), ("right" if side == "left" else "left")
            assert not simulate_caught(sit, impulse, direction, lands, holds), (impulse, direction, phase, holds)
    assert checked["lost"] >= 3 and checked["held"] >= 5


def test_a_push_the_bound_catches_with_one_step_is_caught_by_a_simulated_step(walk):
    # the other way round: where the analysis catches a push with one step, some foothold on a grid inside the
    # step limits, landing at one of the analysis's times, catches it in the forward integration too
    import numpy as np

    box = pc.steer_box(walk)
    caught = 0
    for impulse, direction, phase in pc.draws(40, 23, 2.0):
        sit = pc.situation_at(walk, pc.push_time_s(walk, phase))
        verdict = pc.capturable(sit, impulse, direction, box)
        if verdict["steps"] != 1:
            continue
        stance, s = sit.feet_m[sit.stance], (1.0 if sit.swing == "left" else -1.0)
        found = any(simulate_caught(sit, impulse, direction, [t], [(stance[0] + x, stance[1] + s * y)])
                    for t in pc.landing_times(sit)
                    for x in np.linspace(-box.backward_m, box.forward_m, 9)
                    for y in np.linspace(box.spread_min_m, box.spread_max_m, 9))
        assert found, (impulse, direction, phase)
        caught += 1
    assert caught >= 5


def test_the_bound_check_counts_every_push_once_by_what_the_bound_needs():
    """tools/push_bound_check.py --all: each push falls in exactly one row by the bound's verdict, each row
    counts its survivors per feedback and its smallest loss, and the totals are the pushes' own."""
    import push_bound_check as bc

    def push(impulse, capturable, steps, none, full):
        return {"impulse_n_s": impulse, "a": {"capturable": capturable, "steps": steps},
                "survived": {"none": none, "full": full}}

    found = [push(0.2, True, 0, True, True), push(0.6, True, 0, False, False), push(0.9, True, 0, False, True),
             push(1.1, True, 1, False, True), push(1.3, True, 2, True, False), push(1.7, True, 3, False, False),
             push(1.9, False, None, False, False)]
    table = bc.by_need(found, ("none", "full")).splitlines()
    rows = {line.split(" | ")[0].lstrip("| "): line.strip("| ").split(" | ")[1:] for line in table[3:-1]}
    assert rows[bc.NEEDS[0]] == ["3", "1", "2", "0.60"]
    assert rows[bc.NEEDS[1]] == ["1", "0", "1", "-"]
    assert rows[bc.NEEDS[2]] == ["2", "1", "0", "1.30"]  # two steps and three in one row
    assert rows[bc.NEEDS[3]] == ["1", "0", "0", "1.90"]
    assert rows["all"] == ["7", "2", "3", "0.60"]
