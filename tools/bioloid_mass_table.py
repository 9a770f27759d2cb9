"""Print config/bioloid.toml's [links.*] table: the ROBOTIS BIOLOID Premium (Type A) legs' masses, estimated.

Why a script: ROBOTIS publishes no link masses for the BIOLOID, and the public robot descriptions'
masses are placeholders or unit-garbled CAD exports, so the table is an estimate whose method must be
visible and repeatable: each link carries the AX-12A servo bodies mounted on it (54.6 g each, ROBOTIS
e-Manual AX-12A) plus about 8 g per plastic frame and 14 g for the sole plate (assumed), its centre of
mass where those parts sit, its inertia that of a uniform box of the link's size. Geometry and servo
placement: the Type A URDF (typea.xacro by Mathieu R., as copied in robkwan/bioloid_ros2
bioloid_description/urdf/typea.urdf), its "Motor N" visuals. Frames as in gaitbot/gait/body.py (left
leg, origin at the link's joint point, x forward, y left, z up). Weigh the robot and correct the table.

    python tools/bioloid_mass_table.py     # prints the block config/bioloid.toml holds
"""

from __future__ import annotations

import numpy as np

AX12A_KG = 0.0546  # ROBOTIS e-Manual AX-12A: 54.6 g
FRAME_KG = 0.008  # one FP04 plastic frame (assumed)
SOLE_KG = 0.014  # the F12 sole plate (assumed)

# link: (mass_kg, centre of mass (m, link frame), box size (m) for the inertia, what is on it)
LINKS = {
    "torso": (0.411 + 0.296 + 0.050, (-0.010, 0.0, 0.021), (0.06, 0.12, 0.13),
              "frame with servos 1, 2, 7, 8, CM-530 and battery (0.411 kg), two arms held down (0.296 kg, "
              "CoM about 5 mm below the root), the sensor head (0.05 kg, 0.105 m up); CoM of the three"),
    "hip_yaw": (FRAME_KG, (0.0, 0.0, 0.025), (0.03, 0.03, 0.02), "one F5 frame between the yaw and roll servos"),
    "hip_roll": (2 * AX12A_KG + 3 * FRAME_KG, (0.0, 0.0, -0.005), (0.04, 0.035, 0.05),
                 "servos 10 and 12 (hip roll and pitch) and three frames around the hip point"),
    "thigh": (2 * FRAME_KG, (0.0, 0.0, -0.038), (0.02, 0.03, 0.075), "two frames along the thigh"),
    "shank": (AX12A_KG + 2 * FRAME_KG, (0.0, 0.0, -0.020), (0.032, 0.04, 0.05),
              "servo 14 (knee) below the knee axis and two frames"),
    "ankle": (2 * AX12A_KG + 3 * FRAME_KG, (0.0, 0.0, 0.010), (0.04, 0.035, 0.05),
              "servos 16 and 18 (ankle pitch and roll) and three frames around the ankle point"),
    "foot": (FRAME_KG + SOLE_KG + 0.008, (0.0, 0.0, -0.028), (0.101, 0.061, 0.009),
             "the sole plate, a frame and the horn bracket"),
}


def box_inertia(mass_kg: float, size_m) -> np.ndarray:
    x, y, z = size_m
    return np.array([y * y + z * z, x * x + z * z, x * x + y * y]) * mass_kg / 12.0


def main() -> None:
    total = LINKS["torso"][0] + 2 * sum(v[0] for k, v in LINKS.items() if k != "torso")
    print("[mass]")
    print(f"total_kg = {total:.6g}\n")
    for name, (mass, com, size, what) in LINKS.items():
        ixx, iyy, izz = box_inertia(mass, size)
        print(f"[links.{name}]   # {what}")
        print(f"mass_kg = {mass:.6g}")
        print(f"com_m = [{', '.join(f'{c:.6g}' for c in com)}]")
        print(f"inertia_kg_m2 = [{ixx:.6g}, {iyy:.6g}, {izz:.6g}, 0, 0, 0]\n")


if __name__ == "__main__":
    main()
