"""The emulator's bring-up side at the byte level: EEPROM id and baud writes, the line's baud rate, the Feetech
lock over a power cycle, factory-fresh chains plugged one at a time, collisions, heat and a sagging supply.

Packets are built here from the protocol documents (gaitbot.servos.wire framing) and fed to the chain
directly; expected values are the vendors' (factory id 1, X series at 57,600 baud) or worked by hand.
"""

from __future__ import annotations

import math

import pytest

import gaitbot.emulator as se
from gaitbot.emulator.units import ACCESS_ERROR
from gaitbot.servos import wire
from gaitbot.servos.models import servo_model

XL430, AX12, STS, SCS = (servo_model(n) for n in ("XL430-W250", "AX-12A", "STS3215", "SCS0009"))


def build(framing, servo_id, instruction, params=b""):
    return (wire.build_v2 if framing == "v2" else wire.build_v1)(servo_id, instruction, params)


def addr(framing, address, *rest):
    head = bytes([address & 0xFF, address >> 8]) if framing == "v2" else bytes([address])
    return head + bytes(rest)


def read(framing, servo_id, address, length):
    params = addr(framing, address) + (bytes([length, 0]) if framing == "v2" else bytes([length]))
    return build(framing, servo_id, wire.INST_READ, params)


def ask(chain, packet, now_s):
    chain.receive(packet, now_s)
    return [wire.parse(r, chain.framing, status=True) for r in chain.due(now_s + 1.0)]


def fresh(backend, protocol, *models, **kwargs):
    return se.EmulatedChain(se.EmulatorConfig(backend, protocol, {}, fresh=tuple(models), **kwargs))


CASES = [("dynamixel", 2.0, XL430, 57_600), ("dynamixel", 1.0, AX12, 1_000_000), ("feetech", 1.0, STS, 1_000_000)]


@pytest.mark.parametrize("backend, protocol, model, factory_rate", CASES)
def test_a_fresh_servo_answers_at_id_1_and_its_factory_rate_only(backend, protocol, model, factory_rate):
    chain = fresh(backend, protocol, model)
    framing = chain.framing
    chain.line_baud = factory_rate
    (reply,) = ask(chain, build(framing, 1, wire.INST_PING), 1.0)
    assert reply.packet_id == 1 and reply.checksum_ok
    chain.line_baud = 115_200
    assert ask(chain, build(framing, 1, wire.INST_PING), 2.0) == []  # it hears noise at another rate


@pytest.mark.parametrize("backend, protocol, model, factory_rate", CASES)
def test_id_and_baud_writes_take_effect_at_once_and_survive_a_power_cycle(backend, protocol, model, factory_rate):
    chain = fresh(backend, protocol, model)
    framing, table = chain.framing, model.control_table
    chain.line_baud = factory_rate
    if backend == "feetech":  # unlock the EEPROM first, or the writes are lost at power-off
        ask(chain, build(framing, 1, wire.INST_WRITE, addr(framing, table["Lock"].address, 0)), 1.0)
    ask(chain, build(framing, 1, wire.INST_WRITE, addr(framing, table["ID"].address, 13)), 1.1)
    assert ask(chain, build(framing, 1, wire.INST_PING), 1.2) == []
    assert [r.packet_id for r in ask(chain, build(framing, 13, wire.INST_PING), 1.3)] == [13]
    new_rate, value = (115_200, 2) if backend == "dynamixel" and protocol == 2.0 else \
        (57_600, 34) if backend == "dynamixel" else (57_600, 6)
    ask(chain, build(framing, 13, wire.INST_WRITE, addr(framing, table["Baud Rate"].address, value)), 1.4)
    assert ask(chain, build(framing, 13, wire.INST_PING), 1.5) == []  # still at the old rate: silence
    chain.line_baud = new_rate
    assert [r.packet_id for r in ask(chain, build(framing, 13, wire.INST_PING), 1.6)] == [13]
    chain.power_cycle()
    assert [r.packet_id for r in ask(chain, build(framing, 13, wire.INST_PING), 1.7)] == [13]
    assert [(w[1], w[2], w[3][0]) for w in chain.writes if w[2] != table.get("Lock", (None,))[0]] == \
        [(1, table["ID"].address, 13), (13, table["Baud Rate"].address, value)]


def test_a_feetech_id_written_with_the_lock_on_is_lost_at_power_off():
    chain = fresh("feetech", 1.0, STS)
    ask(chain, build("v1", 1, wire.INST_WRITE, bytes([5, 7])), 1.0)  # ID = 7 with Lock = 1 (its power-on state)
    assert [r.packet_id for r in ask(chain, build("v1", 7, wire.INST_PING), 1.1)] == [7]
    chain.power_cycle()
    assert [r.packet_id for r in ask(chain, build("v1", 1, wire.INST_PING), 1.2)] == [1]
    assert ask(chain, build("v1", 7, wire.INST_PING), 1.3) == []


def test_a_protocol2_servo_refuses_an_eeprom_write_with_torque_on():
    chain = fresh("dynamixel", 2.0, XL430)
    ask(chain, build("v2", 1, wire.INST_WRITE, addr("v2", 64, 1)), 1.0)  # torque on
    (reply,) = ask(chain, build("v2", 1, wire.INST_WRITE, addr("v2", 7, 9)), 1.1)
    assert reply.error == ACCESS_ERROR
    assert chain.units[0].servo_id == 1 and chain.writes[-1][-1] is False


