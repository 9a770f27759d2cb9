"""The simulated robot as MJCF, built from the robot config: links, masses, servos, feet, floor, boom.

A planar (sagittal) biped, as research bipeds are first tested: the torso rides on a boom that
lets it move forward (slide x) and up and down (slide z); its pitch is held (no pitch joint) unless
``free_pitch``, which adds a free hinge. Both legs hang from the torso, hip_width apart, and only
touch the floor, never each other.

Legs (``[geometry]``, the numbers the gait's LegGeometry is made of, so the feet are where the gait
thinks they are): thigh and shank capsules, and a foot whose sole is a box from the heel
(heel_back_m behind the ankle) to the toe (foot_m ahead of the heel), its underside ankle_height_m
below the ankle axis. (The sim room reads the robot config only; the gait's plan comes in through walk.py.)
Hinge axes follow the flexion-positive convention: hip and ankle about -y, knee about +y.

Masses (``[mass]``): torso, thigh, shank, foot; inertias follow from each link's shape as a
uniform solid. The torso is a box 0.6 leg lengths tall standing on the hips (its centre of mass
0.3 leg lengths above them); it matters only with a free pitch. The boom itself is massless.

Servos: one MuJoCo position actuator per walking joint, modelled as a DC gearmotor under a
proportional position loop, which is what these servos are:

    torque = clip(kp * (goal - angle), -stall, +stall) - b * speed,    b = stall / no_load_speed

kp = stall torque / full-torque error. The model starts at the factory gain (ServoModel.full_torque_error_deg);
what the session writes to a servo's gain register then sets it (port.py reads the register, the
robot's ``set_full_torque_error``), so ``[servo] full_torque_error_deg`` reaches the simulated robot only
through the packets a real robot would get. ``[servo]`` stall torque and no-load speed override the
datasheet figures. The back-EMF term b * speed is the joint's damping: it gives the datasheet no-load speed
at full effort and the motor's straight torque-speed line below it. The gearbox's reflected rotor
inertia (armature) is b * MOTOR_TIME_CONSTANT_S. Joint ranges are the config's min_deg..max_deg.
Held joints (e.g. the ax12a-biped's hip roll) are not modelled: a planar model has no roll; the sim
bus answers for them as an ideal servo at its goal.

Contacts: stiff, because MuJoCo's soft defaults (solref 0.02 s, solimp 0.9/0.95, impratio 1) let
the feet creep under sideways load: measured here, 1.5 mm in 2 s under a push of 0.3 m g (and a
0.2 mm sink), which would read as slip that a rubber sole on a hard floor does not have. We use
solref 0.004 s (critically damped) with solimp (0.95, 0.99, 1 mm) and elliptic friction cones with
impratio 10 (stiff friction): 0.015 mm of creep and a 0.004 mm sink (tests/sim/test_sim_model.py).
Sliding friction 1.0 (a rubber sole on a hard floor). Timestep: a frame is cut into whole steps
of at most 1 ms (MuJoCo wants solref's time constant >= 2 timesteps; here 4); halving it changes
the walks' distances by under 0.5%.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from gaitbot.robot.config import Geometry, RobotConfig

MAX_TIMESTEP_S = 0.001
CONTACT_SOLREF = (0.004, 1.0)
CONTACT_SOLIMP = (0.95, 0.99, 0.001)
FLOOR_FRICTION = 1.0
IMPRATIO = 10.0
# Mechanical time constant of a small servo gearmotor, J / b: MuJoCo Menagerie's ROBOTIS OP3 model
# gives its XM430 joints armature 0.045 kg m^2 over damping 1.084 N m s = 42 ms; assumed for all models.
MOTOR_TIME_CONSTANT_S = 0.042
SOLE_THICKNESS_M = 0.004
TORSO_HEIGHT_LEGS = 0.6
JOINT_AXES = {"hip": "0 -1 0", "knee": "0 1 0", "ankle": "0 -1 0"}
SIDES = ("left", "right")
LEG_RGBA = {"left": "0.45 0.5 0.6 1", "right": "0.9 0.6 0.2 1"}  # the video's near (right) leg bright


@dataclass(frozen=True)
class JointDrive:
    """One walking joint's servo as the simulation drives it (SI units; angles of the joint)."""

    name: str
    min_deg: float
    max_deg: float
    stall_torque_nm: float
    no_load_speed_rad_s: float
    full_torque_error_deg: float

    @property
    def kp_nm_per_rad(self) -> float:
        return self.stall_torque_nm / math.radians(self.full_torque_error_deg)

    @property
    def damping_nm_s_per_rad(self) -> float:
        """Back-EMF damping: at the no-load speed it eats the whole stall torque."""
        return self.stall_torque_nm / self.no_load_speed_rad_s

    @property
    def armature_kg_m2(self) -> float:
        return self.damping_nm_s_per_rad * MOTOR_TIME_CONSTANT_S


