"""A calibration file: each joint's zero tick and direction as measured on the robot (``gaitbot calibrate``),
applied on top of its robot config.

Why a file of its own: the config describes a robot design (links, limits, ids), a calibration one build
of it (where each horn sits on its spline). It names the servos it was measured on (id and model per
joint) and is refused for any other servo, so a calibration cannot follow a config onto another robot.
docs/file-formats.md describes it::

    [calibration]
    format = "gaitbot-calibration"
    version = 1
    robot = "xl430-biped"             # the config's [robot] name when it was taken

    [joints.knee_pitch_left]
    id = 3                            # the servo it was taken on ...
    model = "XL430-W250"              # ... and its model: both must match the config
    zero_tick = 2071                  # tick at the zero pose (legs straight, feet flat)
    direction = 1                     # +1: ticks grow as the joint moves in its positive direction
    moved_deg = 38.5                  # how far it was bent (information; checked against the limits then)

Applied (:func:`apply_calibration`): each listed joint takes ``zero_tick`` and ``direction``; joints not
listed keep the config's. Every problem is one line naming the file and the field (exit 2).
Found by :func:`calibration_path_for` when no ``--calibration FILE`` is given: next to the config
(``<config stem>.calibration.toml``), or for a shipped robot (whose file belongs to gaitbot, not to one build)
in the current folder. ``gaitbot calibrate`` writes it there by default, ``gaitbot setup`` names that place.
"""

from __future__ import annotations

import dataclasses
from pathlib import Path

from gaitbot.fields import FieldError, Fields, kind, read_toml
from gaitbot.robot.config import (RobotConfig, angle_outside_servo, default_config_path,
                                  load_robot_config, resolve_config)
from gaitbot.robot.shipped_configs import shipped_config_dirs

FORMAT = "gaitbot-calibration"
VERSION = 1
SUFFIX = ".calibration.toml"
_TOP_KEYS = ("calibration", "joints")
_HEADER_KEYS = ("format", "version", "robot")
_JOINT_KEYS = ("id", "model", "zero_tick", "direction", "moved_deg")


class CalibrationError(FieldError):
    """A calibration file is unusable, or belongs to other servos: ``<file>: <field>: <what is wrong>``."""


@dataclasses.dataclass(frozen=True)
class JointCalibration:
    """One joint as calibrated: on servo ``id`` of ``model``, ``zero_tick`` at the zero pose, ``direction``
    +1 or -1, and ``moved_deg`` (how far it was bent when calibrated; None when not recorded)."""

    name: str
    id: int
    model: str
    zero_tick: int
    direction: int
    moved_deg: float | None = None


@dataclasses.dataclass(frozen=True)
class CalibrationFile:
    path: Path
    robot: str
    joints: tuple[JointCalibration, ...]


def calibration_path_for(config_path: str | Path) -> Path:
    """Where a config's own calibration lives: ``robots/mybot.toml`` -> ``robots/mybot.calibration.toml``
    beside it; a shipped robot's (``xl430-biped``) in the current folder, ``xl430-biped.calibration.toml``
    (a calibration is one build's, and the shipped file is gaitbot's: not written into the package)."""
    config_path = Path(config_path)
    name = config_path.stem + SUFFIX
    shipped = {d.resolve() for d in shipped_config_dirs()}
    if config_path.resolve().parent in shipped:
        return Path(name)
    return config_path.with_name(name)


def read_calibration(path: str | Path) -> CalibrationFile:
    """Read and check a calibration file's own fields (not yet against a config)."""
    path = Path(path)
    data = read_toml(path, CalibrationError)
    f = Fields(path, CalibrationError)
    f.no_unknown_keys(data, "", _TOP_KEYS)
    header = f.table(data, "calibration", "calibration", _HEADER_KEYS)
    if header.get("format") != FORMAT:
        raise f.fail("calibration.format", f"must be {FORMAT!r} (is this a gaitbot calibration file?), "
                                           f"got {kind(header.get('format'))}")
    version = f.integer(header, "version", "calibration")
    if version != VERSION:
        raise f.fail("calibration.version", f"{version} is not a version this gaitbot reads ({VERSION})")
    robot = f.string(header, "robot", "calibration")
    tables = data.get("joints")
    if not isinstance(tables, dict) or not tables:
        raise f.fail("joints", "missing: one [joints.<name>] table per calibrated joint")
    joints = []
    for name, t in tables.items():
        field = f"joints.{name}"
        if not isinstance(t, dict):
            raise f.fail(field, f"must be a table [{field}], got {kind(t)}")
        f.no_unknown_keys(t, field, _JOINT_KEYS)
        direction = f.integer(t, "direction", field, "1 or -1")
        if direction not in (1, -1):
            raise f.fail(f"{field}.direction", f"must be 1 or -1, got {direction}")
        moved = f.number(t, "moved_deg", field) if "moved_deg" in t else None
        joints.append(JointCalibration(name, f.integer(t, "id", field, "a servo id"), f.string(t, "model", field),
                                       f.integer(t, "zero_tick", field, "an integer tick"), direction, moved))
    return CalibrationFile(path, robot, tuple(joints))


