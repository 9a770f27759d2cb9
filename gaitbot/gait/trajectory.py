"""The Trajectory type: joint angles and the root in 3D over time, and its CSV/NPZ files.

Every later room reads trajectories, so the file contract is fixed here (docs/file-formats.md):
format 2 is a CSV whose first line is ``# gaitbot trajectory 2``, then a header
``t_s, <joint>_deg for each moving joint, root_x_m, root_y_m, root_z_m[, torso_roll_deg,
torso_pitch_deg, torso_yaw_deg]``; format 1 (the six pitch joints, ``root_y_m`` the height) still
loads. Angles are degrees in files and radians in memory.
"""

from __future__ import annotations

import csv
import difflib
import io
import os
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from gaitbot.errors import UserError
from gaitbot.fields import read_user_file
from gaitbot.gait.file_origin import (CSV_PREFIX, MAX_LINE_CHARS, ORIGIN_ARRAYS, FileOrigin, OriginProblem,
                                      origin_from_csv_text, origin_from_npz)
from gaitbot.gait.joints import LEG_JOINTS, PITCH_JOINTS, canonical, is_leg_joint
from gaitbot.gait.npz_file import NpzProblem, numeric, read_npz

FORMAT_VERSION = 2
VERSION_LINE = f"# gaitbot trajectory {FORMAT_VERSION}"
ROOT_COLUMNS = ("root_x_m", "root_y_m", "root_z_m")
TORSO_COLUMNS = ("torso_roll_deg", "torso_pitch_deg", "torso_yaw_deg")
V1_COLUMNS = ("t_s",) + tuple(f"{name}_deg" for name in PITCH_JOINTS) + ("root_x_m", "root_y_m")
"""Format 1 (before 3D): the six pitch joints and the root in the sagittal plane, root_y_m its height."""


class TrajectoryFileError(UserError, ValueError):
    """A trajectory file cannot be read; the message names the file and what is wrong."""


@dataclass(frozen=True)
class HeelStrike:
    """One heel strike: when, which leg, and where the heel touched the ground (world x, metres), with
    the sole centre's lateral position y_m (metres, left positive) where the walk is 3D (None: planar)."""

    t_s: float
    leg: str  # "left" or "right"
    x_m: float
    y_m: float | None = None


