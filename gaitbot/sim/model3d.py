"""The simulated robot in 3D, built from the robot config alone: every joint, every link's inertia.

Bodies: the torso (``[links.torso]``: the pelvis with held arms and head, lumped) and per leg
hip_yaw -> hip_roll -> thigh -> shank -> ankle -> foot (gaitbot.gait.body), each with its mass, centre
of mass and full inertia from ``config.body``, its joint where the config has one (a joint the config
does not list is welded at 0), axes in gaitbot's sign conventions (gaitbot.gait.kinematics6), so
MuJoCo's joint angle *is* the trajectory's angle. A robot with a ``[mass]`` table of four segments gets
the body model gaitbot.gait.body makes of it. Feet: one box of foot_m x foot_width_m per foot, its
underside ankle_height_m below the ankle point, centred heel_back_m / sole_outward_m as configured.
Thigh, shank and torso carry massless collision shapes only so that a fall (a part other than a sole on
the floor) is seen; the robot never collides with itself.

Support (``support``): "free", a free-floating torso (the default of ``gaitbot walk --sim``); "boom",
the torso on today's boom (slides along x and z, pitch held); "boom-pitch", the boom with a free pitch
hinge. Servos, contacts and the timestep are those of the planar model (gaitbot.sim.model): a clipped
P loop with back-EMF damping and the gearbox's armature, stiff contacts, <= 1 ms steps.
"""

from __future__ import annotations

from enum import Enum

import numpy as np

from gaitbot.gait.body import LEG_LINKS
from gaitbot.gait.joints import LEG_JOINT_KINDS, SIDES
from gaitbot.gait.kinematics6 import joint_axis
from gaitbot.robot.config import RobotConfig
from gaitbot.sim.model import LEG_RGBA, SOLE_THICKNESS_M, JointDrive, joint_drives, mjcf_document, substeps_per_frame

class TorsoSupport(str, Enum):
    """How the simulated torso is held; compares and hashes as its value ("free", "boom", "boom-pitch")."""

    FREE = "free"  # free-floating
    BOOM = "boom"  # slides along x and z, pitch held
    BOOM_PITCH = "boom-pitch"  # the boom, with a free pitch hinge

    def __str__(self) -> str:
        return self.value

    def __hash__(self) -> int:
        return hash(self.value)


SUPPORTS = tuple(support.value for support in TorsoSupport)
MIN_MOVING_LINK_KG = 1e-4  # MuJoCo needs mass on a body that moves; a massless link of a pitch-only leg gets this
MIN_MOVING_LINK_INERTIA_KG_M2 = 1e-9


def _f(*values) -> str:
    return " ".join(f"{float(v):.9g}" for v in values)


def _inertial(link, moving: bool) -> str:
    mass, inertia = link.mass_kg, link.inertia_kg_m2
    if mass < MIN_MOVING_LINK_KG:
        if not moving:
            return ""
        mass, inertia = MIN_MOVING_LINK_KG, np.eye(3) * MIN_MOVING_LINK_INERTIA_KG_M2
    i = inertia
    return (f'<inertial pos="{_f(*link.com_m)}" mass="{_f(mass)}" '
            f'fullinertia="{_f(i[0, 0], i[1, 1], i[2, 2], i[0, 1], i[0, 2], i[1, 2])}"/>')


def _held_turn(config: RobotConfig, name: str, drive) -> str:
    """A held joint that is not modelled (the exported model: held joints fixed) is welded at its hold angle."""
    held = {j.name: j.hold_deg for j in config.held_joints}
    if drive is not None or not held.get(name):
        return ""
    half = np.radians(held[name]) / 2
    axis = np.array(joint_axis(*name.rsplit("_", 1)))
    return f' quat="{_f(np.cos(half), *(np.sin(half) * axis))}"'


def capsule_radius_m(config: RobotConfig) -> float:
    return 0.055 * config.body.geometry.leg_length_m


