"""Calibration: joint angles (radians, flexion positive) <-> servo ticks, vectorised over frames.

Per joint ``ticks = zero_tick + direction * angle_rad * model.ticks_per_rad``, rounded to the
nearest integer tick (numpy ``rint``: halves go to the even tick). The same map is used by
config validation (do the limits land inside the servo's tick range?), by the limit check and by
the streamer, so all three agree on which tick an angle becomes.

A :class:`Calibration` is built once per robot (``RobotConfig.calibration``) from its joints; the
functions below take the config for callers that have one at hand. Column order everywhere is the
config's joint order: the moving joints in canonical order (gaitbot.gait.joints), then the held
joints. Angles for some of the joints (a trajectory's) are placed by name. This module does not
import the config: the config imports it.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

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
    """Every joint's name, (zero_tick, direction, ticks_per_rad) and limits as arrays in joint order, and
    the held joints' angles; the first ``n_walking`` joints move, the rest are held."""

    names: tuple[str, ...]
    ids: tuple[int, ...]
    zero_tick: np.ndarray
    direction: np.ndarray
    ticks_per_rad: np.ndarray
    hold_rad: np.ndarray
    min_rad: np.ndarray
    max_rad: np.ndarray
    n_walking: int

    @classmethod
    def of(cls, joints: Sequence[Any]) -> "Calibration":
        """From a config's joints (JointConfig: name, id, model, zero_tick, direction, min/max/hold_deg),
        moving joints first."""
        def column(values) -> np.ndarray:
            array = np.array(values, dtype=float)
            array.setflags(write=False)
            return array

        n_walking = sum(1 for j in joints if j.hold_deg is None)
        return cls(names=tuple(j.name for j in joints), ids=tuple(j.id for j in joints),
                   zero_tick=column([j.zero_tick for j in joints]), direction=column([j.direction for j in joints]),
                   ticks_per_rad=column([j.model.ticks_per_rad for j in joints]),
                   hold_rad=np.radians(column([j.hold_deg for j in joints[n_walking:]])),
                   min_rad=np.radians(column([j.min_deg for j in joints])),
                   max_rad=np.radians(column([j.max_deg for j in joints])), n_walking=n_walking)

    @property
    def n_joints(self) -> int:
        return len(self.ids)

    @property
    def walking_names(self) -> tuple[str, ...]:
        return self.names[: self.n_walking]

    def full_angles_rad(self, angles_rad, names: Sequence[str] | None = None) -> np.ndarray:
        """Angles for every joint, shape (N, n_joints) (or (n_joints,) for one frame).

        ``names`` says which joint each column of ``angles_rad`` is. Without it, the columns are every
        joint, or the moving joints (held joints then at their hold angle). With it, each named joint
        takes its column, held joints their hold angle, and moving joints that are not named stay at
        0 (the straight leg): a planar trajectory on a robot with roll joints walks with them upright.
        A named joint the robot holds must stay at its hold angle (within 0.01 deg): ValueError if not,
        and for a name the robot does not have.
        """
        a = np.asarray(angles_rad, dtype=float)
        if names is None:
            if a.shape[-1] == self.n_joints:
                return a
            if a.shape[-1] != self.n_walking:
                raise ValueError(f"angles must have {self.n_walking} (walking) or {self.n_joints} (all joints) "
                                 f"columns, got shape {a.shape}")
            names = self.walking_names
        if a.shape[-1] != len(names):
            raise ValueError(f"angles have {a.shape[-1]} columns for {len(names)} joint names")
        out = np.zeros(a.shape[:-1] + (self.n_joints,))
        out[..., self.n_walking:] = self.hold_rad
        for column, name in enumerate(names):
            if name not in self.names:
                raise ValueError(f"the robot has no joint {name} (its joints: {', '.join(self.names)})")
            index = self.names.index(name)
            if index >= self.n_walking:
                hold = self.hold_rad[index - self.n_walking]
                if np.any(np.abs(a[..., column] - hold) > np.radians(0.01)):
                    raise ValueError(f"{name} moves, but this robot holds it at {np.degrees(hold):g} deg")
                continue
            out[..., index] = a[..., column]
        return out

    def angles_to_ticks(self, angles_rad, names: Sequence[str] | None = None) -> np.ndarray:
        """Goal ticks (int64) for every joint (see :meth:`full_angles_rad` for which angles are taken)."""
        return angle_rad_to_ticks(self.full_angles_rad(angles_rad, names), self.zero_tick, self.direction,
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


def full_angles_rad(config, angles_rad, names: Sequence[str] | None = None) -> np.ndarray:
    """Angles for every joint of the config (see :meth:`Calibration.full_angles_rad`)."""
    return config.calibration.full_angles_rad(angles_rad, names)


def angles_to_ticks(config, angles_rad, names: Sequence[str] | None = None) -> np.ndarray:
    """Goal ticks (int64) for every joint: (N, J) angles of the ``names`` joints (default: the moving
    joints, or every joint) -> (N, n_joints) ticks; held joints at their hold_deg. One frame (J,) gives
    (n_joints,)."""
    return config.calibration.angles_to_ticks(angles_rad, names)


def trajectory_ticks(config, trajectory) -> np.ndarray:
    """Goal ticks (N, n_joints) of a Trajectory on this robot, its joints placed by name."""
    return config.calibration.angles_to_ticks(trajectory.angles_rad, trajectory.joints)


def ticks_to_angles(config, ticks) -> np.ndarray:
    """Angles in radians for every joint from ticks of shape (N, n_joints) or (n_joints,).

    The first columns are the moving joints; round trips are exact to within half a tick.
    """
    return config.calibration.ticks_to_angles(ticks)


def standing_ticks(config) -> np.ndarray:
    """Ticks of the standing pose: every walking joint at 0 rad, held joints at hold_deg. Shape (n_joints,)."""
    return angles_to_ticks(config, np.zeros(config.calibration.n_walking))


def tick_limits(config) -> dict[int, tuple[int, int]]:
    """Per servo id, the lowest and highest tick its joint's min_deg/max_deg round to."""
    return config.calibration.tick_limits()
