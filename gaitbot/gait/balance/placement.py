"""Pelvis placement on the whole-body centre of mass, the multibody ZMP, and the sag feedforward.

Why: the cart-table model plans the *whole* robot's CoM, but the walker moves the pelvis; the legs
(a third of an OP3's mass) move the CoM as they swing. So each frame the root is placed where every
link's mass (gaitbot.gait.mass, held arms and head in the torso) puts the CoM on the plan: a fixed
point on the root's x and y, root += (target - CoM) / slope, the slope dCoM/droot measured once per
walker (~0.8: the torso and most of the legs move with the root, the feet do not) and refined by
secants; it stops below PLACEMENT_TOLERANCE_M (observed residual ~1e-12 m, docs/balance.md).
Vectorised over frames (the offline walker); gaitbot.gait.balance.flat_frame is the same for one frame.

Turned feet (a steered walk, docs/steering.md): ``yaw`` (n, 2) gives each foot's yaw; the torso (root)
turns with the mean of the two (torso yaw follows the feet), stays upright, and the legs' IK works in
its turned frame (each foot turned by its yaw minus the torso's: the hip yaw joints). ``yaw=None`` is
the straight walk's code, unchanged.
"""

from __future__ import annotations

import numpy as np

from gaitbot.gait.body import BodyModel
from gaitbot.gait.joints import SIDES
from gaitbot.gait.kinematics6 import leg_ik, rot_z
from gaitbot.gait.mass import GRAVITY_M_S2, MassModel

PLACEMENT_TOLERANCE_M = 1e-10
MAX_PLACEMENT_ITERATIONS = 12
SLOPE_PROBE_M = 1e-4


