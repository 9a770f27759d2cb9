"""From a box of servos to a walking robot, end to end on the emulator through the real SDKs (Dynamixel 2.0 and
1.0, Feetech): ``gaitbot setup`` on factory-fresh servos plugged one at a time, ``gaitbot calibrate`` with a
scripted hand, ``gaitbot scan``, and walks stopped by a servo heating up or a supply sagging, then checked.

The test plays the person: it reads the command's prompts and answers them (plugging in the next servo, pressing
Enter). What must come out is given here: the config's ids and baud rate, the hand's zero ticks and directions,
the temperatures and voltages the emulator was told to have; never what gaitbot computed. Protocol 1.0 has no
broadcast ping, so its setup pings 254 ids at six rates one by one: it sets up one joint, not all eight
(plugging in the next servo is the same code for every protocol, tested with the other two).
"""

from __future__ import annotations

import json
import math
import re
import subprocess
import sys
import threading

import pytest

import gaitbot.emulator as se
from gaitbot.bus.bringup import WRITE_TRIES, SetupFailed, assign_id_and_baud, survey
from gaitbot.bus.factory import make_probe_bus
from gaitbot.bus.recording import decode_goal_frames
from gaitbot.robot.calibration_file import read_calibration
from gaitbot.servos import baud_register_value, factory_baudrate
from gaitbot.servos.health import health_block
from gaitbot.servos.models import SERVO_MODELS
from helpers import REPO_ROOT, config, slow_except

ROBOTS = {"dxl2": "xl430-biped", "dxl1": "ax12a-biped", "feetech": "sts3215-biped"}
SET_UP = {"dxl2": None, "dxl1": 1, "feetech": None}  # joints set up (None: all)
FAST = ["--reply-timeout-ms", "3"]  # the emulator answers within a millisecond or two
TIMEOUT_S = 240


def gaitbot_talking(argv, answer):
    """Run the gaitbot command line; ``answer(line)`` returns what to type after each line it prints (or None)."""
    proc = subprocess.Popen([sys.executable, "-m", "gaitbot.app.cli", *argv], stdin=subprocess.PIPE,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, cwd=REPO_ROOT)
    watchdog = threading.Timer(TIMEOUT_S, proc.kill)
    watchdog.start()
    out = []
    try:
        for line in proc.stdout:
            out.append(line)
            reply = answer(line)
            if reply is not None:
                proc.stdin.write(reply)
                proc.stdin.flush()
        proc.stdin.close()
        err = proc.stderr.read()
        proc.wait()
    finally:
        watchdog.cancel()
    return proc.returncode, "".join(out), err


def fresh_emulator(robot, n=None, one_at_a_time=True, models=None):
    models = models or tuple(j.model for j in robot.joints)[:n]
    return se.ServoEmulator(se.EmulatorConfig(robot.bus.backend, robot.bus.protocol, {}, robot.bus.baudrate,
                                              fresh=models, one_at_a_time=one_at_a_time))


def setup(robot, emulator, joints, *extra):
    plugged = {"n": 0}

    def answer(line):
        if line.startswith("Connect only the servo for"):
            if plugged["n"]:
                emulator.plug_next()  # the person unplugs the last servo and plugs in the next
            plugged["n"] += 1
            return "\n"
        return None

    argv = ["setup", "--robot", str(robot.path), "--port", emulator.path, *FAST, *extra]
    for name in joints:
        argv += ["--joint", name]
    return gaitbot_talking(argv, answer)


# --------------------------------------------------------------------------- setup


