"""An MJCF file as a description tree (gaitbot.robot.description.tree), compiled by MuJoCo itself.

Why MuJoCo: an MJCF's meaning (default classes, frames, euler sequences, inertias from geoms, includes) is
what MuJoCo's compiler makes of it; reading the compiled model takes every one of those rules from their
authors rather than from a second reader. The robot is the body that floats (a free joint), else the one
child of the world that carries hinges. Hinges become the tree's joints; slide and ball joints are rigid at
0 (a leg cannot use them); box geoms that collide are the feet's shapes. Also reads URDF files' root tag to
hand them to the URDF reader (``read_description``).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from gaitbot.robot.description.tree import (MAX_BODIES, Body, Box, DescriptionError, Hinge, Tree, checked_inertial,
                                            ordered, quaternion_matrix)
from gaitbot.robot.description.urdf_reader import read_urdf, read_xml
from gaitbot.sim import import_mujoco


def read_description(path: str | Path) -> Tree:
    """A URDF (root ``<robot>``) or MJCF (root ``<mujoco>``) file as a tree, whatever its suffix."""
    path = Path(path)
    tag = read_xml(path).tag
    if tag == "robot":
        return read_urdf(path)
    if tag == "mujoco":
        return read_mjcf(path)
    raise DescriptionError(path, "file", f"the root element is <{tag[:40]}>: neither a URDF (<robot>) nor an MJCF "
                                         f"(<mujoco>)")


def _compile(path: Path):
    mujoco = import_mujoco()
    try:
        return mujoco, mujoco.MjModel.from_xml_path(str(path))
    except Exception as exc:  # MuJoCo's compiler errors are plain exceptions with a multi-line message
        first = " ".join(str(exc).split())[:300]
        raise DescriptionError(path, "file", f"MuJoCo cannot compile this MJCF ({first})") from None


def _root(mujoco, model, path: Path) -> int:
    free = [int(model.jnt_bodyid[j]) for j in range(model.njnt) if model.jnt_type[j] == mujoco.mjtJoint.mjJNT_FREE]
    if len(free) == 1:
        return free[0]
    hinged = {int(model.jnt_bodyid[j]) for j in range(model.njnt) if model.jnt_type[j] == mujoco.mjtJoint.mjJNT_HINGE}
    tops = set()
    for b in hinged:
        while model.body_parentid[b] != 0:
            b = int(model.body_parentid[b])
        tops.add(b)
    if len(tops) != 1:
        raise DescriptionError(path, "worldbody", f"{len(free)} free joints and {len(tops)} bodies with hinges under "
                                                  f"the world: cannot tell which body is the robot")
    return tops.pop()


def _name(model, kind, i: int, prefix: str) -> str:
    return getattr(model, kind)(i).name or f"{prefix}{i}"


def _hinge(mujoco, model, b: int, name: str, path: Path) -> Hinge | None:
    hinges = [j for j in range(model.body_jntadr[b], model.body_jntadr[b] + model.body_jntnum[b])
              if model.jnt_type[j] == mujoco.mjtJoint.mjJNT_HINGE]
    if not hinges:
        return None
    if len(hinges) > 1:
        raise DescriptionError(path, f"body {name}", f"carries {len(hinges)} hinge joints; gaitbot's legs have one "
                                                     f"joint per body")
    j = hinges[0]
    bounds = tuple(float(v) for v in model.jnt_range[j]) if model.jnt_limited[j] else None
    return Hinge(_name(model, "joint", j, "joint"), np.array(model.jnt_axis[j], dtype=float),
                 np.array(model.jnt_pos[j], dtype=float), bounds)


def _check_masses(root, path: Path) -> None:
    """An inertial's mass must be positive (MuJoCo takes 0 on a body whose children carry mass, and says less
    clearly what is wrong with a negative one); a geom's may be 0 (shapes that only collide), never negative."""
    for body in root.iter("body"):
        name = body.get("name") or "(unnamed body)"
        checks = [(body.find("inertial"), "positive")] + [(g, "not negative") for g in body.findall("geom")]
        for element, least in checks:
            if element is None or element.get("mass") is None:
                continue
            try:
                mass = float(element.get("mass"))
            except ValueError:
                raise DescriptionError(path, f"body {name}", f"mass {element.get('mass')[:40]!r} is not a number") \
                    from None
            if not (mass > 0 if least == "positive" else mass >= 0):
                raise DescriptionError(path, f"body {name}", f"{element.tag} mass {mass:g} kg: must be {least}")


def read_mjcf(path: str | Path) -> Tree:
    """The MJCF file at ``path`` as a description tree; DescriptionError (one line) when it cannot be one."""
    path = Path(path)
    _check_masses(read_xml(path), path)  # the size cap, the entity refusal and the masses before MuJoCo reads it
    mujoco, model = _compile(path)
    if model.nbody > MAX_BODIES:
        raise DescriptionError(path, "file", f"{model.nbody} bodies, more than a robot has (at most {MAX_BODIES})")
    root = _root(mujoco, model, path)
    keep = {root}
    for b in range(root + 1, model.nbody):
        if int(model.body_parentid[b]) in keep:
            keep.add(b)
    bodies = []
    for b in sorted(keep):
        name = _name(model, "body", b, "body")
        inertial = None
        if model.body_mass[b] != 0:
            r = quaternion_matrix(*model.body_iquat[b])
            inertial = checked_inertial(str(path), f"body {name}", float(model.body_mass[b]), model.body_ipos[b],
                                        r @ np.diag(model.body_inertia[b]) @ r.T)
        boxes = tuple(Box(np.array(model.geom_pos[g]), quaternion_matrix(*model.geom_quat[g]),
                          np.array(model.geom_size[g]))
                      for g in range(model.ngeom)
                      if model.geom_bodyid[g] == b and model.geom_type[g] == mujoco.mjtGeom.mjGEOM_BOX
                      and (model.geom_contype[g] or model.geom_conaffinity[g]))
        parent = None if b == root else _name(model, "body", int(model.body_parentid[b]), "body")
        position = np.zeros(3) if b == root else np.array(model.body_pos[b], dtype=float)
        rotation = np.eye(3) if b == root else quaternion_matrix(*model.body_quat[b])
        bodies.append(Body(name, parent, position, rotation, _hinge(mujoco, model, b, name, path), inertial, boxes))
    ordered_bodies, root_name = ordered(str(path), bodies)
    return Tree(str(path), path.stem, ordered_bodies, root_name)
