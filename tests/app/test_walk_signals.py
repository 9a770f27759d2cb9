"""A real ``gaitbot walk`` process stopped from outside: Ctrl-C (SIGINT), SIGTERM and SIGKILL.

Each waits for the recording to show frames (no fixed sleeps decide the outcome), then stops the
process. SIGINT/SIGTERM must end in a ramp to the standing pose with exit 130/143; SIGKILL gives
no chance to clean up, and the recording must still be readable up to the kill (flushed per packet).
"""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from gaitbot.bus.recording import decode_goal_frames, read_recording

STAND_TICKS = 2048  # xl430-biped: every joint's zero_tick, the standing pose


def start_walk(record: Path) -> subprocess.Popen:
    cmd = [sys.executable, "-m", "gaitbot.app.cli", "walk", "--dry-run", "--realtime", "--distance", "1.0",
           "--record", str(record)]
    return subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)


def wait_for_frames(record: Path, count: int, process: subprocess.Popen, timeout_s: float = 30.0) -> None:
    deadline = time.monotonic() + timeout_s
    while time.monotonic() < deadline:
        if record.exists() and record.read_text().count('"tx"') >= count:
            return
        assert process.poll() is None, process.communicate()
        time.sleep(0.05)
    raise AssertionError("the walk never started sending frames")


@pytest.mark.parametrize("sig, code", [(signal.SIGINT, 130), (signal.SIGTERM, 143)])
def test_signal_ends_standing_with_conventional_code(sig, code, tmp_path):
    record = tmp_path / "run.jsonl"
    process = start_walk(record)
    wait_for_frames(record, 120, process)  # well into the walk: the crouch is over
    process.send_signal(sig)
    out, err = process.communicate(timeout=60)
    assert process.returncode == code, (out, err)
    assert "Traceback" not in err
    _, _, ticks = decode_goal_frames(record)
    assert np.abs(ticks[-1] - STAND_TICKS).max() <= 1, "the last goal sent is the standing pose"


def test_sigkill_leaves_a_readable_recording(tmp_path):
    record = tmp_path / "run.jsonl"
    process = start_walk(record)
    wait_for_frames(record, 60, process)
    process.send_signal(signal.SIGKILL)
    process.communicate(timeout=30)
    header, packets = read_recording(record, allow_partial_last_line=True)
    assert header["format"] == "gaitbot-bus-log" and header["robot"] == "xl430-biped"
    assert sum(p.direction == "tx" for p in packets) >= 60
    lines = record.read_text().splitlines()
    for line in lines[:-1]:
        json.loads(line)  # every complete line is valid JSON


if os.name != "posix":  # pragma: no cover
    pytestmark = pytest.mark.skip("POSIX signals")