@pytest.mark.parametrize("protocol", slow_except(["dxl2", "dxl1", "feetech"], "dxl1"))
def test_setup_gives_factory_fresh_servos_the_configs_ids_and_baud_rate(protocol):
    robot = config(ROBOTS[protocol])
    joints = robot.joints[:SET_UP[protocol]]
    with fresh_emulator(robot, len(joints)) as emulator:
        code, out, err = setup(robot, emulator, [j.name for j in joints])
        assert code == 0, out + err
        chain = emulator.chain
        with emulator.lock:
            chain.power_cycle()  # what was written is in EEPROM (Feetech: written with the lock off)
            got = [(u.servo_id, u.rate) for u in chain.units]
        assert got == [(j.id, robot.bus.baudrate) for j in joints]
        table = joints[0].model.control_table
        feetech = robot.bus.backend == "feetech"
        for unit, joint in zip(chain.units, joints):
            written = [(w[2], w[3][0]) for w in chain.writes if w[0] == unit.index]
            needs_id, needs_rate = joint.id != 1, robot.bus.baudrate != factory_baudrate(joint.model.name)
            expected = []
            if needs_id or needs_rate:  # exactly these registers, in this order (docs/bring-up.md)
                expected = [(table["Torque Enable"].address, 0)] + ([(table["Lock"].address, 0)] if feetech else [])
                expected += [(table["ID"].address, joint.id)] if needs_id else []
                expected += [(table["Baud Rate"].address, baud_register_value(joint.model.name, robot.bus.baudrate))
                             ] if needs_rate else []
                expected += [(table["Lock"].address, 1)] if feetech else []
            assert written == expected, (joint.name, written)
        assert f"{len(joints)} of {len(joints)} servos set up" in out


@pytest.mark.slow
def test_setup_on_the_emulator_command_line_plugged_with_enter(tmp_path):
    """The user's way: tools/servo_emulator.py --factory-fresh --one-at-a-time, Enter there plugs the next servo."""
    robot = config("xl430-biped")
    emu = subprocess.Popen([sys.executable, str(REPO_ROOT / "tools" / "servo_emulator.py"), "--robot", "xl430-biped",
                            "--factory-fresh", "3", "--one-at-a-time"], stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                           stderr=subprocess.PIPE, text=True)
    try:
        path = emu.stdout.readline().strip()
        plugged = {"n": 0}

        def answer(line):
            if line.startswith("Connect only"):
                if plugged["n"]:
                    emu.stdin.write("\n")  # Enter in the emulator's terminal: the next servo
                    emu.stdin.flush()
                    while "connected" not in emu.stderr.readline():
                        pass
                plugged["n"] += 1
                return "\n"
            return None

        argv = ["setup", "--robot", "xl430-biped", "--port", path, *FAST]
        for joint in robot.joints[:3]:
            argv += ["--joint", joint.name]
        code, out, err = gaitbot_talking(argv, answer)
        assert code == 0, out + err
        code, out, err = gaitbot_talking(["scan", "--robot", "xl430-biped", "--port", path, "--baud", "1000000",
                                          "--json", *FAST], lambda line: None)
        assert [s["id"] for s in json.loads(out)["servos"]] == [3]  # the last one plugged in, now id 3
    finally:
        emu.terminate()
        emu.wait(timeout=10)


@pytest.mark.parametrize("protocol", slow_except(["dxl2", "feetech"], "dxl2"))
def test_two_servos_on_the_bus_are_refused_in_one_line_with_nothing_written(protocol):
    robot = config(ROBOTS[protocol])
    with fresh_emulator(robot, 2, one_at_a_time=False) as emulator:
        code, out, err = setup(robot, emulator, [robot.joints[1].name])
        assert code == 2, out + err
        assert err.count("\n") == 1 and "more than one servo answers" in err and "nothing written" in err
        assert emulator.chain.writes == []


@pytest.mark.slow
def test_two_servos_on_a_protocol1_bus_are_refused_too():
    robot = config("ax12a-biped")
    with fresh_emulator(robot, 2, one_at_a_time=False) as emulator:
        code, out, err = setup(robot, emulator, [robot.joints[0].name], "--yes")
        assert code == 2 and "more than one servo answers" in err and err.count("\n") == 1, err
        assert emulator.chain.writes == []


def test_a_servo_of_another_model_is_refused():
    robot = config("xl430-biped")
    xl320 = SERVO_MODELS["XL-320"]
    with fresh_emulator(robot, models=(xl320,)) as emulator:
        code, out, err = setup(robot, emulator, [robot.joints[0].name])
        assert code == 2 and "is a XL-320" in err and "the config says XL430-W250" in err, err
        assert emulator.chain.writes == []


