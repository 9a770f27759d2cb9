"""The stiffness setting on the wire: which WRITE packets a session sends, to whom, and when.

Packets are decoded with test_walk_cli's decoder (written from the protocol documents, not gaitbot's)
and checksums worked by hand; expected register values come from the datasheet formulas
(tests/robot/test_robot_servo_gains.py): full torque at 2 deg is Position P Gain 4978 on a Dynamixel X,
compliance slope 4 on an AX-12A (the stiffest step not above 2 deg), P coefficient 199 on an STS3215.
"""

from __future__ import annotations

import json
import re
from pathlib import Path

import pytest

from gaitbot.bus import ServoStatusError, ServoTimeout
from gaitbot.bus.dynamixel import DynamixelBus
from gaitbot.bus.factory import make_bus
from gaitbot.bus.feetech import FeetechBus
from gaitbot.bus.guard import LimitGuard
from gaitbot.bus.dry_run import DryRunPort
from gaitbot.bus.recording import BusRecorder
from gaitbot.check.recording import check_recording
from gaitbot.app.cli import main
from gaitbot.stream.clock import VirtualClock
from gaitbot.stream.record import record_session
from gaitbot.robot.calibration import tick_limits
from gaitbot.robot.config import load_robot_config
from gaitbot.servos.models import SERVO_MODELS
from gaitbot.robot.gains import gain_writes
from helpers import CONFIG_DIR, crc16, emulator_for, gaitbot, parse_packet, slow_except  # noqa: E402 - the independent decoder

WRITE = 0x03
XM, AX, STS = SERVO_MODELS["XM430-W350"], SERVO_MODELS["AX-12A"], SERVO_MODELS["STS3215"]
#: robot -> (protocol of its framing, torque enable address, [(address, bytes written)] per servo, in order)
EXPECTED = {
    "xl430-biped": (2.0, 64, [(84, (4978).to_bytes(2, "little"))]),
    "sts3215-biped": (1.0, 40, [(55, b"\x01"), (21, bytes([199]))]),
    "ax12a-biped": (1.0, 24, [(28, b"\x04"), (29, b"\x04")]),
}


def writes_in(recording: Path, protocol: float) -> list[tuple[int, int, bytes]]:
    """(servo id, address, data) of every WRITE the host sent, in order."""
    out = []
    for line in recording.read_text().splitlines()[1:]:
        packet = json.loads(line)
        if packet["dir"] != "tx":
            continue
        servo_id, instruction, params = parse_packet(bytes.fromhex(packet["hex"]), protocol)
        if instruction == WRITE:
            split = 2 if protocol == 2.0 else 1
            address = params[0] | (params[1] << 8 if split == 2 else 0)
            out.append((servo_id, address, bytes(params[split:])))
    return out


def factory_config(name: str, tmp_path: Path) -> Path:
    text = re.sub(r"(?m)^\[servo\]\nfull_torque_error_deg = .*\n", "", (CONFIG_DIR / f"{name}.toml").read_text())
    path = tmp_path / f"{name}-factory.toml"
    path.write_text(text)
    return path


@pytest.mark.parametrize("name", sorted(EXPECTED))
def test_a_walk_writes_every_servos_gain_before_its_torque_goes_on(name, tmp_path, capsys):
    protocol, torque_addr, gains = EXPECTED[name]
    config = load_robot_config(CONFIG_DIR / f"{name}.toml")
    record = tmp_path / "run.jsonl"
    assert main(["walk", "--robot", name, "--steps", "0.03", "--dry-run", "--record", str(record)]) == 0
    writes = writes_in(record, protocol)
    for servo_id in config.ids:
        own = [(address, data) for i, address, data in writes if i == servo_id]
        torque_on = own.index((torque_addr, b"\x01"))
        assert own[:torque_on] == gains, f"servo {servo_id}: {own[:torque_on]}"
        assert (torque_addr, b"\x01") not in own[:torque_on]
    assert "servo stiffness" in capsys.readouterr().err


