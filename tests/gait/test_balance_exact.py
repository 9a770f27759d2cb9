"""The balanced walk of every shipped robot whose legs roll (op3, bioloid) checked from its trajectory file
alone, with forward kinematics written here.

The FK below is built from the joint conventions as the issue states them (pitch joints flexion
positive, hip_roll abduction positive, ankle_roll in its hip_roll's sense, hip_yaw toe outward), with
rotations about each joint's axis composed down the chain (Rodrigues), and the leg's numbers read from
the robot's config/<robot>.toml with tomllib: it imports nothing of gaitbot's kinematics. From the angles
and root of ``gaitbot generate --robot NAME`` it finds the soles flat and still in stance, the heels where
``gaitbot plan --json`` says, the swing soles the configured clearance up, every joint inside its limits.
"""

from __future__ import annotations

import json
import math
import tomllib

import numpy as np
import pytest

from gaitbot.gait.trajectory import Trajectory
from gaitbot.robot.config import load_robot_config
from helpers import CONFIG_DIR

# The robots the balanced walker drives: those whose legs roll (pitch-only ones walk planar: test_gait_walk.py).
BALANCED = sorted(p.stem for p in CONFIG_DIR.glob("*.toml") if load_robot_config(p).is_3d)
KINDS = ("hip_yaw", "hip_roll", "hip_pitch", "knee_pitch", "ankle_pitch", "ankle_roll")
STEP_SHARES = (0.6, 1.0, 0.8, 1.0, 0.4, 1.0, 0.7)  # uneven steps, as shares of the robot's max_step_m


def steps_m(robot: dict) -> list[float]:
    """The walk's step lengths: op3 (max 0.05 m) walks 0.03, 0.05, 0.04, 0.05, 0.02, 0.05, 0.035."""
    return [round(share * robot["gait"]["max_step_m"], 4) for share in STEP_SHARES]


def axis(kind: str, s: float) -> np.ndarray:
    """Each joint's axis at the zero pose, x forward, y left, z up; positive angle = the convention's sense:
    flexion raises the thigh forward (about -y), bends the knee back (about +y), raises the toes (about
    -y); abduction moves the left foot left (about +x for the left leg); toe outward (about +z left)."""
    return {"hip_yaw": (0, 0, s), "hip_roll": (s, 0, 0), "hip_pitch": (0, -1, 0), "knee_pitch": (0, 1, 0),
            "ankle_pitch": (0, -1, 0), "ankle_roll": (s, 0, 0)}[kind]


def rodrigues(a, angle: float) -> np.ndarray:
    a = np.asarray(a, dtype=float)
    k = np.array([[0, -a[2], a[1]], [a[2], 0, -a[0]], [-a[1], a[0], 0]])
    return np.eye(3) + math.sin(angle) * k + (1 - math.cos(angle)) * k @ k


def sole(geo: dict, q6, root, side: str):
    """(rotation of the foot, its four sole corners (4, 3), its sole centre (3,), heel point (3,)) in the world,
    for the [geometry] table ``geo`` of a robot's TOML."""
    g = {"sole_outward_m": 0.0, **geo}  # sole_outward_m is optional (0: the sole centred under the ankle)
    s = 1.0 if side == "left" else -1.0
    r = np.eye(3)
    hip = np.asarray(root) + [0.0, s * g["hip_width_m"] / 2, -g["hip_below_root_m"]]
    frames = []
    for kind, angle in zip(KINDS, q6):
        r = r @ rodrigues(axis(kind, s), angle)
        frames.append(r)
    knee = hip + frames[2] @ [0.0, 0.0, -g["thigh_m"]]
    ankle = knee + frames[3] @ [0.0, 0.0, -g["shank_m"]]
    foot = frames[5]
    ahead, back = g["foot_m"] - g["heel_back_m"], -g["heel_back_m"]
    out, width = s * g["sole_outward_m"], g["foot_width_m"] / 2
    corners = np.array([ankle + foot @ [x, out + w, -g["ankle_height_m"]] for x in (back, ahead) for w in (-width, width)])
    centre = ankle + foot @ [(ahead + back) / 2, out, -g["ankle_height_m"]]
    heel = ankle + foot @ [back, out, -g["ankle_height_m"]]
    return foot, corners, centre, heel


