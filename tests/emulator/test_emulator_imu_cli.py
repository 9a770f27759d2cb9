"""The emulator's --imu switches: the OpenCR device at the robot's [imu] id answers a hand-built READ of its IMU
block, its fall and fault come from the command line, and bad switches are refused in one line (ValueError)."""

from __future__ import annotations

import pytest

from gaitbot.app import emulator as emulator_cli
from gaitbot.emulator import EmulatedChain
from helpers import crc16, parse_packet


def config_of(*argv: str):
    return emulator_cli.config_from_args(emulator_cli.build_parser().parse_args(list(argv)))


def imu_block(line: EmulatedChain, t_s: float, device_id: int = 200) -> bytes | None:
    body = bytes([0xFF, 0xFF, 0xFD, 0x00, device_id, 0x07, 0x00, 0x02, 32, 0, 18, 0])  # READ 18 bytes at 32
    line.receive(body + crc16(body).to_bytes(2, "little"), t_s)
    replies = line.due(t_s + 0.01)
    if not replies:
        return None
    packet_id, instruction, params = parse_packet(replies[0], 2.0)
    assert (packet_id, instruction, params[0]) == (device_id, 0x55, 0)  # a status packet, no error
    return bytes(params[1:])


def test_imu_on_the_op3_line_answers_at_its_config_id_and_freezes_when_told():
    config = config_of("--robot", "op3", "--imu", "--imu-fault", "frozen@2")
    assert config.imu.device_id == 200 and config.imu.fault == "frozen" and config.imu.fault_at_s == 2.0
    line = EmulatedChain(config)
    imu_block(line, 0.0)  # the line's first packet: the device's time starts here
    early, later = imu_block(line, 0.5), imu_block(line, 1.1)
    assert early is not None and len(early) == 18 and early != later  # the sway moves the readings
    # frozen from 2 s: the registers keep what the last read before then (1.1 s) found, and stop changing
    assert imu_block(line, 2.2) == later and imu_block(line, 3.7) == later


def test_absent_imu_stops_answering_and_no_imu_without_the_switch():
    line = EmulatedChain(config_of("--robot", "op3", "--imu", "--imu-fault", "absent"))
    assert imu_block(line, 0.0) is not None and imu_block(line, 0.5) is not None
    assert imu_block(line, 1.5) is None  # absent from the default 1 s after the first packet
    assert config_of("--robot", "op3").imu is None
    assert config_of("--robot", "op3", "--imu", "--imu-fall-at-s", "3").imu.fall_at_s == 3.0
    assert config_of("--robot", "op3", "--imu", "--imu-drop-at-s", "2.5").imu.drop_at_s == 2.5


@pytest.mark.parametrize("argv, words", [
    (["--robot", "op3", "--imu-fault", "frozen"], "need --imu"),
    (["--robot", "op3", "--imu", "--imu-fault", "wobbly"], "KIND is one of"),
    (["--robot", "op3", "--imu", "--imu-fault", "noisy@soon"], "S must be a number"),
    (["--robot", "op3", "--imu", "--imu-fall-at-s", "-1"], "--imu-fall-at-s"),
    (["--robot", "op3", "--imu", "--imu-drop-at-s", "nan"], "--imu-drop-at-s must be within"),
    (["--robot", "op3", "--imu-drop-at-s", "2"], "need --imu"),
    (["--protocol", "dxl1", "--imu"], "Protocol 2.0 only"),
    (["--protocol", "dxl2", "--ids", "199-200", "--imu"], "id 200 is a servo's"),
])
def test_bad_imu_switches_are_refused_naming_the_argument(argv, words):
    with pytest.raises(ValueError, match=words):
        config_of(*argv)
