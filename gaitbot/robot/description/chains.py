"""Which of a description's joints are gaitbot's leg joints, and in which sense they turn.

A leg is the chain of hinges from the root (the pelvis) down to the foot: six (hip yaw, hip roll, hip
pitch, knee, ankle pitch, ankle roll, in that order from the pelvis down) or three (hip, knee and ankle
pitch), both legs alike (docs/robot-config.md). The joints are found by their names (``l_hip_yaw``,
``LeftKneePitch``, ``knee_pitch_left`` ...) or given by a mapping file, the same form as the sim room's
``--sim-map``::

    [joints]
    hip_yaw_left = "l_hip_yaw"       # gaitbot joint = "the description's joint"
    knee_pitch_right = "-r_knee"     # a leading "-": gaitbot's angle is minus the description's

The sense is then read off the axes: each joint's axis at the zero pose, in the root frame, must lie along
gaitbot's (gaitbot.gait.kinematics6.joint_axis) one way or the other; the sign says which. A mapping's "-"
must agree with the axes. Anything else is refused in one line naming what was found.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from gaitbot.fields import read_toml
from gaitbot.gait.joints import LEG_JOINT_KINDS, PITCH_KINDS, SIDES, is_leg_joint, split_joint
from gaitbot.gait.kinematics6 import joint_axis
from gaitbot.robot.description.tree import DescriptionError, Tree

#: How far a joint's axis may lie from gaitbot's (deg) and still be taken for it.
AXIS_TOLERANCE_DEG = 5.0
_ARM_WORDS = {"sho", "shoulder", "el", "elbow", "wrist", "head", "neck", "arm", "hand", "waist", "torso", "gripper"}
_HIP_WORDS = {"hip", "thigh"}
_ANKLE_WORDS = {"ank", "ankle", "foot"}


@dataclass(frozen=True)
class LegJoint:
    """One of gaitbot's leg joints in a description: gaitbot's angle = ``sign`` x the description's."""

    name: str  # gaitbot's (knee_pitch_left)
    theirs: str  # the description's joint
    sign: int
    axis_error_deg: float


def _tokens(name: str) -> set[str]:
    spaced = re.sub(r"([a-z0-9])([A-Z])", r"\1_\2", name).lower()
    return set(t for t in re.split(r"[^a-z]+", spaced) if t)


def classify(name: str) -> str | None:
    """gaitbot's leg joint a description's joint name says it is (``l_ank_roll`` -> ``ankle_roll_left``), or None."""
    words = _tokens(name)
    sides = [side for side in SIDES if side in words or side[0] in words]
    if len(sides) != 1 or words & _ARM_WORDS:
        return None
    hip, ankle = bool(words & _HIP_WORDS), bool(words & _ANKLE_WORDS)
    kind = None
    if "knee" in words or "kn" in words:
        kind = "knee_pitch"
    elif "yaw" in words and not ankle:
        kind = "hip_yaw"
    elif hip != ankle and words & {"roll", "pitch"} and len(words & {"roll", "pitch"}) == 1:
        kind = ("hip_" if hip else "ankle_") + ("roll" if "roll" in words else "pitch")
    return f"{kind}_{sides[0]}" if kind else None


def read_map(path: str | Path) -> dict[str, tuple[str, int | None]]:
    """A mapping file: gaitbot joint -> (the description's joint, -1 for a leading "-", else +1)."""
    data = read_toml(Path(path), DescriptionError)
    table = data.get("joints")
    if set(data) != {"joints"} or not isinstance(table, dict):
        raise DescriptionError(path, "joints", "a mapping file holds one [joints] table: gaitbot joint = "
                                               "\"description joint\" (a leading \"-\" flips the sign)")
    out = {}
    for ours, theirs in table.items():
        if not is_leg_joint(ours):
            raise DescriptionError(path, f"joints.{ours}", "not one of gaitbot's leg joints (hip_yaw_left ... "
                                                           "ankle_roll_right)")
        if not isinstance(theirs, str) or not theirs.lstrip("-"):
            raise DescriptionError(path, f"joints.{ours}", "must be a joint name in quotes")
        out[ours] = (theirs.lstrip("-"), -1 if theirs.startswith("-") else 1)
    return out


