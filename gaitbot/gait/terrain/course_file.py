"""Terrain courses from TOML files a person writes by hand, checked field by field.

    [course]
    start_m = 0.0        # both heels here at the start
    end_m = 1.2          # the walk ends with both heels at the first foothold at or past this
    margin_m = 0.01      # heel and toe at least this far inside a tread's edges (default 0.01)
    # clearance_m = 0.015  swing sole above every tread edge it passes (default: the robot's)
    # max_step_m = 0.16    longest step onto another surface (default 0.75 leg lengths)
    # max_rise_m = 0.05    highest rise or drop between footholds (default 0.25 leg lengths)

    [search]             # optional: the grid search of the pelvis's lowest points (seed 003)
    weights = [1.0, 1.0, 0.8]   # hip, knee, ankle (default: the joints' ranges, normalised)

    [[tread]]
    start_m = 0.5
    length_m = 0.15
    height_m = 0.03

Ground outside the listed treads is at height 0. Every problem is one line naming the file and
the field, like the robot config: ``config/terrain/kerb.toml: tread[2].start_m: ...``.
"""

from __future__ import annotations

import difflib
import math
from dataclasses import dataclass
from pathlib import Path

from gaitbot.gait.terrain.model import Terrain, TerrainError, Tread

try:
    import tomllib
except ModuleNotFoundError:  # Python 3.10
    import tomli as tomllib  # type: ignore[no-redef]


class TerrainFileError(ValueError):
    """A terrain file is unusable: ``<file>: <field>: <what is wrong>`` on one line."""

    def __init__(self, path, field: str, reason: str) -> None:
        self.path, self.field, self.reason = str(path), field, " ".join(str(reason).split())
        super().__init__(f"{self.path}: {field}: {self.reason}")


@dataclass(frozen=True)
class Course:
    """A terrain and how to walk it. Optional values are None when the file leaves them to the defaults."""

    path: str
    terrain: Terrain
    start_m: float
    end_m: float
    margin_m: float = 0.01
    clearance_m: float | None = None
    max_step_m: float | None = None
    max_rise_m: float | None = None
    weights: tuple[float, float, float] | None = None


_COURSE_KEYS = ("start_m", "end_m", "margin_m", "clearance_m", "max_step_m", "max_rise_m")
_TREAD_KEYS = ("start_m", "length_m", "height_m")


def _unknown(path, where: str, table: dict, allowed) -> None:
    for key in table:
        if key not in allowed:
            close = difflib.get_close_matches(key, allowed, n=1)
            hint = f" (did you mean {close[0]!r}?)" if close else f" (allowed: {', '.join(allowed)})"
            raise TerrainFileError(path, f"{where}{key}", f"unknown key{hint}")


def _number(path, field: str, value, minimum: float | None = None, positive: bool = False) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
        raise TerrainFileError(path, field, f"must be a finite number, got {value!r}")
    if positive and value <= 0:
        raise TerrainFileError(path, field, f"must be positive, got {value!r}")
    if minimum is not None and value < minimum:
        raise TerrainFileError(path, field, f"must be {minimum:g} or more, got {value!r}")
    return float(value)


def load_course(path) -> Course:
    """Read and check a terrain file; raise TerrainFileError (one line) for the first problem."""
    path = Path(path)
    try:
        with open(path, "rb") as f:
            data = tomllib.load(f)
    except FileNotFoundError:
        raise TerrainFileError(path, "file", "no such file") from None
    except OSError as exc:
        raise TerrainFileError(path, "file", f"cannot read ({exc.strerror})") from None
    except tomllib.TOMLDecodeError as exc:
        raise TerrainFileError(path, "file", f"not valid TOML ({exc})") from None
    _unknown(path, "", data, ("course", "search", "tread"))
    course = data.get("course")
    if not isinstance(course, dict):
        raise TerrainFileError(path, "course", "missing [course] table (needs start_m and end_m)")
    _unknown(path, "course.", course, _COURSE_KEYS)
    for key in ("start_m", "end_m"):
        if key not in course:
            raise TerrainFileError(path, f"course.{key}", "missing")
    start = _number(path, "course.start_m", course["start_m"])
    end = _number(path, "course.end_m", course["end_m"])
    if end <= start:
        raise TerrainFileError(path, "course.end_m", f"{end:g} must lie beyond start_m {start:g}")
    margin = _number(path, "course.margin_m", course.get("margin_m", 0.01), minimum=0.0)
    optional = {}
    for key in ("clearance_m", "max_step_m", "max_rise_m"):
        if key in course:
            optional[key] = _number(path, f"course.{key}", course[key], minimum=0.0,
                                    positive=key != "clearance_m")
    weights = None
    search = data.get("search", {})
    if not isinstance(search, dict):
        raise TerrainFileError(path, "search", "must be a table")
    _unknown(path, "search.", search, ("weights",))
    if "weights" in search:
        raw = search["weights"]
        if not isinstance(raw, list) or len(raw) != 3:
            raise TerrainFileError(path, "search.weights", f"must be a list of 3 numbers (hip, knee, ankle), got {raw!r}")
        weights = tuple(_number(path, f"search.weights[{i + 1}]", w, minimum=0.0) for i, w in enumerate(raw))
        if sum(weights) <= 0:
            raise TerrainFileError(path, "search.weights", "at least one weight must be positive")
    raw_treads = data.get("tread", [])
    if not isinstance(raw_treads, list):
        raise TerrainFileError(path, "tread", "write each tread as a [[tread]] table")
    treads = []
    for i, t in enumerate(raw_treads, start=1):
        _unknown(path, f"tread[{i}].", t, _TREAD_KEYS)
        for key in _TREAD_KEYS:
            if key not in t:
                raise TerrainFileError(path, f"tread[{i}].{key}", "missing")
        treads.append(Tread(_number(path, f"tread[{i}].start_m", t["start_m"]),
                            _number(path, f"tread[{i}].length_m", t["length_m"], positive=True),
                            _number(path, f"tread[{i}].height_m", t["height_m"])))
    try:
        terrain = Terrain(tuple(treads))
    except TerrainError as exc:
        raise TerrainFileError(path, exc.field, exc.reason) from None
    return Course(str(path), terrain, start, end, margin, optional.get("clearance_m"), optional.get("max_step_m"),
                  optional.get("max_rise_m"), weights)
