"""A description tree and its leg joints (gaitbot.robot.description.chains) as gaitbot's leg model.

Geometry (gaitbot.gait.body's model, docs/robot-config.md): the hip point is where the hip axes come
nearest to meeting (least squares), the ankle point likewise for the ankle axes, the knee on its axis
level with the hip; thigh and shank are the distances between them. gaitbot's root lies over the middle
of the hips (the description's root moved sideways and forwards to it, and up to the hips if it was
below them). The sole is the union of the foot's collision boxes. Both legs are averaged (the right one
mirrored) and what the model leaves out is measured and reported: axes that miss each other, a knee or
ankle not straight under the hip, a difference between the legs.

Masses: every body belongs to the gaitbot link that the deepest leg joint above it turns (none: the
torso, which so holds the arms and head at the description's zero pose); each link's mass, centre of
mass and inertia are summed (parallel axes) and written in gaitbot's link frames.

The forward kinematics of the result are compared with the description's at random poses (the joints
turned through the mapping's signs): the knees' and ankles' places and the feet's turn must agree.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from gaitbot.gait.body import LEG_LINKS, BodyGeometry, LinkInertial
from gaitbot.gait.joints import SIDES
from gaitbot.gait.kinematics6 import leg_frames
from gaitbot.robot.description.chains import LegJoint
from gaitbot.robot.description.tree import Tree

_MIRROR = np.diag([1.0, -1.0, 1.0])
#: A mapping whose forward kinematics miss the description's by more than this share of the leg is refused.
FK_REFUSE_SHARE_OF_LEG = 0.1
FK_POSES = 200


@dataclass
class Imported:
    """What the description says in gaitbot's terms (lengths m, angles deg, link tables as in [links.*])."""

    geometry: dict
    links: dict  # name -> LinkInertial (torso and the left leg's six)
    limits_deg: dict  # gaitbot joint -> (min, max), where the description gives a range
    legs: dict  # side -> list[LegJoint]
    origin_m: np.ndarray  # gaitbot's root in the description's root frame
    notes: list = field(default_factory=list)  # what the model leaves out, measured

    @property
    def total_kg(self) -> float:
        return self.links["torso"].mass_kg + 2 * sum(self.links[n].mass_kg for n in LEG_LINKS)


def nearest_point(points, axes) -> np.ndarray:
    """The point nearest (least squares) to the lines through ``points`` along unit ``axes``; where the lines
    leave a direction free (parallel axes), the one nearest their points' mean."""
    a, b = np.zeros((3, 3)), np.zeros(3)
    for p, u in zip(points, axes):
        m = np.eye(3) - np.outer(u, u)
        a, b = a + m, b + m @ p
    centre = np.mean(points, axis=0)
    return centre + np.linalg.pinv(a, rcond=1e-9) @ (b - a @ centre)


def _joint_lines(tree: Tree, frames, legs):
    """Per side, per gaitbot kind: (anchor, axis) in the description's root frame at the zero pose."""
    out = {}
    for side in SIDES:
        out[side] = {}
        for j in legs[side]:
            body = tree.hinges[j.theirs]
            r, o = frames[body.name]
            out[side][j.name.rsplit("_", 1)[0]] = (o + r @ body.hinge.anchor_m, r @ body.hinge.axis)
    return out


def _points(lines) -> dict:
    """Hip, knee and ankle points of one leg (description root frame)."""
    hip = nearest_point(*zip(*[lines[k] for k in ("hip_yaw", "hip_roll", "hip_pitch") if k in lines]))
    ankle = nearest_point(*zip(*[lines[k] for k in ("ankle_pitch", "ankle_roll") if k in lines]))
    p, u = lines["knee_pitch"]
    knee = p + u * (hip[1] - p[1]) / u[1]
    return {"hip": hip, "knee": knee, "ankle": ankle}


def _body_link(tree: Tree, legs) -> dict[str, tuple[str, str] | None]:
    """Body -> (gaitbot link, side) of the deepest leg joint above it, or None (the torso)."""
    owner = {}
    for side in SIDES:
        names = [j.theirs for j in legs[side]]
        links = LEG_LINKS if len(names) == 6 else ("thigh", "shank", "foot")
        owner.update({theirs: (link, side) for theirs, link in zip(names, links)})
    out = {}
    for name in tree.bodies:
        chain = tree.hinge_ancestors(name)
        leg = [j for j in chain if j in owner]
        out[name] = owner[leg[-1]] if leg else None
    return out


