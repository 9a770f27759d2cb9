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
from gaitbot.gait.joints import LEG_JOINT_KINDS, SIDES
from gaitbot.gait.kinematics6 import joint_axis
from gaitbot.robot.config import RobotConfig
from gaitbot.robot.description.tree import axis_angle, matrix_rpy

ROOT_LINK = "base_link"
TORSO_LINK = "torso"
ALIAS_FRAMES = {"trunk": ROOT_LINK}
SOLE_FRAMES = {"left": ("l_sole", "left_foot"), "right": ("r_sole", "right_foot")}
HIP_FRAMES = {"left": "left_hip_yaw", "right": "right_hip_yaw"}  # PlaCo measures the legs' spacing between these
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
    text = f'<visual>{_origin(xyz)}{geometry}<material name=""><color rgba="{colour}"/></material></visual>'
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


def _leg(config: RobotConfig, side: str) -> list[str]:
    g = config.body.geometry
    joints = {j.name: j for j in config.joints}
    shapes = _leg_shapes(config, side)
    offsets = {"hip_yaw": g.hip_in_root(side), "shank": (0, 0, -g.thigh_m), "ankle": (0, 0, -g.shank_m)}
    parent, out = ROOT_LINK, []
    for kind, link in zip(LEG_JOINT_KINDS, LEG_LINKS):
        name, child = f"{kind}_{side}", f"{link}_{side}"
        xyz, joint = offsets.get(link, (0, 0, 0)), joints.get(f"{kind}_{side}")
        out.append(f'<link name="{child}">{_inertial(config.body.leg_link(link, side))}{shapes.get(link, "")}</link>')
        axis = joint_axis(kind, side)
        if joint is None or joint.hold_deg is not None:
            hold = math.radians(joint.hold_deg) if joint is not None else 0.0
            out.append(_fixed(name, parent, child, xyz, matrix_rpy(axis_angle(axis, hold))))
        else:
            effort = joint.model.stall_torque_nm
            out.append(f'<joint name="{name}" type="revolute"><parent link="{parent}"/><child link="{child}"/>'
                       f'{_origin(xyz)}<axis xyz="{_f(*axis)}"/><limit lower="{_f(math.radians(joint.min_deg))}" '
                       f'upper="{_f(math.radians(joint.max_deg))}" effort="{_f(effort)}" '
                       f'velocity="{_f(math.radians(joint.max_velocity_dps))}"/></joint>')
        parent = child
    out.append(f'<link name="{HIP_FRAMES[side]}"/>' + _fixed(f"{HIP_FRAMES[side]}_frame", f"hip_yaw_{side}",
                                                             HIP_FRAMES[side]))
    sole = g.sole_centre_in_foot(side)
    for frame in SOLE_FRAMES[side]:
        out.append(f'<link name="{frame}"/>' + _fixed(f"{frame}_frame", parent, frame, sole))
    return out


def urdf_text(config: RobotConfig) -> str:
    """The URDF document of the robot (module docstring)."""
    g = config.body.geometry
    radius = 0.055 * g.leg_length_m
    torso_half = (max(g.foot_m / 3, 0.02), g.hip_width_m / 2 + radius, 0.3 * g.leg_length_m)
    torso_shape = _shape("box", f'size="{_f(*(2 * np.array(torso_half)))}"',
                         (0, 0, torso_half[2] - g.hip_below_root_m), COLOURS["torso"])
    parts = [f'<link name="{ROOT_LINK}"/>',
             f'<link name="{TORSO_LINK}">{_inertial(config.body.torso)}{torso_shape}</link>',
             _fixed(f"{TORSO_LINK}_frame", ROOT_LINK, TORSO_LINK)]
    for alias, target in ALIAS_FRAMES.items():
        parts += [f'<link name="{alias}"/>', _fixed(f"{alias}_frame", target, alias)]
    for side in SIDES:
        parts += _leg(config, side)
    body = "\n  ".join(parts)
    return (f'<?xml version="1.0"?>\n<!-- {config.name}: written by gaitbot robot export from {config.path.name} '
            f'(frames: docs/robot-description.md) -->\n<robot name={quoteattr(config.name)}>\n  {body}\n</robot>\n')
