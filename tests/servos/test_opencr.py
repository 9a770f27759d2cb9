"""The OpenCR's IMU block, byte-exact against the OP3 firmware's control table, written here independently:
Gyro_X/Y/Z int16 at 32/34/36, Acc_X/Y/Z at 38/40/42, Roll/Pitch/Yaw at 44/46/48, little-endian
(ROBOTIS-GIT/OpenCR .../opencr_op3/dxl_node_op3.h); 16.4 LSB per deg/s, 16384 LSB per g, the fused angles
in tenths of a degree; the board turned 180 deg about z in the OP3 (ROBOTIS-OP3 open_cr_module.cpp)."""

from __future__ import annotations

import numpy as np
import pytest

from gaitbot.servos import opencr


def firmware_bytes(board_values: list[int]) -> bytes:
    """The 18 bytes from address 32 as the firmware's packed struct holds them."""
    out = bytearray()
    for v in board_values:
        out += (v & 0xFFFF).to_bytes(2, "little")
    return bytes(out)


def test_the_block_sits_where_the_firmware_puts_it_and_reads_in_one_read():
    assert opencr.IMU_BLOCK == (32, 18)
    table = opencr.initial_table()
    assert table[0] | table[1] << 8 == 0x7400 and table[2] == 2 and table[3] == 200
    # Protocol 2.0 READ of 18 bytes: 14-byte instruction, 11 + 18 byte status, 10 bits a byte at 2 Mbaud
    assert opencr.IMU_READ_WIRE_S == pytest.approx((14 + 29) * 10 / 2e6)


def test_a_reading_encodes_to_the_firmwares_bytes():
    # robot frame: pitching forward at 10 deg/s, rolling at -20, yawing at 30; standing: +1 g up; fused angles
    block = opencr.encode_imu_block([-20.0, 10.0, 30.0], [0.0, 0.0, 1.0], [1.5, -2.5, 90.0])
    board = [round(20 * 16.4), round(-10 * 16.4), round(30 * 16.4), 0, 0, 16384, 15, -25, 900]
    assert block == firmware_bytes(board)


def test_decoding_is_the_inverse_within_one_lsb():
    rng = np.random.default_rng(3)
    for _ in range(50):
        gyro, acc, rpy = rng.uniform(-1500, 1500, 3), rng.uniform(-1.9, 1.9, 3), rng.uniform(-170, 170, 3)
        reading = opencr.decode_imu_block(opencr.encode_imu_block(gyro, acc, rpy))
        assert np.allclose(reading.gyro_dps, gyro, atol=0.5 / 16.4)
        assert np.allclose(reading.acc_g, acc, atol=0.5 / 16384)
        assert np.allclose(reading.fused_rpy_deg, rpy, atol=0.05)


def test_out_of_range_values_saturate_and_a_wrong_length_is_refused():
    block = opencr.encode_imu_block([5000.0, 0, 0], [0, 0, 9.0], [0, 0, 0])
    assert block[0:2] == (-32768 & 0xFFFF).to_bytes(2, "little")  # board x = -robot x
    assert block[10:12] == (32767).to_bytes(2, "little")
    with pytest.raises(ValueError, match="18 bytes"):
        opencr.decode_imu_block(b"\x00" * 17)