class WholeBody:
    """The robot's legs and masses, for an upright root and flat feet, vectorised over frames."""

    def __init__(self, body: BodyModel) -> None:
        self.body = body
        self.mass = MassModel.of(body)
        self.point_masses_kg = np.concatenate([[self.mass.torso_kg], self.mass.leg_kg, self.mass.leg_kg])

    def legs(self, root, ankles, yaw=None) -> np.ndarray:
        """Leg angles (n, 12) for an upright root at ``root`` (n, 3) and flat feet at ``ankles`` (n, 2, 3)
        turned by ``yaw`` (n, 2) rad (None: straight ahead)."""
        if yaw is None:
            eye = np.broadcast_to(np.eye(3), (len(root), 3, 3))
            q = [leg_ik(self.body.geometry, side, ankles[:, i] - root, eye, strict=False)
                 for i, side in enumerate(SIDES)]
            return np.concatenate(q, axis=-1)
        psi = torso_yaw(yaw)
        back = rot_z(-psi)
        q = [leg_ik(self.body.geometry, side, np.einsum("nij,nj->ni", back, ankles[:, i] - root),
                    rot_z(yaw[:, i] - psi), strict=False) for i, side in enumerate(SIDES)]
        return np.concatenate(q, axis=-1)

    def com(self, root, ankles, yaw=None) -> np.ndarray:
        """Whole-body CoM (n, 3) in the world."""
        return root + to_world(self.mass.com_in_root(self.legs(root, ankles, yaw)), yaw)

    def com_slope(self, root_z_m: float, ankles) -> float:
        """dCoM_x / droot_x at a standing pose (ankles (2, 3)): the fixed point's first slope."""
        root = np.array([[0.0, 0.0, root_z_m], [SLOPE_PROBE_M, 0.0, root_z_m]])
        c = self.com(root, np.repeat(ankles[None], 2, 0))[:, 0]
        return float((c[1] - c[0]) / SLOPE_PROBE_M)

    def place(self, com_xy, ankles, root_z, guess_offset, slope: float,
              yaw=None) -> tuple[np.ndarray, np.ndarray, float]:
        """Root (n, 3), leg angles (n, 12) and the largest residual (m) putting the whole CoM at
        ``com_xy`` (n, 2); guess_offset (2,) or (n, 2): root minus CoM to start from; yaw: the feet's."""
        n = len(com_xy)
        root = np.empty((n, 3))
        root[:, 2] = root_z
        root[:, :2] = com_xy + guess_offset
        slopes = np.full((n, 2), slope)
        last_root = last_com = None
        q = residual = None
        for _ in range(MAX_PLACEMENT_ITERATIONS):
            q = self.legs(root, ankles, yaw)
            com = root[:, :2] + to_world(self.mass.com_in_root(q), yaw)[:, :2]
            error = com_xy - com
            residual = float(np.abs(error).max())
            if residual < PLACEMENT_TOLERANCE_M:
                break
            if last_root is not None:  # secant slope per frame and axis where the step was large enough
                moved = root[:, :2] - last_root
                ok = np.abs(moved) > 1e-9
                slopes = np.where(ok, (com - last_com) / np.where(ok, moved, 1.0), slopes)
            last_root, last_com = root[:, :2].copy(), com
            root[:, :2] += error / slopes
        return root, q, residual

    def link_points(self, root, q, yaw=None) -> np.ndarray:
        """World positions (n, 13, 3) of the torso's and the 12 leg links' CoMs."""
        points = [np.broadcast_to(self.mass.torso_com_m, (len(q), 1, 3))]
        for i, side in enumerate(SIDES):
            points.append(self.mass.leg_link_coms(side, q[:, 6 * i:6 * i + 6]))
        local = np.concatenate(points, axis=1)
        if yaw is not None:
            local = np.einsum("nij,nkj->nki", rot_z(torso_yaw(yaw)), local)
        return root[:, None, :] + local

    def sag_goals(self, q, share_left, cops_xy, root, kp_nm_per_rad, yaw=None) -> np.ndarray:
        """Servo goals that a position servo of stiffness kp (N m/rad per joint) under the pose's
        gravity load turns into the planned angles q: q + tau_gravity / kp. The floor's force is split
        between the feet by share_left (n,), acting at each foot's planned centre of pressure cops_xy
        (n, 2, 2) in the world (quasi-static: inertial forces are left out)."""
        back = None if yaw is None else rot_z(-torso_yaw(yaw))[:, :2, :2]
        rel = [cops_xy[:, k] - root[:, :2] for k in (0, 1)]
        if back is not None:
            rel = [np.einsum("nij,nj->ni", back, r) for r in rel]
        cop_l = np.column_stack([rel[0], -root[:, 2]])
        cop_r = np.column_stack([rel[1], -root[:, 2]])
        return q + self.mass.gravity_torques(q, share_left, cop_l, cop_r) / kp_nm_per_rad


def torso_yaw(yaw) -> np.ndarray:
    """The torso's yaw (n,) for the feet's yaws (n, 2): their mean (the torso follows the feet)."""
    yaw = np.asarray(yaw, dtype=float)
    return 0.5 * (yaw[..., 0] + yaw[..., 1])


def to_world(vectors, yaw) -> np.ndarray:
    """Vectors (n, 3) in the torso's frame turned into the world's (yaw None: the same)."""
    if yaw is None:
        return vectors
    return np.einsum("nij,nj->ni", rot_z(torso_yaw(yaw)), vectors)


def multibody_zmp(points, masses_kg, dt_s: float) -> np.ndarray:
    """ZMP (n, 2) of point masses at ``points`` (n + 2, m, 3) over frames (accelerations by second
    differences; result i belongs to points[i + 1]). Agrees with MuJoCo's inverse dynamics to ~1 mm
    on the OP3 (the links' rotational inertia is left out)."""
    p = np.asarray(points)
    acc = (p[2:] - 2 * p[1:-1] + p[:-2]) / (dt_s * dt_s)
    mid = p[1:-1]
    load = masses_kg * (acc[..., 2] + GRAVITY_M_S2)
    den = load.sum(-1)
    x = (mid[..., 0] * load - masses_kg * mid[..., 2] * acc[..., 0]).sum(-1) / den
    y = (mid[..., 1] * load - masses_kg * mid[..., 2] * acc[..., 1]).sum(-1) / den
    return np.stack([x, y], axis=-1)
