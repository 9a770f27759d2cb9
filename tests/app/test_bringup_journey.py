"""The bring-up journey between its steps: the emulator keeps its servos across a restart and connects the whole
chain after the last, stands in for the person calibrating, the calibration lives in one place every command
finds, scan's search answers at a short reply timeout with progress, and a dry run with an off-centre or
reversed calibration starts where the robot stands. The whole journey (tools/bringup_journey.py) runs as a
person would take it: factory-fresh -> setup one at a time -> scan -> calibrate -> walk.

Expected values come from the inputs: the config's ids, the calibration file written here, the emulated
build's mounting (gaitbot.app.emulator_hand.mounting_zero_ticks, drawn from the seed), never from what the
command under test printed.
"""

from __future__ import annotations

import json
import math
import subprocess
import sys
from pathlib import Path

import pytest

import gaitbot.emulator as se
from gaitbot.app import emulator as emulator_cli
from gaitbot.app.emulator_hand import calibration_hand, mounting_zero_ticks
from gaitbot.bus import probe as probe_module
from gaitbot.bus.bringup import survey
from gaitbot.bus.factory import make_probe_bus, make_robot_bus
from gaitbot.emulator.state import read_state
from gaitbot.robot.calibration_file import calibration_path_for, load_robot_with_calibration, read_calibration
from gaitbot.servos import common_baud_rates, max_servo_id, wire
from gaitbot.stream.calibrate import CalibrationJoint, _judge
from helpers import REPO_ROOT, config, knee_calibration, run_cli



# --------------------------------------------------------------------------- the mock servos stand


@pytest.mark.parametrize("zero, direction", [(2298, 1), (1798, 1), (2048, -1), (2300, -1)])
def test_a_dry_run_with_an_off_centre_or_reversed_calibration_walks(zero, direction, tmp_path, capsys):
    path = tmp_path / "bot.calibration.toml"
    path.write_text(knee_calibration(zero, direction))
    code, out, err = run_cli(capsys, "walk", "--robot", "xl430-biped", "--calibration", path, "--dry-run",
                             "--steps", "0.03,0.03")
    assert code == 0 and "Walk completed" in out, out + err


def test_the_dry_run_servos_start_at_the_stand_pose_in_the_calibrations_ticks(tmp_path):
    path = tmp_path / "bot.calibration.toml"
    path.write_text(knee_calibration(2298, -1))
    robot = load_robot_with_calibration("xl430-biped", path)
    with make_robot_bus(robot, dry_run=True) as bus:
        present = bus.read_present_ticks(robot.ids)
    # every joint of this robot walks (no held joint), and 0 rad is its zero tick: the file's, else the config's
    expected = {j.id: (2298 if j.name == "knee_pitch_left" else j.zero_tick) for j in robot.joints}
    assert present == expected


# --------------------------------------------------------------------------- the emulator's state


def fresh_config(robot, state, one_at_a_time=True):
    return se.EmulatorConfig(robot.bus.backend, robot.bus.protocol, {}, robot.bus.baudrate,
                             fresh=tuple(j.model for j in robot.joints), one_at_a_time=one_at_a_time,
                             state_path=str(state))


def write_id(chain, servo_id, new_id):
    model = chain.models[servo_id]
    address = model.control_table["ID"].address
    params = bytes([address & 0xFF, address >> 8, new_id]) if chain.framing == "v2" else bytes([address, new_id])
    build = wire.build_v2 if chain.framing == "v2" else wire.build_v1
    chain.receive(build(servo_id, wire.INST_WRITE, params), 1.0)


@pytest.mark.parametrize("robot_name", ["xl430-biped", "ax12a-biped"])
def test_the_state_file_keeps_each_servos_id_across_a_restart(robot_name, tmp_path):
    robot = config(robot_name)
    state = tmp_path / "chain.json"
    chain = se.EmulatedChain(fresh_config(robot, state))
    chain.line_baud = None  # every servo hears
    for k in range(len(robot.joints)):
        if k:
            chain.plug_next()
        write_id(chain, 1, 10 + k)  # the servo plugged in now leaves id 1
    assert chain.state_changed
    chain.save_state()  # what the pty server does once the replies are out
    restored = tuple(read_state(state, robot.bus.backend, robot.bus.protocol))
    again = se.EmulatedChain(se.EmulatorConfig(robot.bus.backend, robot.bus.protocol, {}, robot.bus.baudrate,
                                               restored=restored))
    assert [u.servo_id for u in again.units] == [10 + k for k in range(len(robot.joints))]
    assert all(u.connected for u in again.units)
    assert [u.model.name for u in again.units] == [j.model.name for j in robot.joints]
    se.EmulatedChain(fresh_config(robot, state))  # factory-fresh again: the file starts afresh
    anew = tuple(read_state(state, robot.bus.backend, robot.bus.protocol))
    chain = se.EmulatedChain(se.EmulatorConfig(robot.bus.backend, robot.bus.protocol, {}, robot.bus.baudrate,
                                               restored=anew))
    assert {u.servo_id for u in chain.units} == {1}  # every new servo at the factory id