def _named(tree: Tree, mapping) -> dict[str, tuple[str, int | None]]:
    hinges = tree.hinges
    if mapping is not None:
        for ours, (theirs, _) in mapping.items():
            if theirs not in hinges:
                raise tree.fail(f"--map {ours}", f"no hinge joint {theirs!r} in this description (hinges: "
                                                 f"{', '.join(list(hinges)[:30])})")
        return dict(mapping)
    found: dict[str, tuple[str, int | None]] = {}
    for theirs in hinges:
        ours = classify(theirs)
        if ours is None:
            continue
        if ours in found:
            raise tree.fail(f"joint {theirs}", f"its name and {found[ours][0]!r}'s both say {ours}: give a --map file")
        found[ours] = (theirs, None)
    return found


def leg_joints(tree: Tree, mapping=None) -> dict[str, list[LegJoint]]:
    """Per side, the leg's joints from the pelvis down (6 or 3); DescriptionError naming what was found."""
    named = _named(tree, mapping)
    kinds = {side: [k for k in LEG_JOINT_KINDS if f"{k}_{side}" in named] for side in SIDES}
    for side in SIDES:
        if not kinds[side]:
            raise tree.fail("joints", f"no joint's name says it is a {side} leg joint (hinges: "
                                      f"{', '.join(list(tree.hinges)[:30])}): give a --map file")
        other = kinds[SIDES[1 - SIDES.index(side)]]
        if tuple(kinds[side]) not in (LEG_JOINT_KINDS, PITCH_KINDS) or kinds[side] != other:
            raise tree.fail(f"{side} leg", f"{len(kinds[side])} joints found ({', '.join(kinds[side])}); gaitbot's "
                                           f"legs have 6 (hip yaw, roll, pitch, knee, ankle pitch, roll) or 3 (hip, "
                                           f"knee, ankle pitch), both legs alike")
    frames = tree.frames()
    out = {}
    for side in SIDES:
        ours = [f"{k}_{side}" for k in kinds[side]]
        theirs = [named[n][0] for n in ours]
        chain = tree.hinge_ancestors(tree.hinges[theirs[-1]].name)
        if chain != theirs:
            raise tree.fail(f"{side} leg", f"the chain from the root to {theirs[-1]} has {len(chain)} hinge joints "
                                           f"({', '.join(chain)}); gaitbot's legs are {len(ours)} joints in the order "
                                           f"{', '.join(ours)}, mapped to {', '.join(theirs)}")
        out[side] = [_sensed(tree, frames, o, named[o]) for o in ours]
    return out


def _sensed(tree: Tree, frames, ours: str, named: tuple[str, int | None]) -> LegJoint:
    theirs, given = named
    body = tree.hinges[theirs]
    axis = frames[body.name][0] @ body.hinge.axis
    dot = float(np.dot(axis, joint_axis(*split_joint(ours))))
    error = math.degrees(math.acos(min(1.0, abs(dot))))
    if error > AXIS_TOLERANCE_DEG:
        shown = ", ".join(f"{a:.3f}" for a in axis)
        raise tree.fail(f"joint {theirs}", f"taken for gaitbot's {ours}, but its axis ({shown}) "
                                           f"in the root frame is {error:.1f} deg from gaitbot's "
                                           f"{joint_axis(*split_joint(ours))} (at most {AXIS_TOLERANCE_DEG:g})")
    sign = 1 if dot > 0 else -1
    if given is not None and given != sign:
        right = f"{'-' if sign < 0 else ''}{theirs}"
        raise tree.fail(f"--map {ours}", f"the axes say gaitbot's angle is {'minus ' if sign < 0 else ''}{theirs}'s: "
                                         f"write {ours} = \"{right}\"")
    return LegJoint(ours, theirs, sign, error)


def mapping_text(legs: dict[str, list[LegJoint]]) -> str:
    """The mapping found, as a mapping file (``--map`` and the sim room's ``--sim-map`` read it)."""
    lines = ["[joints]"]
    for side in SIDES:
        lines += [f'{j.name} = "{"-" if j.sign < 0 else ""}{j.theirs}"' for j in legs[side]]
    return "\n".join(lines) + "\n"
