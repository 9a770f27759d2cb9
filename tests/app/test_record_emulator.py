"""``gaitbot record`` against tools/servo_emulator.py with a scripted hand: the real SDK on a pty.

The hand plays walks made by the walker (several step lengths) on the emulated servos while their
torque is off, one sample per read cycle, so the recording must give back every sample to one tick
whatever the host's timing. The expected ticks are the script's, computed here from the walker's
angles; then ``gaitbot eigen fit`` must learn from the recorded files (heel strikes found from the
feet, labels from the root rebuilt by foot contact).

Runs one recording at a time with a generous reply timeout, as test_emulator_e2e.py does: a busy
2-core host must not be taken for a servo answering late.
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from gaitbot.bus.factory import make_bus
from gaitbot.app.cli import main
from gaitbot.stream.clock import VirtualClock
from gaitbot.gait import generate_walk
from gaitbot.gait.eigen import EigenGaitModel
from gaitbot.gait.trajectory import Trajectory
from gaitbot.stream.record import record_session
from gaitbot.app.record import TrajectorySink
from gaitbot.robot.calibration import angles_to_ticks
from gaitbot.robot.walk_settings import leg_geometry, walk_settings
from gaitbot.app.options import load_robot

import gaitbot.emulator as se  # noqa: E402 - the emulator, imported as a module
from helpers import REPO_ROOT, slow_except

ROOT = REPO_ROOT
REPLY_TIMEOUT_MS = 250
STEPS = (0.03, 0.06, 0.09)


def script(config, step: float, n_steps: int = 6):
    """A walker walk and the ticks a hand playing it puts on each servo (config joint order)."""
    walk = generate_walk(leg_geometry(config), [step] * n_steps, walk_settings(config))
    return walk, angles_to_ticks(config, walk.angles_rad)


def emulator(config, ticks, faults=None, hand_rate=None):
    hand = se.Hand({j.id: ticks[:, c].tolist() for c, j in enumerate(config.joints)}, hand_rate)
    return se.ServoEmulator(se.EmulatorConfig(config.bus.backend, config.bus.protocol, config.models_by_id,
                                              config.bus.baudrate, faults or se.Faults(), hand=hand))


def record_in_process(config, ticks, out: Path, extra: int = 5):
    """Record len(ticks) + extra samples through the SDK on the emulator's pty, on a virtual clock."""
    with emulator(config, ticks) as emu:
        bus = make_bus(config.bus.backend, config.bus.protocol, emu.path, config.bus.baudrate, config.models_by_id,
                       interface="serial", reply_timeout_ms=REPLY_TIMEOUT_MS)
        result = record_session(bus, config.ids, 1.0 / config.gait.rate_hz, TrajectorySink(config, out, print),
                                confirm=lambda n: True, n_samples=len(ticks) + extra, clock=VirtualClock())
    assert result.outcome == "completed", result.message()
    return Trajectory.load(out)


def recorded_ticks(config, trajectory) -> np.ndarray:
    return angles_to_ticks(config, trajectory.angles_rad)


@pytest.fixture(scope="session")
def recorded_walks(tmp_path_factory):
    """The XL430 biped: three walks recorded one after the other (once per worker: the real-time tests of
    several modules interleave on it, which would set up a module's fixture again)."""
    config = load_robot("xl430-biped")
    base = tmp_path_factory.mktemp("recorded")
    out = {}
    for step in STEPS:
        walk, ticks = script(config, step)
        path = base / f"rec_{step}.csv"
        out[step] = (walk, ticks, path, record_in_process(config, ticks, path))
    return config, out


@pytest.mark.slow
@pytest.mark.parametrize("step", STEPS)
def test_recording_gives_back_the_hand_motion_to_one_tick(recorded_walks, step):
    config, walks = recorded_walks
    walk, ticks, _, rec = walks[step]
    got = recorded_ticks(config, rec)
    assert len(got) == len(ticks) + 5
    assert np.abs(got[:len(ticks)] - ticks).max() <= 1
    assert np.abs(got[len(ticks):] - ticks[-1]).max() <= 1  # the hand stays at its last sample
    np.testing.assert_allclose(rec.t_s, np.arange(len(rec)) / config.gait.rate_hz, atol=1e-8)
    # the root rebuilt from foot contact travels as the walker's did (the same contact model; 1 tick of
    # XL430 is 0.088 deg, which moves a stance switch by a frame now and then: a few mm over the walk)
    travel = rec.root_m[len(ticks) - 1, 0] - rec.root_m[0, 0]
    walker_travel = walk.root_m[-1, 0] - walk.root_m[0, 0]
    assert abs(travel - walker_travel) < 0.02 * walker_travel + 0.003


