"""How fast ``gaitbot check`` reads and checks a trajectory CSV: the figure behind the file size limit.

    python tools/bench_check.py            # a 32 MB file (about 400,000 rows), timed, and the 256 MB limit
    python tools/bench_check.py --mb 256   # the largest file gaitbot reads (gaitbot.fields.MAX_FILE_BYTES)
    python tools/bench_check.py --mb 8 --robot op3   # a robot whose balance is checked too

Writes a valid walk-shaped CSV of the given size (the generate format: t_s, six joint angles, the root) in a
temporary folder, then runs ``gaitbot check`` on it in this process and prints the seconds, the rate in MB/s
and what that rate makes of the largest allowed file (it must be checked within a minute).
"""

from __future__ import annotations

import argparse
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from gaitbot.app.cli import main as gaitbot
from gaitbot.fields import MAX_FILE_BYTES
from gaitbot.gait.trajectory import VERSION_LINE


def write_csv(path: Path, megabytes: float) -> int:
    """A slow sway within every limit of the default robot, ``megabytes`` MB; returns its rows."""
    header = "t_s,hip_pitch_left_deg,knee_pitch_left_deg,ankle_pitch_left_deg,hip_pitch_right_deg," \
             "knee_pitch_right_deg,ankle_pitch_right_deg,root_x_m,root_y_m,root_z_m"
    rows, chunk = 0, 100_000
    with open(path, "w") as f:
        f.write(f"{VERSION_LINE}\n{header}\n")
        while f.tell() < megabytes * 2**20:
            k = np.arange(rows, rows + chunk)
            t = k / 60.0
            sway = 5.0 * np.sin(2 * np.pi * 0.2 * t)
            table = np.column_stack([t, 10 + sway, 20 + sway, 10 + sway, 10 - sway, 20 - sway, 10 - sway,
                                     0.001 * sway, 0 * t, 0.3 + 0 * t])
            np.savetxt(f, table, fmt="%.9g", delimiter=",")
            rows += chunk
    return rows


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--mb", type=float, default=32.0, help="file size in MB (default 32)")
    parser.add_argument("--robot", default="xl430-biped", help="the robot checked against (op3: its balance too)")
    args = parser.parse_args(argv)
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / "big.csv"
        rows = write_csv(path, args.mb)
        size_mb = path.stat().st_size / 2**20
        start = time.perf_counter()
        status = gaitbot(["check", str(path), "--robot", args.robot, "--json"])
        elapsed_s = time.perf_counter() - start
    rate = size_mb / elapsed_s
    limit_mb = MAX_FILE_BYTES / 2**20
    print(f"gaitbot check --robot {args.robot} of a {size_mb:.0f} MB CSV ({rows} rows): {elapsed_s:.1f} s, {rate:.1f} MB/s, exit {status}; "
          f"the largest allowed file ({limit_mb:.0f} MB) at this rate: {limit_mb / rate:.0f} s", file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