def _lump(parts: list[tuple[float, np.ndarray, np.ndarray]]) -> LinkInertial:
    """Masses at points with inertias (root frame) as one body: total mass, CoM, inertia about it."""
    mass = sum(m for m, _, _ in parts)
    if mass <= 0:
        return LinkInertial(0.0, np.zeros(3), np.zeros((3, 3)))
    com = sum(m * c for m, c, _ in parts) / mass
    inertia = sum(i + m * (np.dot(c - com, c - com) * np.eye(3) - np.outer(c - com, c - com)) for m, c, i in parts)
    return LinkInertial(float(mass), com, inertia)


SOLE_KEYS = ("foot_m", "foot_width_m", "ankle_height_m", "heel_back_m", "sole_outward_m")


def import_tree(tree: Tree, legs: dict[str, list[LegJoint]], sole_m: dict | None = None) -> Imported:
    """The description in gaitbot's terms; DescriptionError where it cannot be gaitbot's leg model. ``sole_m``
    (SOLE_KEYS, e.g. a --like config's) stands in for a sole the description has no box for (meshes only)."""
    frames = tree.frames()
    lines = _joint_lines(tree, frames, legs)
    points = {side: _points(lines[side]) for side in SIDES}
    hips = np.array([points[s]["hip"] for s in SIDES])
    if hips[0, 1] <= hips[1, 1]:
        raise tree.fail("left leg", f"its hip ({hips[0, 1]:.4f} m) is not left of the right one's ({hips[1, 1]:.4f} m) "
                                    f"along the root's y (REP-103: x forward, y left, z up)")
    origin = np.array([hips[:, 0].mean(), hips[:, 1].mean(), max(0.0, hips[:, 2].mean())])
    points = {s: {k: v - origin for k, v in points[s].items()} for s in SIDES}
    notes = [f"{j.name}: axis {j.axis_error_deg:.2f} deg off gaitbot's (taken as gaitbot's)"
             for side in SIDES for j in legs[side] if j.axis_error_deg > 0.01]
    geometry = _geometry(tree, points, legs, frames, origin, notes, sole_m)
    links = _links(tree, legs, frames, origin, points, notes)
    limits = {}
    for side in SIDES:
        for j in legs[side]:
            bounds = tree.hinges[j.theirs].hinge.range_rad
            if bounds is not None:
                limits[j.name] = tuple(sorted(float(np.degrees(j.sign * b)) for b in bounds))
    return Imported(geometry, links, limits, legs, origin, notes)


def _geometry(tree, points, legs, frames, origin, notes, sole_m) -> dict:
    lengths = {"thigh_m": [], "shank_m": []}
    for side in SIDES:
        p = points[side]
        lengths["thigh_m"].append(float(np.linalg.norm(p["knee"] - p["hip"])))
        lengths["shank_m"].append(float(np.linalg.norm(p["ankle"] - p["knee"])))
        for a, b in (("hip", "knee"), ("hip", "ankle")):
            off = float(np.linalg.norm((p[b] - p[a])[:2]))
            if off > 1e-6:
                notes.append(f"{side} {b} {off * 1000:.2f} mm off the vertical through the hip point (neglected)")
    hip_l, hip_r = points["left"]["hip"], points["right"]["hip"]
    geometry = {"thigh_m": np.mean(lengths["thigh_m"]), "shank_m": np.mean(lengths["shank_m"]),
                "hip_width_m": float(hip_l[1] - hip_r[1]), "hip_below_root_m": float(-(hip_l[2] + hip_r[2]) / 2)}
    for key, values in lengths.items():
        if abs(values[0] - values[1]) > 1e-6:
            notes.append(f"{key}: left {values[0]:.6f}, right {values[1]:.6f} m (averaged)")
    geometry.update(_sole(tree, points, legs, frames, origin, notes, sole_m))
    return {k: float(v) for k, v in geometry.items()}


def _sole(tree, points, legs, frames, origin, notes, sole_m) -> dict:
    """The sole from the union of the foot's collision boxes (the bodies rigid with the last leg joint)."""
    found = {}
    for side in SIDES:
        foot = tree.hinges[legs[side][-1].theirs].name
        corners = []
        for name in tree.subtree(foot):
            if name != foot and tree.hinge_ancestors(name)[-1:] != [legs[side][-1].theirs]:
                continue
            r, o = frames[name]
            for box in tree.bodies[name].boxes:
                signs = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)])
                corners += list(o + (r @ (box.centre_m + (signs * box.half_m) @ box.rotation.T).T).T - origin)
        if not corners and sole_m is not None:
            notes.append("no box collision shape on the feet: the sole is the --like config's")
            return dict(sole_m)
        if not corners:
            raise tree.fail(f"body {foot}", f"no box collision shape on the {side} foot: gaitbot needs the sole's size "
                                            f"(add a box to the foot, or give a config with --like)")
        lo, hi = np.min(corners, axis=0), np.max(corners, axis=0)
        ankle = points[side]["ankle"]
        s = 1 if side == "left" else -1
        found[side] = {"foot_m": hi[0] - lo[0], "foot_width_m": hi[1] - lo[1], "ankle_height_m": ankle[2] - lo[2],
                       "heel_back_m": ankle[0] - lo[0], "sole_outward_m": s * ((hi[1] + lo[1]) / 2 - ankle[1])}
    for key in found["left"]:
        if abs(found["left"][key] - found["right"][key]) > 1e-6:
            notes.append(f"{key}: left {found['left'][key]:.6f}, right {found['right'][key]:.6f} m (averaged)")
    return {k: (found["left"][k] + found["right"][k]) / 2 for k in found["left"]}


