"""Frame budget: byte counts from the packet layouts, counted by hand in the comments."""

import pytest

from gaitbot.servos.budget import check_rate, frame_budget, max_rate_hz
from gaitbot.servos.models import SERVO_MODELS

X = SERVO_MODELS["XL430-W250"]


def test_protocol2_write_and_sync_read_bytes():
    b = frame_budget("dynamixel", 2.0, X, 12, 57_600, read_back=False)
    assert b.bytes_per_frame == 14 + 12 * 5  # header 4, id, len 2, inst, addr 2, len 2, crc 2; id + 4 data each
    b = frame_budget("dynamixel", 2.0, X, 12, 57_600, read_back=True)
    # + sync read (14 + 12 ids) + 12 status packets of (4 hdr + id + len 2 + inst + err + 4 data + crc 2) = 15
    assert b.bytes_per_frame == 74 + 26 + 12 * 15 == 280
    assert b.wire_time_s == pytest.approx(280 * 10 / 57_600 + 12 * 500e-6)


def test_protocol1_reads_each_servo():
    b = frame_budget("dynamixel", 1.0, "AX-12A", 6, 1_000_000, read_back=True)
    # sync write 8 + 6 * 3; each read 8 bytes + status 6 + 2
    assert (b.write_bytes, b.read_bytes) == (26, 6 * 16)


def test_feetech_sts_sync_read_and_scs_single_reads():
    sts = frame_budget("feetech", 1.0, "STS3215", 6, 1_000_000, read_back=True)
    scs = frame_budget("feetech", 1.0, "SCS0009", 6, 1_000_000, read_back=True)
    assert sts.read_bytes == 8 + 6 + 6 * 8
    assert scs.read_bytes == 6 * (8 + 8)


def test_twelve_x_servos_at_57600_baud_cannot_carry_60_hz_with_reads():
    with pytest.raises(ValueError, match="60 Hz is too fast"):
        check_rate(60, "dynamixel", 2.0, X, 12, 57_600, read_back=True)


def test_twelve_x_servos_at_1_mbps_carry_60_hz_with_reads():
    budget = check_rate(60, "dynamixel", 2.0, X, 12, 1_000_000, read_back=True)
    assert budget.wire_time_s < 0.7 / 60


def test_max_rate_is_the_boundary_of_check_rate():
    limit_hz = max_rate_hz("feetech", 1.0, "STS3215", 12, 500_000, read_back=True)
    check_rate(limit_hz * 0.99, "feetech", 1.0, "STS3215", 12, 500_000, read_back=True)
    with pytest.raises(ValueError):
        check_rate(limit_hz * 1.01, "feetech", 1.0, "STS3215", 12, 500_000, read_back=True)