def joint_drives(config: RobotConfig, joints=None) -> tuple[JointDrive, ...]:
    """The walking joints' drives (or those of ``joints``): each joint's servo model at its factory gain,
    with the ``[servo]`` stall torque and no-load speed overrides applied (the gain is the control table's
    business)."""
    over = config.servo
    drives = []
    for joint in (config.walking_joints if joints is None else joints):
        model = joint.model
        rpm = over.no_load_speed_rpm if over.no_load_speed_rpm is not None else model.no_load_speed_rpm
        drives.append(JointDrive(
            name=joint.name, min_deg=joint.min_deg, max_deg=joint.max_deg,
            stall_torque_nm=over.stall_torque_nm if over.stall_torque_nm is not None else model.stall_torque_nm,
            no_load_speed_rad_s=rpm * 2.0 * math.pi / 60.0, full_torque_error_deg=model.full_torque_error_deg))
    return tuple(drives)


def substeps_per_frame(rate_hz: float) -> int:
    """Physics steps per frame: the fewest that keep the timestep at or below MAX_TIMESTEP_S."""
    return max(1, math.ceil(1.0 / (rate_hz * MAX_TIMESTEP_S) - 1e-9))


def _f(*values: float) -> str:
    return " ".join(f"{v:.6g}" for v in values)


def _leg(side: str, y_m: float, g: Geometry, config: RobotConfig, drives: dict[str, JointDrive]) -> str:
    mass = config.mass
    radius = 0.1 * (g.thigh_m + g.shank_m) / 2
    sole_centre_x = g.foot_m / 2 - g.heel_back_m
    sole_centre_z = -g.ankle_height_m + SOLE_THICKNESS_M / 2
    sole_half = (g.foot_m / 2, max(g.hip_width_m / 4, 0.01), SOLE_THICKNESS_M / 2)

    colour = LEG_RGBA[side]

    def joint(kind: str) -> str:
        d = drives[f"{kind}_pitch_{side}"]
        return (f'<joint name="{d.name}" axis="{JOINT_AXES[kind]}" range="{_f(d.min_deg, d.max_deg)}" '
                f'damping="{_f(d.damping_nm_s_per_rad)}" armature="{_f(d.armature_kg_m2)}"/>')

    return f"""
    <body name="thigh_{side}" pos="0 {_f(y_m)} 0">
      {joint("hip")}
      <geom name="thigh_{side}" type="capsule" fromto="0 0 0 0 0 {_f(-g.thigh_m)}" size="{_f(radius)}" mass="{_f(mass.thigh_kg)}" rgba="{colour}"/>
      <body name="shank_{side}" pos="0 0 {_f(-g.thigh_m)}">
        {joint("knee")}
        <geom name="shank_{side}" type="capsule" fromto="0 0 0 0 0 {_f(-g.shank_m)}" size="{_f(radius)}" mass="{_f(mass.shank_kg)}" rgba="{colour}"/>
        <body name="foot_{side}" pos="0 0 {_f(-g.shank_m)}">
          {joint("ankle")}
          <geom name="sole_{side}" type="box" pos="{_f(sole_centre_x, 0, sole_centre_z)}" size="{_f(*sole_half)}" mass="{_f(mass.foot_kg)}" rgba="0.2 0.2 0.25 1"/>
          <geom name="bracket_{side}" type="capsule" fromto="0 0 0 0 0 {_f(-g.ankle_height_m + SOLE_THICKNESS_M)}" size="{_f(radius * 0.8)}" contype="0" conaffinity="0" mass="0" rgba="{colour}"/>
          <site name="touch_{side}" type="box" pos="{_f(sole_centre_x, 0, -g.ankle_height_m + SOLE_THICKNESS_M / 4)}" size="{_f(sole_half[0] + 1e-3, sole_half[1] + 1e-3, SOLE_THICKNESS_M)}" rgba="0 0 0 0"/>
        </body>
      </body>
    </body>"""


