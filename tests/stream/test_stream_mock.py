"""walk_session on the real bus classes and packet code, over the bus room's DryRunPort.

The stream tests with a fake bus check the logic; these check it with the bytes a real run
sends: the emulated servos end where the session says it left them, and a recording made
during an interrupted walk is flushed and strictly readable.
"""

from __future__ import annotations

import numpy as np
import pytest

pytest.importorskip("dynamixel_sdk")

from gaitbot.bus.factory import make_bus  # noqa: E402
from gaitbot.bus.recording import BusRecorder, decode_goal_frames  # noqa: E402
from gaitbot.stream.clock import VirtualClock  # noqa: E402
from gaitbot.servos.models import servo_model  # noqa: E402
from gaitbot.stream import walk_session  # noqa: E402

PERIOD_S = 1 / 60
IDS = [1, 2, 3, 4]
STAND = np.array([2200, 1900, 2048, 2100])  # away from the mock's initial centre tick (2048)
VMAX, AMAX = 2000.0, 30_000.0


def walk_frames(count: int = 90) -> np.ndarray:
    phase = 2 * np.pi * np.arange(count) / count
    return np.rint(STAND + np.array([100, -60, 80, -40]) * (1 - np.cos(phase))[:, None] / 2).astype(np.int64)


def mock_bus(tmp_path, recorder=None):
    models = {i: servo_model("XL430-W250") for i in IDS}
    return make_bus("dynamixel", 2.0, "mock", 1_000_000, models, interface="dry-run", recorder=recorder)


def test_completed_walk_on_the_mock_bus_leaves_servos_standing(tmp_path):
    bus = mock_bus(tmp_path)
    result = walk_session(bus, IDS, walk_frames(), STAND, max_velocity_ticks_per_s=VMAX,
                          max_accel_ticks_per_s2=AMAX, period_s=PERIOD_S, clock=VirtualClock())
    assert result.outcome == "completed", result.message()
    assert [bus.port.present_ticks(i) for i in IDS] == STAND.tolist()


def test_ctrl_c_on_the_mock_bus_leaves_a_readable_recording_ending_at_stand(tmp_path):
    path = tmp_path / "run.jsonl"
    recorder = BusRecorder(path, robot="test", joints={f"j{i}": i for i in IDS})
    bus = mock_bus(tmp_path, recorder=recorder)
    walk = walk_frames()

    def status_line(k, stats):
        if k == 40:
            raise KeyboardInterrupt  # as if Ctrl-C arrived while the CLI printed its status line

    result = walk_session(bus, IDS, walk, STAND, max_velocity_ticks_per_s=VMAX,
                          max_accel_ticks_per_s2=AMAX, period_s=PERIOD_S, clock=VirtualClock(),
                          on_frame=status_line, torque_off_on_exit=True)
    assert result.outcome == "interrupted" and result.exit_code == 130
    assert result.walk_stats.frames == 41
    _header, _t_s, ticks = decode_goal_frames(path)  # strict: no truncated line allowed
    np.testing.assert_array_equal(ticks[-1], STAND)
    # the walk's first 41 frames are in the recording, in order, before the stop ramp
    rows = ticks.astype(np.int64)
    starts = [i for i in range(len(rows) - 40) if (rows[i:i + 41] == walk[:41]).all()]
    assert len(starts) == 1
    stop = rows[starts[0] + 41:]
    assert len(stop) > 1 and not (stop == walk[41]).all(axis=1).any()
    assert [bus.port.present_ticks(i) for i in IDS] == STAND.tolist()