def assign_with_lost_writes(register, lost):
    """assign_id_and_baud on one factory-fresh XL430 (id 1, 57,600 baud) towards the config's second joint (id 2,
    1,000,000 baud), the first ``lost`` writes of ``register`` (ID or Baud Rate) never reaching the line (a
    packet lost to noise, or to a host that switched rate before the servo heard it): (the Assignment or the
    SetupFailed, the servo's id and rate, the robot, the joint)."""
    robot = config("xl430-biped")
    joint = robot.joints[1]
    address = joint.model.control_table[register].address
    with fresh_emulator(robot, 1, one_at_a_time=False) as emulator:
        probe = make_probe_bus(robot.bus.backend, robot.bus.protocol, emulator.path, reply_timeout_ms=5)
        with probe:
            (found,) = survey(probe, [factory_baudrate(joint.model.name)])[0].found
            assert (found.servo_id, joint.id) == (1, 2)  # both registers need writing
            sent = probe.write
            left = {"lost": lost}

            def write(servo_id, at, data, *, confirm=True):
                if at == address and left["lost"]:
                    left["lost"] -= 1
                    return 0
                return sent(servo_id, at, data, confirm=confirm)

            probe.write = write
            try:
                outcome = assign_id_and_baud(probe, found, joint.model, joint.id, robot.bus.baudrate)
            except SetupFailed as failed:
                outcome = failed
        with emulator.lock:
            (unit,) = emulator.chain.units
            return outcome, (unit.servo_id, unit.rate), robot, joint


@pytest.mark.parametrize("register", ["ID", "Baud Rate"])
@pytest.mark.parametrize("lost", [1, WRITE_TRIES - 1])
def test_an_id_or_baud_rate_write_the_servo_never_heard_is_sent_again(register, lost):
    """The servo still answers as its old self, so the write was lost: setup writes it again and the servo
    ends at the config's id and rate, read back."""
    assignment, (servo_id, rate), robot, joint = assign_with_lost_writes(register, lost)
    assert not isinstance(assignment, SetupFailed), assignment
    assert (servo_id, rate) == (joint.id, robot.bus.baudrate)
    assert (assignment.servo_id, assignment.baudrate) == (joint.id, robot.bus.baudrate)
    value = joint.id if register == "ID" else baud_register_value(joint.model.name, robot.bus.baudrate)
    assert [w for w in assignment.writes if w[0] == register] == [(register, value)] * (lost + 1)


@pytest.mark.parametrize("register, words", [("ID", "still answers at id 1 after {n} writes of its ID (2)"),
                                             ("Baud Rate", "still answers at 57,600 baud after {n} writes of its "
                                                           "Baud Rate (3, 1,000,000 baud)")])
def test_a_servo_that_never_hears_its_id_or_baud_rate_write_fails_setup_in_words(register, words):
    """Words and numbers from the XL430's e-Manual: factory id 1 at 57,600 baud; Baud Rate 3 is 1 Mbaud."""
    failed, (servo_id, rate), robot, joint = assign_with_lost_writes(register, WRITE_TRIES)
    assert isinstance(failed, SetupFailed)
    assert words.format(n=WRITE_TRIES) in str(failed), failed
    assert rate == 57_600 and servo_id == (1 if register == "ID" else 2)  # what it heard, and nothing else


# --------------------------------------------------------------------------- calibrate


def scripted_hand(robot, seed_offset=0):
    """Zero ticks off centre and directions per joint, then each joint bent 30 deg its way, one sample a step."""
    zero = {j.id: j.model.centre_tick + ((7 * k + seed_offset) % 41) - 20 for k, j in enumerate(robot.joints)}
    direction = {j.id: (1 if (k + seed_offset) % 3 else -1) for k, j in enumerate(robot.joints)}
    rows = [dict(zero)]
    for j in robot.joints:
        row = dict(zero)
        row[j.id] += direction[j.id] * round(math.radians(30) * j.model.ticks_per_rad)
        rows.append(row)
    return zero, direction, se.Hand({i: [r[i] for r in rows] for i in zero})