@pytest.fixture(scope="module", params=BALANCED)
def walk(request, tmp_path_factory):
    """The robot's TOML, the trajectory file and plan of an uneven-stepped walk of it, and every frame's soles
    by our FK."""
    name = request.param
    robot = tomllib.loads((CONFIG_DIR / f"{name}.toml").read_text())
    steps = ",".join(f"{length:g}" for length in steps_m(robot))
    path = tmp_path_factory.mktemp(name) / "walk.csv"
    import contextlib
    import io

    from gaitbot.app.cli import main

    buffer = io.StringIO()
    with contextlib.redirect_stdout(buffer):
        assert main(["generate", "--robot", name, "--steps", steps, "-o", str(path)]) == 0
        buffer.truncate(0)
        buffer.seek(0)
        assert main(["plan", "--robot", name, "--steps", steps, "--json"]) == 0
    plan = json.loads(buffer.getvalue())
    trajectory = Trajectory.load(path)
    names = [f"{k}_{side}" for side in ("left", "right") for k in KINDS]
    q = trajectory.angles_of(names)
    feet = {}
    for i, side in enumerate(("left", "right")):
        rows = [sole(robot["geometry"], q[k, 6 * i:6 * i + 6], trajectory.root_m[k], side) for k in range(len(q))]
        feet[side] = {"rot": np.array([r[0] for r in rows]), "corners": np.array([r[1] for r in rows]),
                      "centre": np.array([r[2] for r in rows]), "heel": np.array([r[3] for r in rows])}
    return robot, trajectory, plan, feet


def leg_m(robot: dict) -> float:
    return robot["geometry"]["thigh_m"] + robot["geometry"]["shank_m"]


def stance(foot) -> np.ndarray:
    """Frames whose sole lies flat on the floor (every corner at z = 0 within 1e-9 m)."""
    return np.abs(foot["corners"][:, :, 2]).max(axis=1) < 1e-9


def spells(mask: np.ndarray) -> list[np.ndarray]:
    edges = np.flatnonzero(np.diff(np.r_[0, mask.astype(int), 0]))
    return [np.arange(a, b) for a, b in zip(edges[::2], edges[1::2])]


def test_stance_soles_are_flat_and_still(walk):
    robot, _, _, feet = walk
    for side, foot in feet.items():
        down = stance(foot)
        assert down.sum() > 100
        # flat to the file's precision (9 significant digits of degrees: ~2e-9 rad)
        assert np.abs(foot["rot"][down] - np.eye(3)).max() < 1e-8, f"{side} sole not flat in stance"
        for spell in spells(down):
            slide = np.abs(foot["centre"][spell, :2] - foot["centre"][spell[0], :2]).max()
            assert slide < 1e-6 * leg_m(robot), f"{side} sole slides {slide:.3g} m"
        assert (foot["corners"][:, :, 2] > -1e-9).all(), f"{side} sole goes under the floor"


def test_heels_land_on_their_planned_footholds(walk):
    robot, trajectory, plan, feet = walk
    lengths = steps_m(robot)
    planned = plan["heel_strikes"]
    assert [h["x_m"] for h in planned[:len(lengths)]] == pytest.approx(np.cumsum(lengths), abs=1e-12)
    for strike in planned:
        k = int(round(strike["t_s"] * 60))
        heel = feet[strike["leg"]]["heel"][k]
        assert stance(feet[strike["leg"]])[k] and not stance(feet[strike["leg"]])[k - 1]  # it lands on this frame
        assert abs(heel[0] - strike["x_m"]) < 1e-6 * leg_m(robot)
        centre = feet[strike["leg"]]["centre"][k]
        assert abs(centre[1] - strike["y_m"]) < 1e-6 * leg_m(robot)


def test_swing_soles_keep_the_configured_clearance(walk):
    """docs/balance.md: the whole flat sole clearance_m up from 20% to 80% of each swing's time."""
    robot, _, _, feet = walk
    clearance = robot["gait"]["clearance_m"]
    swings = 0
    for foot in feet.values():
        for spell in spells(~stance(foot)):
            tau = (np.arange(len(spell)) + 1) / (len(spell) + 1)  # the swing from lift-off to landing
            inside = spell[(tau >= 0.2) & (tau <= 0.8)]
            lowest = foot["corners"][inside, :, 2].min()
            assert lowest >= clearance - 1e-9
            assert lowest < clearance + 0.004  # and not much more than asked
            swings += 1
    assert swings == len(STEP_SHARES) + 1  # each step, and the closing step


def test_every_joint_stays_inside_its_limits(walk):
    robot, trajectory, _, _ = walk
    for name, joint in robot["joints"].items():
        angles = trajectory.joint_deg(name)
        assert joint["min_deg"] <= angles.min() and angles.max() <= joint["max_deg"], name


def test_the_walk_starts_and_ends_with_every_joint_at_zero(walk):
    _, trajectory, _, _ = walk
    assert np.abs(trajectory.angles_rad[[0, -1]]).max() == 0.0
