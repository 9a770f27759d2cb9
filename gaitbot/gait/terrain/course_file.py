"""Terrain courses from TOML files a person writes by hand, checked field by field.

    [course]             # optional, as is each of its values
    start_m = 0.0        # both heels here at the start (default 0)
    end_m = 1.2          # the walk ends with both heels at the first foothold at or past this
                         # (default: END_PAST_TREADS_M past the far end of the last tread)
    margin_m = 0.01      # heel and toe at least this far inside a tread's edges (default 0.01)
    # clearance_m = 0.015  swing sole above every tread edge it passes (default: the robot's)
    # max_step_m = 0.16    longest step onto another surface (default 0.75 leg lengths)
    # max_rise_m = 0.05    highest rise or drop between footholds (default 0.25 leg lengths)

    [search]             # optional: the grid search of the pelvis's lowest points (Zhang 2008)
    weights = [1.0, 1.0, 0.8]   # hip, knee, ankle (default: the joints' ranges, normalised)

    [[tread]]
    start_m = 0.5
    length_m = 0.15
    height_m = 0.03

Ground outside the listed treads is at height 0. Every problem is one line naming the file and
the field, like the robot config (both read through gaitbot.fields):
``config/terrain/kerb.toml: tread[2].start_m: ...``.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from gaitbot.fields import FieldError, Fields, read_toml
from gaitbot.gait.terrain.model import Terrain, TerrainError, Tread


class TerrainFileError(FieldError):
    """A terrain file is unusable: ``<file>: <field>: <what is wrong>`` on one line."""

    @classmethod
    def unreadable(cls, path: Path, exc: BaseException) -> "TerrainFileError":
        if isinstance(exc, FileNotFoundError):
            return cls(path, "file", "no such file")
        return super().unreadable(path, exc)

    @classmethod
    def not_toml(cls, path: Path, exc: Exception) -> "TerrainFileError":
        return cls(path, "file", f"not valid TOML ({exc})")


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


#: Bounds of every size a course can ask for (both ends included): a course is walked, planned and searched
#: over its whole length, so its length bounds the work (docs/file-formats.md).
POSITION_RANGE_M = (-100.0, 100.0, "m")
MAX_COURSE_M = 20.0
MARGIN_RANGE_M = (0.0, 0.1, "m")
OPTIONAL_RANGES_M = {"clearance_m": (0.0, 0.5, "m"), "max_step_m": (0.005, 2.0, "m"), "max_rise_m": (0.001, 1.0, "m")}
TREAD_LENGTH_RANGE_M = (0.005, 20.0, "m")
HEIGHT_RANGE_M = (-1.0, 1.0, "m")
MAX_TREADS = 100
#: Without ``end_m`` the walk crosses every tread and goes on this far past the far end of the last one,
#: so the course's extent follows from its treads and the walk closes on the ground beyond them.
END_PAST_TREADS_M = 0.3

_COURSE_KEYS = ("start_m", "end_m", "margin_m", "clearance_m", "max_step_m", "max_rise_m")
_TREAD_KEYS = ("start_m", "length_m", "height_m")


def _tread(fields: Fields, t: dict, i: int) -> Tread:
    try:
        return Tread(fields.number(t, "start_m", f"tread[{i}]", within=POSITION_RANGE_M),
                     fields.number(t, "length_m", f"tread[{i}]", positive=True, within=TREAD_LENGTH_RANGE_M),
                     fields.number(t, "height_m", f"tread[{i}]", within=HEIGHT_RANGE_M))
    except TerrainFileError as exc:
        raise TerrainFileError(exc.path, exc.field, f"{exc.reason} (tread {i})") from None


def load_course(path) -> Course:
    """Read and check a terrain file; raise TerrainFileError (one line) for the first problem."""
    path = Path(path)
    data = read_toml(path, TerrainFileError)
    fields = Fields(path, TerrainFileError)
    fields.no_unknown_keys(data, "", ("course", "search", "tread"))
    course = fields.optional_table(data, "course", "course", _COURSE_KEYS)
    start = fields.number(course, "start_m", "course", default=0.0, within=POSITION_RANGE_M)
    margin = fields.number(course, "margin_m", "course", non_negative=True, default=0.01, within=MARGIN_RANGE_M)
    optional = {key: fields.number(course, key, "course", positive=key != "clearance_m",
                                   non_negative=key == "clearance_m", within=OPTIONAL_RANGES_M[key])
                for key in ("clearance_m", "max_step_m", "max_rise_m") if key in course}
    search = fields.optional_table(data, "search", "search", ("weights",))
    weights = None
    if "weights" in search:
        raw = search["weights"]
        if not isinstance(raw, list) or len(raw) != 3:
            raise fields.fail("search.weights", f"must be a list of 3 numbers (hip, knee, ankle), got {raw!r}")
        weights = tuple(fields.check_number(w, f"search.weights[{i}]", non_negative=True, within=(0.0, 1e6, ""))
                        for i, w in enumerate(raw, start=1))
        if sum(weights) <= 0:
            raise fields.fail("search.weights", "at least one weight must be positive")
    tables = fields.tables(data, "tread", _TREAD_KEYS)
    if len(tables) > MAX_TREADS:
        raise fields.fail("tread", f"{len(tables)} treads, more than the {MAX_TREADS} a course may have")
    treads = tuple(_tread(fields, t, i) for i, t in enumerate(tables, start=1))
    try:
        terrain = Terrain(treads)
    except TerrainError as exc:
        raise TerrainFileError(path, exc.field, exc.reason) from None
    far_end = max([start, *(t.start_m + t.length_m for t in treads)])
    end = fields.number(course, "end_m", "course", default=far_end + END_PAST_TREADS_M, within=POSITION_RANGE_M)
    if end <= start:
        raise fields.fail("course.end_m", f"{end:g} must lie beyond start_m {start:g}")
    if end - start > MAX_COURSE_M:
        raise fields.fail("course.end_m", f"{end:g} is {end - start:g} m beyond start_m {start:g}; a course may be at "
                                          f"most {MAX_COURSE_M:g} m long")
    return Course(str(path), terrain, start, end, margin, optional.get("clearance_m"), optional.get("max_step_m"),
                  optional.get("max_rise_m"), weights)