@pytest.mark.parametrize("protocol", slow_except(["dxl2", "dxl1", "feetech"], "dxl2"))
def test_calibrate_with_a_scripted_hand_gives_back_its_zero_ticks_and_directions(protocol, tmp_path):
    robot = config(ROBOTS[protocol])
    zero, direction, hand = scripted_hand(robot, len(protocol))
    out_file = tmp_path / "bot.calibration.toml"
    emulator = se.ServoEmulator(se.EmulatorConfig(robot.bus.backend, robot.bus.protocol, robot.models_by_id,
                                                  robot.bus.baudrate, hand=hand))
    with emulator:
        code, out, err = gaitbot_talking(
            ["calibrate", "--robot", str(robot.path), "--port", emulator.path, "--yes", "-o", str(out_file),
             "--reply-timeout-ms", "250"], lambda line: "\n" if line.rstrip().endswith("Press Enter.") else None)
        writes = list(emulator.chain.writes)
    assert code == 0, out + err
    cal = read_calibration(out_file)
    assert {j.id: j.zero_tick for j in cal.joints} == zero
    assert {j.id: j.direction for j in cal.joints} == direction
    assert {(j.name, j.model) for j in cal.joints} == {(j.name, j.model.name) for j in robot.joints}
    assert all(abs(j.moved_deg - 30) < 0.3 for j in cal.joints)
    assert "Bend the left knee" in out
    torque = robot.joints[0].model.addr_torque_enable
    assert {(w[2], w[3]) for w in writes} == {(torque, b"\x00")}  # nothing written but torque off


# --------------------------------------------------------------------------- scan


@pytest.mark.parametrize("protocol", slow_except(["dxl2", "dxl1", "feetech"], "dxl2"))
def test_scan_lists_what_the_emulator_holds(protocol):
    robot = config(ROBOTS[protocol])
    models = dict(robot.models_by_id)
    missing = robot.joints[-1]
    del models[missing.id]
    hot, flat = robot.joints[0].id, robot.joints[1].id
    faults = se.Faults(errors={flat: {"voltage"}})
    emulator = se.ServoEmulator(se.EmulatorConfig(robot.bus.backend, robot.bus.protocol, models, robot.bus.baudrate,
                                                  faults, temperatures_c={hot: 58.0}))
    with emulator:
        code, out, err = gaitbot_talking(["scan", "--robot", str(robot.path), "--port", emulator.path, "--json",
                                          "--baud", str(robot.bus.baudrate), *FAST], lambda line: None)
    assert code == 1, out + err  # a configured joint did not answer
    result = json.loads(out)
    servos = {s["id"]: s for s in result["servos"]}
    assert sorted(servos) == sorted(models)
    model = robot.joints[0].model
    supply = health_block(model).voltage.factory / 10
    for servo_id, s in servos.items():
        joint = next(j for j in robot.joints if j.id == servo_id)
        assert (s["model"], s["baudrate"], s["joint"], s["torque"]) == (joint.model.name, robot.bus.baudrate,
                                                                         joint.name, "off")
        assert s["position_ticks"] == joint.model.centre_tick
        assert s["angle_deg"] == pytest.approx((joint.model.centre_tick - joint.zero_tick) /
                                               (joint.direction * joint.model.ticks_per_rad) * 180 / math.pi, abs=0.01)
        assert s["voltage_v"] == supply
    assert 57 <= servos[hot]["temperature_c"] <= 58  # it cools towards ambient while the scan runs
    assert servos[flat]["hardware_errors"] == ["input voltage"]
    assert [m["joint"] for m in result["missing_joints"]] == [missing.name]


def test_scan_asks_a_configured_servo_again_before_calling_it_missing():
    """A servo whose broadcast reply comes 40 ms late, after the 3 ms quiet window closed: it is found by a
    ping of its own (the emulator's other servos answer in time, so the window does close before it)."""
    robot = config(ROBOTS["dxl2"])
    slow = robot.joints[3].id
    emulator = se.ServoEmulator(se.EmulatorConfig(robot.bus.backend, robot.bus.protocol, dict(robot.models_by_id),
                                                  robot.bus.baudrate, se.Faults(late_s={slow: 0.04})))
    with emulator:
        code, out, err = gaitbot_talking(["scan", "--robot", str(robot.path), "--port", emulator.path, "--json",
                                          "--baud", str(robot.bus.baudrate), *FAST], lambda line: None)
    assert code == 0, out + err
    result = json.loads(out)
    assert sorted(s["id"] for s in result["servos"]) == sorted(robot.models_by_id)
    assert result["missing_joints"] == []


# --------------------------------------------------------------------------- health while walking


