"""An imported description as a robot config draft (TOML text): ``gaitbot robot import -o new.toml``.

What a description says (geometry, link masses, joint limits where it gives them) comes from the import
(gaitbot.robot.description.importer); what it cannot say (the bus, servo models, ids, zero ticks,
directions, gait and balance settings) comes from an existing config (``--like``, by joint name), or else
is a placeholder that plans, generates, checks and simulates, and ``[robot] draft`` says so: the hardware
commands refuse a config with that key until the user has filled the placeholders in and deleted it.
"""

from __future__ import annotations

import dataclasses

from gaitbot.gait.body import LEG_LINKS
from gaitbot.gait.joints import LEG_JOINTS, PITCH_KINDS, split_joint
from gaitbot.robot.config import RobotConfig
from gaitbot.robot.description.importer import Imported

#: Placeholders of a draft without --like (docs/robot-description.md): a Dynamixel X bus, the servo
#: and the joint ranges a small biped's joints usually have (deg), a gait sized by the leg.
PLACEHOLDER_BUS = {"backend": "dynamixel", "protocol": 2.0, "port": "/dev/ttyUSB0", "baudrate": 1000000,
                   "torque_off_on_exit": False}
PLACEHOLDER_SERVO = "XM430-W350"
PLACEHOLDER_LIMITS_DEG = {"hip_yaw": (-30.0, 30.0), "hip_roll": (-30.0, 30.0), "hip_pitch": (-60.0, 90.0),
                          "knee_pitch": (-5.0, 130.0), "ankle_pitch": (-60.0, 60.0), "ankle_roll": (-30.0, 30.0)}
PLACEHOLDER_SPEED = {"max_velocity_dps": 240.0, "max_acceleration_dps2": 20000.0}
DRAFT_NOTE = ("imported from {source}: the bus, servo models, ids, zero ticks, directions and gait settings are "
              "placeholders; check them against the robot, then delete this line")


def _value(v) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, str):
        return '"' + v.replace("\\", "\\\\").replace('"', '\\"') + '"'
    if isinstance(v, (list, tuple)):
        return "[" + ", ".join(_value(x) for x in v) + "]"
    if isinstance(v, int):
        return str(v)
    text = format(float(v), ".12g")
    return text if any(c in text for c in ".en") else text + ".0"


def _table(name: str, values: dict, comment: str = "") -> list[str]:
    lines = [f"[{name}]" + (f"   # {comment}" if comment else "")]
    return lines + [f"{k} = {_value(v)}" for k, v in values.items() if v is not None] + [""]


def _settings(like: RobotConfig | None, leg_m: float) -> list[str]:
    if like is None:
        gait = {"cycle_s": 1.2, "max_step_m": round(0.2 * leg_m, 4), "clearance_m": round(0.04 * leg_m, 4),
                "rate_hz": 60.0}
        return _table("gait", gait, "placeholder, sized by the leg") + _table("bus", PLACEHOLDER_BUS, "placeholder")
    lines = _table("gait", dataclasses.asdict(like.gait), f"from {like.path.name}")
    lines += _table("bus", dataclasses.asdict(like.bus), f"from {like.path.name}")
    for name in ("servo", "health"):
        values = dataclasses.asdict(getattr(like, name))
        if any(v is not None for v in values.values()):
            lines += _table(name, values, f"from {like.path.name}")
    if like.is_3d:
        lines += _table("balance", dataclasses.asdict(like.balance), f"from {like.path.name}")
    return lines


def _links(imported: Imported) -> list[str]:
    masses = {name: float(format(link.mass_kg, ".12g")) for name, link in imported.links.items()}
    total = masses["torso"] + 2 * sum(masses[n] for n in LEG_LINKS)
    lines = _table("mass", {"total_kg": round(total, 9)})
    for name, link in imported.links.items():
        i = link.inertia_kg_m2
        lines += _table(f"links.{name}", {"mass_kg": masses[name], "com_m": list(link.com_m),
                                          "inertia_kg_m2": [i[0, 0], i[1, 1], i[2, 2], i[0, 1], i[0, 2], i[1, 2]]})
    return lines


def _joint(name: str, imported: Imported, like: RobotConfig | None, index: int, theirs: str) -> list[str]:
    kind = split_joint(name)[0]
    own = imported.limits_deg.get(name)
    have = like is not None and name in like.joint_names
    if have:
        j = like.joint(name)
        values = {"id": j.id, "model": j.model.name, "zero_tick": j.zero_tick, "direction": j.direction}
        lo, hi = (max(own[0], j.min_deg), min(own[1], j.max_deg)) if own else (j.min_deg, j.max_deg)
        speed = {"max_velocity_dps": j.max_velocity_dps, "max_acceleration_dps2": j.max_acceleration_dps2}
    else:
        values = {"id": index + 1, "model": PLACEHOLDER_SERVO, "zero_tick": 2048, "direction": 1}
        lo, hi = own or PLACEHOLDER_LIMITS_DEG[kind]
        speed = PLACEHOLDER_SPEED
    values.update({"min_deg": round(lo, 9), "max_deg": round(hi, 9), **speed})
    where = "limits: the description's" + (f" within {like.path.name}'s" if have and own else "") if own else (
        f"limits from {like.path.name}" if have else "placeholder limits")
    return _table(f"joints.{name}", values, f"{theirs}; {where}")


def draft_text(name: str, source: str, imported: Imported, like: RobotConfig | None) -> str:
    """The config draft's TOML text (module docstring)."""
    legs = imported.legs
    mapped = {j.name: f"{'-' if j.sign < 0 else ''}{j.theirs}" for side in legs for j in legs[side]}
    three_d = len(legs["left"]) == 6
    g = imported.geometry
    header = [f"# {name}: imported by gaitbot robot import from {source}",
              "# Joint mapping (gaitbot joint = description joint, '-': opposite sense; a --map file's form):"]
    header += ["#   " + ", ".join(f"{j.name} = {mapped[j.name]}" for j in legs[side]) for side in legs]
    header += [f"# Left out by gaitbot's leg model: {note}" for note in imported.notes[:20]] + [""]
    robot = {"name": name, "boom": like.boom if like is not None else not three_d}
    if like is None:
        robot["draft"] = DRAFT_NOTE.format(source=source)
    lines = header + _table("robot", robot)
    geometry = {k: g[k] for k in ("thigh_m", "shank_m", "foot_m", "foot_width_m", "hip_width_m", "ankle_height_m",
                                  "heel_back_m", "sole_outward_m", "hip_below_root_m")}
    lines += _table("geometry", geometry, "from the description (gaitbot.robot.description.importer)")
    lines += _settings(like, g["thigh_m"] + g["shank_m"])
    lines += _links(imported)
    joints = [n for n in LEG_JOINTS if n in mapped]
    for index, joint in enumerate(joints):
        lines += _joint(joint, imported, like, index, mapped[joint])
    if like is not None:  # joints the description does not turn but the like config holds (on the bus)
        for j in like.held_joints:
            if j.name not in mapped and (three_d or split_joint(j.name)[0] not in PITCH_KINDS):
                lines += _table(f"joints.{j.name}", {"id": j.id, "model": j.model.name, "zero_tick": j.zero_tick,
                                                     "direction": j.direction, "min_deg": j.min_deg,
                                                     "max_deg": j.max_deg, "max_velocity_dps": j.max_velocity_dps,
                                                     "max_acceleration_dps2": j.max_acceleration_dps2,
                                                     "hold_deg": j.hold_deg}, f"held, from {like.path.name}")
    return "\n".join(lines)
