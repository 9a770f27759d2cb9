"""The Trajectory type: joint angles and root position over time, and its CSV/NPZ files.

Every later room reads trajectories, so the file contract is fixed here:
CSV with a header row ``t_s, <joint>_deg x 6, root_x_m, root_y_m``; angles are
flexion-positive degrees in files and radians in memory.
"""

from __future__ import annotations

import csv
import io
import os
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from gaitbot.errors import UserError
from gaitbot.fields import read_user_file
from gaitbot.gait.npz_file import NpzProblem, numeric, read_npz

WALKING_JOINTS = (
    "hip_pitch_left",
    "knee_pitch_left",
    "ankle_pitch_left",
    "hip_pitch_right",
    "knee_pitch_right",
    "ankle_pitch_right",
)
CSV_COLUMNS = ("t_s",) + tuple(f"{name}_deg" for name in WALKING_JOINTS) + ("root_x_m", "root_y_m")


class TrajectoryFileError(UserError, ValueError):
    """A trajectory file cannot be read; the message names the file and what is wrong."""


@dataclass(frozen=True)
class HeelStrike:
    """One heel strike: when, which leg, and where the heel touched the ground (world x, metres)."""

    t_s: float
    leg: str  # "left" or "right"
    x_m: float


@dataclass(frozen=True)
class Trajectory:
    """Sampled walking motion.

    t_s: (N,) sample times in seconds, increasing.
    angles_rad: (N, 6) joint angles in radians, columns in WALKING_JOINTS order, flexion positive.
    root_m: (N, 2) the hip point in the world (x forward, y up; ground at y = 0), metres.
    heel_strikes: the planned heel-strike events, in time order.
    """

    t_s: np.ndarray
    angles_rad: np.ndarray
    root_m: np.ndarray
    heel_strikes: tuple[HeelStrike, ...] = field(default_factory=tuple)

    def __post_init__(self) -> None:
        n = len(self.t_s)
        if self.angles_rad.shape != (n, len(WALKING_JOINTS)):
            raise ValueError(f"angles_rad must have shape ({n}, {len(WALKING_JOINTS)}), got {self.angles_rad.shape}")
        if self.root_m.shape != (n, 2):
            raise ValueError(f"root_m must have shape ({n}, 2), got {self.root_m.shape}")

    def __len__(self) -> int:
        return len(self.t_s)

    @property
    def angles_deg(self) -> np.ndarray:
        return np.degrees(self.angles_rad)

    def joint_deg(self, name: str) -> np.ndarray:
        """Angle of one walking joint over time, in degrees."""
        return np.degrees(self.angles_rad[:, WALKING_JOINTS.index(name)])

    def save(self, path: str | Path) -> None:
        """Write to ``.csv`` or ``.npz`` (chosen by the suffix)."""
        path = Path(path)
        if path.suffix == ".npz":
            strikes = np.array([(h.t_s, 0 if h.leg == "left" else 1, h.x_m) for h in self.heel_strikes]).reshape(-1, 3)
            np.savez(path, t_s=self.t_s, angles_deg=self.angles_deg, root_m=self.root_m,
                     heel_strikes=strikes, joints=np.array(WALKING_JOINTS))
        elif path.suffix == ".csv":
            table = np.column_stack([self.t_s, self.angles_deg, self.root_m])
            with open(path, "w", newline="") as f:
                f.write(",".join(CSV_COLUMNS) + "\n")
                np.savetxt(f, table, delimiter=",", fmt="%.9g")
        else:
            raise TrajectoryFileError(f"{path}: unknown trajectory format {path.suffix!r} (allowed: .csv, .npz)")

    @classmethod
    def load(cls, path: str | Path) -> "Trajectory":
        """Read a ``.csv`` or ``.npz`` trajectory; raise TrajectoryFileError with a one-line reason."""
        path = Path(path)
        if not path.exists():
            raise TrajectoryFileError(f"{path}: no such file")
        if path.suffix == ".npz":
            return _load_npz(path)
        if path.suffix == ".csv":
            return _load_csv(path)
        raise TrajectoryFileError(f"{path}: unknown trajectory format {path.suffix!r} (allowed: .csv, .npz)")


#: Values a trajectory file may hold (far beyond any walk; beyond them arithmetic on them overflows).
MAX_TIME_S = 1e7
MAX_ANGLE_DEG = 3600.0
MAX_ROOT_M = 1e4


class CsvTrajectoryWriter:
    """A trajectory CSV written row by row (``gaitbot record``), readable at every moment.

    The header goes out at once; every row is handed to the operating system as it is written
    (one ``write`` of the whole line, then ``flush``), so a process that stops for any reason,
    even SIGKILL, leaves a file holding every complete row; ``sync()`` (fsync) also makes it
    survive a power cut. Same columns and number format as ``Trajectory.save``.
    """

    def __init__(self, path: str | Path) -> None:
        self.path = Path(path)
        self.rows = 0
        self._file = open(self.path, "w", newline="", encoding="ascii")
        self._file.write(",".join(CSV_COLUMNS) + "\n")
        self._file.flush()

    def write(self, t_s: float, angles_rad, root_m) -> None:
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


