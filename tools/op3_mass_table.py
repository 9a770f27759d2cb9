"""Derive config/op3.toml's mass table from ROBOTIS's published OP3 description, reproducibly.

    python tools/op3_mass_table.py                          # prints the [links.*] block and [mass] total_kg
    python tools/op3_mass_table.py --check config/op3.toml  # exit 1 if the file differs from the derivation

Why a script: the robot file holds numbers in gaitbot's frames (gaitbot.gait.body: link origins at the
leg's joint points, ROS REP-103 axes, the left leg given, the right mirrored) and a torso that lumps the
pelvis, the arms and the head (held at ROBOTIS's initial pose) into one rigid body. Converting ROBOTIS's
link table by hand would be error-prone; this does the arithmetic (tests/robot/test_op3_mass_table.py
runs --check).

Sources (facts only, no code copied):
- ROBOTIS-GIT/ROBOTIS-OP3, op3_kinematics_dynamics/src/op3_kinematics_dynamics.cpp: link masses,
  centres of mass (in each link's joint frame), joint offsets and axes (the same offsets as the URDF
  xacros in ROBOTIS-GIT/ROBOTIS-OP3-Common robotis_op3_description/_urdf/*.xacro).
- google-deepmind/mujoco_menagerie, robotis_op3/op3.xml: the same masses and CoMs, and each link's
  rotational inertia as principal moments + orientation (ROBOTIS's own link table gives inertias that
  disagree with it by 10-100x; Menagerie's are used).
- ROBOTIS-GIT/ROBOTIS-OP3, op3_base_module/data/ini_pose.yaml: the arms/head hold pose (deg).
"""

from __future__ import annotations

import numpy as np

# --- ROBOTIS link table (left side and trunk), metres / kg, each in its own joint frame ----------
# name: (parent, offset from parent's frame, joint axis, mass, CoM)
ROBOTIS = {
    "pelvis": (None, (0, 0, 0), (0, 0, 0), 1.3492787, (-0.015014868, 0.00013099, 0.065815797)),
    "head_pan": ("pelvis", (-0.001, 0, 0.1365), (0, 0, 1), 0.011759436, (0.002327479, 0, 0.008227847)),
    "head_tilt": ("head_pan", (0.01, 0.019, 0.0285), (0, -1, 0), 0.13630649, (0.002298411, -0.018634079, 0.027696734)),
    "l_sho_pitch": ("pelvis", (-0.001, 0.06, 0.111), (0, 1, 0), 0.011759436, (0, 0.008227847, -0.002327479)),
    "l_sho_roll": ("l_sho_pitch", (0.019, 0.0285, -0.01), (-1, 0, 0), 0.1775763, (-0.018438243, 0.045143767, 0.000281212)),
    "l_el": ("l_sho_roll", (0, 0.0904, -0.0001), (1, 0, 0), 0.041267974, (-0.018999997, 0.070330391, 0.003800117)),
    "r_sho_pitch": ("pelvis", (-0.001, -0.06, 0.111), (0, -1, 0), 0.011759436, (0, -0.008227847, -0.002327479)),
    "r_sho_roll": ("r_sho_pitch", (0.019, -0.0285, -0.01), (-1, 0, 0), 0.1775763, (-0.018438243, -0.045143767, 0.000281212)),
    "r_el": ("r_sho_roll", (0, -0.0904, -0.0001), (1, 0, 0), 0.041267974, (-0.019000003, -0.070330391, 0.00380012)),
    "l_hip_yaw": ("pelvis", (0, 0.035, 0), (0, 0, -1), 0.011813898, (-0.001566062, 0, -0.00774017)),
    "l_hip_roll": ("l_hip_yaw", (-0.024, 0, -0.0285), (-1, 0, 0), 0.17885985, (0.00388263, 0.000278863, -0.012138713)),
    "l_hip_pitch": ("l_hip_roll", (0.0241, 0.019, 0), (0, 1, 0), 0.11543381, (0.000590367, -0.019005093, -0.084075186)),
    "l_knee": ("l_hip_pitch", (0.0, 0, -0.11015), (0, 1, 0), 0.040146918, (0, -0.021514031, -0.055)),
    "l_ank_pitch": ("l_knee", (0, 0, -0.110), (0, -1, 0), 0.17885985, (-0.02021825, -0.018721131, 0.012138988)),
    "l_ank_roll": ("l_ank_pitch", (-0.0241, -0.019, 0), (1, 0, 0), 0.069344849, (0.023733194, 0.010370444, -0.027601507)),
}
# (ROBOTIS's kinematics table puts the knee 0.1 mm ahead of the hip pitch axis, the URDF and Menagerie
# do not; the URDF's 0.0 is used. Its roll/pitch axes meet 0.1 mm ahead of the yaw axis: neglected,
# our hip point is on the yaw axis.)

