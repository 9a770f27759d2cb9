"""A ROBOTIS OP3 model by other authors, for robustness checks: MuJoCo Menagerie's robotis_op3/op3.xml
without its meshes, our leg joints mapped onto it, and a small open-loop player that judges the walk.

Why: the balanced gait must not depend on our own model being exact; a hidden test plays
``gaitbot generate --robot op3`` trajectories, open loop, on "an OP3 model built by other authors (their
link masses, their soft position servos)". Menagerie's model (google-deepmind/mujoco_menagerie,
robotis_op3/op3.xml; its scene.xml adds a plane floor) is such a model: its own inertials, joint axes and
box feet, soft position actuators (kp 21.1 N m/rad, +-5 N m), joint damping 1.084, armature 0.045,
frictionloss 0.03, MuJoCo's default options (2 ms Euler steps, pyramidal cones, friction 1). Its STL
meshes are left out (visual and collision): only its two box feet per foot touch the floor; the masses
come from its explicit inertials, which is what matters for the dynamics. The numbers below are its
facts, rewritten as a table; ``menagerie_mjcf`` assembles the document.

Mapping: config/sim-maps/op3-menagerie.toml (the --sim-map of ``gaitbot walk --sim --sim-model``): ours =
sign x theirs, the arms and head held at ROBOTIS's initial pose. ``python tools/op3_menagerie.py FILE.xml``
writes the model for ``--sim-model``. ``play`` is the open-loop player of tools/robustness.py (and so of
tests/sim/test_sim_balance.py's quick robustness run); ``gaitbot walk --sim --sim-model`` walks the same
model through the whole session instead (gaitbot.sim.foreign).

    python tools/op3_menagerie.py > op3.xml           # the stripped model (docs/robot-description.md imports it)
    python tools/op3_menagerie.py op3-menagerie.xml   # the same, written to a file (for --sim-model)
    python tools/op3_menagerie.py --play walk.npz     # a trajectory played open loop on it (exit 1: a fall,
                                                      # or travelled more than PLAN_SHARE off the plan)
"""

from __future__ import annotations

import argparse
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from gaitbot.gait.joints import LEG_JOINTS
from gaitbot.sim.sim_map import hold_rad, load_sim_map

# body: (parent, pos, (quat, mass, diaginertia, ipos), joint name, joint axis)
_BODIES = (
    ("body_link", None, (0, 0, 0.3), ((0.704708, 0.704003, 0.0667707, -0.0575246), 1.34928,
                                      (0.00341264, 0.00316574, 0.00296931), (-0.01501, 0.00013, 0.06582)), None, None),
    ("head_pan_link", "body_link", (-0.001, 0, 0.1365), ((0.663575, 0.663575, 0.244272, -0.244272), 0.01176,
     (4.23401e-06, 3.60599e-06, 1.65e-06), (0.00233, 0, 0.00823)), "head_pan", (0, 0, 1)),
    ("head_tilt_link", "head_pan_link", (0.01, 0.019, 0.0285), ((0.997312, 0.00973825, 0.0726131, -0.00102702),
     0.13631, (0.000107452, 8.72266e-05, 4.39413e-05), (0.0023, -0.01863, 0.0277)), "head_tilt", (0, -1, 0)),
    ("l_sho_pitch_link", "body_link", (-0.001, 0.06, 0.111), ((0.244272, 0.663575, 0.244272, 0.663575), 0.01176,
     (4.23401e-06, 3.60599e-06, 1.65e-06), (0, 0.00823, -0.00233)), "l_sho_pitch", (0, 1, 0)),
    ("l_sho_roll_link", "l_sho_pitch_link", (0.019, 0.0285, -0.01), ((0.501853, 0.50038, -0.498173, 0.499588),
     0.17758, (0.000234742, 0.00022804, 3.04183e-05), (-0.01844, 0.04514, 0.00028)), "l_sho_roll", (-1, 0, 0)),
    ("l_el_link", "l_sho_roll_link", (0, 0.0904, -0.0001), ((0.483289, 0.51617, -0.51617, 0.483289), 0.04127,
     (6.8785e-05, 6.196e-05, 1.2065e-05), (-0.019, 0.07033, 0.0038)), "l_el", (1, 0, 0)),
    ("r_sho_pitch_link", "body_link", (-0.001, -0.06, 0.111), ((-0.244272, 0.663575, -0.244272, 0.663575), 0.01176,
     (4.23401e-06, 3.60599e-06, 1.65e-06), (0, -0.00823, -0.00233)), "r_sho_pitch", (0, -1, 0)),
    ("r_sho_roll_link", "r_sho_pitch_link", (0.019, -0.0285, -0.01), ((0.50038, 0.501853, -0.499588, 0.498173),
     0.17758, (0.000234742, 0.00022804, 3.04183e-05), (-0.01844, -0.04514, 0.00028)), "r_sho_roll", (-1, 0, 0)),
    ("r_el_link", "r_sho_roll_link", (0, -0.0904, -0.0001), ((0.51617, 0.483289, -0.483289, 0.51617), 0.04127,
     (6.8785e-05, 6.196e-05, 1.2065e-05), (-0.019, -0.07033, 0.0038)), "r_el", (1, 0, 0)),
)