def test_a_state_file_of_another_bus_or_not_a_state_file_is_refused_in_one_line(tmp_path):
    robot = config("xl430-biped")
    state = tmp_path / "chain.json"
    se.EmulatedChain(fresh_config(robot, state))
    with pytest.raises(ValueError, match="holds dynamixel protocol 2.0 servos"):
        read_state(state, "feetech", 1.0)
    state.write_text("{}")
    with pytest.raises(ValueError, match="not an emulator state file"):
        read_state(state, "dynamixel", 2.0)
    args = emulator_cli.build_parser().parse_args(["--robot", "xl430-biped", "--state", str(state)])
    with pytest.raises(ValueError, match="--state"):
        emulator_cli.config_from_args(args)


def test_the_emulator_command_line_restores_the_chain_of_a_state_file(tmp_path):
    robot = config("xl430-biped")
    state = tmp_path / "chain.json"
    chain = se.EmulatedChain(fresh_config(robot, state, one_at_a_time=False))
    chain.line_baud = None
    write_id(chain, 1, 7)  # all six at id 1 hear it: they all become 7
    chain.save_state()
    args = emulator_cli.build_parser().parse_args(["--robot", "xl430-biped", "--state", str(state)])
    restored = emulator_cli.config_from_args(args)
    assert restored.models == {7: robot.joints[0].model} and len(restored.restored) == len(robot.joints)


# --------------------------------------------------------------------------- the emulator's hand


def test_the_calibration_hand_holds_the_zero_pose_then_bends_each_joint_its_positive_way_and_lets_it_back():
    robot = config("ax12a-biped")
    hand = calibration_hand(robot, seed=3)
    zero = mounting_zero_ticks(robot, seed=3)
    assert zero == mounting_zero_ticks(robot, seed=3) and zero != mounting_zero_ticks(robot, seed=4)
    for j in robot.joints:
        off_deg = math.degrees((zero[j.id] - j.zero_tick) / j.model.ticks_per_rad)
        assert abs(off_deg) <= 4.0 + 0.5  # within the spread, to a tick
    samples = len(robot.joints) + 1
    assert {len(t) for t in hand.ticks.values()} == {samples} and hand.rate_hz is None
    for k, j in enumerate(robot.joints, start=1):
        for other in robot.joints:
            tick = hand.ticks[other.id][k]
            if other is j:
                bent_deg = math.degrees((tick - zero[j.id]) / (j.direction * j.model.ticks_per_rad))
                assert 8.0 - 0.3 <= bent_deg <= min(25.0, max(j.max_deg, 8.0)) + 0.3
            else:
                assert tick == zero[other.id]


def test_a_joint_held_bent_from_the_step_before_is_not_said_to_have_moved():
    robot = config("xl430-biped")
    joints = [CalibrationJoint(j.name, j.id, j.model, j.min_deg, j.max_deg) for j in robot.joints]
    first, second, third = joints[:3]
    per_deg = first.model.ticks_per_rad * math.pi / 180
    zero = {j.id: 2048 for j in joints}
    held = {**zero, first.id: 2048 + round(30 * per_deg)}  # the first joint still bent, as asked
    bent = {**held, second.id: 2048 + round(30 * per_deg)}
    assert _judge(second, joints, zero, held, bent).notes == ()
    let_back = {**zero, second.id: 2048 + round(30 * per_deg)}  # or let back to zero
    assert _judge(second, joints, zero, held, let_back).notes == ()
    wandered = {**bent, third.id: 2048 + round(10 * per_deg)}  # a joint never bent moved 10 deg
    (note,) = _judge(second, joints, zero, held, wandered).notes
    assert third.name in note and "10.0 deg" in note


# --------------------------------------------------------------------------- one place for the calibration


def test_the_calibration_lives_beside_a_users_config_and_in_this_folder_for_a_shipped_robot(tmp_path):
    assert calibration_path_for(tmp_path / "mybot.toml") == tmp_path / "mybot.calibration.toml"
    shipped = config("xl430-biped").path
    assert calibration_path_for(shipped) == Path("xl430-biped.calibration.toml")


