"""A robot's identity as a file written for it records it (gaitbot.gait.file_origin): its name, its
config's path and a fingerprint of its geometry.

Why a fingerprint: a name says which robot, not which build of its config; a trajectory planned for
one leg walks another's badly (its feet float or dig in), so a file remembers the leg it was planned
for and is refused on a config whose ``[geometry]`` changed since.
"""

from __future__ import annotations

import dataclasses
import hashlib

from gaitbot.gait.file_origin import FileOrigin
from gaitbot.gait.terrain.model import Terrain
from gaitbot.robot.config_types import RobotConfig


def geometry_fingerprint(config: RobotConfig) -> str:
    """12 hex digits of the SHA-256 of the config's ``[geometry]`` values, each rounded to 0.1 um (so
    the same lengths written differently in the TOML give the same fingerprint)."""
    values = dataclasses.asdict(config.geometry)
    text = ";".join(f"{k}={'none' if v is None else f'{round(float(v), 7):.7f}'}" for k, v in sorted(values.items()))
    return hashlib.sha256(text.encode("ascii")).hexdigest()[:12]


def origin_for(config: RobotConfig | None, terrain_file: str | None = None, terrain: Terrain | None = None,
               ground_known: bool = True) -> FileOrigin | None:
    """The origin a file made for ``config`` (None: a leg given on the command line, no config) records,
    with the terrain course walked (None: flat ground, or with ``ground_known`` False not said)."""
    if config is None and terrain is None and not ground_known:
        return None
    robot = {}
    if config is not None:
        path = str(config.path.resolve())
        robot = {"robot": config.name, "robot_geometry": geometry_fingerprint(config),
                 "robot_config": path if len(path) <= 256 else None}
    if terrain is None:
        course = {"treads": ()} if ground_known else {}
    else:
        short = terrain_file if terrain_file and len(terrain_file) <= 256 else None
        course = {"terrain": short, "treads": tuple(terrain.treads)}
    return FileOrigin(**robot, **course)
