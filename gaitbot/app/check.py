"""``gaitbot check``: a trajectory or a recording against a robot's limits (exit 0 ok, 1 broken, 2 unreadable).

``run_check(args)`` reads ``args.file``, ``args.robot``, ``args.json``, ``args.margin_deg`` and,
when the command line offers it, ``args.allow_partial`` (check a recording whose last line was cut
short by a crash, with a warning, instead of refusing it). Unreadable input raises one of
``gaitbot.errors.USER_ERRORS`` (one line, exit 2); ``tools/check_trajectory.py`` calls the same.

What is a recording: a ``.jsonl`` file, or any other file (not ``.csv``/``.npz``) whose first
character is ``{``. A trajectory: ``.csv`` or ``.npz`` as written by ``gaitbot generate``. A
``.csv`` whose last line has no newline is taken as truncated (exit 2): ``generate`` always ends
its files with one, and a row cut inside its last number would still parse.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np

from gaitbot.check import check_trajectory, trajectory_angles_deg
from gaitbot.check_recording import check_recording, robot_for_recording
from gaitbot.gait.trajectory import CSV_COLUMNS, Trajectory, TrajectoryFileError
from gaitbot.session import UsageError, load_robot


def run_check(args) -> int:
    margin = args.margin_deg if args.margin_deg is not None else 0.0
    if not (math.isfinite(margin) and margin >= 0):
        raise UsageError(f"--margin-deg must be a finite number of degrees >= 0, got {margin!r}")
    path = Path(args.file)
    if is_recording(path):
        return _check_recording(args, path, margin)
    return _check_trajectory_file(args, path, margin)


def is_recording(path: Path) -> bool:
    """A bus recording (JSON Lines) rather than a trajectory file."""
    if path.suffix == ".jsonl":
        return True
    if path.suffix in (".csv", ".npz") or not path.is_file():
        return False
    try:
        with open(path, "rb") as f:
            return f.read(64).lstrip()[:1] == b"{"
    except OSError:
        return False


def _check_trajectory_file(args, path: Path, margin: float) -> int:
    config = load_robot(args.robot)
    if path.suffix == ".csv" and path.is_file():
        _refuse_truncated_csv(path)
    trajectory = _load_trajectory(path)
    report = check_trajectory(config, trajectory.t_s, trajectory_angles_deg(config, trajectory.angles_rad), margin)
    if args.json:
        print(json.dumps({"kind": "trajectory", "file": str(path), **report.to_dict()}, indent=2))
    else:
        print(f"{path}: trajectory checked against {config.name}")
        print(report.format_text())
    return 0 if report.ok else 1


def _load_trajectory(path: Path) -> Trajectory:
    """Trajectory.load, with a fast path for plain CSV files as ``generate`` writes them (numpy's C
    reader: a one-hour file in a fraction of a second instead of over one). Anything the fast path
    does not take as it is -- another header, a bad cell, a non-finite or non-increasing time -- goes
    to Trajectory.load, whose one-line errors name the problem."""
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


def _refuse_truncated_csv(path: Path) -> None:
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


def _check_recording(args, path: Path, margin: float) -> int:
    config = robot_for_recording(path, args.robot, load_robot)
    report = check_recording(config, path, margin, allow_partial_last_line=bool(getattr(args, "allow_partial", False)))
    if args.json:
        print(json.dumps({**report.to_dict(), "config": str(config.path)}, indent=2))
    else:
        print(report.format_text())
    return 0 if report.ok else 1
