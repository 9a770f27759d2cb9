"""The emulator's IMU device (gaitbot.bus.imu_device) on the emulated line: a READ of the OpenCR's IMU block built
by hand gets a Protocol 2.0 status packet whose bytes, decoded here with the firmware's table (int16 at 32..48,
16.4 LSB per deg/s, 16384 per g, board x and y reversed), are the scripted motion; faults as documented."""

from __future__ import annotations

import math
import struct

import pytest

from gaitbot.emulator import EmulatedChain, EmulatorConfig
from gaitbot.bus.imu_device import ImuDevice
from helpers import config, crc16, parse_packet


def read_packet(device_id: int = 200) -> bytes:
    body = bytes([0xFF, 0xFF, 0xFD, 0x00, device_id, 0x07, 0x00, 0x02, 32, 0, 18, 0])
    return body + crc16(body).to_bytes(2, "little")


def chain(imu: ImuDevice) -> EmulatedChain:
    """The op3's line with the device, its first packet (a READ of the IMU) at t = 0: the device's time."""
    cfg = config("op3")
    line = EmulatedChain(EmulatorConfig("dynamixel", 2.0, cfg.models_by_id, baudrate=2_000_000, imu=imu))
    ask(line, 0.0)
    return line


def ask(line: EmulatedChain, t_s: float) -> list[bytes]:
    line.receive(read_packet(), t_s)
    return line.due(t_s + 0.01)


@pytest.mark.parametrize("t_s", [0.1, 0.37, 2.5])
def test_a_read_of_the_imu_block_answers_the_scripted_motion_byte_exact(t_s):
    device = ImuDevice(fall_at_s=2.0)
    replies = ask(chain(device), t_s)
    assert len(replies) == 1
    packet_id, instruction, params = parse_packet(replies[0], 2.0)
    assert (packet_id, instruction, params[0], len(params)) == (200, 0x55, 0, 19)
    raw = struct.unpack("<9h", params[1:])
    gyro, acc, rpy = device.motion(t_s)
    assert raw[0] == round(-gyro[0] * 16.4) and raw[1] == round(-gyro[1] * 16.4) and raw[2] == round(gyro[2] * 16.4)
    assert raw[3] == round(-acc[0] * 16384) and raw[5] == round(min(acc[2] * 16384, 32767))
    assert raw[6] == round(rpy[0] * 10) and raw[7] == round(rpy[1] * 10)
    if t_s > 2.0:  # falling forwards: pitch grows at 120 deg/s
        assert rpy[1] == pytest.approx(min(90.0, 0.5 * 2.0 * math.sin(2 * 2 * math.pi * 0.8 * t_s) + 120 * (t_s - 2.0)))


def test_an_absent_imu_does_not_answer_and_a_frozen_one_repeats_itself():
    assert ask(chain(ImuDevice(fault="absent", fault_at_s=1.0)), 0.5)
    assert ask(chain(ImuDevice(fault="absent", fault_at_s=1.0)), 1.5) == []
    line = chain(ImuDevice(fault="frozen", fault_at_s=1.0))
    first, later = ask(line, 1.2), ask(line, 1.7)
    assert first == later
    assert ask(chain(ImuDevice()), 1.2) != ask(chain(ImuDevice()), 1.7)


def test_a_dropped_robot_reads_zero_g_from_the_drop_on():
    """Falling freely, an accelerometer feels nothing (gravity acts on its proof mass as on its case): from
    drop_at_s on, the three int16 registers read 0 g within the sensor's noise (0.002 g: 33 LSB; 5 sigma
    here), not all exactly 0 (a dead sensor's reading); about 1 g (16384) on z before."""
    for t_s, falling in ((0.9, False), (1.1, True), (4.0, True)):
        packet_id, _, params = parse_packet(ask(chain(ImuDevice(drop_at_s=1.0)), t_s)[0], 2.0)
        acc = struct.unpack("<3h", params[7:13])
        if falling:
            assert max(abs(a) for a in acc) < 5 * 33 and acc != (0, 0, 0)
        else:
            assert 0.99 * 16384 < acc[2] <= 16384


def test_the_scripted_times_count_from_the_lines_first_packet_not_the_hosts_clock():
    """On the pty the emulator's clock is the host's monotonic one (hours, not zero, at the first packet): a
    fall scripted at 1 s is still upright half a second after the first packet and falling 2 s after it."""
    cfg = config("op3")
    line = EmulatedChain(EmulatorConfig("dynamixel", 2.0, cfg.models_by_id, baudrate=2_000_000,
                                        imu=ImuDevice(fall_at_s=1.0)))
    boot_s = 12_345.0
    pitch_deg = []
    for t_s in (boot_s, boot_s + 0.5, boot_s + 2.0):
        params = parse_packet(ask(line, t_s)[0], 2.0)[2]
        pitch_deg.append(struct.unpack("<9h", params[1:])[7] / 10)
    assert abs(pitch_deg[0]) < 3 and abs(pitch_deg[1]) < 3  # the sway only (2 deg at most, halved in pitch)
    assert pitch_deg[2] > 80  # 120 deg/s for 1 s: lying flat (90 deg) or nearly