# --- Menagerie inertias: principal moments and body quaternion (w, x, y, z) -----------------------
MENAGERIE_INERTIA = {
    "pelvis": ((0.704708, 0.704003, 0.0667707, -0.0575246), (0.00341264, 0.00316574, 0.00296931)),
    "head_pan": ((0.663575, 0.663575, 0.244272, -0.244272), (4.23401e-06, 3.60599e-06, 1.65e-06)),
    "head_tilt": ((0.997312, 0.00973825, 0.0726131, -0.00102702), (0.000107452, 8.72266e-05, 4.39413e-05)),
    "l_sho_pitch": ((0.244272, 0.663575, 0.244272, 0.663575), (4.23401e-06, 3.60599e-06, 1.65e-06)),
    "l_sho_roll": ((0.501853, 0.50038, -0.498173, 0.499588), (0.000234742, 0.00022804, 3.04183e-05)),
    "l_el": ((0.483289, 0.51617, -0.51617, 0.483289), (6.8785e-05, 6.196e-05, 1.2065e-05)),
    "r_sho_pitch": ((-0.244272, 0.663575, -0.244272, 0.663575), (4.23401e-06, 3.60599e-06, 1.65e-06)),
    "r_sho_roll": ((0.50038, 0.501853, -0.499588, 0.498173), (0.000234742, 0.00022804, 3.04183e-05)),
    "r_el": ((0.51617, 0.483289, -0.483289, 0.51617), (6.8785e-05, 6.196e-05, 1.2065e-05)),
    "l_hip_yaw": ((0.499041, 0.500957, 0.500957, 0.499041), (4.3e-06, 4.12004e-06, 1.50996e-06)),
    "l_hip_roll": ((0.502657, 0.490852, 0.498494, 0.507842), (0.000125243, 0.000108598, 4.65693e-05)),
    "l_hip_pitch": ((0.999682, 0.0246915, 0.00447825, -0.002482), (0.000104996, 9.63044e-05, 2.47492e-05)),
    "l_knee": ((1, 0, 0, 0), (3.715e-05, 2.751e-05, 1.511e-05)),
    "l_ank_pitch": ((0.490852, 0.502657, 0.507842, 0.498494), (0.000125243, 0.000108598, 4.65693e-05)),
    "l_ank_roll": ((0.0078515, 0.707601, 0.0113965, 0.706477), (0.000115818, 7.87135e-05, 4.03389e-05)),
}

# ROBOTIS ini_pose.yaml tar_pose (deg), the arms/head hold pose, in ROBOTIS's own joint senses.
HOLD_DEG = {"head_pan": 0.0, "head_tilt": -10.0, "l_sho_pitch": -15.0, "r_sho_pitch": 15.0,
            "l_sho_roll": 45.0, "r_sho_roll": -45.0, "l_el": -45.0, "r_el": 45.0}

# Our leg links: (our name, ROBOTIS link, our frame's origin point)
HIP_M = np.array([0.0, 0.035, -0.0285])  # hip point (left) in the pelvis frame
KNEE_M = HIP_M + [0, 0, -0.11015]
ANKLE_M = KNEE_M + [0, 0, -0.110]
LEG_LINKS = (("hip_yaw", "l_hip_yaw", HIP_M), ("hip_roll", "l_hip_roll", HIP_M), ("thigh", "l_hip_pitch", HIP_M),
             ("shank", "l_knee", KNEE_M), ("ankle", "l_ank_pitch", ANKLE_M), ("foot", "l_ank_roll", ANKLE_M))
TRUNK = ("pelvis", "head_pan", "head_tilt", "l_sho_pitch", "l_sho_roll", "l_el", "r_sho_pitch", "r_sho_roll", "r_el")


def quat_to_matrix(q) -> np.ndarray:
    w, x, y, z = np.asarray(q, float) / np.linalg.norm(q)
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                     [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                     [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]])


def rodrigues(axis, angle_rad: float) -> np.ndarray:
    a = np.asarray(axis, float)
    k = np.array([[0, -a[2], a[1]], [a[2], 0, -a[0]], [-a[1], a[0], 0]])
    return np.eye(3) + np.sin(angle_rad) * k + (1 - np.cos(angle_rad)) * k @ k


def link_inertia(name: str) -> np.ndarray:
    """Rotational inertia about the link's CoM, in the link frame (kg m^2)."""
    quat, diag = MENAGERIE_INERTIA[name]
    r = quat_to_matrix(quat)
    return r @ np.diag(diag) @ r.T