def test_two_servos_at_one_id_garble_each_other_and_a_write_reaches_both():
    chain = fresh("dynamixel", 2.0, XL430, XL430)
    (reply,) = ask(chain, build("v2", 1, wire.INST_PING), 1.0)
    assert not reply.checksum_ok
    ask(chain, build("v2", 1, wire.INST_WRITE, addr("v2", 65, 1)), 1.1)  # LED on: both hear it
    assert [u.table[65] for u in chain.units] == [1, 1]


def test_broadcast_pings_protocol2_servos_take_turns_feetech_servos_collide():
    chain = fresh("dynamixel", 2.0, XL430, XL430)
    chain.units[1].table[7] = 2
    replies = ask(chain, build("v2", 0xFE, wire.INST_PING), 1.0)
    assert [(r.packet_id, r.checksum_ok) for r in replies] == [(1, True), (2, True)]
    chain = fresh("feetech", 1.0, STS, STS)
    chain.units[1].table[5] = 2
    (reply,) = ask(chain, build("v1", 0xFE, wire.INST_PING), 1.0)
    assert not reply.checksum_ok
    chain = fresh("feetech", 1.0, STS)
    (reply,) = ask(chain, build("v1", 0xFE, wire.INST_PING), 1.0)
    assert reply.checksum_ok and reply.packet_id == 1  # one servo alone answers a broadcast ping cleanly
    chain = fresh("dynamixel", 1.0, AX12)
    assert ask(chain, build("v1", 0xFE, wire.INST_PING), 1.0) == []  # Protocol 1.0: no status to a broadcast


def test_one_at_a_time_plugs_the_next_servo_and_unplugs_the_last():
    chain = fresh("dynamixel", 1.0, AX12, AX12, AX12, one_at_a_time=True)
    assert [u.connected for u in chain.units] == [True, False, False]
    assert chain.plug_next().index == 1 and [u.connected for u in chain.units] == [False, True, False]
    chain.plug_next()
    assert chain.plug_next() is None


def test_a_servo_holding_a_load_warms_then_cools_and_shuts_down_at_its_limit():
    heat = se.Heat(ambient_c=25.0, heat_c_per_s=2.0, cool_time_s=100.0)
    config = se.EmulatorConfig("dynamixel", 2.0, {1: XL430}, heat=heat, loads_pct={1: 50.0})
    chain = se.EmulatedChain(config)
    block_read = read("v2", 1, 146, 1)  # Present Temperature
    ask(chain, block_read, 0.0)  # time starts
    ask(chain, build("v2", 1, wire.INST_WRITE, addr("v2", 64, 1)), 0.0)  # torque on: it holds 50 %
    (reply,) = ask(chain, block_read, 10.0)
    equilibrium = 25.0 + 2.0 * 0.25 * 100.0  # heat x load^2 x tau = 50 C above ambient
    expected = equilibrium + (25.0 - equilibrium) * math.exp(-10.0 / 100.0)
    assert reply.params[0] == round(expected)
    (load,) = ask(chain, read("v2", 1, 126, 2), 10.0)
    assert int.from_bytes(load.params, "little", signed=True) == 500  # 50.0 % in 0.1 % units
    ask(chain, build("v2", 1, wire.INST_WRITE, addr("v2", 64, 0)), 10.0)  # torque off: it cools
    (reply,) = ask(chain, block_read, 20.0)
    assert reply.params[0] == round(25.0 + (expected - 25.0) * math.exp(-10.0 / 100.0))
    chain.units[0].temperature_c = 71.9
    chain.units[0].load_pct = 100.0
    ask(chain, build("v2", 1, wire.INST_WRITE, addr("v2", 64, 1)), 20.0)
    (reply,) = ask(chain, block_read, 21.0)  # past its Temperature Limit (72 C)
    assert reply.error & 0x80 and chain.units[0].table[70] & 0x04  # Alert; Hardware Error Status: overheating
    assert chain.units[0].table[64] == 0  # its Shutdown setting switched torque off


def test_the_supply_sags_once_faults_start_and_the_servo_reports_input_voltage():
    faults = se.Faults(after_s=1.0)
    config = se.EmulatorConfig("feetech", 1.0, {1: STS}, faults=faults, supply_v=7.4, voltage_sag_v_per_s=1.0)
    chain = se.EmulatedChain(config)
    voltage = read("v1", 1, 62, 1)
    assert ask(chain, voltage, 0.0)[0].params[0] == 74  # first packet: time zero
    assert ask(chain, voltage, 0.9)[0].params[0] == 74
    assert ask(chain, voltage, 1.0)[0].params[0] == 74  # faults (and the sag) start now
    assert ask(chain, voltage, 3.0)[0].params[0] == 54
    (reply,) = ask(chain, voltage, 4.5)  # 3.9 V: under its Min Voltage Limit (4.0 V)
    assert reply.params[0] == 39 and reply.error & 0x01


def test_a_reply_sent_at_a_rate_the_host_left_is_lost():
    chain = fresh("dynamixel", 2.0, XL430)
    chain.line_baud = 57_600
    chain.receive(build("v2", 1, wire.INST_PING), 1.0)
    chain.line_baud = 1_000_000  # the host switched before the status packet came
    assert chain.due(2.0) == []