def walk_on(robot, emulator_config, tmp_path):
    record = tmp_path / "walk.jsonl"
    with se.ServoEmulator(emulator_config) as emulator:
        proc = subprocess.run([sys.executable, "-m", "gaitbot.app.cli", "walk", "--robot", str(robot.path), "--steps",
                               "0.03,0.03", "--port", emulator.path, "--record", str(record), "--reply-timeout-ms",
                               "250"], capture_output=True, text=True, timeout=TIMEOUT_S, cwd=REPO_ROOT)
    check = subprocess.run([sys.executable, "-m", "gaitbot.app.cli", "check", str(record), "--robot", str(robot.path)],
                           capture_output=True, text=True, timeout=TIMEOUT_S, cwd=REPO_ROOT)
    return proc, record, check


@pytest.mark.parametrize("protocol", slow_except(["dxl2", "dxl1", "feetech"], "dxl2"))
def test_a_servo_heating_past_its_limit_stops_the_walk_safely_and_check_reports_it(protocol, tmp_path):
    robot = config(ROBOTS[protocol])
    knee = robot.joint("knee_pitch_left")
    stop_c = {"dxl2": 67, "dxl1": 65, "feetech": 65}[protocol]
    config_ = se.EmulatorConfig(robot.bus.backend, robot.bus.protocol, robot.models_by_id, robot.bus.baudrate,
                                heat=se.Heat(heat_c_per_s=6.0), loads_pct={knee.id: 90.0},
                                temperatures_c={knee.id: stop_c - 8.0})
    proc, record, check = walk_on(robot, config_, tmp_path)
    out = proc.stdout + proc.stderr
    assert proc.returncode == 1, out
    # the knee is read about every 0.1 s while it heats 6 °C/s: the first reading at or above the stop is the stop
    # temperature, or a degree or two more when a busy host's frames came late and its reads were spaced further
    seen = re.search(rf"servo {knee.id} \(knee_pitch_left\) is at (\d+) °C, at or above its stop temperature "
                     rf"{stop_c} °C", out)
    assert seen, out
    hot_c = int(seen.group(1))
    assert stop_c <= hot_c <= stop_c + 2, out
    assert "Walk stopped to protect a servo" in out and "ramped to the stand pose" in out and "Traceback" not in out
    decode_goal_frames(record)  # strictly readable
    assert check.returncode == 1
    assert f"hottest servo: servo {knee.id} (knee_pitch_left) at {hot_c} °C" in check.stdout
    assert f"servo {knee.id} (knee_pitch_left) at {hot_c} °C, at or above the stop temperature" in check.stdout
    as_json = subprocess.run([sys.executable, "-m", "gaitbot.app.cli", "check", str(record), "--json"],
                             capture_output=True, text=True, timeout=TIMEOUT_S, cwd=REPO_ROOT)
    hottest = json.loads(as_json.stdout)["servo_health"]["hottest"]
    assert (hottest["id"], hottest["temperature_c"]) == (knee.id, hot_c)


@pytest.mark.parametrize("protocol", slow_except(["dxl2", "dxl1", "feetech"]))
def test_a_sagging_supply_stops_the_walk_safely_and_check_reports_it(protocol, tmp_path):
    robot = config(ROBOTS[protocol])
    stop_v = {"dxl2": 6.5, "dxl1": 9.0, "feetech": 6.0}[protocol]
    faults = se.Faults(after_frames=20)
    config_ = se.EmulatorConfig(robot.bus.backend, robot.bus.protocol, robot.models_by_id, robot.bus.baudrate, faults,
                                supply_v=stop_v + 0.8, voltage_sag_v_per_s=1.0)
    proc, record, check = walk_on(robot, config_, tmp_path)
    out = proc.stdout + proc.stderr
    assert proc.returncode == 1, out
    assert f"V input voltage, at or under its stop voltage {stop_v:.1f} V" in out
    assert "Walk stopped to protect a servo" in out and "ramped to the stand pose" in out
    decode_goal_frames(record)
    assert check.returncode == 1
    assert f"lowest voltage: {stop_v:.1f} V" in check.stdout or f"lowest voltage: {stop_v - 0.1:.1f} V" in check.stdout
    assert "at or under the stop voltage" in check.stdout
