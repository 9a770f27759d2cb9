"""The leg joints gaitbot knows: their names, their order, and which of them the planar walker moves.

Per leg, from the pelvis down: hip yaw, hip roll, hip pitch, knee, ankle pitch, ankle roll, named
``<kind>_<side>`` (``knee_pitch_left``). Signs, mirrored for each leg (docs/gait-model.md section 8):
pitch joints flexion positive (thigh forward, knee bent, toes up); ``hip_roll`` abduction positive
(the foot away from the midline); ``ankle_roll`` in the same sense as its leg's hip_roll, so a flat
sole under an upright torso has ankle_roll = -hip_roll; ``hip_yaw`` toe outward positive. Zero is
the straight standing pose with the soles flat.

The canonical order (left leg, then right, each from the pelvis down) is the column order of
trajectories and of a robot's moving joints; a robot may have any mirrored subset that includes the
three pitch joints of each leg.
"""

from __future__ import annotations

from collections.abc import Iterable

SIDES = ("left", "right")
LEG_JOINT_KINDS = ("hip_yaw", "hip_roll", "hip_pitch", "knee_pitch", "ankle_pitch", "ankle_roll")
PITCH_KINDS = ("hip_pitch", "knee_pitch", "ankle_pitch")

LEG_JOINTS = tuple(f"{kind}_{side}" for side in SIDES for kind in LEG_JOINT_KINDS)
"""Every leg joint gaitbot knows, in canonical order (12 names)."""

PITCH_JOINTS = tuple(f"{kind}_{side}" for side in SIDES for kind in PITCH_KINDS)
"""The joints of the sagittal-plane walker (Jing et al.'s hip, knee and ankle), in canonical order."""

_RANK = {name: i for i, name in enumerate(LEG_JOINTS)}


def is_leg_joint(name: str) -> bool:
    return name in _RANK


def split_joint(name: str) -> tuple[str, str]:
    """``"knee_pitch_left"`` -> ``("knee_pitch", "left")``; ValueError for a name gaitbot does not know."""
    if name not in _RANK:
        raise ValueError(f"unknown joint {name!r} (allowed: {', '.join(LEG_JOINTS)})")
    kind, _, side = name.rpartition("_")
    return kind, side


def mirror(name: str) -> str:
    """The same joint of the other leg."""
    kind, side = split_joint(name)
    return f"{kind}_{SIDES[1 - SIDES.index(side)]}"


def canonical(names: Iterable[str]) -> tuple[str, ...]:
    """Leg joint names sorted into canonical order (every name must be a known leg joint)."""
    names = tuple(names)
    for name in names:
        split_joint(name)
    return tuple(sorted(names, key=_RANK.__getitem__))
