"""A robot config as URDF (``gaitbot robot export --urdf``), for the tools the field looks at robots with.

The same body as the simulated robot (gaitbot.gait.body, gaitbot.sim.model3d): the torso and, per leg,
hip_yaw -> hip_roll -> thigh -> shank -> ankle -> foot, each link's frame parallel to the root at the zero
pose with its origin at its joint point, so a URDF joint angle *is* gaitbot's angle. Joints are named as
gaitbot's (``knee_pitch_left``); a walking joint is revolute with the config's limits, speed and its
servo's stall torque; a held joint is fixed at its hold angle, and a joint the robot does not have is fixed
at 0 (the link stays, massless, so every robot has the same frames). Masses, centres of mass and inertias
are ``config.body``'s. The feet are boxes (collision and visual) from the sole to the ankle point; thigh,
shank and torso get simple visual shapes. Frames for other tools, all fixed (docs/robot-description.md):
``base_link`` (the root, REP-120), ``torso`` (its mass), ``trunk`` (PlaCo's name for the root),
``l_sole``/``r_sole`` (REP-120) and ``left_foot``/``right_foot`` (PlaCo) at each sole's centre, z up, and
``left_hip_yaw``/``right_hip_yaw`` (PlaCo) at the hip points.
"""

from __future__ import annotations

import math
from xml.sax.saxutils import quoteattr

import numpy as np

from gaitbot.gait.body import LEG_LINKS
from gaitbot.gait.joints import SIDES
from gaitbot.robot.config import RobotConfig
from gaitbot.robot.description.frames import ROOT_LINK, TORSO_LINK, JointFrame, joint_frames
from gaitbot.robot.description.tree import matrix_rpy

MIN_FOOT_BOX_M = 0.004  # a foot box at least this tall, when the sole is at the ankle axis
COLOURS = {"left": "0.45 0.5 0.6 1", "right": "0.9 0.6 0.2 1", "torso": "0.3 0.45 0.7 1", "sole": "0.2 0.2 0.25 1"}


def _f(*values) -> str:
    """Numbers with 12 significant digits: a config's lengths come back exactly, computed ones to 1e-12."""
    return " ".join(format(float(v), ".12g") for v in values)


def _origin(xyz=(0, 0, 0), rpy=(0, 0, 0)) -> str:
    return f'<origin xyz="{_f(*xyz)}" rpy="{_f(*rpy)}"/>'


def _inertial(link) -> str:
    if link.mass_kg <= 0:
        return ""  # a massless frame: URDF leaves the inertial out
    i = link.inertia_kg_m2
    return (f'<inertial>{_origin(link.com_m)}<mass value="{_f(link.mass_kg)}"/>'
            f'<inertia ixx="{_f(i[0, 0])}" ixy="{_f(i[0, 1])}" ixz="{_f(i[0, 2])}" iyy="{_f(i[1, 1])}" '
            f'iyz="{_f(i[1, 2])}" izz="{_f(i[2, 2])}"/></inertial>')


def _shape(kind: str, size: str, xyz, colour: str, collision: bool = False) -> str:
    geometry = f'<geometry><{kind} {size}/></geometry>'
    name = next(key for key, rgba in COLOURS.items() if rgba == colour)
    material = f'<material name="gaitbot_{name}"><color rgba="{colour}"/></material>'
    text = f'<visual>{_origin(xyz)}{geometry}{material}</visual>'
    return text + (f'<collision>{_origin(xyz)}{geometry}</collision>' if collision else "")


def _fixed(name: str, parent: str, child: str, xyz=(0, 0, 0), rpy=(0, 0, 0)) -> str:
    return (f'<joint name={quoteattr(name)} type="fixed"><parent link="{parent}"/><child link="{child}"/>'
            f'{_origin(xyz, rpy)}</joint>')


def _leg_shapes(config: RobotConfig, side: str) -> dict[str, str]:
    g = config.body.geometry
    radius = 0.055 * g.leg_length_m
    colour = COLOURS[side]
    sole = g.sole_centre_in_foot(side)
    height = max(g.ankle_height_m, MIN_FOOT_BOX_M)
    return {
        "thigh": _shape("cylinder", f'radius="{_f(radius)}" length="{_f(g.thigh_m)}"', (0, 0, -g.thigh_m / 2), colour),
        "shank": _shape("cylinder", f'radius="{_f(radius)}" length="{_f(g.shank_m)}"', (0, 0, -g.shank_m / 2), colour),
        "foot": _shape("box", f'size="{_f(g.foot_m, g.foot_width_m, height)}"',
                       sole + [0.0, 0.0, height / 2], COLOURS["sole"], collision=True),
    }


def _joint(config: RobotConfig, frame: JointFrame) -> str:
    ends = f'<parent link="{frame.parent}"/><child link="{frame.child}"/>'
    if not frame.moving:
        origin = _origin(frame.origin_m, matrix_rpy(frame.transform()[1]))
        return f'<joint name={quoteattr(frame.name)} type="fixed">{ends}{origin}</joint>'
    joint = config.joint(frame.name)
    return (f'<joint name="{frame.name}" type="revolute">{ends}{_origin(frame.origin_m)}<axis xyz="{_f(*frame.axis)}"/>'
            f'<limit lower="{_f(math.radians(joint.min_deg))}" upper="{_f(math.radians(joint.max_deg))}" '
            f'effort="{_f(joint.model.stall_torque_nm)}" velocity="{_f(math.radians(joint.max_velocity_dps))}"/>'
            f'</joint>')


def _link(config: RobotConfig, name: str, shapes: dict[str, str]) -> str:
    """A link: its inertial (the torso's, a leg link's, none for a frame) and its shapes."""
    link, _, side = name.rpartition("_")
    inertial = ""
    if name == TORSO_LINK:
        inertial = _inertial(config.body.torso)
    elif side in SIDES and link in LEG_LINKS:
        inertial = _inertial(config.body.leg_link(link, side))
    return f'<link name="{name}">{inertial}{shapes.get(name, "")}</link>' if inertial or name in shapes \
        else f'<link name="{name}"/>'


def urdf_text(config: RobotConfig) -> str:
    """The URDF document of the robot (module docstring)."""
    g = config.body.geometry
    radius = 0.055 * g.leg_length_m
    torso_half = (max(g.foot_m / 3, 0.02), g.hip_width_m / 2 + radius, 0.3 * g.leg_length_m)
    shapes = {TORSO_LINK: _shape("box", f'size="{_f(*(2 * np.array(torso_half)))}"',
                                 (0, 0, torso_half[2] - g.hip_below_root_m), COLOURS["torso"])}
    for side in SIDES:
        shapes.update({f"{link}_{side}": text for link, text in _leg_shapes(config, side).items()})
    parts = [f'<link name="{ROOT_LINK}"/>']
    for frame in joint_frames(config):
        parts += [_link(config, frame.child, shapes), _joint(config, frame)]
    body = "\n  ".join(parts)
    return (f'<?xml version="1.0"?>\n<!-- {config.name}: written by gaitbot robot export from {config.path.name} '
            f'(frames: docs/robot-description.md) -->\n<robot name={quoteattr(config.name)}>\n  {body}\n</robot>\n')
