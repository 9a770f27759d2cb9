"""The whole robot's centre of mass and gravity torques from its body model (gaitbot.gait.body).

Why: the cart-table model plans the *whole* robot's CoM (legs are a third of an OP3's mass), so the
pelvis is placed where every link's mass puts the CoM on the plan (docs/gait-model.md section 8); and a
soft position servo sags by its gravity torque / stiffness, which the optional feedforward undoes.
Everything is vectorised over frames: arrays (n, ...) in, arrays out.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .body import LEG_LINKS, SIDE_SIGN, BodyModel
from .joints import SIDES
from .kinematics6 import leg_chain, leg_points

GRAVITY_M_S2 = 9.81


@dataclass(frozen=True)
class MassModel:
    """Link masses and CoMs as arrays, ready for vectorised sums."""

    body: BodyModel
    torso_kg: float
    torso_com_m: np.ndarray  # (3,) in the root frame
    leg_kg: np.ndarray  # (6,) per link, the same both sides
    leg_com_m: dict  # side -> (6, 3), each in its link frame

    @classmethod
    def of(cls, body: BodyModel) -> "MassModel":
        coms = {side: np.array([body.leg_link(name, side).com_m for name in LEG_LINKS]) for side in SIDES}
        return cls(body, body.torso.mass_kg, body.torso.com_m.copy(),
                   np.array([body.leg_links[name].mass_kg for name in LEG_LINKS]), coms)

    @property
    def total_kg(self) -> float:
        return self.torso_kg + 2.0 * float(self.leg_kg.sum())

    def leg_link_coms(self, side: str, q_leg_rad) -> np.ndarray:
        """Each leg link's CoM in the root frame, (..., 6, 3)."""
        return leg_points(self.body.geometry, side, q_leg_rad, self.leg_com_m[side])

    def com_in_root(self, q_rad) -> np.ndarray:
        """The whole robot's CoM in the root frame for the 12 leg angles q_rad (..., 12) (left leg first)."""
        q = np.asarray(q_rad, dtype=float)
        total = self.torso_kg * self.torso_com_m
        for i, side in enumerate(SIDES):
            coms = self.leg_link_coms(side, q[..., 6 * i:6 * i + 6])
            total = total + self.leg_kg @ coms
        return total / self.total_kg

    def gravity_torques(self, q_rad, support_share_left, cop_left_m, cop_right_m) -> np.ndarray:
        """Joint torques (..., 12) (N m, in each joint's positive sense) that hold the pose against gravity.

        Root upright. The floor pushes each foot up with ``support_share_left`` (left) / 1 - it (right) of
        the robot's weight, along the vertical through that foot's planned centre of pressure
        ``cop_*_m`` (..., 3), root frame: in single support the stance foot's is the planned ZMP; a
        double support is split by where the planned ZMP lies between the two feet's points. A leg
        joint's torque balances, about its axis, gravity on the links distal to it and that floor force.
        Quasi-static: the floor's horizontal (inertial) forces are left out."""
        q = np.asarray(q_rad, dtype=float)
        share_left = np.asarray(support_share_left, dtype=float)
        weight = self.total_kg * GRAVITY_M_S2
        cops = {"left": np.asarray(cop_left_m, dtype=float), "right": np.asarray(cop_right_m, dtype=float)}
        out = []
        for i, side in enumerate(SIDES):
            share = share_left if side == "left" else 1.0 - share_left
            rotations, origins = leg_chain(self.body.geometry, side, q[..., 6 * i:6 * i + 6])
            coms = [o + r @ c for r, o, c in zip(rotations, origins, self.leg_com_m[side])]
            s = SIDE_SIGN[side]
            local_axes = np.array([[0, 0, s], [s, 0, 0], [0, -1, 0], [0, 1, 0], [0, -1, 0], [s, 0, 0]], dtype=float)
            # vertical forces f at (x, y) have the moment (f (y - jy), -f (x - jx), 0) about a joint at j
            floor = share * weight
            for j in range(6):
                axis = rotations[j] @ local_axes[j]
                point = origins[j]
                mx = floor * (cops[side][..., 1] - point[..., 1])
                my = -floor * (cops[side][..., 0] - point[..., 0])
                for k in range(j, 6):
                    f = -self.leg_kg[k] * GRAVITY_M_S2
                    mx = mx + f * (coms[k][..., 1] - point[..., 1])
                    my = my - f * (coms[k][..., 0] - point[..., 0])
                out.append(-(mx * axis[..., 0] + my * axis[..., 1]))
        return np.stack(out, axis=-1)
