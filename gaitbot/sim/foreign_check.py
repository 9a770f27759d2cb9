"""Does a --sim-map agree with the model's forward kinematics? Checked against gaitbot's own kinematics.

At a few poses of each leg (straight; crouched; crouched, turned and rolled) every mapped leg joint is
turned by +DELTA_DEG in gaitbot's kinematics (gaitbot.gait.kinematics6) and, through the map, in the model
(mj_kinematics, the torso fixed): the foot's rotation must turn about the same axis, the same way (cosine
above MIN_AXIS_COS), and where gaitbot's ankle point moves noticeably (hip and knee joints), the model's must
move the same way (cosine above MIN_MOVE_COS). Link lengths may differ between the two; directions may
not. A flipped sign shows as an opposite axis, a joint mapped to the wrong model joint as another axis or a
missing motion. Before that, the model's torso frame must be gaitbot's root frame (x forward, y left, z
up): at the straight pose both feet hang below the torso, the left one on +y.

Also found here, at the straight pose: each foot's ankle point (where its ankle pitch and roll axes meet)
and gaitbot's foot axes in the model's foot body, for the heel-strike measure (gaitbot.sim.metrics).
"""

from __future__ import annotations

import math

import numpy as np

from gaitbot.gait.joints import LEG_JOINT_KINDS, SIDES
from gaitbot.gait.kinematics6 import foot_pose
from gaitbot.sim.sim_map import SimMap, SimMapError

DELTA_DEG = 3.0
MIN_AXIS_COS = 0.8
MIN_MOVE_COS = 0.5
POSES_DEG = {  # hip_yaw, hip_roll, hip_pitch, knee_pitch, ankle_pitch, ankle_roll
    "straight": (0, 0, 0, 0, 0, 0),
    "crouched": (0, 0, 30, 60, 30, 0),
    "crouched, turned and rolled": (10, 8, 25, 50, 25, -8),
}


def _vee(r: np.ndarray) -> np.ndarray:
    """The rotation vector of a small rotation r (its axis times sin(angle))."""
    return 0.5 * np.array([r[2, 1] - r[1, 2], r[0, 2] - r[2, 0], r[1, 0] - r[0, 1]])


def _cos(a: np.ndarray, b: np.ndarray) -> float:
    na, nb = np.linalg.norm(a), np.linalg.norm(b)
    return float(a @ b / (na * nb)) if na > 0 and nb > 0 else 0.0


def _words(v: np.ndarray) -> str:
    return "(" + ", ".join(f"{x:+.2f}" for x in v / max(np.linalg.norm(v), 1e-12)) + ")"


class _ModelLeg:
    """The model's foot in its torso frame for gaitbot angles of one leg (the torso fixed at the origin)."""

    def __init__(self, robot, side: str) -> None:
        self.robot, self.side = robot, side
        self.index = {kind: i for i, name in enumerate(robot.joint_names) for kind in LEG_JOINT_KINDS
                      if name == f"{kind}_{side}"}
        self.foot = robot.foot_bodies[SIDES.index(side)]
        self.ankle_in_foot = np.zeros(3)

    def pose(self, q6_rad) -> tuple[np.ndarray, np.ndarray]:
        """(ankle point, foot rotation) in the torso frame."""
        robot = self.robot
        data, r = robot.data, robot.root_qpos
        data.qpos[:] = robot.model.qpos0
        data.qpos[r + 3:r + 7] = (1.0, 0.0, 0.0, 0.0)
        for kind, i in self.index.items():
            data.qpos[robot.qpos_index[i]] = robot.signs[i] * q6_rad[LEG_JOINT_KINDS.index(kind)]
        robot.mujoco.mj_kinematics(robot.model, data)
        torso_rot = data.xmat[robot.torso_body].reshape(3, 3)
        foot_rot = data.xmat[self.foot].reshape(3, 3)
        point = data.xpos[self.foot] + foot_rot @ self.ankle_in_foot - data.xpos[robot.torso_body]
        return torso_rot.T @ point, torso_rot.T @ foot_rot

    def find_ankle_point(self) -> None:
        """The ankle point in the foot body: the closest approach of the ankle pitch and roll axes (or the
        ankle pitch axis's point nearest the foot body's origin if the leg has no ankle roll)."""
        robot, data = self.robot, self.robot.data
        self.pose(np.zeros(6))
        pitch = robot.mapped[self.index["ankle_pitch"]].joint_id if "ankle_pitch" in self.index else None
        roll = robot.mapped[self.index["ankle_roll"]].joint_id if "ankle_roll" in self.index else None
        origin = data.xpos[self.foot].copy()
        if pitch is None:
            point = origin
        elif roll is None:
            a, u = data.xanchor[pitch], data.xaxis[pitch]
            point = a + u * (u @ (origin - a))
        else:
            point = _closest_between(data.xanchor[pitch], data.xaxis[pitch], data.xanchor[roll], data.xaxis[roll])
        self.ankle_in_foot = data.xmat[self.foot].reshape(3, 3).T @ (point - origin)