def mjcf_document(name: str, timestep: float, drives, torso: str, number=_f) -> str:
    """The MJCF both models share around the robot: solver options, contact defaults, the floor, one
    position actuator per servo (``drives``, in actuator order), the soles' touch sensors; ``torso`` is the
    robot's body element, legs included; ``number`` writes the actuators' numbers (the 3D model keeps more
    digits)."""
    actuators = "\n    ".join(
        f'<position name="{d.name}" joint="{d.name}" kp="{number(d.kp_nm_per_rad)}" '
        f'forcerange="{number(-d.stall_torque_nm, d.stall_torque_nm)}" '
        f'ctrlrange="{number(math.radians(d.min_deg), math.radians(d.max_deg))}"/>' for d in drives)
    sensors = "\n    ".join(f'<touch name="touch_{side}" site="touch_{side}"/>' for side in SIDES)
    return f"""<mujoco model="{name}">
  <compiler angle="degree" autolimits="true"/>
  <option timestep="{_f(timestep)}" integrator="implicitfast" cone="elliptic" impratio="{_f(IMPRATIO)}"/>
  <visual><global offwidth="640" offheight="480"/></visual>
  <default>
    <geom contype="2" conaffinity="1" condim="3" friction="{_f(FLOOR_FRICTION, 0.005, 0.0001)}"
          solref="{_f(*CONTACT_SOLREF)}" solimp="{_f(*CONTACT_SOLIMP)}"/>
  </default>
  <asset>
    <texture name="grid" type="2d" builtin="checker" rgb1="0.92 0.92 0.92" rgb2="0.78 0.8 0.84" width="256" height="256"/>
    <material name="grid" texture="grid" texrepeat="1 1" texuniform="true"/>
  </asset>
  <worldbody>
    <light pos="0 -2 3" dir="0 1 -1.5" directional="true"/>
    <geom name="floor" type="plane" size="0 0 0.05" material="grid" contype="1" conaffinity="2"/>
    {torso}
  </worldbody>
  <actuator>
    {actuators}
  </actuator>
  <sensor>
    {sensors}
  </sensor>
</mujoco>
"""


def build_mjcf(config: RobotConfig, rate_hz: float, free_pitch: bool = False) -> str:
    """The MJCF document of the robot standing straight with its soles on the floor at z = 0.

    rate_hz: the frame rate; the timestep divides a frame into whole substeps_per_frame steps.
    free_pitch: let the torso pitch freely on the boom (default: held upright)."""
    g = config.geometry
    drives = {d.name: d for d in joint_drives(config)}
    timestep = 1.0 / (rate_hz * substeps_per_frame(rate_hz))
    leg_length = g.thigh_m + g.shank_m
    torso_h = TORSO_HEIGHT_LEGS * leg_length
    radius = 0.1 * leg_length / 2
    torso_half = (max(g.foot_m / 3, 0.02), g.hip_width_m / 2 + radius, torso_h / 2)
    pitch = '<joint name="boom_pitch" type="hinge" axis="0 1 0"/>' if free_pitch else ""
    legs = "".join(_leg(side, y, g, config, drives) for side, y in zip(SIDES, (g.hip_width_m / 2, -g.hip_width_m / 2)))
    torso = f"""<body name="torso" pos="0 0 {_f(leg_length + g.ankle_height_m)}">
      <joint name="boom_x" type="slide" axis="1 0 0"/>
      <joint name="boom_z" type="slide" axis="0 0 1"/>
      {pitch}
      <geom name="torso" type="box" pos="0 0 {_f(torso_half[2] + radius)}" size="{_f(*torso_half)}" mass="{_f(config.mass.torso_kg)}" rgba="0.3 0.45 0.7 1"/>
      {legs}
    </body>"""
    return mjcf_document(config.name, timestep, drives.values(), torso)
