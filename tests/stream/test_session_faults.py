"""The walk session under faults, on the real bus class and SDK over a mock chain, in virtual time
(issue 13 cases 1-3): the goal stream keeps its grid whatever the read-back does, the stop ramp
starts where the goals were, one period after the last walk frame, and holds every limit (judged by
``gaitbot check``'s own reader and checks on the recording), the right servo is named, and a
recording that cannot be written stops the walk with the normal ramp, blaming the recording.
"""

from __future__ import annotations

import errno

import numpy as np
import pytest

from gaitbot.bus.factory import guarded, make_bus
from gaitbot.bus.recording import BusRecorder, read_log
from gaitbot.bus.dry_run import DryRunPort
from gaitbot.check.recording import check_recording
from gaitbot.gait.walker import generate_walk
from gaitbot.robot.calibration import angles_to_ticks, standing_ticks
from gaitbot.robot.config import load_robot_config
from gaitbot.robot.walk_settings import joint_limits_ticks, leg_geometry, walk_settings
from gaitbot.servos import wire
from gaitbot.stream.clock import VirtualClock
from gaitbot.stream.readback import READ_BACK_SILENCE_S
from gaitbot.stream.session import walk_session
from helpers import CONFIG_DIR

FAULT_FRAME = 100


class FaultyChain(DryRunPort):
    """DryRunPort whose ``silent`` servos stop answering and whose ``damaged`` servos send bad checksums."""

    silent: set[int] = set()
    damaged: set[int] = set()

    def _reply(self, servo_id: int, params: bytes) -> None:
        if servo_id in self.silent:
            return
        if servo_id in self.damaged:
            before = len(self._rx_buffer)
            super()._reply(servo_id, params)
            self._rx_buffer[-1] ^= 0x5A
            assert len(self._rx_buffer) > before
            return
        super()._reply(servo_id, params)


def faulty_walk(tmp_path, robot: str, fault: str, victim: int, monkeypatch, recorder_fails_after: int | None = None):
    config = load_robot_config(CONFIG_DIR / f"{robot}.toml")
    walk = generate_walk(leg_geometry(config), [0.05] * 6, walk_settings(config))
    frames = angles_to_ticks(config, walk.angles_rad)
    clock = VirtualClock()
    path = tmp_path / "run.jsonl"
    recorder = BusRecorder(path, robot=config.name, joints={j.name: j.id for j in config.joints}, clock=clock.now,
                           rate_hz=config.gait.rate_hz)
    chains: list[FaultyChain] = []

    def chain(backend, protocol, models, port_name="mock", baudrate=None):
        port = FaultyChain(backend, protocol, models, port_name, baudrate=baudrate)
        port.silent, port.damaged = set(), set()
        chains.append(port)
        return port

    monkeypatch.setattr("gaitbot.bus.factory.DryRunPort", chain)
    bus = guarded(config, make_bus(config.bus.backend, config.bus.protocol, "mock", config.bus.baudrate,
                                   config.models_by_id, interface="dry-run", recorder=recorder))
    if recorder_fails_after is not None:
        fail_file_after(recorder, recorder_fails_after)

    def on_frame(k, _stats):
        if k == FAULT_FRAME and fault:
            getattr(chains[0], fault).add(victim)

    velocity, acceleration = joint_limits_ticks(config)
    result = walk_session(bus, config.ids, frames, standing_ticks(config), max_velocity_ticks_per_s=velocity,
                          max_accel_ticks_per_s2=acceleration, period_s=1 / config.gait.rate_hz, clock=clock,
                          on_frame=on_frame, handle_sigterm=False)
    recorder.close()
    return config, result, path, chains[0]


def goal_times(path) -> list[float]:
    log = read_log(path, allow_partial_last_line=True)
    framing = log.framing
    return [line.t_s for line in log.lines if line.direction == "tx" and line.data
            and wire.parse(line.data, framing, status=False).instruction == wire.INST_SYNC_WRITE]


@pytest.mark.parametrize("robot, fault, victim, words", [
    ("xl430-biped", "silent", 3, "did not answer"),
    ("sts3215-biped", "damaged", 3, "damaged status packet"),
    ("ax12a-biped", "silent", 13, "did not answer"),
])
def test_a_servo_fault_stops_on_the_grid_within_every_limit(tmp_path, monkeypatch, robot, fault, victim, words):
    config, result, path, _chain = faulty_walk(tmp_path, robot, fault, victim, monkeypatch)
    assert result.outcome == "bus_error" and result.exit_code == 1
    assert result.error.servo_id == victim
    message = result.message()
    assert f"servo {victim} " in message and words in message and "ramped to the stand pose" in message
    named = {int(x) for x in __import__("re").findall(r"servos? (\d+)", message)}
    assert named == {victim}
    # every goal frame, walk and stop ramp, exactly one period after the one before: no frame waited on a read
    gaps = np.diff(goal_times(path)) * config.gait.rate_hz
    assert gaps[1:] == pytest.approx(np.ones(len(gaps) - 1), abs=1e-4)  # times are logged to the microsecond
    # the stop came within the silence bound plus a round of the servos
    stopped_at = result.walk_stats.frames
    assert FAULT_FRAME < stopped_at <= FAULT_FRAME + len(config.ids) + READ_BACK_SILENCE_S * config.gait.rate_hz + 3
    report = check_recording(config, path)
    assert report.joints.ok, report.joints.first_error  # position, velocity, acceleration: stop ramp included
    assert report.timing.n_late == 0
    # the one kind of error left is the damaged status packets themselves
    assert all(issue.kind == "packet" and issue.message.startswith("rx") for issue in report.errors)
    assert result.reached_stand


def fail_file_after(recorder: BusRecorder, lines: int) -> None:
    """The recorder's file fills up after ``lines`` more lines (ENOSPC), as a full disk would."""
    real = recorder._file
    budget = [lines]

    class Full:
        def write(self, data):
            if budget[0] <= 0:
                raise OSError(errno.ENOSPC, "No space left on device")
            budget[0] -= 1
            return real.write(data)

        def close(self):
            real.close()

    recorder._file = Full()


def test_a_recording_that_cannot_be_written_stops_the_walk_with_the_normal_ramp(tmp_path, monkeypatch):
    config, result, path, chain = faulty_walk(tmp_path, "xl430-biped", "", 0, monkeypatch, recorder_fails_after=400)
    assert result.outcome == "bus_error" and result.exit_code == 1
    message = result.message()
    assert "recording failed" in message and "No space left on device" in message
    assert "port" not in message.replace("the serial port is fine", "")
    assert "ramped to the stand pose" in message and result.reached_stand
    # what was written is kept and readable; the servos got the whole stop ramp
    assert len(read_log(path).lines) == 400
    sent_goals = [p for p in chain.tx_packets if wire.parse(p, chain.framing, status=False).instruction
                  == wire.INST_SYNC_WRITE]
    recorded_goals = goal_times(path)
    assert len(sent_goals) > len(recorded_goals) + 5
    assert chain.present_ticks(1) == int(standing_ticks(config)[0])
