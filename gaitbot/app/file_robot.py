"""The robot and the terrain a command uses for a trajectory file: what the file says it was made for
(gaitbot.gait.file_origin), unless the command line names them; a ``--robot`` or ``--terrain`` that
contradicts the file is refused in one line (exit 2). A file that says nothing (written before files
remembered their robot, or by hand) gets the command line's robot, else the default, as before.
"""

from __future__ import annotations

from pathlib import Path

from gaitbot.app.options import UsageError, file_option, load_robot
from gaitbot.gait.file_origin import FileOrigin
from gaitbot.gait.terrain.course_file import load_course
from gaitbot.gait.terrain.model import Terrain
from gaitbot.gait.trajectory import read_origin
from gaitbot.robot.config import RobotConfig
from gaitbot.robot.origin import geometry_fingerprint
from gaitbot.robot.shipped_configs import shipped_config_dirs


def robot_for_file(file: str | Path, origin: FileOrigin | None, robot: str | None,
                   calibration: str | None = None) -> RobotConfig:
    """``--robot`` (checked against the file's robot), else the robot the file was made for, else the default."""
    if origin is None or origin.robot is None:
        return load_robot(robot, calibration)
    if robot is not None:
        config = load_robot(robot, calibration)
        if config.name != origin.robot:
            raise UsageError(f"--robot {robot}: {file} was made for robot {origin.robot!r}, not {config.name!r} "
                             f"(leave --robot out to use the file's robot)")
    else:
        found = _config_of(origin)
        if found is None:
            raise UsageError(f"{file}: made for robot {origin.robot!r}, whose config is neither where it was "
                             f"({origin.robot_config}) nor a shipped robot; give it with --robot PATH")
        config = load_robot(str(found), calibration)
    if origin.robot_geometry is not None and geometry_fingerprint(config) != origin.robot_geometry:
        raise UsageError(f"{file}: made for {origin.robot} with geometry {origin.robot_geometry}, but {config.path} "
                         f"has geometry {geometry_fingerprint(config)} (its [geometry] changed since): make the "
                         f"file again for this config")
    return config


def robot_for_walk(args) -> RobotConfig:
    """``walk``'s robot: with ``--trajectory FILE``, the file's (robot_for_file), else ``--robot`` or the default."""
    calibration = getattr(args, "calibration", None)
    trajectory = getattr(args, "trajectory", None)
    if trajectory is None:
        return load_robot(args.robot, calibration)
    file = file_option(trajectory, "--trajectory")
    return robot_for_file(file, read_origin(file), args.robot, calibration)


def _config_of(origin: FileOrigin) -> Path | None:
    """Where the file's robot config is: where it was when the file was written, else the shipped robot."""
    if origin.robot_config is not None and Path(origin.robot_config).is_file():
        return Path(origin.robot_config)
    for directory in shipped_config_dirs():
        candidate = directory / f"{origin.robot}.toml"
        if candidate.is_file():
            return candidate
    return None


def terrain_for_file(file: str | Path, origin: FileOrigin | None, terrain: str | None) -> Terrain | None:
    """``--terrain`` (checked against the course the file says it walked, flat ground included), else that
    course, else None (flat ground)."""
    said = None if origin is None else origin.treads  # () flat ground, None not said
    if terrain is None:
        return origin.course if said else None
    course = load_course(file_option(terrain, "--terrain")).terrain
    if said is not None and _treads(said) != _treads(course.treads):
        walked = f"the course {origin.terrain or 'it lists'}" if said else "flat ground"
        raise UsageError(f"--terrain {terrain}: {file} was walked on {walked}, not on this course "
                         f"(leave --terrain out to use the file's)")
    return course


def _treads(treads) -> list[tuple[float, float, float]]:
    return sorted((round(t.start_m, 9), round(t.length_m, 9), round(t.height_m, 9)) for t in treads)
