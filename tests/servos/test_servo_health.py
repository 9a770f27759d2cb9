"""Servo health and bring-up facts as data: health blocks, their decoding, each model's own limits, the default
thresholds, baud-rate tables. Expected figures are the vendors' (vendor-facts.md sections 2, 3, 8, 9), written
out here, not computed from gaitbot's tables."""

from __future__ import annotations

import pytest

from gaitbot.servos import baud_register_value, common_baud_rates, factory_baudrate
from gaitbot.servos.health import decode_health, decode_load, default_thresholds, encode_load, health_block, servo_limits
from gaitbot.servos.models import SERVO_MODELS


@pytest.mark.parametrize("name, address, length, has_load", [
    ("XL430-W250", 126, 21, True), ("XM430-W350", 132, 15, False), ("XL-320", 37, 10, True),
    ("AX-12A", 36, 8, True), ("STS3215", 56, 8, True), ("SCS0009", 56, 8, True)])
def test_health_blocks_are_the_contiguous_runs_of_the_control_tables(name, address, length, has_load):
    block = health_block(SERVO_MODELS[name])
    assert (block.address, block.length) == (address, length)
    assert (block.load is not None) == has_load


def test_decoding_an_x_series_block_by_hand():
    # XL430 126..146: load -12.5 % (0xFF83), velocity 0, position 2100 (signed 4 bytes), 12.1 V, 41 C
    data = bytearray(21)
    data[0:2] = (-125 & 0xFFFF).to_bytes(2, "little")
    data[6:10] = (2100).to_bytes(4, "little")
    data[18:20] = (121).to_bytes(2, "little")
    data[20] = 41
    r = decode_health(health_block(SERVO_MODELS["XL430-W250"]), 7, bytes(data))
    assert (r.servo_id, r.position_ticks, r.voltage_v, r.temperature_c, r.load_pct) == (7, 2100, 12.1, 41.0, -12.5)


def test_decoding_a_big_endian_scs_block_by_hand():
    # SCS0009 56..63, words high byte first: position 600, speed 0, load bit 10 set + 300 (CW 30 %), 5.9 V, 38 C
    data = bytes([0x02, 0x58, 0, 0, 0x05, 0x2C, 59, 38])
    r = decode_health(health_block(SERVO_MODELS["SCS0009"]), 1, data)
    assert (r.position_ticks, r.load_pct, r.voltage_v, r.temperature_c) == (600, -30.0, 5.9, 38.0)


@pytest.mark.parametrize("load", [0.0, 12.5, -40.0, 99.9, -100.0])
@pytest.mark.parametrize("encoding, size", [("signed", 2), ("bit10", 2)])
def test_load_encodings_round_trip(load, encoding, size):
    assert decode_load(encode_load(load, encoding, size), encoding, size) == pytest.approx(load)


@pytest.mark.parametrize("name, shutdown_c, min_v, register_min_v", [
    ("XL430-W250", 72, 6.5, 6.0), ("XM430-W350", 80, 10.0, 9.5), ("XL-320", 65, 6.0, 6.0),
    ("AX-12A", 70, 9.0, 6.0), ("STS3215", 70, 6.0, 4.0), ("SCS0009", 70, 4.8, 4.0)])
def test_each_models_own_limits_and_the_default_thresholds(name, shutdown_c, min_v, register_min_v):
    limits = servo_limits(name)
    assert (limits.shutdown_temperature_c, limits.min_input_v, limits.min_voltage_register_v) == \
        (shutdown_c, min_v, register_min_v)
    t = default_thresholds(name)
    assert (t.warn_temperature_c, t.stop_temperature_c) == (shutdown_c - 10, shutdown_c - 5)
    assert (t.stop_voltage_v, t.warn_voltage_v) == (min_v, pytest.approx(min_v + 0.5))
    assert t.warn_load_pct == 80


def test_factory_baud_rates_and_register_values():
    assert [factory_baudrate(n) for n in ("XL430-W250", "XM430-W350", "XL-320", "AX-12A", "STS3215", "SCS0009")] == \
        [57_600, 57_600, 1_000_000, 1_000_000, 1_000_000, 1_000_000]
    assert baud_register_value("XL430-W250", 1_000_000) == 3 and baud_register_value("XL430-W250", 57_600) == 1
    assert baud_register_value("AX-12A", 1_000_000) == 1 and baud_register_value("AX-12A", 57_600) == 34
    assert baud_register_value("STS3215", 57_600) == 6 and baud_register_value("STS3215", 76_800) == 5  # Feetech's table
    assert baud_register_value("XL430-W250", 500_000) is None


def test_scanned_rates_are_what_a_register_holds_and_the_sdk_opens():
    assert common_baud_rates("dynamixel", 2.0) == (4_000_000, 3_000_000, 2_000_000, 1_000_000, 115_200, 57_600, 9_600)
    assert common_baud_rates("dynamixel", 1.0, ["AX-12A"]) == (1_000_000, 500_000, 115_200, 57_600, 19_200, 9_600)
    assert common_baud_rates("feetech", 1.0) == (1_000_000, 500_000, 250_000, 128_000, 115_200, 57_600, 38_400)