@dataclass(frozen=True)
class Trajectory:
    """Sampled walking motion.

    t_s: (N,) sample times in seconds, increasing.
    angles_rad: (N, J) joint angles in radians, one column per name in ``joints`` (canonical order,
        gaitbot.gait.joints), signs as documented there.
    root_m: (N, 3) the root (pelvis) in the world, ROS REP-103 axes: x forward, y left, z up; ground
        at z = 0. A sagittal walk has y = 0 and its root at the hip point.
    heel_strikes: the planned heel-strike events, in time order.
    joints: the joint names of the columns of angles_rad (default: the planar walker's six).
    torso_rpy_rad: (N, 3) torso roll, pitch, yaw (radians) where the gait moves them; None: upright.
    origin: the robot and terrain it was made for (gaitbot.gait.file_origin); None: not said.
    """

    t_s: np.ndarray
    angles_rad: np.ndarray
    root_m: np.ndarray
    heel_strikes: tuple[HeelStrike, ...] = field(default_factory=tuple)
    joints: tuple[str, ...] = PITCH_JOINTS
    torso_rpy_rad: np.ndarray | None = None
    origin: FileOrigin | None = None

    def __post_init__(self) -> None:
        n = len(self.t_s)
        if tuple(self.joints) != canonical(self.joints) or len(set(self.joints)) != len(self.joints):
            raise ValueError(f"joints must be distinct leg joints in canonical order, got {self.joints}")
        if self.angles_rad.shape != (n, len(self.joints)):
            raise ValueError(f"angles_rad must have shape ({n}, {len(self.joints)}), got {self.angles_rad.shape}")
        if self.root_m.shape != (n, 3):
            raise ValueError(f"root_m must have shape ({n}, 3), got {self.root_m.shape}")
        if self.torso_rpy_rad is not None and self.torso_rpy_rad.shape != (n, 3):
            raise ValueError(f"torso_rpy_rad must have shape ({n}, 3), got {self.torso_rpy_rad.shape}")

    @classmethod
    def sagittal(cls, t_s, angles_rad, root_xz_m, heel_strikes=()) -> "Trajectory":
        """A planar walk of the six pitch joints, its root given in the sagittal plane as (x, height)."""
        root_xz_m = np.asarray(root_xz_m, dtype=float)
        return cls(np.asarray(t_s, dtype=float), np.asarray(angles_rad, dtype=float), sagittal_to_world(root_xz_m),
                   tuple(heel_strikes))

    def __len__(self) -> int:
        return len(self.t_s)

    @property
    def angles_deg(self) -> np.ndarray:
        return np.degrees(self.angles_rad)

    @property
    def root_xz_m(self) -> np.ndarray:
        """The root in the sagittal plane, (N, 2): forward and height (what the planar gait code uses)."""
        return self.root_m[:, [0, 2]]

    def joint_deg(self, name: str) -> np.ndarray:
        """Angle of one joint over time, in degrees."""
        return np.degrees(self.angles_rad[:, self.joints.index(name)])

    def angles_of(self, names) -> np.ndarray:
        """(N, len(names)) angles in radians of the named joints; KeyError names one the file lacks."""
        missing = [n for n in names if n not in self.joints]
        if missing:
            raise KeyError(f"the trajectory has no {missing[0]} (it moves {', '.join(self.joints)})")
        return self.angles_rad[:, [self.joints.index(n) for n in names]]

    def columns(self) -> tuple[str, ...]:
        """The CSV header of this trajectory (format 2)."""
        torso = TORSO_COLUMNS if self.torso_rpy_rad is not None else ()
        return ("t_s",) + tuple(f"{name}_deg" for name in self.joints) + ROOT_COLUMNS + torso

    def table(self) -> np.ndarray:
        """One row per frame in the order of ``columns()``: seconds, degrees, metres."""
        parts = [self.t_s[:, None], self.angles_deg, self.root_m]
        if self.torso_rpy_rad is not None:
            parts.append(np.degrees(self.torso_rpy_rad))
        return np.column_stack(parts)

    def save(self, path: str | Path) -> None:
        """Write to ``.csv`` or ``.npz`` (chosen by the suffix), format 2."""
        path = Path(path)
        if path.suffix == ".npz":
            strikes = np.array([(h.t_s, 0 if h.leg == "left" else 1, h.x_m, np.nan if h.y_m is None else h.y_m)
                                for h in self.heel_strikes], dtype=float).reshape(-1, 4)
            extra = {} if self.torso_rpy_rad is None else {"torso_rpy_deg": np.degrees(self.torso_rpy_rad)}
            extra.update(self.origin.npz_arrays() if self.origin is not None else {})
            np.savez(path, format_version=np.array(FORMAT_VERSION), t_s=self.t_s, angles_deg=self.angles_deg,
                     root_m=self.root_m, heel_strikes=strikes, joints=np.array(self.joints), **extra)
        elif path.suffix == ".csv":
            with open(path, "w", newline="") as f:
                origin = "" if self.origin is None else self.origin.csv_suffix()
                f.write(VERSION_LINE + origin + "\n" + ",".join(self.columns()) + "\n")
                np.savetxt(f, self.table(), delimiter=",", fmt="%.9g")
        else:
            raise TrajectoryFileError(f"{path}: unknown trajectory format {path.suffix!r} (allowed: .csv, .npz)")

    @classmethod
    def load(cls, path: str | Path) -> "Trajectory":
        """Read a ``.csv`` or ``.npz`` trajectory (format 1 or 2); raise TrajectoryFileError with a one-line reason."""
        path = Path(path)
        if not path.exists():
            raise TrajectoryFileError(f"{path}: no such file")
        _refuse_too_large(path)
        if path.suffix == ".npz":
            return _load_npz(path)
        if path.suffix == ".csv":
            return _load_csv(path)
        raise TrajectoryFileError(f"{path}: unknown trajectory format {path.suffix!r} (allowed: .csv, .npz)")


def sagittal_to_world(root_xz_m: np.ndarray) -> np.ndarray:
    """(N, 2) sagittal-plane points (forward, up) -> (N, 3) world points (x, y = 0, z)."""
    return np.column_stack([root_xz_m[:, 0], np.zeros(len(root_xz_m)), root_xz_m[:, 1]])


