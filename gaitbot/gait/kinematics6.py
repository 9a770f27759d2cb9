"""Forward and analytic inverse kinematics of the 6-joint leg, vectorised over frames.

The leg (docs/gait-model.md section 8 conventions): hip yaw, hip roll, hip pitch about axes meeting at
the hip point; knee; ankle pitch and ankle roll about axes meeting at the ankle point. For side sign
s (+1 left, -1 right), as rotations about the root's fixed axes at the zero pose:

    R_foot = Rz(s yaw) Rx(s roll) Ry(-pitch) Ry(knee) Ry(-ankle_pitch) Rx(s ankle_roll)

(flexion positive: a thigh forward is a rotation about -y; hip roll abduction moves the left foot
to +y, i.e. about +x; ankle roll turns in the same sense as its hip roll). The knee sits thigh_m
below the hip along the thigh, the ankle shank_m below the knee along the shank. With yaw = roll = 0
this is the planar leg of gaitbot.gait.geometry (foot pitch = hip - knee + ankle).
Lengths come from a BodyGeometry (gaitbot.gait.body).

FK composes the rotations; IK is closed form (the hip-to-ankle vector seen from the foot gives knee,
ankle pitch and ankle roll; the hip's rotation then gives yaw, roll, pitch). They are written apart
so each tests the other (tests/gait/test_kinematics6.py); both take arrays of frames.
"""

from __future__ import annotations

import numpy as np

from .body import SIDE_SIGN, BodyGeometry


def _rotation(a, i: int, j: int) -> np.ndarray:
    """Rotations (..., 3, 3) by angles a (...,) in the plane of axes i -> j (filled in place: fast)."""
    a = np.asarray(a, dtype=float)
    c, s = np.cos(a), np.sin(a)
    out = np.zeros(a.shape + (3, 3))
    k = 3 - i - j
    out[..., k, k] = 1.0
    out[..., i, i] = c
    out[..., j, j] = c
    out[..., i, j] = -s
    out[..., j, i] = s
    return out


def rot_x(a) -> np.ndarray:
    """Rotations about x by angles a (...,) -> (..., 3, 3)."""
    return _rotation(a, 1, 2)


def rot_y(a) -> np.ndarray:
    return _rotation(a, 2, 0)


def rot_z(a) -> np.ndarray:
    return _rotation(a, 0, 1)


def joint_axis(kind: str, side: str) -> tuple[float, float, float]:
    """A leg joint's axis in the root frame at the zero pose (positive angle = the convention's sense):
    the rotations of the chain above, written as axes (the simulated and the exported models use them)."""
    s = SIDE_SIGN[side]
    return {"hip_yaw": (0, 0, s), "hip_roll": (s, 0, 0), "hip_pitch": (0, -1, 0), "knee_pitch": (0, 1, 0),
            "ankle_pitch": (0, -1, 0), "ankle_roll": (s, 0, 0)}[kind]


def leg_frames(geometry: BodyGeometry, side: str, q_rad) -> tuple[np.ndarray, np.ndarray]:
    """Every leg link's frame in the root frame, for joint angles q_rad (..., 6).

    Returns (rotations (..., 6, 3, 3), origins (..., 6, 3)) for the links hip_yaw, hip_roll, thigh,
    shank, ankle, foot (each link's frame turns with its joint; origins at the hip, hip, hip, knee,
    ankle, ankle points)."""
    rotations, origins = leg_chain(geometry, side, q_rad)
    return np.stack(rotations, axis=-3), np.stack(origins, axis=-2)


def leg_chain(geometry: BodyGeometry, side: str, q_rad) -> tuple[list, list]:
    """As leg_frames, as two lists of 6 arrays (no stacking: the mass model's fast path)."""
    q = np.asarray(q_rad, dtype=float)
    s = SIDE_SIGN[side]
    r1 = rot_z(s * q[..., 0])
    r2 = r1 @ rot_x(s * q[..., 1])
    r3 = r2 @ rot_y(-q[..., 2])
    r4 = r3 @ rot_y(q[..., 3])
    r5 = r4 @ rot_y(-q[..., 4])
    r6 = r5 @ rot_x(s * q[..., 5])
    hip = np.broadcast_to(geometry.hip_in_root(side), q.shape[:-1] + (3,))
    knee = hip - geometry.thigh_m * r3[..., :, 2]
    ankle = knee - geometry.shank_m * r4[..., :, 2]
    return [r1, r2, r3, r4, r5, r6], [hip, hip, hip, knee, ankle, ankle]


def _turn(v, axis: int, cs):
    """Rotate vectors v (3 arrays) about a coordinate axis by the angle whose (cos, sin) is cs."""
    c, s = cs
    x, y, z = v
    if axis == 0:
        return x, c * y - s * z, s * y + c * z
    if axis == 1:
        return c * x + s * z, y, -s * x + c * z
    return c * x - s * y, s * x + c * y, z


