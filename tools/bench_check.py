#!/usr/bin/env python3
"""Benchmark of ``gaitbot check``: a one-hour 60 Hz trajectory, and a dry-run recording.

Prints figures (best of a few runs), no pass/fail: the README quotes them with the machine.
The hour is a real ``generate`` walk (1 m, starting and ending standing) repeated end to end, so
it is continuous and as busy as walking; it is checked three ways: ``check_trajectory`` on
arrays, and the whole ``gaitbot check`` path (file load + check + report) from .npz and from .csv.

    python tools/bench_check.py [--robot xl430-biped] [--repeat 3]
"""

from __future__ import annotations

import argparse
import contextlib
import io
import platform
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

import numpy as np  # noqa: E402


def best_of(repeat: int, fn) -> float:
    best = float("inf")
    for _ in range(repeat):
        start = time.perf_counter()
        fn()
        best = min(best, time.perf_counter() - start)
    return best


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--robot", default="xl430-biped")
    parser.add_argument("--repeat", type=int, default=3)
    args = parser.parse_args(argv)

    from gaitbot.check.trajectory import check_trajectory, trajectory_angles_deg
    from gaitbot.check.recording import check_recording
    from gaitbot.app.cli import main as gaitbot
    from gaitbot.gait.trajectory import Trajectory
    from gaitbot.app.options import load_robot

    config = load_robot(args.robot)
    quiet = contextlib.redirect_stdout(io.StringIO())
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        with quiet:
            gaitbot(["generate", "--distance", "1", "--robot", args.robot, "-o", str(tmp / "walk.npz")])
            gaitbot(["walk", "--dry-run", "--distance", "1", "--robot", args.robot, "--record", str(tmp / "run.jsonl")])
        walk = Trajectory.load(tmp / "walk.npz")
        rate = 60.0
        n_hour = int(3600 * rate) + 1
        reps = -(-n_hour // (len(walk) - 1))
        angles = np.concatenate([walk.angles_rad[:-1]] * reps + [walk.angles_rad[-1:]])[:n_hour]
        t = np.arange(n_hour) / rate
        hour = Trajectory(t, angles, np.zeros((n_hour, 2)))
        hour.save(tmp / "hour.npz")
        hour.save(tmp / "hour.csv")
        degrees = trajectory_angles_deg(config, hour.angles_rad)

        report = check_trajectory(config, t, degrees)
        assert report.ok, report.first_error
        arrays_s = best_of(args.repeat, lambda: check_trajectory(config, t, degrees))

        def cli(path):
            with contextlib.redirect_stdout(io.StringIO()):
                code = gaitbot(["check", str(path), "--robot", args.robot])
            assert code == 0, f"check {path} exited {code}"

        npz_s = best_of(args.repeat, lambda: cli(tmp / "hour.npz"))
        csv_s = best_of(args.repeat, lambda: cli(tmp / "hour.csv"))
        rec = check_recording(config, tmp / "run.jsonl")
        rec_s = best_of(args.repeat, lambda: check_recording(config, tmp / "run.jsonl"))

    print(f"bench_check on {platform.processor() or platform.machine()}, Python {platform.python_version()}, "
          f"numpy {np.__version__}, robot {args.robot}, best of {args.repeat}")
    print(f"  one hour at 60 Hz ({n_hour} frames x {len(config.joints)} joints):")
    print(f"    check_trajectory on arrays        {arrays_s * 1000:8.1f} ms")
    print(f"    gaitbot check hour.npz (load+check) {npz_s * 1000:6.1f} ms")
    print(f"    gaitbot check hour.csv (load+check) {csv_s * 1000:6.1f} ms")
    print(f"  dry-run recording ({rec.n_packets} packets, {rec.n_goal_frames} goal frames, "
          f"{rec.n_goal_frames / rate:.1f} s of walk): check_recording {rec_s * 1000:.1f} ms "
          f"({rec_s / (rec.n_goal_frames / rate) * 3600:.2f} s per recorded hour)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
