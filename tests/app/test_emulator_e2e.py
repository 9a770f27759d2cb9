"""``gaitbot walk --port <pty>`` end to end against tools/servo_emulator.py: no hardware, real time.

The real SDK PortHandler opens the emulator's pty, so these runs exercise the very code a walk on
a robot runs. Expected goals come from the dry-run recording of the same plan
(``gaitbot walk --dry-run --record`` + decode_goal_frames), never from the emulator.

Cost: one 4.6 s walk per protocol (a single 0.03 m step: start ramp, crouch, step, close, final ramp;
each protocol its own test, so they spread over the workers; before, four 0.3 m walks in one 50 s module
fixture) and one such walk per fault, which stops within about a second of the fault.
"""

from __future__ import annotations

import re
import time
from pathlib import Path

import numpy as np
import pytest

from gaitbot.bus.recording import decode_goal_frames
from gaitbot.robot.config import load_robot_config

import gaitbot.emulator as se  # noqa: E402 - the emulator, imported as a module
from helpers import REPO_ROOT, emulator_for, gaitbot, grid_limit_errors, slow_except

ROOT = REPO_ROOT
CONFIGS = {"dxl2": ROOT / "config" / "xl430-biped.toml", "dxl1": ROOT / "config" / "ax12a-biped.toml",
           "feetech-sts": ROOT / "config" / "sts3215-biped.toml"}
#: Stated stop bound: from the first frame the fault touches to the last packet the driver sends.
#: Detection (4 reads of at most ~34 ms reply timeout + 40 ms late-reply watch) plus the stop ramp
#: (under 1 s for the shipped configs) plus torque-off.
STOP_BOUND_S = 2.0
SHORT = ["--steps", "0.03"]  # 4.6 s if nothing goes wrong (276 goal frames); faults end it much sooner


def scs_config(tmp_path: Path) -> Path:
    """The STS biped with SCS0009 servos (Feetech, high byte first, no sync read): no shipped config has one."""
    text = (ROOT / "config" / "sts3215-biped.toml").read_text()
    text = text.replace('name = "sts3215-biped"', 'name = "scs0009-biped"').replace('"STS3215"', '"SCS0009"')
    text = text.replace("zero_tick = 2048", "zero_tick = 512")
    text = re.sub(r"(?m)^\[servo\]\nfull_torque_error_deg = .*\n", "", text)  # no known gain register on an SCS0009
    path = tmp_path / "scs0009-biped.toml"
    path.write_text(text)
    return path


def walk_through_emulator(config_path: Path, workdir: Path, walk_args: list[str], faults=None, imu=None):
    """(process, emulator goal ticks, driver recording path, seconds) of one walk on the emulator's pty."""
    workdir.mkdir(parents=True, exist_ok=True)
    emu_log, record = workdir / "emulator-goals.jsonl", workdir / "walk.jsonl"
    with emulator_for(config_path, emu_log, faults, imu=imu) as emulator:
        start = time.monotonic()
        proc = gaitbot("walk", "--robot", str(config_path), *walk_args, "--port", emulator.path,
                       "--record", str(record))
        elapsed = time.monotonic() - start
    _, _, emulator_ticks = decode_goal_frames(emu_log)
    return proc, emulator_ticks, record, elapsed


def dry_run_ticks(config_path: Path, workdir: Path, walk_args: list[str]) -> np.ndarray:
    record = workdir / "dry.jsonl"
    proc = gaitbot("walk", "--robot", str(config_path), *walk_args, "--dry-run", "--record", str(record))
    assert proc.returncode == 0, proc.stderr
    return decode_goal_frames(record)[2]


# --------------------------------------------------------------------------- full walks