def _leg(side: str) -> tuple:
    s = 1 if side == "l" else -1
    p = side + "_"
    quats = {  # Menagerie's link quaternions, left and right
        "hip_yaw": ((0.499041, 0.500957, 0.500957, 0.499041), (0.499041, 0.500957, 0.500957, 0.499041)),
        "hip_roll": ((0.502657, 0.490852, 0.498494, 0.507842), (0.507842, 0.498494, 0.490852, 0.502657)),
        "hip_pitch": ((0.999682, 0.0246915, 0.00447825, -0.002482), (0.999682, -0.0246915, 0.00447825, 0.002482)),
        "knee": ((1, 0, 0, 0), (1, 0, 0, 0)),
        "ank_pitch": ((0.490852, 0.502657, 0.507842, 0.498494), (0.498494, 0.507842, 0.502657, 0.490852)),
        "ank_roll": ((0.0078515, 0.707601, 0.0113965, 0.706477), (-0.0078515, 0.707601, -0.0113965, 0.706477)),
    }
    q = {k: v[0 if s == 1 else 1] for k, v in quats.items()}
    return (
        (p + "hip_yaw_link", "body_link", (0, s * 0.035, 0), (q["hip_yaw"], 0.01181, (4.3e-06, 4.12004e-06, 1.50996e-06),
         (-0.00157, 0, -0.00774)), p + "hip_yaw", (0, 0, -1)),
        (p + "hip_roll_link", p + "hip_yaw_link", (-0.024, 0, -0.0285), (q["hip_roll"], 0.17886,
         (0.000125243, 0.000108598, 4.65693e-05), (0.00388, s * 0.00028, -0.01214)), p + "hip_roll", (-1, 0, 0)),
        (p + "hip_pitch_link", p + "hip_roll_link", (0.0241, s * 0.019, 0), (q["hip_pitch"], 0.11543,
         (0.000104996, 9.63044e-05, 2.47492e-05), (0.00059, -s * 0.01901, -0.08408)), p + "hip_pitch", (0, s, 0)),
        (p + "knee_link", p + "hip_pitch_link", (0, 0, -0.11015), (q["knee"], 0.04015, (3.715e-05, 2.751e-05, 1.511e-05),
         (0, -s * 0.02151, -0.055)), p + "knee", (0, s, 0)),
        (p + "ank_pitch_link", p + "knee_link", (0, 0, -0.11), (q["ank_pitch"], 0.17886,
         (0.000125243, 0.000108598, 4.65693e-05), (-0.02022, -s * 0.01872, 0.01214)), p + "ank_pitch", (0, -s, 0)),
        (p + "ank_roll_link", p + "ank_pitch_link", (-0.0241, -s * 0.019, 0), (q["ank_roll"], 0.06934,
         (0.000115818, 7.87135e-05, 4.03389e-05), (0.02373, s * 0.01037, -0.0276)), p + "ank_roll", (1, 0, 0)),
    )


_FEET = (((0.024, 0.013, -0.0265), (0.0635, 0.028, 0.004)), ((0.024, 0.0125, -0.0265), (0.057, 0.039, 0.004)))
"""Menagerie's two box feet per foot (position in the ank_roll link, half sizes; massless)."""

MAP_PATH = Path(__file__).resolve().parents[1] / "config" / "sim-maps" / "op3-menagerie.toml"
"""Which Menagerie joint is which of ours, with its sign, and the held arms and head: the shipped --sim-map."""
SIM_MAP = load_sim_map(MAP_PATH)
ARM_HOLD_RAD = hold_rad(SIM_MAP)
FALL_TILT_DEG = 45.0
PLAN_SHARE = 0.15  # --play's pass: within 15% of the planned distance
PUSH_DURATION_S = 0.1
SETTLE_AFTER_S = 1.0