def _links(tree, legs, frames, origin, points, notes) -> dict:
    owner = _body_link(tree, legs)
    parts: dict = {}
    for name, body in tree.bodies.items():
        if body.inertial is None:
            continue
        r, o = frames[name]
        i = body.inertial
        parts.setdefault(owner[name], []).append((i.mass_kg, o + r @ i.com_m - origin, r @ i.inertia_kg_m2 @ r.T))
    torso = _lump(parts.get(None, []))
    if torso.mass_kg <= 0:
        raise tree.fail("file", "no mass above the hips (the root and the bodies not in a leg have no inertial)")
    joint_point = {"hip_yaw": "hip", "hip_roll": "hip", "thigh": "hip", "shank": "knee", "ankle": "ankle",
                   "foot": "ankle"}
    links = {"torso": torso}
    for link in LEG_LINKS:
        left = _lump(parts.get((link, "left"), []))
        right = _lump(parts.get((link, "right"), []))
        com_l = left.com_m - points["left"][joint_point[link]]
        com_r = _MIRROR @ (right.com_m - points["right"][joint_point[link]])
        inertia_r = _MIRROR @ right.inertia_kg_m2 @ _MIRROR
        if abs(left.mass_kg - right.mass_kg) > 1e-6 or (left.mass_kg > 0 and np.abs(com_l - com_r).max() > 1e-6):
            notes.append(f"{link}: left {left.mass_kg:.6f} kg, right {right.mass_kg:.6f} kg, centres of mass "
                         f"{np.abs(com_l - com_r).max() * 1000:.2f} mm apart (averaged)")
        mass = (left.mass_kg + right.mass_kg) / 2
        com = (left.mass_kg * com_l + right.mass_kg * com_r) / (2 * mass) if mass > 0 else np.zeros(3)
        links[link] = LinkInertial(mass, com, (left.inertia_kg_m2 + inertia_r) / 2)
    return links


def fk_deviation_m(tree: Tree, legs, origin, geometry: BodyGeometry, limits_rad: dict, seed: int = 0) -> float:
    """The largest distance (m) between the description's knee and ankle points and gaitbot's, and the feet's
    turn (rad, times the foot's length), over FK_POSES random poses within ``limits_rad`` (gaitbot joint ->
    (lo, hi)); the description's joints turned by sign x gaitbot's angle."""
    rng = np.random.default_rng(seed)
    zero = tree.frames()
    worst = 0.0
    for _ in range(FK_POSES):
        ours = {n: rng.uniform(*limits_rad[n]) for side in SIDES for n in (j.name for j in legs[side])}
        angles = {j.theirs: j.sign * ours[j.name] for side in SIDES for j in legs[side]}
        moved = tree.frames(angles)
        for side in SIDES:
            q = np.array([ours.get(f"{k}_{side}", 0.0) for k in ("hip_yaw", "hip_roll", "hip_pitch", "knee_pitch",
                                                                   "ankle_pitch", "ankle_roll")])
            rotations, origins = leg_frames(geometry, side, q)
            standing = leg_frames(geometry, side, np.zeros(6))[1]
            knee_body = tree.hinges[next(j.theirs for j in legs[side] if j.name.startswith("knee"))].name
            foot_body = tree.hinges[legs[side][-1].theirs].name
            for body, index in ((knee_body, 3), (foot_body, 5)):
                r0, o0 = zero[body]
                r1, o1 = moved[body]
                local = r0.T @ (standing[index] + origin - o0)  # gaitbot's point, fixed in the body at the zero pose
                worst = max(worst, float(np.linalg.norm(o1 + r1 @ local - origin - origins[index])))
            turn = moved[foot_body][0] @ zero[foot_body][0].T
            worst = max(worst, float(np.abs(turn - rotations[5]).max()) * geometry.foot_m)
    return worst