#: The largest trajectory file (CSV or NPZ) gaitbot reads: what ``gaitbot check`` checks within a minute on
#: two cores, the 12 joints and the balance of op3 included (2.8 MB/s on a loaded 2-core machine: 46 s;
#: ``python tools/bench_check.py --robot op3``). Other files keep gaitbot.fields.MAX_FILE_BYTES.
MAX_TRAJECTORY_BYTES = 128 * 2**20

#: Values a trajectory file may hold (far beyond any walk; beyond them arithmetic on them overflows).
MAX_TIME_S = 1e7
MAX_ANGLE_DEG = 3600.0
MAX_ROOT_M = 1e4


class CsvTrajectoryWriter:
    """A trajectory CSV written row by row (``gaitbot record``), readable at every moment.

    The version line and header go out at once; every row is handed to the operating system as it is
    written (one ``write`` of the whole line, then ``flush``), so a process that stops for any reason,
    even SIGKILL, leaves a file holding every complete row; ``sync()`` (fsync) also makes it survive a
    power cut. Same columns and number format as ``Trajectory.save``.
    """

    def __init__(self, path: str | Path, joints: tuple[str, ...] = PITCH_JOINTS,
                 origin: FileOrigin | None = None) -> None:
        self.path = Path(path)
        self.joints = canonical(joints)
        self.rows = 0
        self._file = open(self.path, "w", newline="", encoding="utf-8")
        header = ("t_s",) + tuple(f"{name}_deg" for name in self.joints) + ROOT_COLUMNS
        origin_text = "" if origin is None else origin.csv_suffix()
        self._file.write(VERSION_LINE + origin_text + "\n" + ",".join(header) + "\n")
        self._file.flush()

    def write(self, t_s: float, angles_rad, root_m) -> None:
        """One frame: angles (radians) of ``joints``, the root (x, y, z metres)."""
        values = [float(t_s), *np.degrees(np.asarray(angles_rad, dtype=float)), *np.asarray(root_m, dtype=float)]
        self._file.write(",".join(f"{v + 0.0:.9g}" for v in values) + "\n")  # + 0.0: no "-0" in the file
        self._file.flush()
        self.rows += 1

    def sync(self) -> None:
        os.fsync(self._file.fileno())

    def close(self) -> None:
        if not self._file.closed:
            self._file.flush()
            self.sync()
            self._file.close()


def _from_table(path: Path, t: np.ndarray, angles_deg: np.ndarray, root: np.ndarray, strikes=(),
                joints: tuple[str, ...] = PITCH_JOINTS, torso_deg: np.ndarray | None = None,
                origin: FileOrigin | None = None) -> Trajectory:
    if len(t) < 2:
        raise TrajectoryFileError(f"{path}: needs at least 2 samples, found {len(t)}")
    named = (("t_s", t), ("joint angles", angles_deg), ("root", root), ("torso attitude", torso_deg))
    for name, values in named:
        if values is not None and not np.all(np.isfinite(values)):
            raise TrajectoryFileError(f"{path}: column {name} holds a value that is not a finite number")
    for name, values, bound, unit in (("t_s", t, MAX_TIME_S, "s"), ("joint angles", angles_deg, MAX_ANGLE_DEG, "deg"),
                                      ("root", root, MAX_ROOT_M, "m")):
        if np.any(np.abs(values) > bound):
            raise TrajectoryFileError(f"{path}: column {name} holds a value beyond +-{bound:g} {unit}")
    if np.any(np.diff(t) <= 0):
        i = int(np.argmax(np.diff(t) <= 0)) + 1
        raise TrajectoryFileError(f"{path}: t_s must increase, but row {i + 1} has t_s={t[i]!r} after {t[i - 1]!r}")
    order = [joints.index(name) for name in canonical(joints)]
    torso = None if torso_deg is None else np.radians(torso_deg.astype(float))
    return Trajectory(t.astype(float), np.radians(angles_deg[:, order].astype(float)), root.astype(float),
                      tuple(strikes), canonical(joints), torso, origin)


