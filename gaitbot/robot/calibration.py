"""Calibration: joint angles (radians, flexion positive) <-> servo ticks, vectorised over frames.

Per joint ``ticks = zero_tick + direction * angle_rad * model.ticks_per_rad``, rounded to the
nearest integer tick (numpy ``rint``: halves go to the even tick). The same function is used by
config validation (do the limits land inside the servo's tick range?), by the limit check and by
the streamer, so all three agree on which tick an angle becomes.

Column order everywhere is the config's joint order: the six walking joints in WALKING_JOINTS
order, then the held joints in file order.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:  # config.py imports this module; the type import only is needed here
    from gaitbot.robot.config import RobotConfig

N_WALKING = 6


def angle_rad_to_ticks(angle_rad, zero_tick, direction, ticks_per_rad) -> np.ndarray:
    """Ticks (int64) for angles in radians; arguments broadcast as numpy arrays."""
    raw = np.asarray(zero_tick, dtype=float) + np.asarray(direction, dtype=float) * np.asarray(
        angle_rad, dtype=float) * np.asarray(ticks_per_rad, dtype=float)
    return np.rint(raw).astype(np.int64)


def ticks_to_angle_rad(ticks, zero_tick, direction, ticks_per_rad) -> np.ndarray:
    """Angles in radians for ticks; the exact inverse of the unrounded map."""
    return (np.asarray(ticks, dtype=float) - np.asarray(zero_tick, dtype=float)) / (
        np.asarray(direction, dtype=float) * np.asarray(ticks_per_rad, dtype=float))


def joint_parameters(config: "RobotConfig") -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(zero_tick, direction, ticks_per_rad), each shape (n_joints,), in the config's joint order."""
    zero = np.array([j.zero_tick for j in config.joints], dtype=float)
    direction = np.array([j.direction for j in config.joints], dtype=float)
    tpr = np.array([j.model.ticks_per_rad for j in config.joints], dtype=float)
    return zero, direction, tpr


def hold_angles_rad(config: "RobotConfig") -> np.ndarray:
    """Angles of the held (non-walking) joints in radians, shape (n_held,)."""
    return np.radians(np.array([j.hold_deg for j in config.held_joints], dtype=float))


def full_angles_rad(config: "RobotConfig", angles_rad) -> np.ndarray:
    """Angles for every joint of the config, shape (N, n_joints) (or (n_joints,) for one frame).

    Accepts either the six walking joints (held joints are then filled in at their hold_deg) or
    already every joint. When a config has no held joints the two shapes coincide.
    """
    a = np.asarray(angles_rad, dtype=float)
    n_joints = len(config.joints)
    if a.shape[-1] == n_joints:
        return a
    if a.shape[-1] != N_WALKING:
        raise ValueError(f"angles must have {N_WALKING} (walking) or {n_joints} (all joints) columns, "
                         f"got shape {a.shape}")
    held = np.broadcast_to(hold_angles_rad(config), a.shape[:-1] + (n_joints - N_WALKING,))
    return np.concatenate([a, held], axis=-1)


def angles_to_ticks(config: "RobotConfig", angles_rad) -> np.ndarray:
    """Goal ticks (int64) for every joint: (N, 6) walking angles -> (N, n_joints) ticks.

    Held joints are set to their hold_deg. A single frame of shape (6,) gives (n_joints,).
    (N, n_joints) angles for every joint are accepted too.
    """
    zero, direction, tpr = joint_parameters(config)
    return angle_rad_to_ticks(full_angles_rad(config, angles_rad), zero, direction, tpr)


def ticks_to_angles(config: "RobotConfig", ticks) -> np.ndarray:
    """Angles in radians for every joint from ticks of shape (N, n_joints) or (n_joints,).

    The first six columns are the walking joints; round trips are exact to within half a tick.
    """
    t = np.asarray(ticks)
    if t.shape[-1] != len(config.joints):
        raise ValueError(f"ticks must have {len(config.joints)} columns (one per joint), got shape {t.shape}")
    zero, direction, tpr = joint_parameters(config)
    return ticks_to_angle_rad(t, zero, direction, tpr)


def standing_ticks(config: "RobotConfig") -> np.ndarray:
    """Ticks of the standing pose: every walking joint at 0 rad, held joints at hold_deg. Shape (n_joints,)."""
    return angles_to_ticks(config, np.zeros(N_WALKING))


def tick_limits(config: "RobotConfig") -> dict[int, tuple[int, int]]:
    """Per servo id, the lowest and highest tick its joint's min_deg/max_deg round to.

    Rounding is monotone, so every angle inside [min_deg, max_deg] becomes a tick inside these."""
    zero, direction, per_rad = joint_parameters(config)
    lo = angle_rad_to_ticks(np.radians([j.min_deg for j in config.joints]), zero, direction, per_rad)
    hi = angle_rad_to_ticks(np.radians([j.max_deg for j in config.joints]), zero, direction, per_rad)
    return {j.id: (int(min(a, b)), int(max(a, b))) for j, a, b in zip(config.joints, lo, hi)}