def test_calibrate_writes_by_default_where_the_config_finds_it(tmp_path, monkeypatch):
    """calibrate without -o on a user's config: the file lands beside it, and loading the config applies it."""
    import shutil

    robot_path = tmp_path / "mybot.toml"
    shutil.copy(config("xl430-biped").path, robot_path)
    robot = config(str(robot_path))
    zero = {j.id: j.model.centre_tick + 11 * k - 30 for k, j in enumerate(robot.joints)}
    rows = [dict(zero)] + [{**zero, j.id: zero[j.id] + j.direction * 300} for j in robot.joints]
    hand = se.Hand({i: [r[i] for r in rows] for i in zero})
    emulator = se.ServoEmulator(se.EmulatorConfig(robot.bus.backend, robot.bus.protocol, robot.models_by_id,
                                                  robot.bus.baudrate, hand=hand))
    monkeypatch.chdir(tmp_path)
    with emulator:
        proc = subprocess.run([sys.executable, "-m", "gaitbot", "calibrate", "--robot", str(robot_path), "--port",
                               emulator.path, "--yes", "--reply-timeout-ms", "250"], input="\n" * 10,
                              capture_output=True, text=True, timeout=120, cwd=REPO_ROOT)
    assert proc.returncode == 0, proc.stdout + proc.stderr
    assert (tmp_path / "mybot.calibration.toml").is_file()
    applied = load_robot_with_calibration(str(robot_path))
    assert {j.id: j.zero_tick for j in applied.joints} == zero
    assert "moved" not in proc.stderr  # each joint bent alone: no other joint said to have moved


# --------------------------------------------------------------------------- scan's search


def test_a_search_pings_each_id_at_a_short_timeout_unless_told_and_reports_each_ping(monkeypatch):
    robot = config("ax12a-biped")
    timeouts = []
    original = probe_module.ProbeBus._ping_once

    def ping_once(self, servo_id, timeout_ms=None):
        timeouts.append(timeout_ms)
        return original(self, servo_id, timeout_ms)

    monkeypatch.setattr(probe_module.ProbeBus, "_ping_once", ping_once)
    rates = common_baud_rates(robot.bus.backend, robot.bus.protocol)[:2]
    pinged = []
    probe = make_probe_bus(robot.bus.backend, robot.bus.protocol, "mock", dry_run=True, models=robot.models_by_id,
                           baudrate=robot.bus.baudrate)
    with probe:
        survey(probe, rates, on_ping=pinged.append)
    ids = list(range(max_servo_id(robot.bus.backend, robot.bus.protocol) + 1))
    assert pinged == ids * len(rates)  # one report a PING: the progress bar's steps
    assert set(timeouts[:len(ids)]) == {probe_module.SEARCH_PING_TIMEOUT_MS}
    assert probe_module.SEARCH_PING_TIMEOUT_MS < 34  # shorter than the SDK's own


# --------------------------------------------------------------------------- the whole journey


@pytest.mark.slow
def test_the_whole_journey_on_the_emulator(tmp_path):
    """Factory-fresh servos, set up one at a time, scanned as a whole chain, calibrated by the emulator's hand
    after a restart that keeps them, then a walk with that calibration."""
    robot = config("xl430-biped")
    proc = subprocess.run([sys.executable, str(REPO_ROOT / "tools" / "bringup_journey.py"), "--robot", "xl430-biped",
                           "--folder", str(tmp_path), "--seed", "5"], capture_output=True, text=True, timeout=600)
    assert proc.returncode == 0, proc.stdout[-4000:] + proc.stderr
    state = read_state(tmp_path / "chain.json", robot.bus.backend, robot.bus.protocol)
    assert [eeprom[robot.joints[0].model.control_table["ID"].address] for _m, eeprom in state] == list(robot.ids)
    calibration = {j.id: j for j in read_calibration(tmp_path / "xl430-biped.calibration.toml").joints}
    assert {i: c.zero_tick for i, c in calibration.items()} == mounting_zero_ticks(robot, seed=5)
    assert {i: c.direction for i, c in calibration.items()} == {j.id: j.direction for j in robot.joints}
    assert "all 6 servos connected" in proc.stdout and "Walk completed" in proc.stdout
    assert "moved" not in proc.stdout.split("$ gaitbot calibrate")[1].split("$ gaitbot walk")[0]  # no warning
    scan = proc.stdout.split("$ gaitbot scan")[1].split("$ python")[0]
    assert "missing" not in scan and all(f" {j.name} " in scan for j in robot.joints)
    assert json.loads((tmp_path / "chain.json").read_text())["format"] == "gaitbot-emulator-state"