def _csv_layout(path: Path, version: int | None, header: list[str]) -> tuple[tuple[str, ...], bool, bool]:
    """From a CSV's version line and header: (joint names in file order, format-1 root, has torso)."""
    if version is None and "root_z_m" not in header:  # format 1: today's six joints, root_y_m the height
        missing = [c for c in V1_COLUMNS if c not in header]
        if missing:
            raise TrajectoryFileError(f"{path}: missing column {missing[0]!r} (format 1 holds {','.join(V1_COLUMNS)}; "
                                      f"format 2 starts with the line {VERSION_LINE!r})")
        return PITCH_JOINTS, True, False
    if version not in (None, FORMAT_VERSION):
        raise TrajectoryFileError(f"{path}: trajectory format {version} is not one this gaitbot reads (1 or 2)")
    for column in ("t_s",) + ROOT_COLUMNS:
        if column not in header:
            raise TrajectoryFileError(f"{path}: missing column {column!r} (format 2 holds t_s, <joint>_deg columns, "
                                      f"{', '.join(ROOT_COLUMNS)})")
    torso = [c for c in TORSO_COLUMNS if c in header]
    if torso and len(torso) != 3:
        missing = next(c for c in TORSO_COLUMNS if c not in header)
        raise TrajectoryFileError(f"{path}: missing column {missing!r} (the torso attitude needs all of "
                                  f"{', '.join(TORSO_COLUMNS)})")
    joints = []
    for column in header:
        if column.endswith("_deg") and column not in TORSO_COLUMNS:
            name = column[: -len("_deg")]
            if not is_leg_joint(name):
                close = difflib.get_close_matches(name, LEG_JOINTS, n=1)
                hint = f"did you mean {close[0]}_deg? " if close else ""
                raise TrajectoryFileError(f"{path}: column {column!r} is not a joint gaitbot knows ({hint}joints: "
                                          f"{', '.join(LEG_JOINTS)})")
            if name in joints:
                raise TrajectoryFileError(f"{path}: column {column!r} appears twice")
            joints.append(name)
    _require_pitch_joints(path, joints, lambda name: f"column '{name}_deg'")
    return tuple(joints), False, bool(torso)


def _require_pitch_joints(path: Path, joints, what) -> None:
    """Every walk moves both legs' hip, knee and ankle pitch: a file without one of them is not a walk."""
    for name in PITCH_JOINTS:
        if name not in joints:
            raise TrajectoryFileError(f"{path}: missing {what(name)} (a trajectory holds at least the pitch "
                                      f"joints {', '.join(PITCH_JOINTS)})")


def _read_version_line(path: Path, first: str) -> int | None:
    """The format version of a ``# gaitbot trajectory N`` line; None when the first line is the header."""
    if not first.startswith("#"):
        return None
    words = first.lstrip("#").split()
    if len(words) == 3 and words[:2] == ["gaitbot", "trajectory"] and words[2].isdigit() and len(words[2]) < 4:
        return int(words[2])
    raise TrajectoryFileError(f"{path}: the first line must be {VERSION_LINE!r} or the header, got {first[:60]!r}")


def _load_csv(path: Path) -> Trajectory:
    try:
        text = read_user_file(path).decode("utf-8")
    except UnicodeDecodeError as exc:
        raise TrajectoryFileError(f"{path}: cannot read (not UTF-8 text: {exc.reason} at byte {exc.start})") from None
    except OSError as exc:
        raise TrajectoryFileError(f"{path}: cannot read ({exc.strerror or exc})") from None
    version, origin, skipped = None, None, 0
    head, _, rest = text.partition("\n")
    if head.startswith("#"):
        head, origin = _split_origin(path, head)
        version, text, skipped = _read_version_line(path, head.strip()), rest, 1
    try:
        rows = list(csv.reader(io.StringIO(text)))
    except csv.Error as exc:  # a cell over the csv module's field limit, a NUL byte ...
        raise TrajectoryFileError(f"{path}: not a CSV table ({exc})") from None
    if not rows:
        raise TrajectoryFileError(f"{path}: empty file (expected a header row, e.g. {','.join(V1_COLUMNS)})")
    header = [h.strip() for h in rows[0]]
    joints, v1_root, torso = _csv_layout(path, version, header)
    root_columns = ("root_x_m", "root_y_m") if v1_root else ROOT_COLUMNS
    wanted = ("t_s",) + tuple(f"{n}_deg" for n in joints) + root_columns + (TORSO_COLUMNS if torso else ())
    index = [header.index(c) for c in wanted]
    data = []
    for line_no, row in enumerate(rows[1:], start=2 + skipped):
        if not row or all(not cell.strip() for cell in row):
            continue
        if len(row) != len(header):
            raise TrajectoryFileError(f"{path}: line {line_no} has {len(row)} fields, header has {len(header)} (truncated file?)")
        try:
            data.append([float(row[i]) for i in index])
        except ValueError:
            raise TrajectoryFileError(f"{path}: line {line_no} holds a value that is not a number") from None
    table = np.array(data, dtype=float).reshape(-1, len(wanted))
    j = len(joints)
    if v1_root:
        root = sagittal_to_world(table[:, 1 + j:3 + j])
    else:
        root = table[:, 1 + j:4 + j]
    torso_deg = table[:, 4 + j:7 + j] if torso else None
    return _from_table(path, table[:, 0], table[:, 1:1 + j], root, joints=joints, torso_deg=torso_deg, origin=origin)


