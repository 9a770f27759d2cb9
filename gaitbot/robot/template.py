"""A new robot's config, written whole and commented: ``gaitbot robot new NAME --legs 6|12 -o FILE``.

Why a template and not a page of docs: a maker starts from a file that already plans, generates, checks
and simulates (a made-up robot of the usual size: 220 mm legs, Dynamixel X servos), then changes one
value at a time and sees what it does. Every value that only the real robot can give (the servos' ids,
models, zero ticks and directions, the bus) is marked ``FILL IN``, and ``[robot] draft`` stays until they
are: the hardware commands refuse a draft (gaitbot.app.hardware), the dry run and the simulation do not.
The numbers are those of the shipped robots of the same shape (xl430-biped for 6 joints, op3 for 12).
"""

from __future__ import annotations

from gaitbot.gait.joints import LEG_JOINTS, PITCH_JOINTS

#: The joints of a template, by legs' joint count: the pitch-only robot (on a boom) or the one whose legs roll.
TEMPLATE_JOINTS = {6: PITCH_JOINTS, 12: LEG_JOINTS}

DRAFT = ("made by gaitbot robot new: the servo ids, models, zero ticks, directions and the bus are placeholders "
         "(FILL IN); measure them on the robot (gaitbot scan, gaitbot calibrate), then delete this line")

_HEADER = """\
# {name}: a robot config made by `gaitbot robot new {name} --legs {legs}` (every key: docs/robot-config.md).
# It plans, generates, checks and simulates as it is (gaitbot walk --sim --robot {file}); it is a made-up
# robot until every value marked FILL IN is the real robot's. [robot] draft keeps the hardware commands
# from using it until then: delete that line when the file describes your robot.
# Lengths in metres, angles in degrees, masses in kilograms. Joint signs: flexion positive (knee bent,
# hip forward, toes up); roll outward positive; yaw toe-outward positive (docs/robot-config.md).

[robot]
name = "{name}"
draft = "{draft}"
{boom}
[geometry]                # FILL IN: measure your robot (docs/robot-config.md, the leg's drawing)
thigh_m = 0.110           # hip pitch axis to knee axis
shank_m = 0.110           # knee axis to ankle pitch axis
foot_m = {foot_m}            # sole length, heel to toe
hip_width_m = 0.070       # between the two hip pitch joints
ankle_height_m = 0.0305   # ankle pitch axis above the sole
heel_back_m = {heel_back_m}        # the heel behind the ankle axis: the ankle stands over the middle half of the sole
{three_d_geometry}
[gait]                    # how it walks; tune after the first walks (docs/gait.md)
cycle_s = {cycle_s}              # two steps, seconds
max_step_m = {max_step_m}         # the longest step gaitbot plans
clearance_m = {clearance_m}        # the swing sole's height above the ground
rate_hz = 60              # goal frames a second (the bus must carry them: gaitbot refuses a rate it cannot)

[mass]                    # FILL IN: weigh the parts (a planar estimate of each segment is enough to start)
torso_kg = {torso_kg}           # everything above the hips
thigh_kg = {thigh_kg}           # one thigh, its servos included
shank_kg = {shank_kg}           # one shank
foot_kg = {foot_kg}            # one foot
{balance}
[servo]
full_torque_error_deg = {stiffness}   # position error at which a servo gives its full torque (its P gain)

[bus]                     # FILL IN: your adapter and the servos' baud rate (gaitbot scan finds them)
backend = "dynamixel"     # or "feetech"
protocol = 2.0
port = "/dev/ttyUSB0"
baudrate = 1000000
torque_off_on_exit = false
"""

_THREE_D_GEOMETRY = """\
foot_width_m = 0.078      # sole width: a robot whose legs roll balances sideways on its soles
sole_outward_m = 0.0125   # the sole's centre outward of the ankle (the soles must not touch: 5 mm apart at least)
hip_below_root_m = 0.0285 # the hip point below the pelvis frame's origin (the root)
"""

_BALANCE = """
[balance]                 # the balanced walk (docs/balance.md); these walk the template in the simulation
crouch_knee_deg = 60.0
double_support_share = 0.15
zmp_forward_m = 0.025
zmp_inward_m = 0.0
preview_horizon_s = 1.0
preview_jerk_weight = 1e-6
sag_feedforward = true
progression_end = 0.85
"""

_JOINT = """\
[joints.{joint}]{note}
id = {id}                    # FILL IN: the servo's id on the bus (gaitbot setup, gaitbot scan)
model = "{model}"     # FILL IN: the servo model (docs/robot-config.md lists the known ones)
zero_tick = 2048          # FILL IN: the tick at the zero pose (gaitbot calibrate measures it)
direction = {direction}             # FILL IN: 1 or -1, the way the ticks grow as the joint flexes (gaitbot calibrate)
min_deg = {min_deg}
max_deg = {max_deg}
max_velocity_dps = {max_velocity_dps}
max_acceleration_dps2 = {max_acceleration_dps2}
"""

#: Joint ranges (deg) of the templates: the shipped robots' of the same shape (xl430-biped, op3).
_LIMITS_DEG = {6: {"hip_pitch": (-45.0, 60.0), "knee_pitch": (-5.0, 110.0), "ankle_pitch": (-60.0, 60.0)},
               12: {"hip_yaw": (-45.0, 45.0), "hip_roll": (-30.0, 54.0), "hip_pitch": (-60.0, 72.0),
                    "knee_pitch": (-5.0, 126.0), "ankle_pitch": (-72.0, 72.0), "ankle_roll": (-45.0, 45.0)}}
_SHAPE = {6: {"foot_m": "0.120", "heel_back_m": "0.040", "cycle_s": "2.8", "max_step_m": "0.100",
              "clearance_m": "0.012", "torso_kg": "0.40", "thigh_kg": "0.09", "shank_kg": "0.09", "foot_kg": "0.04",
              "stiffness": "2.0", "model": "XL430-W250", "speed": (300.0, 12000.0)},
          12: {"foot_m": "0.127", "heel_back_m": "0.0635", "cycle_s": "1.2", "max_step_m": "0.050",
               "clearance_m": "0.005", "torso_kg": "1.95", "thigh_kg": "0.30", "shank_kg": "0.04", "foot_kg": "0.25",
               "stiffness": "6.0", "model": "XM430-W350", "speed": (240.0, 20000.0)}}


def template_text(name: str, legs: int, file: str) -> str:
    """The TOML text of a new robot ``name`` with ``legs`` joints in its two legs (6 or 12); ``file`` is
    where it will be written (said in its first comment, for the command that walks it)."""
    shape = _SHAPE[legs]
    text = _HEADER.format(name=name, legs=legs, file=file, draft=DRAFT,
                          boom="boom = true                # a pitch-only robot cannot balance sideways: it walks "
                               "on a boom\n" if legs == 6 else "",
                          three_d_geometry=_THREE_D_GEOMETRY if legs == 12 else "",
                          balance=_BALANCE if legs == 12 else "", **shape)
    velocity, acceleration = shape["speed"]
    for index, joint in enumerate(TEMPLATE_JOINTS[legs], start=1):
        kind, side = joint.rsplit("_", 1)
        lo, hi = _LIMITS_DEG[legs][kind]
        text += "\n" + _JOINT.format(joint=joint, note="   # min/max_deg: FILL IN your robot's" if index == 1 else "",
                                     id=index, model=shape["model"], direction=1 if side == "left" else -1,
                                     min_deg=lo, max_deg=hi, max_velocity_dps=velocity,
                                     max_acceleration_dps2=acceleration)
    return text