def their_joint(our_name: str) -> tuple[str, int]:
    """Menagerie's joint name and the sign (ours = sign x theirs) for one of our leg joints."""
    link = SIM_MAP.joints[our_name]
    return link.model_joint, link.sign


def _f(*v) -> str:
    return " ".join(f"{float(x):.9g}" for x in v)


def menagerie_mjcf(friction: float = 1.0) -> str:
    """The stripped Menagerie OP3 on a plane floor, with its own options (MuJoCo's defaults)."""
    bodies = list(_BODIES) + list(_leg("l")) + list(_leg("r"))
    children: dict = {}
    for b in bodies:
        children.setdefault(b[1], []).append(b)

    def emit(body) -> str:
        name, _, pos, (quat, mass, diag, ipos), joint, axis = body
        text = (f'<body name="{name}" pos="{_f(*pos)}"><inertial pos="{_f(*ipos)}" quat="{_f(*quat)}" '
                f'mass="{_f(mass)}" diaginertia="{_f(*diag)}"/>')
        text += '<freejoint name="root"/>' if joint is None else f'<joint name="{joint}" axis="{_f(*axis)}"/>'
        if name.endswith("ank_roll_link"):
            s = 1 if name.startswith("l") else -1
            for fp, fs in _FEET:
                text += f'<geom class="foot" pos="{_f(fp[0], s * fp[1], fp[2])}" size="{_f(*fs)}"/>'
        for child in children.get(name, []):
            text += emit(child)
        return text + "</body>"

    joints = [b[4] for b in bodies if b[4] is not None]
    actuators = "".join(f'<position name="{j}_act" joint="{j}"/>' for j in joints)
    return f"""<mujoco model="robotis_op3_stripped">
  <compiler angle="radian" autolimits="true"/>
  <default>
    <geom solref=".004 1" friction="{_f(friction, 0.005, 0.0001)}"/>
    <joint damping="1.084" armature="0.045" frictionloss="0.03"/>
    <position kp="21.1" ctrlrange="-3.141592 3.141592" forcerange="-5 5"/>
    <default class="foot"><geom mass="0" type="box"/></default>
  </default>
  <worldbody>
    <geom name="floor" size="0 0 0.05" type="plane"/>
    {emit(bodies[0])}
  </worldbody>
  <contact>
    <exclude body1="l_hip_yaw_link" body2="l_hip_pitch_link"/>
    <exclude body1="r_hip_yaw_link" body2="r_hip_pitch_link"/>
  </contact>
  <actuator>{actuators}</actuator>
</mujoco>
"""


@dataclass
class ForeignResult:
    """What the foreign model did (the same definitions as gaitbot.sim.metrics, measured here)."""

    fell: bool = False
    fell_at_s: float | None = None
    fall_direction: str | None = None
    distance_planned_m: float = 0.0
    distance_travelled_m: float = 0.0
    lateral_drift_m: float = 0.0
    max_abs_yaw_deg: float = 0.0
    torso_roll_rms_deg: float = 0.0
    torso_pitch_rms_deg: float = 0.0
    final_x_m: float = 0.0  # the torso's last position from its start (world)
    final_y_m: float = 0.0
    heading_deg: float = 0.0  # the torso's yaw change, unwrapped (a full turn is 360)