def _from_table(path: Path, t: np.ndarray, angles_deg: np.ndarray, root: np.ndarray, strikes=()) -> Trajectory:
    if len(t) < 2:
        raise TrajectoryFileError(f"{path}: needs at least 2 samples, found {len(t)}")
    for name, values in (("t_s", t), ("joint angles", angles_deg), ("root", root)):
        if not np.all(np.isfinite(values)):
            raise TrajectoryFileError(f"{path}: column {name} holds a value that is not a finite number")
    for name, values, bound, unit in (("t_s", t, MAX_TIME_S, "s"), ("joint angles", angles_deg, MAX_ANGLE_DEG, "deg"),
                                      ("root", root, MAX_ROOT_M, "m")):
        if np.any(np.abs(values) > bound):
            raise TrajectoryFileError(f"{path}: column {name} holds a value beyond +-{bound:g} {unit}")
    if np.any(np.diff(t) <= 0):
        i = int(np.argmax(np.diff(t) <= 0)) + 1
        raise TrajectoryFileError(f"{path}: t_s must increase, but row {i + 1} has t_s={t[i]!r} after {t[i - 1]!r}")
    return Trajectory(t.astype(float), np.radians(angles_deg.astype(float)), root.astype(float), tuple(strikes))


def _load_csv(path: Path) -> Trajectory:
    try:
        text = read_user_file(path).decode("utf-8")
    except UnicodeDecodeError as exc:
        raise TrajectoryFileError(f"{path}: cannot read (not UTF-8 text: {exc.reason} at byte {exc.start})") from None
    except OSError as exc:
        raise TrajectoryFileError(f"{path}: cannot read ({exc.strerror or exc})") from None
    try:
        rows = list(csv.reader(io.StringIO(text)))
    except csv.Error as exc:  # a cell over the csv module's field limit, a NUL byte ...
        raise TrajectoryFileError(f"{path}: not a CSV table ({exc})") from None
    if not rows:
        raise TrajectoryFileError(f"{path}: empty file (expected a header row {','.join(CSV_COLUMNS)})")
    header = [h.strip() for h in rows[0]]
    missing = [c for c in CSV_COLUMNS if c not in header]
    if missing:
        raise TrajectoryFileError(f"{path}: missing column {missing[0]!r} (header must hold {','.join(CSV_COLUMNS)})")
    index = [header.index(c) for c in CSV_COLUMNS]
    data = []
    for line_no, row in enumerate(rows[1:], start=2):
        if not row or all(not cell.strip() for cell in row):
            continue
        if len(row) != len(header):
            raise TrajectoryFileError(f"{path}: line {line_no} has {len(row)} fields, header has {len(header)} (truncated file?)")
        try:
            data.append([float(row[i]) for i in index])
        except ValueError:
            raise TrajectoryFileError(f"{path}: line {line_no} holds a value that is not a number") from None
    table = np.array(data, dtype=float).reshape(-1, len(CSV_COLUMNS))
    return _from_table(path, table[:, 0], table[:, 1:7], table[:, 7:9])


def _load_npz(path: Path) -> Trajectory:
    try:
        arrays = read_npz(path)
        missing = [k for k in ("t_s", "angles_deg", "root_m") if k not in arrays]
        if missing:
            raise TrajectoryFileError(f"{path}: missing array {missing[0]!r} (needs t_s, angles_deg, root_m)")
        t = numeric(arrays, "t_s", 1)
        ang = numeric(arrays, "angles_deg", 2, columns=6)
        root = numeric(arrays, "root_m", 2, columns=2)
        raw = numeric(arrays, "heel_strikes", 2, columns=3) if "heel_strikes" in arrays else np.zeros((0, 3))
    except OSError as exc:
        raise TrajectoryFileError(f"{path}: cannot read ({exc.strerror or exc})") from None
    except NpzProblem as exc:
        raise TrajectoryFileError(f"{path}: {exc}") from None
    if ang.shape[0] != len(t) or root.shape[0] != len(t):
        raise TrajectoryFileError(f"{path}: arrays have inconsistent shapes t_s{t.shape} angles_deg{ang.shape} root_m{root.shape}")
    if len(raw) and not np.isin(raw[:, 1], (0.0, 1.0)).all():
        raise TrajectoryFileError(f"{path}: array 'heel_strikes': column 2 (the leg) must be 0 (left) or 1 (right)")
    strikes = [HeelStrike(float(a), "left" if int(b) == 0 else "right", float(c)) for a, b, c in raw]
    return _from_table(path, t, ang, root, strikes)


def load_fast(path: str | Path) -> Trajectory:
    """Trajectory.load, with a fast path for plain CSV files as ``generate`` writes them (numpy's C
    reader: a one-hour file in a fraction of a second instead of over one). Anything the fast path
    does not take as it is -- another header, a bad cell, a non-finite or non-increasing time -- goes
    to Trajectory.load, whose one-line errors name the problem."""
    path = Path(path)
    if path.suffix == ".csv" and path.is_file():
        try:
            with open(path, encoding="utf-8") as f:
                header = f.readline().strip()
                if header == ",".join(CSV_COLUMNS):
                    table = np.loadtxt(f, delimiter=",", ndmin=2, dtype=float)
                    if (table.shape[1] == len(CSV_COLUMNS) and len(table) >= 2 and np.all(np.isfinite(table))
                            and np.all(np.diff(table[:, 0]) > 0)):
                        return Trajectory(table[:, 0].copy(), np.radians(table[:, 1:7]), table[:, 7:9].copy())
        except (OSError, UnicodeDecodeError, ValueError):
            pass
    return Trajectory.load(path)


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
