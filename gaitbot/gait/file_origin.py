"""What a trajectory file was made for: the robot (its config's name, where that config was, and a
fingerprint of its geometry) and the terrain course it walked (the course file's name and its treads).

Why in the file: a trajectory's angles only mean a walk on the leg and the ground they were planned for;
drawn on another robot its feet float, checked against another its limits are another's. ``plot``,
``check`` and ``walk --trajectory`` take the robot and the terrain from here when the command line does
not name them, and refuse one that contradicts it (gaitbot.app.file_robot). Files written before these
fields existed have none and are read as before.

In a CSV: on the version line, after it, `` origin: {JSON object}`` (so the table still starts on line 3,
as readers that skip two lines expect); in an NPZ: the arrays
``origin_robot``, ``origin_robot_config``, ``origin_robot_geometry``, ``origin_terrain`` (text) and
``origin_treads`` (K, 3: start, length, height in metres). docs/file-formats.md.
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass

import numpy as np

from gaitbot.gait.terrain.model import Terrain, TerrainError, Tread

CSV_PREFIX = " origin: "
"""What follows the version line of a CSV to give its origin."""
#: The longest text one origin field may hold (a name, a path, a fingerprint): as an NPZ's text arrays.
MAX_TEXT_CHARS = 256
#: The most treads an origin may list (as a course file: gaitbot.gait.terrain.course_file).
MAX_TREADS = 100
#: The longest origin a CSV's version line may hold, in characters (100 treads of three numbers, names and paths).
MAX_LINE_CHARS = 16_384
_TEXT_KEYS = ("robot", "robot_config", "robot_geometry", "terrain")
_KEYS = _TEXT_KEYS + ("treads",)
#: The arrays an NPZ trajectory keeps its origin in.
ORIGIN_ARRAYS = tuple(f"origin_{k}" for k in _KEYS)


class OriginProblem(ValueError):
    """What is wrong with a file's origin, naming the field (the trajectory reader adds the file)."""


@dataclass(frozen=True)
class FileOrigin:
    """robot: the robot config's ``[robot] name``; robot_config: the path of that config when the file
    was written (absolute); robot_geometry: gaitbot.robot.fingerprint of its ``[geometry]``; terrain:
    the course file's path as given; treads: the course's treads (empty: flat ground; None: not said,
    as in a recording of a real walk)."""

    robot: str | None = None
    robot_config: str | None = None
    robot_geometry: str | None = None
    terrain: str | None = None
    treads: tuple[Tread, ...] | None = None

    @property
    def course(self) -> Terrain | None:
        """The terrain walked, rebuilt from the treads (None: flat ground, or not said)."""
        return Terrain(self.treads) if self.treads else None

    def to_dict(self) -> dict:
        out = {k: getattr(self, k) for k in _TEXT_KEYS if getattr(self, k) is not None}
        if self.treads is not None:
            out["treads"] = [[t.start_m, t.length_m, t.height_m] for t in self.treads]
        return out

    def csv_suffix(self) -> str:
        """What the version line of a CSV written for this origin ends with."""
        return CSV_PREFIX + json.dumps(self.to_dict(), separators=(", ", ": "))

    def npz_arrays(self) -> dict[str, np.ndarray]:
        out = {f"origin_{k}": np.array(getattr(self, k)) for k in _TEXT_KEYS if getattr(self, k) is not None}
        if self.treads is not None:
            out["origin_treads"] = np.array([[t.start_m, t.length_m, t.height_m] for t in self.treads],
                                            dtype=float).reshape(-1, 3)
        return out


def origin_from_dict(data: object) -> FileOrigin:
    """An origin from its JSON object; OriginProblem names the field that is wrong."""
    if not isinstance(data, dict):
        raise OriginProblem("must be a JSON object {\"robot\": ..., ...}")
    unknown = [k for k in data if k not in _KEYS]
    if unknown:
        raise OriginProblem(f"unknown field {str(unknown[0])[:40]!r} (allowed: {', '.join(_KEYS)})")
    values = {}
    for key in _TEXT_KEYS:
        value = data.get(key)
        if value is None:
            continue
        if not isinstance(value, str) or not value or len(value) > MAX_TEXT_CHARS or "\n" in value:
            raise OriginProblem(f"field {key!r} must be text of 1..{MAX_TEXT_CHARS} characters on one line")
        values[key] = value
    if data.get("treads") is not None:
        values["treads"] = _treads(data["treads"])
    return FileOrigin(**values)


def origin_from_csv_text(text: str) -> FileOrigin:
    """The origin of a CSV's version line: the JSON object after ``origin:``."""
    if len(text) > MAX_LINE_CHARS:
        raise OriginProblem(f"the origin is longer than {MAX_LINE_CHARS} characters")
    try:
        data = json.loads(text)
    except (ValueError, RecursionError) as exc:
        raise OriginProblem(f"the origin is not a JSON object ({getattr(exc, 'msg', exc)})") from None
    return origin_from_dict(data)


def origin_from_npz(arrays: dict[str, np.ndarray]) -> FileOrigin | None:
    """The origin of an NPZ's ``origin_*`` arrays (None: it has none)."""
    keys = [k for k in arrays if k.startswith("origin_")]
    if not keys:
        return None
    data: dict = {}
    for key in keys:
        name, value = key[len("origin_"):], arrays[key]
        if name == "treads":
            if value.dtype.kind not in "iuf" or value.ndim != 2 or value.shape[1] != 3:
                raise OriginProblem(f"array {key!r} must be numbers of shape (K, 3), got {value.dtype} {value.shape}")
            data[name] = value.astype(float).tolist()
        elif name in _TEXT_KEYS:
            if value.dtype.kind != "U" or value.ndim != 0:
                raise OriginProblem(f"array {key!r} must be one text, got {value.dtype} {value.shape}")
            data[name] = str(value)
        else:
            raise OriginProblem(f"unknown array {key!r} (allowed: {', '.join('origin_' + k for k in _KEYS)})")
    return origin_from_dict(data)


def _treads(raw: object) -> tuple[Tread, ...]:
    if not isinstance(raw, list) or len(raw) > MAX_TREADS:
        raise OriginProblem(f"field 'treads' must be a list of at most {MAX_TREADS} [start_m, length_m, height_m]")
    treads = []
    for i, item in enumerate(raw, start=1):
        ok = (isinstance(item, list) and len(item) == 3
              and all(isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v) and abs(v) <= 100
                      for v in item))
        if not ok:
            raise OriginProblem(f"field 'treads' item {i} must be [start_m, length_m, height_m], finite numbers "
                                "within +-100 m")
        treads.append(Tread(float(item[0]), float(item[1]), float(item[2])))
    try:
        Terrain(tuple(treads))
    except TerrainError as exc:
        raise OriginProblem(f"field 'treads': {exc}") from None
    return tuple(treads)