def _split_origin(path: Path, line: str) -> tuple[str, FileOrigin | None]:
    """A version line, split into the version and the origin after it (`` origin: {...}``; None: none)."""
    at = line.find(CSV_PREFIX)
    if at < 0:
        return line, None
    try:
        return line[:at], origin_from_csv_text(line[at + len(CSV_PREFIX):].strip())
    except OriginProblem as exc:
        raise TrajectoryFileError(f"{path}: line 1, origin: {exc}") from None


def _load_npz(path: Path) -> Trajectory:
    try:
        arrays = read_npz(path)
        missing = [k for k in ("t_s", "angles_deg", "root_m") if k not in arrays]
        if missing:
            raise TrajectoryFileError(f"{path}: missing array {missing[0]!r} (needs t_s, angles_deg, root_m)")
        version = int(numeric(arrays, "format_version", 0)) if "format_version" in arrays else 1
        if version not in (1, FORMAT_VERSION):
            raise TrajectoryFileError(f"{path}: trajectory format {version} is not one this gaitbot reads (1 or 2)")
        names = _npz_joint_names(path, arrays, version)
        t = numeric(arrays, "t_s", 1)
        ang = numeric(arrays, "angles_deg", 2, columns=len(names))
        root = numeric(arrays, "root_m", 2, columns=2 if version == 1 else 3)
        torso = numeric(arrays, "torso_rpy_deg", 2, columns=3) if "torso_rpy_deg" in arrays else None
        width = 3 if version == 1 else 4
        raw = (numeric(arrays, "heel_strikes", 2, columns=width, finite=False) if "heel_strikes" in arrays
               else np.zeros((0, width)))
        origin = origin_from_npz(arrays)
    except OSError as exc:
        raise TrajectoryFileError(f"{path}: cannot read ({exc.strerror or exc})") from None
    except (NpzProblem, OriginProblem) as exc:
        raise TrajectoryFileError(f"{path}: {exc}") from None
    if ang.shape[0] != len(t) or root.shape[0] != len(t) or (torso is not None and torso.shape[0] != len(t)):
        raise TrajectoryFileError(f"{path}: arrays have inconsistent shapes t_s{t.shape} angles_deg{ang.shape} "
                                  f"root_m{root.shape}")
    if not np.all(np.isfinite(raw[:, :3])):
        raise TrajectoryFileError(f"{path}: array 'heel_strikes' holds a time, leg or x that is not a finite number")
    if len(raw) and not np.isin(raw[:, 1], (0.0, 1.0)).all():
        raise TrajectoryFileError(f"{path}: array 'heel_strikes': column 2 (the leg) must be 0 (left) or 1 (right)")
    if version == 1:
        root = sagittal_to_world(root)
    strikes = [HeelStrike(float(r[0]), "left" if int(r[1]) == 0 else "right", float(r[2]),
                          None if len(r) < 4 or not np.isfinite(r[3]) else float(r[3])) for r in raw]
    return _from_table(path, t, ang, root, strikes, names, torso, origin)


def _npz_joint_names(path: Path, arrays: dict, version: int) -> tuple[str, ...]:
    """The ``joints`` array: distinct leg joint names including the pitch joints (format 1: the six)."""
    if "joints" not in arrays:
        if version == 1:
            return PITCH_JOINTS
        raise TrajectoryFileError(f"{path}: missing array 'joints' (the names of the angles' columns)")
    raw = arrays["joints"]
    if raw.dtype.kind != "U" or raw.ndim != 1:
        raise TrajectoryFileError(f"{path}: array 'joints' must be a list of joint names, not {raw.dtype} {raw.shape}")
    names = tuple(str(n) for n in raw)
    unknown = [n for n in names if not is_leg_joint(n)]
    if unknown or len(set(names)) != len(names) or (version == 1 and names != PITCH_JOINTS):
        raise TrajectoryFileError(f"{path}: array 'joints' must name distinct leg joints, got {list(names)[:12]}")
    _require_pitch_joints(path, names, lambda name: f"joint {name}")
    return names


