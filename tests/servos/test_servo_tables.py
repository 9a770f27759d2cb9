"""Vendor facts are data, written once: the models' addresses come from the vendors' control tables, the
backend list and id ranges are the ones every room uses, and the table-driven CRC is the e-Manual's."""

from __future__ import annotations

import random

import pytest

from gaitbot.bus.dynamixel import DynamixelBus
from gaitbot.bus.factory import BUS_CLASSES
from gaitbot.bus.feetech import FeetechBus
from gaitbot.bus.dry_run import DryRunPort
from gaitbot.servos import BACKENDS, VENDORS, control_table, dynamixel, feetech, max_servo_id, wire
from gaitbot.servos.models import SERVO_MODELS
from gaitbot.servos.registers import overlaps
from helpers import crc16 as crc16_bit_by_bit  # the e-Manual's definition, bit by bit


def test_one_backend_list():
    assert BACKENDS == ("dynamixel", "feetech")
    assert set(BUS_CLASSES) == set(BACKENDS)
    for name, module in VENDORS.items():
        assert module.NAME == name


@pytest.mark.parametrize("name", sorted(SERVO_MODELS))
def test_models_take_their_addresses_from_the_vendor_table(name):
    model = SERVO_MODELS[name]
    table = control_table(name)
    assert model.control_table is table
    assert table["Torque Enable"].address == model.addr_torque_enable
    assert (table["Goal Position"].address, table["Goal Position"].size) == (model.addr_goal_position,
                                                                             model.len_goal_position)
    assert (table["Present Position"].address, table["Present Position"].size) == (model.addr_present_position,
                                                                                   model.len_present_position)
    assert model.model_number == VENDORS[model.family].MODEL_NUMBERS[name]
    if model.gain is not None:
        for address in model.gain.addresses:
            assert any(r.address == address and r.size == model.gain.length and r.factory == model.gain.factory_value
                       for r in table.values())


@pytest.mark.parametrize("name", sorted(SERVO_MODELS))
def test_no_two_registers_of_a_table_overlap(name):
    registers = sorted(control_table(name).values())
    for a, b in zip(registers, registers[1:]):
        assert not overlaps(a.address, a.size, b.address, b.size), (a, b)


def test_id_ranges_per_protocol_agree_between_config_and_bus():
    assert (max_servo_id("dynamixel", 2.0), max_servo_id("dynamixel", 1.0), max_servo_id("feetech", 1.0)) == \
        (252, 253, 253)
    for cls, protocol, model, top in ((DynamixelBus, 2.0, SERVO_MODELS["XL430-W250"], 252),
                                      (DynamixelBus, 1.0, SERVO_MODELS["AX-12A"], 253),
                                      (FeetechBus, 1.0, SERVO_MODELS["STS3215"], 253)):
        port = DryRunPort(cls.family, protocol, {top: model})
        cls("mock", 1_000_000, protocol, {top: model}, port_handler=port)  # accepted
        with pytest.raises(ValueError, match=f"outside 0..{top}"):
            cls("mock", 1_000_000, protocol, {top + 1: model}, port_handler=port)


def test_sdk_baud_rates_are_the_vendors():
    assert 1_000_000 in dynamixel.SDK_BAUDRATES and 4_000_000 in dynamixel.SDK_BAUDRATES
    assert 1_000_000 in feetech.SDK_BAUDRATES and 4_000_000 not in feetech.SDK_BAUDRATES
    assert not DryRunPort("feetech", 1.0, {}).setBaudRate(4_000_000)


def test_table_crc_is_the_emanual_crc():
    # e-Manual Protocol 2.0 ping example: FF FF FD 00 01 03 00 01, CRC 19 4E
    assert wire.crc16(bytes.fromhex("FFFFFD0001030001")) == 0x4E19
    rng = random.Random(0)
    for _ in range(500):
        data = bytes(rng.randrange(256) for _ in range(rng.randrange(0, 64)))
        assert wire.crc16(data) == crc16_bit_by_bit(data)


def test_addressed_parameters_by_framing():
    assert wire.address_length_and_rest(bytes([0x74, 0x00, 0x04, 0x00, 1, 2]), "v2") == (116, 4, bytes([1, 2]))
    assert wire.address_length_and_rest(bytes([30, 2, 1, 2]), "v1") == (30, 2, bytes([1, 2]))
    assert wire.address_and_rest(bytes([64, 1]), "v1") == (64, bytes([1]))
