"""Feetech backend: Dynamixel-1.0 framing, STS low byte first, SCS high byte first.
Expected checksums are computed by hand in the comments: ~(sum of ID..last param) & 0xFF."""

import pytest
from scservo_sdk import scservo_def

from gaitbot.bus.feetech import FeetechBus
from gaitbot.bus.dry_run import DryRunPort
from gaitbot.servos.models import SERVO_MODELS

STS = SERVO_MODELS["STS3215"]
SCS = SERVO_MODELS["SCS0009"]


def h(text: str) -> bytes:
    return bytes.fromhex(text)


def open_bus(models):
    port = DryRunPort("feetech", 1.0, models)
    bus = FeetechBus("mock", 1_000_000, 1.0, models, port_handler=port)
    bus.open()
    return bus, port


def test_sts_sync_write_low_byte_first():
    bus, port = open_bus({1: STS, 2: STS})
    bus.write_goal_ticks({1: 2048, 2: 1000})
    # addr 42 = 0x2A, len 2; 2048 -> 00 08, 1000 -> E8 03; sum FE+0A+83+2A+02+01+00+08+02+E8+03 = 0x2AD -> ~0xAD = 0x52
    assert port.tx_packets == [h("FF FF FE 0A 83 2A 02 01 00 08 02 E8 03 52")]


def test_scs_sync_write_high_byte_first():
    bus, port = open_bus({1: SCS, 2: SCS})
    bus.write_goal_ticks({1: 512, 2: 300})
    # 512 -> 02 00, 300 -> 01 2C; sum FE+0A+83+2A+02+01+02+00+02+01+2C = 0x1E9 -> ~0xE9 = 0x16
    assert port.tx_packets == [h("FF FF FE 0A 83 2A 02 01 02 00 02 01 2C 16")]


def test_sts_reads_with_one_sync_read():
    bus, port = open_bus({1: STS, 2: STS})
    assert bus.read_present_ticks([1, 2]) == {1: 2048, 2: 2048}
    # SYNC READ addr 56 = 0x38 len 2 ids 1 2: FE+06+82+38+02+01+02 = 0x1C3 -> 0x3C
    assert port.tx_packets == [h("FF FF FE 06 82 38 02 01 02 3C")]
    # status id 1, 2048 = 00 08: ~(01+04+00+00+08) = ~0x0D = 0xF2
    assert port.rx_packets[0] == h("FF FF 01 04 00 00 08 F2")


def test_scs_reads_each_servo_and_decodes_high_byte_first():
    bus, port = open_bus({1: SCS})
    bus.write_goal_ticks({1: 300})
    assert bus.read_present_ticks([1]) == {1: 300}
    # READ addr 0x38 len 2: ~(01+04+02+38+02) = ~0x41 = 0xBE; status 01 2C: ~(01+04+00+01+2C) = ~0x32 = 0xCD
    assert port.tx_packets[1:] == [h("FF FF 01 04 02 38 02 BE")]
    assert port.rx_packets == [h("FF FF 01 04 00 01 2C CD")]


def test_torque_enable_write():
    bus, port = open_bus({1: STS})
    bus.set_torque([1], True)
    # WRITE addr 40 = 0x28 value 1: ~(01+04+03+28+01) = ~0x31 = 0xCE; status ~(01+02+00) = 0xFC
    assert port.tx_packets == [h("FF FF 01 04 03 28 01 CE")]
    assert port.rx_packets == [h("FF FF 01 02 00 FC")]


def test_mixing_byte_orders_on_one_bus_is_refused():
    with pytest.raises(ValueError, match="SCS_END"):
        FeetechBus("mock", 1_000_000, 1.0, {1: STS, 5: SCS}, port_handler=DryRunPort("feetech", 1.0, {}))


def test_byte_order_global_is_set_on_open_and_reasserted_per_exchange():
    scs_bus, _ = open_bus({1: SCS})
    assert scservo_def.SCS_END == 1
    sts_bus, _ = open_bus({1: STS})
    assert scservo_def.SCS_END == 0
    assert scs_bus.ping(1)
    assert scservo_def.SCS_END == 1  # the SCS bus took its byte order back before talking


def test_stale_input_is_dropped_before_a_read():
    """scservo_sdk's clearPort does not drop input; a late reply left in the buffer must not be
    taken as the answer to the next read."""
    bus, port = open_bus({1: SCS})
    bus.write_goal_ticks({1: 300})
    # a stale but well-formed status from servo 1 saying 0x03FF: ~(01+04+00+03+FF) = ~0x107 -> 0xF8
    port.inject_input(h("FF FF 01 04 00 03 FF F8"))
    assert bus.read_present_ticks([1]) == {1: 300}