def load_fast(path: str | Path) -> Trajectory:
    """Trajectory.load, with a fast path for plain CSV files as ``generate`` writes them (numpy's C
    reader: a one-hour file in a fraction of a second instead of over one). The fast path's table goes
    through the same checks and bounds as Trajectory.load's (``_from_table``: finite, MAX_TIME_S,
    MAX_ANGLE_DEG, MAX_ROOT_M, increasing times), so ``check`` and ``walk`` refuse the same files the same
    way; anything it does not parse (another header, a bad cell) goes to Trajectory.load."""
    path = Path(path)
    _refuse_too_large(path)
    if path.suffix == ".csv" and path.is_file():
        try:
            with open(path, encoding="utf-8") as f:
                first, origin = _split_origin(path, f.readline(MAX_LINE_CHARS + 64))
                if first.strip() == VERSION_LINE:
                    header = f.readline().strip().split(",")
                    joints = tuple(c[:-4] for c in header[1:] if c.endswith("_deg") and c not in TORSO_COLUMNS)
                    if (all(is_leg_joint(n) for n in joints) and joints == canonical(joints)
                            and set(PITCH_JOINTS) <= set(joints)
                            and header == list(("t_s",) + tuple(f"{n}_deg" for n in joints) + ROOT_COLUMNS)):
                        table = np.loadtxt(f, delimiter=",", ndmin=2, dtype=float)
                        j = len(joints)
                        if table.shape[1] == len(header):  # the same checks and bounds as Trajectory.load
                            return _from_table(path, table[:, 0].copy(), table[:, 1:1 + j],
                                               table[:, 1 + j:4 + j].copy(), joints=joints, origin=origin)
        except TrajectoryFileError:
            raise
        except (OSError, UnicodeDecodeError, ValueError):
            pass
    return Trajectory.load(path)


def _refuse_too_large(path: Path) -> None:
    """A trajectory file over MAX_TRAJECTORY_BYTES is refused before it is read (one line, exit 2)."""
    try:
        size = path.stat().st_size if path.is_file() else 0
    except OSError:
        return  # the reader says what is wrong with it
    if size > MAX_TRAJECTORY_BYTES:
        raise TrajectoryFileError(f"{path}: {size / 2**20:.0f} MB, more than the {MAX_TRAJECTORY_BYTES // 2**20} MB a "
                                  f"trajectory file may have (what gaitbot check checks within a minute)")


def refuse_truncated_csv(path: str | Path) -> None:
    """A ``.csv`` whose last line has no newline is taken as truncated: ``generate`` always ends its files
    with one, and a row cut inside its last number would still parse."""
    path = Path(path)
    if not path.is_file():
        return  # Trajectory.load says what it is instead (missing, a directory, a FIFO, a device)
    try:
        with open(path, "rb") as f:
            f.seek(0, 2)
            if f.tell() == 0:
                return  # Trajectory.load names the empty file
            f.seek(-1, 2)
            last = f.read(1)
    except OSError as exc:
        raise TrajectoryFileError(f"{path}: cannot read ({exc})") from None
    if last not in (b"\n", b"\r"):
        raise TrajectoryFileError(f"{path}: truncated (the last line has no newline, so its last row may be cut "
                                  "short; if the file is complete, end it with a newline)")


def read_origin(path: str | Path) -> FileOrigin | None:
    """The robot and terrain a trajectory file says it was made for, read without reading its table (a
    command picks its robot before it plans); None when it says nothing or is no file (the reader says why)."""
    path = Path(path)
    try:
        if not path.is_file():
            return None
        if path.suffix == ".npz":
            return origin_from_npz(read_npz(path, only=ORIGIN_ARRAYS))
        with open(path, encoding="utf-8", errors="replace") as f:
            first, origin = _split_origin(path, f.readline(MAX_LINE_CHARS + 64))
    except OSError:
        return None
    except (NpzProblem, OriginProblem) as exc:
        raise TrajectoryFileError(f"{path}: {exc}") from None
    return origin if first.strip() == VERSION_LINE else None