def leg_points(geometry: BodyGeometry, side: str, q_rad, local_points) -> np.ndarray:
    """Points fixed in each leg link (local_points (6, 3), link frames as leg_frames) in the root frame,
    (..., 6, 3). Rotates the six vectors directly (a few elementwise operations per link), which is
    several times faster than forming the link rotations: the mass model's hot path."""
    q = np.asarray(q_rad, dtype=float)
    s = SIDE_SIGN[side]
    trig = lambda a: (np.cos(a), np.sin(a))  # noqa: E731
    yaw, roll = trig(s * q[..., 0]), trig(s * q[..., 1])
    pitches = (None, None, trig(-q[..., 2]), trig(-q[..., 2] + q[..., 3]), trig(-q[..., 2] + q[..., 3] - q[..., 4]))

    def to_root(v, pitch=None, ankle_roll=None):
        if ankle_roll is not None:
            v = _turn(v, 0, ankle_roll)
        if pitch is not None:
            v = _turn(v, 1, pitch)
        return _turn(_turn(v, 0, roll), 2, yaw)

    zero = np.zeros(q.shape[:-1])
    hip = geometry.hip_in_root(side)
    kx, ky, kz = to_root((zero, zero, zero - geometry.thigh_m), pitches[2])
    ax, ay, az = to_root((zero, zero, zero - geometry.shank_m), pitches[3])
    knee = (hip[0] + kx, hip[1] + ky, hip[2] + kz)
    ankle = (knee[0] + ax, knee[1] + ay, knee[2] + az)
    origins = (hip, hip, hip, knee, ankle, ankle)
    out = []
    for k, (px, py, pz) in enumerate(local_points):
        v = (zero + px, zero + py, zero + pz)
        if k == 0:
            v = _turn(v, 2, yaw)
        elif k == 1:
            v = to_root(v)
        elif k == 5:
            v = to_root(v, pitches[4], trig(s * q[..., 5]))
        else:
            v = to_root(v, pitches[k])
        o = origins[k]
        out.append(np.stack([o[0] + v[0], o[1] + v[1], o[2] + v[2]], axis=-1))
    return np.stack(out, axis=-2)


def foot_pose(geometry: BodyGeometry, side: str, q_rad) -> tuple[np.ndarray, np.ndarray]:
    """Ankle point (..., 3) and foot rotation (..., 3, 3) in the root frame."""
    rotations, origins = leg_frames(geometry, side, q_rad)
    return origins[..., 5, :], rotations[..., 5, :, :]


def sole_centre(geometry: BodyGeometry, side: str, q_rad) -> np.ndarray:
    """The sole's centre (underside) in the root frame, (..., 3)."""
    ankle, rot = foot_pose(geometry, side, q_rad)
    return ankle + rot @ geometry.sole_centre_in_foot(side)


SOLE_CORNER_SIGNS = ((1, 1), (-1, 1), (-1, -1), (1, -1))
"""The sole's corners as (forward, left) signs of half its length and width: front left, back left, back
right, front right (counter-clockwise seen from above)."""


def sole_corners(geometry: BodyGeometry, side: str, q_rad) -> np.ndarray:
    """The sole's four corners (underside; SOLE_CORNER_SIGNS order) in the root frame, (..., 4, 3)."""
    ankle, rot = foot_pose(geometry, side, q_rad)
    centre = geometry.sole_centre_in_foot(side)
    corners = np.array([centre + [dx * geometry.foot_m / 2, dy * geometry.foot_width_m / 2, 0.0]
                        for dx, dy in SOLE_CORNER_SIGNS])
    return ankle[..., None, :] + np.einsum("...ij,kj->...ki", rot, corners)


class ReachError(ValueError):
    """An ankle target beyond the leg's reach."""


def leg_ik(geometry: BodyGeometry, side: str, ankle_m, foot_rot, *, strict: bool = True) -> np.ndarray:
    """Joint angles (..., 6) placing the ankle point at ``ankle_m`` (..., 3) with the foot turned by
    ``foot_rot`` (..., 3, 3), both in the root frame. The knee bends forward (knee >= 0).

    strict: raise ReachError if any target is out of reach; otherwise the leg is stretched towards it.
    Unique while hip roll and ankle roll stay inside +-90 degrees (always, for a leg that walks)."""
    s = SIDE_SIGN[side]
    ankle = np.asarray(ankle_m, dtype=float)
    rot = np.asarray(foot_rot, dtype=float)
    l1, l2 = geometry.thigh_m, geometry.shank_m
    # hip seen from the ankle, in the foot frame: r = R_foot^T (hip - ankle)
    r = np.einsum("...ji,...j->...i", rot, geometry.hip_in_root(side) - ankle)
    d2 = np.einsum("...i,...i->...", r, r)
    cos_knee = (d2 - l1 * l1 - l2 * l2) / (2 * l1 * l2)
    if strict and (np.any(cos_knee > 1 + 1e-12) or np.any(cos_knee < -1 - 1e-12)):
        raise ReachError(f"{side} ankle target out of reach (hip-ankle {np.sqrt(d2.max()):.4f} m)")
    knee = np.arccos(np.clip(cos_knee, -1.0, 1.0))
    # ankle roll about +x (the chain's sense), inside +-90 degrees: r = Rx(-a6) (vx, 0, vz)
    a6 = np.arctan(r[..., 1] / r[..., 2])
    vz = np.sign(r[..., 2]) * np.hypot(r[..., 1], r[..., 2])
    a5 = -np.arctan2(l1 * np.sin(knee), l1 * np.cos(knee) + l2) - np.arctan2(r[..., 0], vz)
    # hip rotation Rz(a1) Rx(a2) Ry(a3) = R_foot Rx(-a6) Ry(-(knee + a5))
    hip_rot = rot @ rot_x(-a6) @ rot_y(-(knee + a5))
    a2 = np.arcsin(np.clip(hip_rot[..., 2, 1], -1.0, 1.0))
    a1 = np.arctan2(-hip_rot[..., 0, 1], hip_rot[..., 1, 1])
    a3 = np.arctan2(-hip_rot[..., 2, 0], hip_rot[..., 2, 2])
    return np.stack([s * a1, s * a2, -a3, knee, -a5, s * a6], axis=-1)
