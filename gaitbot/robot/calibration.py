"""Calibration: joint angles (radians, flexion positive) <-> servo ticks, vectorised over frames.

Per joint ``ticks = zero_tick + direction * angle_rad * model.ticks_per_rad``, rounded to the
nearest integer tick (numpy ``rint``: halves go to the even tick). The same map is used by
config validation (do the limits land inside the servo's tick range?), by the limit check and by
the streamer, so all three agree on which tick an angle becomes.

A :class:`Calibration` is built once per robot (``RobotConfig.calibration``) from its joints; the
functions below take the config for callers that have one at hand. Column order everywhere is the
config's joint order: the six walking joints in WALKING_JOINTS order, then the held joints in file
order. This module does not import the config: the config imports it.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

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


@dataclass(frozen=True, eq=False)
class Calibration:
    """Every joint's (zero_tick, direction, ticks_per_rad) as arrays in joint order, the held joints'
    angles, and each servo's tick limits; ``n_walking`` leading joints walk, the rest are held."""

    ids: tuple[int, ...]
    zero_tick: np.ndarray
    direction: np.ndarray
    ticks_per_rad: np.ndarray
    hold_rad: np.ndarray
    min_rad: np.ndarray
    max_rad: np.ndarray
    n_walking: int = N_WALKING

    @classmethod
    def of(cls, joints: Sequence[Any], n_walking: int = N_WALKING) -> "Calibration":
        """From a config's joints (JointConfig: id, model, zero_tick, direction, min/max/hold_deg)."""
        def column(values) -> np.ndarray:
            array = np.array(values, dtype=float)
            array.setflags(write=False)
            return array

        return cls(ids=tuple(j.id for j in joints), zero_tick=column([j.zero_tick for j in joints]),
                   direction=column([j.direction for j in joints]),
                   ticks_per_rad=column([j.model.ticks_per_rad for j in joints]),
                   hold_rad=np.radians(column([j.hold_deg for j in joints[n_walking:]])),
                   min_rad=np.radians(column([j.min_deg for j in joints])),
                   max_rad=np.radians(column([j.max_deg for j in joints])), n_walking=n_walking)

    @property
    def n_joints(self) -> int:
        return len(self.ids)

    def full_angles_rad(self, angles_rad) -> np.ndarray:
        """Angles for every joint, shape (N, n_joints) (or (n_joints,) for one frame).

        Accepts either the walking joints (held joints are then filled in at their hold angle) or
        already every joint. When there are no held joints the two shapes coincide.
        """
        a = np.asarray(angles_rad, dtype=float)
        if a.shape[-1] == self.n_joints:
            return a
        if a.shape[-1] != self.n_walking:
            raise ValueError(f"angles must have {self.n_walking} (walking) or {self.n_joints} (all joints) columns, "
                             f"got shape {a.shape}")
        held = np.broadcast_to(self.hold_rad, a.shape[:-1] + (self.n_joints - self.n_walking,))
        return np.concatenate([a, held], axis=-1)

    def angles_to_ticks(self, angles_rad) -> np.ndarray:
        """Goal ticks (int64) for every joint from walking angles (held joints at their hold angle) or all."""
        return angle_rad_to_ticks(self.full_angles_rad(angles_rad), self.zero_tick, self.direction,
                                  self.ticks_per_rad)

    def ticks_to_angles(self, ticks) -> np.ndarray:
        """Angles in radians for every joint from ticks of shape (N, n_joints) or (n_joints,)."""
        t = np.asarray(ticks)
        if t.shape[-1] != self.n_joints:
            raise ValueError(f"ticks must have {self.n_joints} columns (one per joint), got shape {t.shape}")
        return ticks_to_angle_rad(t, self.zero_tick, self.direction, self.ticks_per_rad)

    def tick_limits(self) -> dict[int, tuple[int, int]]:
        """Per servo id, the lowest and highest tick its joint's min/max angle round to.

        Rounding is monotone, so every angle inside the limits becomes a tick inside these."""
        lo = angle_rad_to_ticks(self.min_rad, self.zero_tick, self.direction, self.ticks_per_rad)
        hi = angle_rad_to_ticks(self.max_rad, self.zero_tick, self.direction, self.ticks_per_rad)
        return {i: (int(min(a, b)), int(max(a, b))) for i, a, b in zip(self.ids, lo, hi)}


# The config's calibration (``config.calibration``), for callers that hold a RobotConfig.

def joint_parameters(config) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(zero_tick, direction, ticks_per_rad), each shape (n_joints,), in the config's joint order."""
    c = config.calibration
    return c.zero_tick, c.direction, c.ticks_per_rad


def hold_angles_rad(config) -> np.ndarray:
    """Angles of the held (non-walking) joints in radians, shape (n_held,)."""
    return config.calibration.hold_rad


def full_angles_rad(config, angles_rad) -> np.ndarray:
    """Angles for every joint of the config (see :meth:`Calibration.full_angles_rad`)."""
    return config.calibration.full_angles_rad(angles_rad)


def angles_to_ticks(config, angles_rad) -> np.ndarray:
    """Goal ticks (int64) for every joint: (N, 6) walking angles -> (N, n_joints) ticks.

    Held joints are set to their hold_deg. A single frame of shape (6,) gives (n_joints,).
    (N, n_joints) angles for every joint are accepted too.
    """
    return config.calibration.angles_to_ticks(angles_rad)


def ticks_to_angles(config, ticks) -> np.ndarray:
    """Angles in radians for every joint from ticks of shape (N, n_joints) or (n_joints,).

    The first six columns are the walking joints; round trips are exact to within half a tick.
    """
    return config.calibration.ticks_to_angles(ticks)


def standing_ticks(config) -> np.ndarray:
    """Ticks of the standing pose: every walking joint at 0 rad, held joints at hold_deg. Shape (n_joints,)."""
    return angles_to_ticks(config, np.zeros(N_WALKING))


def tick_limits(config) -> dict[int, tuple[int, int]]:
    """Per servo id, the lowest and highest tick its joint's min_deg/max_deg round to."""
    return config.calibration.tick_limits()