@pytest.mark.parametrize("protocol", slow_except(["dxl1", "dxl2", "feetech-sts", "feetech-scs"], "dxl2"))
def test_walk_through_the_emulator_sends_exactly_the_dry_run_goals(tmp_path, protocol):
    """One short walk per protocol (each shipped config, plus an SCS0009 biped), each its own test so that
    they spread over the workers. Every goal frame of the walk (the start ramp, the steps, the final ramp)
    goes through the SDK and the pty; a longer walk would only repeat the same packets."""
    configs = dict(CONFIGS, **{"feetech-scs": scs_config(tmp_path)})
    # the goals, not the timing, are under test here: a generous reply timeout keeps a busy CI host's
    # scheduling stalls from being taken for a servo answering late (faults are tested below)
    proc, emulator_ticks, record, _elapsed = walk_through_emulator(configs[protocol], tmp_path / "walk", SHORT
                                                                   + ["--reply-timeout-ms", "250"])
    dry_ticks = dry_run_ticks(configs[protocol], tmp_path, SHORT)
    assert proc.returncode == 0, proc.stdout + proc.stderr
    assert "Walk completed" in proc.stdout
    assert emulator_ticks.shape == dry_ticks.shape and emulator_ticks.shape[0] > 250
    np.testing.assert_array_equal(emulator_ticks, dry_ticks)
    np.testing.assert_array_equal(decode_goal_frames(record)[2], dry_ticks)  # the driver's own recording


# --------------------------------------------------------------------------- faults

FAULT_FRAME = 30


def check_failed_walk(proc, record: Path, emulator_ticks: np.ndarray, elapsed: float, *words: str):
    """Exit 1, a message naming the servo and the fault, a strictly readable recording holding every
    frame the servos received, and a bounded stop."""
    out = proc.stdout + proc.stderr
    assert proc.returncode == 1, out
    assert "Traceback" not in out
    for word in words:
        assert word in out, out
    _header, t_s, ticks = decode_goal_frames(record)  # strict: no truncated line
    received = len(emulator_ticks)
    np.testing.assert_array_equal(ticks[:received], emulator_ticks)
    return t_s


def test_a_servo_that_never_answers_stops_before_anything_moves(tmp_path):
    faults = se.Faults(silent={3})
    proc, emulator_ticks, record, elapsed = walk_through_emulator(CONFIGS["dxl2"], tmp_path, SHORT, faults)
    check_failed_walk(proc, record, emulator_ticks, elapsed, "servo 3 did not answer a ping")
    assert len(emulator_ticks) == 0  # no goal was sent
    assert elapsed < 10


@pytest.mark.parametrize("fault, words", [
    (se.Faults(silent={3}, after_frames=FAULT_FRAME), ("servo 3", "did not answer", "read-backs in a row")),
    pytest.param(se.Faults(late_s={3: 0.06}, after_frames=FAULT_FRAME), ("servo 3", "answers late", "ms after the request"),
                 marks=pytest.mark.slow),
    pytest.param(se.Faults(corrupt_fraction=1.0, corrupt_ids={3}, after_frames=FAULT_FRAME),
                 ("servo 3", "damaged status packet"), marks=pytest.mark.slow),
], ids=["silent", "late", "corrupt"])
def test_servo_fault_mid_walk_stops_within_the_bound_at_stand(tmp_path, fault, words):
    proc, emulator_ticks, record, elapsed = walk_through_emulator(CONFIGS["dxl2"], tmp_path, SHORT, fault)
    t_s = check_failed_walk(proc, record, emulator_ticks, elapsed, *words, "ramped to the stand pose")
    stop_s = t_s[-1] - t_s[FAULT_FRAME - 1]
    assert stop_s < STOP_BOUND_S
    assert len(emulator_ticks) < 200  # stopped long before the 276-frame walk would have ended