def _closest_between(a: np.ndarray, u: np.ndarray, b: np.ndarray, v: np.ndarray) -> np.ndarray:
    """The midpoint of the shortest segment between the lines a + s u and b + t v."""
    w = a - b
    uu, uv, vv, uw, vw = u @ u, u @ v, v @ v, u @ w, v @ w
    den = uu * vv - uv * uv
    if abs(den) < 1e-12:
        return a
    s, t = (uv * vw - vv * uw) / den, (uu * vw - uv * uw) / den
    return 0.5 * (a + s * u + b + t * v)


def check_kinematics(robot, sim_map: SimMap) -> None:
    """SimMapError naming the first joint whose sign or axis the model contradicts; on success, sets
    ``robot.ankle_in_foot_m`` (2, 3) and ``robot.foot_axes`` (2, 3, 3) (gaitbot's foot axes in the foot body)."""
    geometry = robot.config.body.geometry
    legs = [_ModelLeg(robot, side) for side in SIDES]
    _check_frame(robot, sim_map, legs)
    delta = math.radians(DELTA_DEG)
    leg_m = geometry.thigh_m + geometry.shank_m
    for leg in legs:
        leg.find_ankle_point()
        for pose, q_deg in POSES_DEG.items():
            q = np.radians([v if kind in leg.index else 0.0 for kind, v in zip(LEG_JOINT_KINDS, q_deg)])
            ours0, model0 = foot_pose(geometry, leg.side, q), leg.pose(q)
            for kind in leg.index:
                turned = q.copy()
                turned[LEG_JOINT_KINDS.index(kind)] += delta
                ours1, model1 = foot_pose(geometry, leg.side, turned), leg.pose(turned)
                axis_ours, axis_model = _vee(ours1[1] @ ours0[1].T), _vee(model1[1] @ model0[1].T)
                move_ours, move_model = ours1[0] - ours0[0], model1[0] - model0[0]
                name = f"{kind}_{leg.side}"
                what, moves = None, np.linalg.norm(move_ours) > 0.3 * leg_m * delta
                if moves and np.linalg.norm(move_model) < 0.3 * np.linalg.norm(move_ours):
                    what = f"+{DELTA_DEG:g} deg hardly moves the model's ankle, which gaitbot's kinematics moves"
                elif _cos(axis_ours, axis_model) < MIN_AXIS_COS:
                    what = (f"+{DELTA_DEG:g} deg turns the foot about {_words(axis_model)} in the model, "
                            f"{_words(axis_ours)} in gaitbot's kinematics")
                elif moves and _cos(move_ours, move_model) < MIN_MOVE_COS:
                    what = (f"+{DELTA_DEG:g} deg moves the ankle along {_words(move_model)} in the model, "
                            f"{_words(move_ours)} in gaitbot's kinematics")
                if what is not None:
                    link = sim_map.joints[name]
                    spec = ("-" if link.sign < 0 else "") + link.model_joint
                    flipped = _cos(axis_ours, axis_model) < -MIN_AXIS_COS and (not moves or _cos(move_ours, move_model) < 0)
                    hint = "flip its sign" if flipped else "is it the right model joint?"
                    raise SimMapError(sim_map.path, f"joints.{name}",
                                      f"= {spec!r}: the model's forward kinematics contradicts it at the {pose} pose "
                                      f"({what}): {hint}")
    robot.ankle_in_foot_m = np.array([leg.ankle_in_foot for leg in legs])
    robot.foot_axes = np.array([leg.pose(np.zeros(6))[1].T for leg in legs])


def _check_frame(robot, sim_map: SimMap, legs: list[_ModelLeg]) -> None:
    """The model's torso frame must be gaitbot's root frame: the feet below, the left foot on +y."""
    left, right = (leg.pose(np.zeros(6))[0] for leg in legs)
    if not (left[2] < 0 and right[2] < 0 and left[1] > right[1]):
        raise SimMapError(sim_map.path, "joints",
                          f"at the straight pose the model's feet are at {_words(left)} (left) and {_words(right)} "
                          "(right) from its torso: the model's torso frame must be x forward, y left, z up, and "
                          "the _left joints on the left leg")
