"""The feet's clearance from each other: the gap between the two soles over a trajectory.

A turn or a sidestep whose feet touch trips the robot, so ``gaitbot check`` (and the preflight of every
walk) measures, frame by frame, the least distance between the two soles' boxes (their corners from the
legs' forward kinematics, check/balance.py's trace) projected on the floor: conservative, since a swing
sole above the other counts as touching it. Below the margin (the robot's ``[steer] min_gap_m`` less
PLAN_TOLERANCE_M, or DEFAULT_MARGIN_M for a robot without ``[steer]``) is a ``feet`` violation.
"""

from __future__ import annotations

import numpy as np

from gaitbot.check.trajectory import Violation
from gaitbot.gait.steer.soles import polygon_gap
from gaitbot.robot.config import RobotConfig

DEFAULT_MARGIN_M = 0.005
"""The least gap a robot without a [steer] table must keep (the bar the steering walks are judged by)."""
PLAN_TOLERANCE_M = 0.001
"""The planner keeps min_gap_m on its sampled swing path; between samples and through the legs' IK the
gap may come this much closer."""


def feet_margin_m(config: RobotConfig) -> float:
    if config.steer is None:
        return DEFAULT_MARGIN_M
    return max(0.0, config.steer.min_gap_m - PLAN_TOLERANCE_M)


def sole_gaps_m(soles: dict) -> np.ndarray:
    """The gap (m, negative: overlap) between the left and right soles (N, 4, 3 corners each) per frame."""
    out = np.empty(len(soles["left"]))
    for k in range(len(out)):
        boxes = []
        for side in ("left", "right"):
            c = soles[side][k, :, :2]
            area = np.sum(c[:, 0] * np.roll(c[:, 1], -1) - np.roll(c[:, 0], -1) * c[:, 1])
            boxes.append([tuple(p) for p in (c if area > 0 else c[::-1])])  # counter-clockwise
        out[k] = polygon_gap(boxes[0], boxes[1])
    return out


def feet_episodes(t_s: np.ndarray, gaps_m: np.ndarray, margin_m: float) -> list[Violation]:
    """One violation per run of frames whose soles are closer than ``margin_m`` (its worst frame)."""
    close = gaps_m < margin_m
    out, k, n = [], 0, len(close)
    while k < n:
        if not close[k]:
            k += 1
            continue
        end = k
        while end + 1 < n and close[end + 1]:
            end += 1
        worst = k + int(np.argmin(gaps_m[k:end + 1]))
        out.append(Violation(kind="feet", joint="soles", t_s=float(t_s[worst]), value=1e3 * float(gaps_m[worst]),
                             limit=1e3 * margin_m, severity="error", limit_name="the least gap",
                             t_start_s=float(t_s[k]), t_end_s=float(t_s[end]), n_samples=end - k + 1))
        k = end + 1
    return out
