"""Issue 26 item 10: ``check`` and ``walk`` read a trajectory file with one reader and one set of bounds: a time
of 1e8 s, an angle of 1e300 deg or a root 1e5 m away is the same one-line refusal, exit 2, from both."""

from __future__ import annotations

import numpy as np
import pytest

from gaitbot.gait.trajectory import MAX_ANGLE_DEG, MAX_ROOT_M, MAX_TIME_S
from helpers import gaitbot


@pytest.fixture(scope="module")
def walk_csv(tmp_path_factory):
    path = tmp_path_factory.mktemp("walk") / "w.csv"
    assert gaitbot("generate", "--steps", "0.05,0.05", "-o", str(path)).returncode == 0
    return path


@pytest.mark.parametrize("column, value, bound", [(0, "1e8", MAX_TIME_S),
                                                  pytest.param(2, "1e300", MAX_ANGLE_DEG, marks=pytest.mark.slow),
                                                  pytest.param(-3, "1e5", MAX_ROOT_M, marks=pytest.mark.slow)])
def test_check_and_walk_refuse_the_same_file_the_same_way(walk_csv, tmp_path, column, value, bound):
    assert float(value) > bound
    lines = walk_csv.read_text().splitlines()
    cells = lines[-1].split(",")
    cells[column] = value
    bad = tmp_path / "bad.csv"
    bad.write_text("\n".join(lines[:-1] + [",".join(cells)]) + "\n")
    checked = gaitbot("check", str(bad))
    walked = gaitbot("walk", "--dry-run", "--trajectory", str(bad))
    for proc in (checked, walked):
        assert proc.returncode == 2, proc.stderr + proc.stdout
        assert "Traceback" not in proc.stderr and len(proc.stderr.strip().splitlines()) == 1, proc.stderr
    reason = checked.stderr.strip().split(": ", 1)[1]  # after "gaitbot check"
    assert reason == walked.stderr.strip().split(": ", 1)[1], (checked.stderr, walked.stderr)
    assert f"{bound:g}" in reason


def test_a_trajectory_over_the_checkable_size_is_refused_before_it_is_read(tmp_path):
    """Issue 26 item 9: the limit is what check reads within a minute (tools/bench_check.py), not 256 MB."""
    from gaitbot.gait.trajectory import MAX_TRAJECTORY_BYTES

    big = tmp_path / "big.csv"
    with open(big, "wb") as f:
        f.seek(MAX_TRAJECTORY_BYTES)
        f.write(b"\n")  # sparse: no disk, and nothing of it is read
    for argv in (["check", str(big)], ["walk", "--dry-run", "--trajectory", str(big)]):
        proc = gaitbot(*argv)
        assert proc.returncode == 2 and "128 MB" in proc.stderr, proc.stderr
        assert len(proc.stderr.strip().splitlines()) == 1