@pytest.mark.parametrize("name", sorted(EXPECTED))
def test_without_the_setting_no_gain_is_written(name, tmp_path, capsys):
    protocol, torque_addr, _ = EXPECTED[name]
    record = tmp_path / "run.jsonl"
    assert main(["walk", "--robot", str(factory_config(name, tmp_path)), "--steps", "0.03", "--dry-run",
                 "--record", str(record)]) == 0
    assert {address for _, address, _ in writes_in(record, protocol)} == {torque_addr}
    assert "servo stiffness" not in capsys.readouterr().err


@pytest.mark.parametrize("name", sorted(EXPECTED))
def test_check_accepts_and_lists_the_gain_writes(name, tmp_path, capsys):
    record = tmp_path / "run.jsonl"
    assert main(["walk", "--robot", name, "--steps", "0.03", "--dry-run", "--record", str(record)]) == 0
    config = load_robot_config(CONFIG_DIR / f"{name}.toml")
    report = check_recording(config, record)
    assert report.ok, report.first_error
    _, _, gains = EXPECTED[name]
    assert len(report.settings) == len(gains) * len(config.ids)
    assert {(s.address, s.value) for s in report.settings} == {(a, int.from_bytes(d, "little")) for a, d in gains}
    capsys.readouterr()
    assert main(["check", str(record)]) == 0
    assert "settings written:" in capsys.readouterr().out


# --- record --hold: the gains go on with the torque ------------------------------------------------

def recorded_hold(tmp_path: Path, hold: bool) -> list[tuple[int, int, bytes]]:
    config = load_robot_config(CONFIG_DIR / "xl430-biped.toml")
    path = tmp_path / "bus.jsonl"
    recorder = BusRecorder(path, robot=config.name, joints={j.name: j.id for j in config.joints})
    bus = make_bus("dynamixel", 2.0, "mock", 1_000_000, config.models_by_id, interface="dry-run", recorder=recorder)
    bus = LimitGuard(bus, tick_limits(config), {j.id: j.name for j in config.joints})

    class Sink:
        def open(self): pass
        def add(self, t_s, ticks): pass
        def sync(self): pass
        def close(self): pass

    result = record_session(bus, config.ids, 1 / 60, Sink(), confirm=lambda n: True, n_samples=5, clock=VirtualClock(),
                            hold_at_end=hold, handle_sigterm=False, setup_writes=gain_writes(config))
    recorder.close()
    assert result.exit_code == 0, result.message()
    return writes_in(path, 2.0)


def test_record_hold_writes_the_gain_after_the_recording_before_torque_on(tmp_path):
    writes = recorded_hold(tmp_path, hold=True)
    for servo_id in range(1, 7):
        own = [(address, data) for i, address, data in writes if i == servo_id]
        assert own == [(64, b"\x00"), (84, (4978).to_bytes(2, "little")), (64, b"\x01")]


def test_record_without_hold_writes_no_gain(tmp_path):
    assert {address for _, address, _ in recorded_hold(tmp_path, hold=False)} == {64}


# --- the bus method, byte for byte -------------------------------------------------------------------

def test_protocol2_gain_write_by_hand():
    port = DryRunPort("dynamixel", 2.0, {1: XM})
    bus = DynamixelBus("mock", 1_000_000, 2.0, {1: XM}, port_handler=port)
    bus.open()
    bus.write_register([1], 84, 2, 4978)
    # WRITE, address 84 = 54 00, 4978 = 0x1372 low byte first; LEN = inst 1 + addr 2 + data 2 + CRC 2 = 7
    body = bytes.fromhex("FF FF FD 00 01 07 00 03 54 00 72 13")
    crc = crc16(body)
    assert port.tx_packets == [body + bytes([crc & 0xFF, crc >> 8])]
    assert int.from_bytes(port.tables[1][84:86], "little") == 4978


