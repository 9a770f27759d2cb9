"""The emulator standing in for the person who calibrates (``--hand-calibrate``): the robot is built with each
servo's horn a little off the config's zero (as a real build is, by up to a spline tooth), and the hand does
what ``gaitbot calibrate`` asks, one step per read cycle of the calibration: the zero pose, then each joint
in the config's order bent its positive way and let back.

So a whole bring-up runs on the emulator without a hand-made ``--hand-ticks`` file, and what calibrate
measures can be checked against the build (:func:`mounting_zero_ticks`), not against gaitbot's own output.
"""

from __future__ import annotations

import math
import random

from gaitbot.emulator import Hand

#: How far off the config's zero each horn is mounted, at most (degrees): within one spline tooth
#: (the XL430's horn has 25 teeth, 14.4 deg apart; a hand assembling it sets it within half a tooth).
MOUNTING_SPREAD_DEG = 4.0
#: How far the hand bends each joint (degrees): calibrate asks for 20 or more; less where the joint's
#: configured range is smaller (never under calibrate's 5 deg minimum plus a margin).
BEND_DEG = 25.0


def mounting_zero_ticks(robot, seed: int = 0) -> dict[int, int]:
    """Servo id -> its tick at the zero pose in this build: the config's zero tick, off by up to
    MOUNTING_SPREAD_DEG, drawn from ``seed`` (the same build every run with the same seed)."""
    rng = random.Random(seed)
    zero = {}
    for joint in robot.joints:
        off_deg = rng.uniform(-MOUNTING_SPREAD_DEG, MOUNTING_SPREAD_DEG)
        zero[joint.id] = int(round(joint.zero_tick + math.radians(off_deg) * joint.model.ticks_per_rad))
    return zero


def bend_deg(joint) -> float:
    """How far the hand bends ``joint`` its positive way: BEND_DEG, or less to stay within its max_deg."""
    return max(min(BEND_DEG, joint.max_deg), 8.0)


def calibration_hand(robot, seed: int = 0) -> Hand:
    """The hand's samples: the zero pose, then each joint bent bend_deg() its positive way (the config's
    direction), the others at zero; one sample per read cycle (``rate_hz`` None)."""
    zero = mounting_zero_ticks(robot, seed)
    rows = [dict(zero)]
    for joint in robot.joints:
        row = dict(zero)
        row[joint.id] += joint.direction * int(round(math.radians(bend_deg(joint)) * joint.model.ticks_per_rad))
        rows.append(row)
    for joint in robot.joints:
        model = joint.model
        if not all(model.min_tick <= row[joint.id] <= model.max_tick for row in rows):
            raise ValueError(f"--hand-calibrate: {joint.name}'s zero tick {joint.zero_tick} leaves no room to bend it "
                             f"{bend_deg(joint):g} deg within the {model.name}'s ticks {model.min_tick}..{model.max_tick}")
    return Hand({joint.id: [row[joint.id] for row in rows] for joint in robot.joints})