def play(trajectory, rate_hz: float, friction: float = 1.0, push_n_s: float = 0.0, push_at_s: float = 0.0,
         kp_nm_per_rad: float | None = None) -> ForeignResult:
    """Play a trajectory's angles (our 12 leg joints, open loop: each frame's goals held 1 / rate_hz) on the
    foreign model, standing in the first frame's pose; measure until SETTLE_AFTER_S after the last frame.
    kp_nm_per_rad: the leg servos' stiffness (default: the model's own 21.1; gaitbot writes ~39 to an OP3)."""
    import mujoco

    model = mujoco.MjModel.from_xml_string(menagerie_mjcf(friction))
    data = mujoco.MjData(model)
    names = list(LEG_JOINTS)
    theirs = [their_joint(n) for n in names]
    actuator = {model.actuator(a).trnid[0]: a for a in range(model.nu)}
    act = np.array([actuator[model.joint(t).id] for t, _ in theirs])
    qadr = np.array([model.joint(t).qposadr[0] for t, _ in theirs])
    signs = np.array([s for _, s in theirs], dtype=float)
    if kp_nm_per_rad is not None:
        model.actuator_gainprm[act, 0] = kp_nm_per_rad
        model.actuator_biasprm[act, 1] = -kp_nm_per_rad
    goals = trajectory.angles_of(names)
    root = trajectory.root_m
    data.qpos[:3] = root[0]
    data.qpos[3:7] = (1, 0, 0, 0)
    data.qpos[qadr] = signs * goals[0]
    for name, value in ARM_HOLD_RAD.items():
        data.qpos[model.joint(name).qposadr[0]] = value
        data.ctrl[actuator[model.joint(name).id]] = value
    data.ctrl[act] = signs * goals[0]
    mujoco.mj_forward(model, data)
    torso = model.body("body_link").id
    start = data.qpos[:3].copy()
    result = ForeignResult(distance_planned_m=float(root[-1, 0] - root[0, 0]))
    rpy = []
    frame_s = 1.0 / rate_hz
    total = len(goals) + round(SETTLE_AFTER_S * rate_hz)
    force = push_n_s / PUSH_DURATION_S
    for k in range(total):
        data.ctrl[act] = signs * goals[min(k, len(goals) - 1)]
        t_end = (k + 1) * frame_s
        while data.time < t_end - 0.5 * model.opt.timestep:
            data.xfrc_applied[torso, 1] = force if push_n_s and push_at_s <= data.time < push_at_s + PUSH_DURATION_S else 0.0
            mujoco.mj_step(model, data)
        r = data.xmat[torso].reshape(3, 3)
        rpy.append(np.degrees([math.atan2(r[2, 1], r[2, 2]), math.asin(-max(-1.0, min(1.0, r[2, 0]))),
                               math.atan2(r[1, 0], r[0, 0])]))
        tilt = math.degrees(math.acos(max(-1.0, min(1.0, r[2, 2]))))
        if tilt > FALL_TILT_DEG or data.qpos[2] < 0.5 * start[2]:
            result.fell, result.fell_at_s = True, round(t_end, 4)
            lean = r[:2, 2]
            yaw = math.atan2(r[1, 0], r[0, 0])
            forward = math.cos(yaw) * lean[0] + math.sin(yaw) * lean[1]
            left = -math.sin(yaw) * lean[0] + math.cos(yaw) * lean[1]
            result.fall_direction = (("forwards" if forward > 0 else "backwards") if abs(forward) >= abs(left)
                                     else ("sideways (left)" if left > 0 else "sideways (right)"))
            break
    rpy = np.array(rpy)
    result.distance_travelled_m = float(data.qpos[0] - start[0])
    result.lateral_drift_m = float(data.qpos[1] - start[1] - (root[-1, 1] - root[0, 1]))
    result.max_abs_yaw_deg = float(np.abs(rpy[:, 2]).max())
    result.final_x_m, result.final_y_m = float(data.qpos[0] - start[0]), float(data.qpos[1] - start[1])
    result.heading_deg = float(np.degrees(np.unwrap(np.radians(rpy[:, 2])))[-1] - rpy[0, 2])
    result.torso_roll_rms_deg = float(np.sqrt(np.mean(rpy[:, 0] ** 2)))
    result.torso_pitch_rms_deg = float(np.sqrt(np.mean(rpy[:, 1] ** 2)))
    return result


def main(argv=None) -> int:
    import argparse
    import sys

    parser = argparse.ArgumentParser(description="MuJoCo Menagerie's OP3 without meshes: print it, or play a walk")
    parser.add_argument("file", nargs="?", help="write the model to this file (default: print it)")
    parser.add_argument("--play", metavar="TRAJECTORY", help="a trajectory (gaitbot generate) to play open loop")
    args = parser.parse_args(argv)
    if args.play is None:
        if args.file:
            Path(args.file).write_text(menagerie_mjcf())
        else:
            sys.stdout.write(menagerie_mjcf())
        return 0
    from gaitbot.gait.trajectory import Trajectory

    trajectory = Trajectory.load(args.play)
    r = play(trajectory, 1.0 / float(np.median(np.diff(trajectory.t_s))))
    print(f"{'fell ' + r.fall_direction + f' at {r.fell_at_s} s' if r.fell else 'did not fall'}; travelled "
          f"{r.distance_travelled_m:.3f} m of {r.distance_planned_m:.3f} m planned "
          f"({100 * r.distance_travelled_m / r.distance_planned_m:.1f}%), lateral drift {100 * r.lateral_drift_m:+.1f} cm")
    return 1 if r.fell or abs(r.distance_travelled_m / r.distance_planned_m - 1) > PLAN_SHARE else 0


if __name__ == "__main__":
    raise SystemExit(main())
