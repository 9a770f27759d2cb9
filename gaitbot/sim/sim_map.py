"""The mapping file of ``--sim-map``: which joint of another author's MuJoCo model is which gaitbot joint.

The form (docs/compare-models.md, "Other people's robot models")::

    [joints]              # gaitbot joint = the model's joint name; a leading "-" flips the sign
    hip_pitch_left = "-l_hip_pitch"
    [hold_deg]            # the model's other actuated joints, held at these angles (degrees, the model's)
    l_sho_roll = 45.0
    [imu]
    body = "body_link"    # the body whose motion the simulated IMU reads

Read here as text only (no MuJoCo): the names are checked against the model and the robot config by
gaitbot.sim.foreign, which loads both.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path

from gaitbot.fields import FieldError, Fields, kind, read_toml

MAX_HOLD_DEG = 360.0
"""A held angle beyond a full turn is a typo (degrees written as something else)."""


class SimMapError(FieldError):
    """A --sim-map file that cannot be used (one line: file, field, what is allowed; exit 2)."""


@dataclass(frozen=True)
class JointLink:
    """One gaitbot joint on one model joint: gaitbot angle = sign x the model's angle."""

    model_joint: str
    sign: int


@dataclass(frozen=True)
class SimMap:
    """A parsed --sim-map file: ``joints`` gaitbot name -> JointLink, ``hold_deg`` model joint -> angle,
    ``imu_body`` the model body the simulated IMU rides on (None: the torso, the free joint's body)."""

    path: Path
    joints: dict[str, JointLink]
    hold_deg: dict[str, float] = field(default_factory=dict)
    imu_body: str | None = None


def load_sim_map(path: str | Path) -> SimMap:
    """The mapping file at ``path``; SimMapError (one line) for anything unusable."""
    path = Path(path)
    data = read_toml(path, SimMapError)
    fields = Fields(path, SimMapError)
    fields.no_unknown_keys(data, "", ("joints", "hold_deg", "imu"))
    table = fields.table(data, "joints", "joints", tuple(data.get("joints", {}) or ()))
    if not table:
        raise fields.fail("joints", "maps no joint (write: gaitbot joint = \"the model's joint\", e.g. "
                                    "knee_pitch_left = \"l_knee\")")
    joints: dict[str, JointLink] = {}
    used: dict[str, str] = {}
    for ours, theirs in table.items():
        if not isinstance(theirs, str) or not theirs.lstrip("-").strip():
            raise fields.fail(f"joints.{ours}", f"must be the model's joint name (a leading \"-\" flips the sign), "
                                                f"got {kind(theirs)}")
        sign = -1 if theirs.startswith("-") else 1
        name = theirs[1:] if sign < 0 else theirs
        if name in used:
            raise fields.fail(f"joints.{ours}", f"the model's joint {name!r} is already mapped to {used[name]}")
        used[name] = ours
        joints[ours] = JointLink(name, sign)
    holds = fields.optional_table(data, "hold_deg", "hold_deg", tuple(data.get("hold_deg", {}) or ()))
    hold_deg = {}
    for name, value in holds.items():
        angle = fields.check_number(value, f"hold_deg.{name}", within=(-MAX_HOLD_DEG, MAX_HOLD_DEG, "deg"))
        if name in used:
            raise fields.fail(f"hold_deg.{name}", f"is mapped to {used[name]} in [joints]: a joint is walked or held")
        hold_deg[name] = angle
    imu = fields.optional_table(data, "imu", "imu", ("body",))
    imu_body = fields.string(imu, "body", "imu") if imu else None
    return SimMap(path, joints, hold_deg, imu_body)


def hold_rad(sim_map: SimMap) -> dict[str, float]:
    """The held angles in radians (the model's units)."""
    return {name: math.radians(deg) for name, deg in sim_map.hold_deg.items()}