@pytest.mark.parametrize("protocol, kind, words", slow_except([
    ("dxl2", "overload", "reports overload"),
    ("dxl1", "overheating", "reports overheating"),
    ("feetech-sts", "voltage", "reports input voltage"),
], "dxl2"))
def test_status_error_bits_stop_the_walk_naming_servo_and_fault(tmp_path, protocol, kind, words):
    servo = load_robot_config(CONFIGS[protocol]).joints[1].id
    faults = se.Faults(errors={servo: {kind}}, after_frames=FAULT_FRAME)
    proc, emulator_ticks, record, elapsed = walk_through_emulator(CONFIGS[protocol], tmp_path, SHORT, faults)
    t_s = check_failed_walk(proc, record, emulator_ticks, elapsed, f"servo {servo}", words)
    assert t_s[-1] - t_s[FAULT_FRAME - 1] < STOP_BOUND_S


def test_a_port_that_disappears_mid_walk_ends_at_once_with_a_complete_recording(tmp_path):
    faults = se.Faults(close_after_frames=FAULT_FRAME + 10)
    proc, emulator_ticks, record, elapsed = walk_through_emulator(CONFIGS["feetech-sts"], tmp_path, SHORT, faults)
    t_s = check_failed_walk(proc, record, emulator_ticks, elapsed, "serial port", "failed",
                            "the servos hold their last goal")
    assert len(emulator_ticks) == FAULT_FRAME + 10
    assert t_s[-1] - t_s[FAULT_FRAME + 9] < 0.5


@pytest.mark.slow
def test_rare_damaged_replies_are_retried_and_the_walk_completes(tmp_path):
    faults = se.Faults(corrupt_fraction=0.05)
    proc, emulator_ticks, _record, _elapsed = walk_through_emulator(CONFIGS["dxl1"], tmp_path, SHORT, faults)
    assert proc.returncode == 0, proc.stdout + proc.stderr
    np.testing.assert_array_equal(emulator_ticks, dry_run_ticks(CONFIGS["dxl1"], tmp_path, SHORT))


@pytest.mark.slow
def test_extra_latency_within_the_timeout_is_tolerated(tmp_path):
    """4 ms late on two servos, well inside the timeout. The timeout is 250 ms here (as for the full walks
    above), not the SDK's 34 ms: on a busy 2-core host a scheduling stall of 30 ms on top of the 4 ms was
    taken, rightly, for a late reply; the tolerance of latency inside the timeout is what is tested."""
    faults = se.Faults(late_s={2: 0.004, 5: 0.004})
    proc, emulator_ticks, _record, _elapsed = walk_through_emulator(CONFIGS["feetech-sts"], tmp_path,
                                                                    SHORT + ["--reply-timeout-ms", "250"], faults)
    assert proc.returncode == 0, proc.stdout + proc.stderr
    np.testing.assert_array_equal(emulator_ticks, dry_run_ticks(CONFIGS["feetech-sts"], tmp_path, SHORT))


def test_a_robot_dropped_mid_walk_is_noticed_by_its_imu_and_stops_with_exit_1(tmp_path):
    """The OpenCR on the line reads 0 g from 2 s after the first packet (the emulator's --imu-drop-at-s): the
    walk notices the feet's load lost within a few frames, says it fell down, exits 1, and its recording
    (the goals up to the drop and the fall stop) keeps every joint limit."""
    from gaitbot.bus.imu_device import ImuDevice

    op3 = ROOT / "config" / "op3.toml"
    proc, _, record, _ = walk_through_emulator(op3, tmp_path, SHORT, imu=ImuDevice(drop_at_s=2.0))
    assert proc.returncode == 1, proc.stderr
    fell = re.search(r"The robot fell down at ([0-9.]+) s \(the feet's load lost: the accelerometer under 0.2 g for "
                     r"50 ms", proc.stdout)
    assert fell, proc.stdout
    # the session's clock starts a little after the line's first packet (the scan): the drop at 2 s on the
    # device's clock, noticed at its third 0 g reading, is said within half a second of 2 s either way
    assert 1.5 < float(fell.group(1)) < 2.5
    # every goal sent, the fall stop's included, within the joints' limits on the session's frame grid (gaitbot
    # check times them by their send times, which a busy test machine jitters: tests/app/test_faults_emulator.py)
    assert grid_limit_errors(load_robot_config(op3), decode_goal_frames(record)[2], 0) == []