def frames(angles_deg: dict[str, float]) -> dict[str, tuple[np.ndarray, np.ndarray]]:
    """World (pelvis-frame) position and orientation of every ROBOTIS link at the given joint angles."""
    out: dict[str, tuple[np.ndarray, np.ndarray]] = {}
    for name, (parent, offset, axis, _, _) in ROBOTIS.items():
        if parent is None:
            out[name] = (np.zeros(3), np.eye(3))
            continue
        p_pos, p_rot = out[parent]
        rot = p_rot @ rodrigues(axis, np.radians(angles_deg.get(name, 0.0)))
        out[name] = (p_pos + p_rot @ np.asarray(offset, float), rot)
    return out


def composite(names, angles_deg) -> tuple[float, np.ndarray, np.ndarray]:
    """Mass, CoM and inertia about the CoM (pelvis frame) of rigidly held links."""
    f = frames(angles_deg)
    masses = np.array([ROBOTIS[n][3] for n in names])
    coms = np.array([f[n][0] + f[n][1] @ np.asarray(ROBOTIS[n][4], float) for n in names])
    mass = masses.sum()
    com = masses @ coms / mass
    inertia = np.zeros((3, 3))
    for m, c, n in zip(masses, coms, names):
        rot = f[n][1]
        d = c - com
        inertia += rot @ link_inertia(n) @ rot.T + m * (d @ d * np.eye(3) - np.outer(d, d))
    return float(mass), com, inertia


def leg_link_table(name: str, link: str, origin) -> tuple[float, np.ndarray, np.ndarray]:
    """A leg link's mass, CoM relative to our joint point, inertia (frames are parallel at zero pose)."""
    f = frames({})
    pos, rot = f[link]
    com = pos + rot @ np.asarray(ROBOTIS[link][4], float) - origin
    return ROBOTIS[link][3], com, link_inertia(link)


def _vec(v) -> str:
    return "[" + ", ".join(f"{x:.6g}" for x in v) + "]"


def _inertia(i) -> str:
    return _vec([i[0, 0], i[1, 1], i[2, 2], i[0, 1], i[0, 2], i[1, 2]])


def links_block() -> str:
    mass, com, inertia = composite(TRUNK, HOLD_DEG)
    lines = [f"[links.torso]   # pelvis {ROBOTIS['pelvis'][3]:.5f} + head + arms at the hold pose, lumped (tools/op3_mass_table.py)",
             f"mass_kg = {mass:.6g}", f"com_m = {_vec(com)}", f"inertia_kg_m2 = {_inertia(inertia)}", ""]
    for name, link, origin in LEG_LINKS:
        m, c, i = leg_link_table(name, link, origin)
        lines += [f"[links.{name}]   # ROBOTIS {link}", f"mass_kg = {m:.6g}", f"com_m = {_vec(c)}",
                  f"inertia_kg_m2 = {_inertia(i)}", ""]
    return "\n".join(lines)


def total_mass_kg() -> float:
    trunk = sum(ROBOTIS[n][3] for n in TRUNK)
    legs = sum(ROBOTIS[link][3] for _, link, _ in LEG_LINKS)
    return trunk + 2 * legs


def check(path) -> list[str]:
    """Where a robot file's [links.*] and [mass] total_kg differ from the derivation (6 significant digits)."""
    import tomllib

    data = tomllib.loads(open(path).read())
    problems = []
    expected = {"torso": composite(TRUNK, HOLD_DEG)}
    for name, link, origin in LEG_LINKS:
        expected[name] = leg_link_table(name, link, origin)
    for name, (mass, com, inertia) in expected.items():
        table = data["links"][name]
        got = [table["mass_kg"], *table["com_m"], *table["inertia_kg_m2"]]
        want = [mass, *com, *(inertia[0, 0], inertia[1, 1], inertia[2, 2], inertia[0, 1], inertia[0, 2], inertia[1, 2])]
        for g, w in zip(got, want):
            if abs(g - w) > 1e-5 * max(abs(w), 1e-6) + 1e-9:
                problems.append(f"links.{name}: file {got} != derived {[float(f'{v:.6g}') for v in want]}")
                break
    if abs(data["mass"]["total_kg"] - total_mass_kg()) > 1e-5:
        problems.append(f"mass.total_kg: file {data['mass']['total_kg']} != derived {total_mass_kg():.6f}")
    return problems


def main(argv=None) -> int:
    import argparse

    parser = argparse.ArgumentParser(description="ROBOTIS OP3 link table -> config/op3.toml's [links.*] block")
    parser.add_argument("--check", metavar="TOML", help="compare a robot file's [links.*] and total mass with the "
                        "derivation instead of printing the block (exit 1 if they differ)")
    args = parser.parse_args(argv)
    if args.check:
        problems = check(args.check)
        for line in problems:
            print(line)
        print(f"{args.check}: {'differs from' if problems else 'matches'} the derivation")
        return 1 if problems else 0
    print(links_block())
    print(f"[mass]\ntotal_kg = {total_mass_kg():.6f}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