def test_protocol1_gain_writes_by_hand():
    port = DryRunPort("dynamixel", 1.0, {1: AX})
    bus = DynamixelBus("mock", 1_000_000, 1.0, {1: AX}, port_handler=port)
    bus.open()
    assert (port.tables[1][28], port.tables[1][29]) == (32, 32)  # factory slopes
    bus.write_register([1], 28, 1, 4)
    assert port.tx_packets == [bytes.fromhex("FF FF 01 04 03 1C 04 D7")]  # ~(01+04+03+1C+04) = ~0x28
    port = DryRunPort("feetech", 1.0, {1: STS})
    bus = FeetechBus("mock", 1_000_000, 1.0, {1: STS}, port_handler=port)
    bus.open()
    assert port.tables[1][21] == 32  # factory P coefficient
    bus.write_register([1], 21, 1, 199)
    assert port.tx_packets == [bytes.fromhex("FF FF 01 04 03 15 C7 1B")]  # ~(01+04+03+15+C7) = ~0xE4


def test_a_lost_status_packet_is_retried_and_a_silent_servo_named():
    port = DryRunPort("dynamixel", 2.0, {1: XM})
    bus = DynamixelBus("mock", 1_000_000, 2.0, {1: XM}, port_handler=port, retries=2)
    bus.open()
    port.drop_next_replies(1)
    bus.write_register([1], 84, 2, 4978)
    assert len(port.tx_packets) == 2
    port.drop_next_replies(3)
    with pytest.raises(ServoTimeout, match="address 84") as info:
        bus.write_register([1], 84, 2, 100)
    assert info.value.servo_id == 1


def test_a_servo_reporting_an_error_on_the_gain_write_stops_it():
    port = DryRunPort("dynamixel", 1.0, {1: AX})
    bus = DynamixelBus("mock", 1_000_000, 1.0, {1: AX}, port_handler=port)
    bus.open()

    def overloaded(servo_id, params):  # a status packet with the overload bit (0x20, protocol 1.0)
        packet = bytes([0xFF, 0xFF, servo_id, 2 + len(params), 0x20, *params])
        packet += bytes([~sum(packet[2:]) & 0xFF])
        port.rx_packets.append(packet)
        port._rx_buffer += packet

    port._reply = overloaded
    with pytest.raises(ServoStatusError):
        bus.write_register([1], 28, 1, 4)


@pytest.mark.parametrize("address, length", [(116, 4), (114, 4), (64, 1), (63, 2)])
def test_goal_and_torque_registers_cannot_be_written_as_settings(address, length):
    port = DryRunPort("dynamixel", 2.0, {1: XM})
    bus = LimitGuard(DynamixelBus("mock", 1_000_000, 2.0, {1: XM}, port_handler=port), {1: (1000, 3000)})
    bus.open()
    with pytest.raises(ValueError, match="use (write_goal_ticks|set_torque)"):
        bus.write_register([1], address, length, 0)
    assert port.tx_packets == []


def test_the_limit_guard_passes_settings_on():
    port = DryRunPort("dynamixel", 2.0, {1: XM})
    bus = LimitGuard(DynamixelBus("mock", 1_000_000, 2.0, {1: XM}, port_handler=port), {1: (1000, 3000)})
    bus.open()
    bus.write_register([1], 84, 2, 4978)
    assert int.from_bytes(port.tables[1][84:86], "little") == 4978


# --- a real pty: the emulator keeps what it was sent ----------------------------------------------

@pytest.mark.parametrize("name", slow_except(sorted(EXPECTED)))
def test_the_emulator_receives_the_gain_registers(name, tmp_path):
    _, _, gains = EXPECTED[name]
    config = load_robot_config(CONFIG_DIR / f"{name}.toml")
    with emulator_for(CONFIG_DIR / f"{name}.toml", tmp_path / "emu.jsonl") as emulator:
        proc = gaitbot("walk", "--robot", name, "--steps", "0.02", "--port", emulator.path,
                       "--reply-timeout-ms", "200")
        tables = {i: bytes(t) for i, t in emulator.chain.tables.items()}  # every write was confirmed
    assert proc.returncode == 0, proc.stderr
    for servo_id in config.ids:
        for address, data in gains:
            assert tables[servo_id][address:address + len(data)] == data, (servo_id, address)