@pytest.mark.slow
def test_recorded_walks_can_be_fitted(recorded_walks, tmp_path, capsys):
    config, walks = recorded_walks
    paths = [str(walks[s][2]) for s in STEPS]
    model_path = tmp_path / "recorded_model.npz"
    assert main(["eigen", "fit", *paths, "-o", str(model_path)]) == 0
    out = capsys.readouterr().out
    assert "eigen-motions kept" in out
    model = EigenGaitModel.load(model_path)
    labels = sorted(set(np.round(model.labels, 6)))
    assert len(labels) == 3 and len(model.labels) >= 6  # two steady cycles per six-step walk
    np.testing.assert_allclose(labels, STEPS, rtol=0.05)  # step lengths read back from the feet
    walk_csv = tmp_path / "synth.csv"
    assert main(["eigen", "synth", str(model_path), "--step-length", "0.05", "--cycles", "2", "-o", str(walk_csv)]) == 0
    assert main(["check", str(walk_csv), "--robot", "xl430-biped"]) == 0


@pytest.mark.parametrize("robot", slow_except(["ax12a-biped", "sts3215-biped"], "sts3215-biped"))
def test_other_protocols_read_the_hand_to_one_tick(tmp_path, robot):
    """Dynamixel 1.0 (one read per servo) and Feetech STS (its sync read): the hand cycle counts them alike."""
    config = load_robot(robot)
    _, ticks = script(config, 0.05, n_steps=2)
    ticks = ticks[:200]
    rec = record_in_process(config, ticks, tmp_path / "rec.csv")
    assert np.abs(recorded_ticks(config, rec)[:len(ticks)] - ticks).max() <= 1


# ---- the command line, in real time ------------------------------------------------------------

def start_record(config_name: str, port: str, out: Path, *extra: str) -> subprocess.Popen:
    return subprocess.Popen([sys.executable, "-m", "gaitbot.app.cli", "record", "--robot", config_name, "--port", port,
                             "--yes", "--reply-timeout-ms", str(REPLY_TIMEOUT_MS), "-o", str(out), *extra],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, cwd=ROOT,
                            stdin=subprocess.DEVNULL)


def wait_for_rows(path: Path, rows: int, process: subprocess.Popen, timeout_s: float = 30.0) -> None:
    deadline = time.monotonic() + timeout_s
    while time.monotonic() < deadline:
        if path.exists() and len(path.read_text().splitlines()) >= rows + 2:  # the version line and the header
            return
        if process.poll() is not None:
            raise AssertionError(f"recording ended early: {process.communicate()}")
        time.sleep(0.05)
    process.kill()
    raise AssertionError(f"no {rows} rows within {timeout_s} s")


@pytest.mark.slow
def test_cli_records_for_a_duration_in_real_time(tmp_path):
    config = load_robot("xl430-biped")
    _, ticks = script(config, 0.06, n_steps=2)
    out = tmp_path / "demo.csv"
    with emulator(config, ticks) as emu:
        proc = start_record("xl430-biped", emu.path, out, "--duration", "1.5")
        stdout, stderr = proc.communicate(timeout=60)
    assert proc.returncode == 0, stdout + stderr
    assert "90 samples" in stdout and "torque stays off" in stdout
    got = recorded_ticks(config, Trajectory.load(out))
    assert len(got) == 90 and np.abs(got - ticks[:90]).max() <= 1


@pytest.mark.parametrize("sig, code, words", [(signal.SIGTERM, 143, "terminated"),
                                               pytest.param(signal.SIGINT, 0, "stopped", marks=pytest.mark.slow)])
def test_a_signal_ends_the_recording_with_every_row_read(tmp_path, sig, code, words):
    config = load_robot("xl430-biped")
    _, ticks = script(config, 0.06)
    out = tmp_path / "demo.csv"
    with emulator(config, ticks) as emu:
        proc = start_record("xl430-biped", emu.path, out)
        wait_for_rows(out, 40, proc)
        os.kill(proc.pid, sig)
        stdout, stderr = proc.communicate(timeout=30)
    assert proc.returncode == code, stdout + stderr
    assert words in stdout.lower() and "Traceback" not in stderr
    got = recorded_ticks(config, Trajectory.load(out))  # strict reader: no partial row
    assert len(got) >= 40 and np.abs(got - ticks[:len(got)]).max() <= 1


@pytest.mark.slow
def test_a_port_that_disappears_ends_with_exit_1_and_a_readable_file(tmp_path):
    config = load_robot("xl430-biped")
    _, ticks = script(config, 0.06)
    out = tmp_path / "demo.csv"
    with emulator(config, ticks, faults=se.Faults(close_after_s=1.0)) as emu:
        proc = start_record("xl430-biped", emu.path, out)
        stdout, stderr = proc.communicate(timeout=60)
    assert proc.returncode == 1, stdout + stderr
    assert "bus error" in stdout and "serial port" in stdout
    got = recorded_ticks(config, Trajectory.load(out))
    assert len(got) >= 20 and np.abs(got - ticks[:len(got)]).max() <= 1