def _leg(config: RobotConfig, side: str, drives: dict[str, JointDrive], exact: bool = False) -> str:
    g = config.body.geometry
    radius = capsule_radius_m(config)
    colour = LEG_RGBA[side]
    gap = radius + 0.005  # collision capsules stop short of the joints (a knee or ankle bracket is not a bone)
    shapes = {
        "thigh": f'<geom name="thigh_{side}" type="capsule" fromto="0 0 {_f(-gap)} 0 0 {_f(-g.thigh_m + gap)}" '
                 f'size="{_f(radius)}" mass="0" rgba="{colour}"/>',
        "shank": f'<geom name="shank_{side}" type="capsule" fromto="0 0 {_f(-gap)} 0 0 {_f(-g.shank_m + gap)}" '
                 f'size="{_f(radius)}" mass="0" rgba="{colour}"/>',
    }
    sole = g.sole_centre_in_foot(side)
    half = (g.foot_m / 2, g.foot_width_m / 2, SOLE_THICKNESS_M / 2)
    shapes["foot"] = (
        f'<geom name="sole_{side}" type="box" pos="{_f(sole[0], sole[1], sole[2] + SOLE_THICKNESS_M / 2)}" '
        f'size="{_f(*half)}" mass="0" rgba="0.2 0.2 0.25 1"/>'
        f'<geom name="bracket_{side}" type="capsule" fromto="0 0 0 0 0 {_f(-g.ankle_height_m + SOLE_THICKNESS_M)}" '
        f'size="{_f(radius * 0.8)}" contype="0" conaffinity="0" mass="0" rgba="{colour}"/>'
        f'<site name="touch_{side}" type="box" pos="{_f(sole[0], sole[1], sole[2] + SOLE_THICKNESS_M / 4)}" '
        f'size="{_f(half[0] + 1e-3, half[1] + 1e-3, SOLE_THICKNESS_M)}" rgba="0 0 0 0"/>'
        f'<site name="sole_{side}" pos="{_f(*sole)}" size="0.003" rgba="0 0 0 0"/>')
    offsets = {"hip_yaw": g.hip_in_root(side), "hip_roll": (0, 0, 0), "thigh": (0, 0, 0), "shank": (0, 0, -g.thigh_m),
               "ankle": (0, 0, -g.shank_m), "foot": (0, 0, 0)}
    text, closing = "", ""
    masses = [config.body.leg_links[link].mass_kg for link in LEG_LINKS]
    for k, (kind, link) in enumerate(zip(LEG_JOINT_KINDS, LEG_LINKS)):
        name = f"{kind}_{side}"
        drive = drives.get(name)
        joint = ""
        if drive is not None:
            joint = (f'<joint name="{name}" axis="{_f(*joint_axis(kind, side))}" range="{_f(drive.min_deg, drive.max_deg)}" '
                     f'damping="{_f(drive.damping_nm_s_per_rad)}" armature="{_f(drive.armature_kg_m2)}"/>')
        # exact (the exported model): a massless link that carries massy ones stays massless (MuJoCo allows it)
        moving = drive is not None and not (exact and sum(masses[k + 1:]) > 0)
        text += (f'<body name="{link}_{side}" pos="{_f(*offsets[link])}"{_held_turn(config, name, drive)}>{joint}'
                 f'{_inertial(config.body.leg_link(link, side), moving)}{shapes.get(link, "")}')
        closing += "</body>"
    return text + closing


def build_mjcf_3d(config: RobotConfig, drives: tuple[JointDrive, ...], rate_hz: float, support: str = "free",
                  exact_masses: bool = False) -> str:
    """The MJCF document of the robot standing straight with its soles on the floor at z = 0 (the root at
    the standing height); ``drives``: the modelled joints' servos, in the order of the actuators.
    ``exact_masses``: no minimum mass on a moving massless link that carries others (the exported model's
    masses are the config's exactly; the simulation keeps the minimum, as it always had)."""
    if support not in SUPPORTS:
        raise ValueError(f"support must be one of {SUPPORTS}, got {support!r}")
    g = config.body.geometry
    by_name = {d.name: d for d in drives}
    timestep = 1.0 / (rate_hz * substeps_per_frame(rate_hz))
    radius = capsule_radius_m(config)
    torso_half = (max(g.foot_m / 3, 0.02), g.hip_width_m / 2 + radius, 0.3 * g.leg_length_m)
    torso_centre_z = torso_half[2] - g.hip_below_root_m  # a box standing on the hips
    if support == "free":
        root_joints = '<freejoint name="root"/>'
    else:
        root_joints = ('<joint name="boom_x" type="slide" axis="1 0 0"/><joint name="boom_z" type="slide" axis="0 0 1"/>'
                       + ('<joint name="boom_pitch" type="hinge" axis="0 1 0"/>' if support == "boom-pitch" else ""))
    legs = "".join(_leg(config, side, by_name, exact_masses) for side in SIDES)
    torso = f"""<body name="torso" pos="0 0 {_f(g.standing_root_height_m)}">
      {root_joints}
      {_inertial(config.body.torso, True)}
      <geom name="torso" type="box" pos="0 0 {_f(torso_centre_z)}" size="{_f(*torso_half)}" mass="0" rgba="0.3 0.45 0.7 1"/>
      {legs}
    </body>"""
    return mjcf_document(config.name, timestep, drives, torso, number=_f)


def exported_mjcf(config: RobotConfig) -> str:
    """``gaitbot robot export --mjcf``: the simulated robot itself (this module's model, free-floating, at the
    config's frame rate), its walking joints driven by their servos and its held joints fixed at their hold
    angles. Body and joint names are gaitbot's (docs/robot-description.md)."""
    return build_mjcf_3d(config, joint_drives(config), config.gait.rate_hz, "free", exact_masses=True)