def apply_calibration(config: RobotConfig, calibration: CalibrationFile) -> RobotConfig:
    """``config`` with the calibrated joints' zero ticks and directions. Refused (CalibrationError) when a
    joint is not the config's, was taken on another servo id or model, or the zero tick (or a configured
    limit with it) lies outside what the servo can hold."""
    f = Fields(calibration.path, CalibrationError)
    by_name = {j.name: j for j in config.joints}
    replaced = {}
    for cal in calibration.joints:
        field = f"joints.{cal.name}"
        joint = by_name.get(cal.name)
        if joint is None:
            raise f.fail(field, f"no such joint in robot config {config.path} (joints: {', '.join(by_name)})")
        if (cal.id, cal.model) != (joint.id, joint.model.name):
            raise f.fail(field, f"taken on servo {cal.id} ({cal.model}), but {config.path} has servo {joint.id} "
                                f"({joint.model.name}) there: a calibration belongs to the servos it was taken on; "
                                "calibrate this robot with gaitbot calibrate")
        model = joint.model
        if not model.min_tick <= cal.zero_tick <= model.max_tick:
            raise f.fail(f"{field}.zero_tick", f"{cal.zero_tick} is outside the {model.name}'s tick range "
                                               f"{model.min_tick}..{model.max_tick}")
        for key, angle_deg in (("min_deg", joint.min_deg), ("max_deg", joint.max_deg)):
            problem = angle_outside_servo(model, cal.zero_tick, cal.direction, angle_deg)
            if problem:
                raise f.fail(f"{field}.zero_tick", f"with this zero the config's {key} cannot be reached: {problem}")
        replaced[cal.name] = dataclasses.replace(joint, zero_tick=cal.zero_tick, direction=cal.direction)
    joints = tuple(replaced.get(j.name, j) for j in config.joints)
    return dataclasses.replace(config, joints=joints, calibration_file=calibration.path)


def load_robot_with_calibration(robot: str | Path | None, calibration: str | Path | None = None) -> RobotConfig:
    """A robot config (a path, a shipped name, or the default robot) with its calibration applied: the file
    given, else the config's own (:func:`calibration_path_for`) when it exists, else none."""
    path = resolve_config(robot) if robot else default_config_path()
    config = load_robot_config(path)
    found = Path(calibration) if calibration else calibration_path_for(path)
    if calibration or found.is_file():
        config = apply_calibration(config, read_calibration(found))
    return config


def write_calibration(path: str | Path, robot: str, joints: list[JointCalibration], comment: str = "") -> None:
    """Write a calibration file (read back by :func:`read_calibration`), one [joints.<name>] table a joint."""
    lines = [f"# {line}" for line in comment.splitlines()] + [
        "[calibration]", f'format = "{FORMAT}"', f"version = {VERSION}", f'robot = "{robot}"', ""]
    for j in joints:
        lines += [f"[joints.{j.name}]", f"id = {j.id}", f'model = "{j.model}"', f"zero_tick = {j.zero_tick}",
                  f"direction = {j.direction}"]
        if j.moved_deg is not None:
            lines.append(f"moved_deg = {j.moved_deg:.1f}")
        lines.append("")
    Path(path).write_text("\n".join(lines), encoding="utf-8")


def sent_calibration(config: RobotConfig) -> dict:
    """What a recording's header keeps of the calibration a walk was sent with: the file (None: the
    config's own zero ticks) and every joint's zero tick and direction, so that ``gaitbot check`` decodes
    the recording as it was sent, whatever calibration lies beside the config later."""
    return {"file": None if config.calibration_file is None else str(Path(config.calibration_file).resolve()),
            "joints": {j.name: {"zero_tick": int(j.zero_tick), "direction": int(j.direction)} for j in config.joints}}


def with_sent_calibration(config: RobotConfig, sent: dict, recording: str | Path) -> RobotConfig:
    """``config`` (without a calibration of its own) with the zero ticks and directions a recording's header
    says it was sent with (:func:`sent_calibration`), checked as a calibration file's are."""
    by_name = {j.name: j for j in config.joints}
    joints = tuple(JointCalibration(name, by_name[name].id, by_name[name].model.name, int(v["zero_tick"]),
                                    int(v["direction"])) for name, v in sent["joints"].items() if name in by_name)
    applied = apply_calibration(config, CalibrationFile(Path(recording), config.name, joints))
    file = sent.get("file")
    return dataclasses.replace(applied, calibration_file=Path(file) if file else None)
