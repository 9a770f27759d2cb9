"""Dynamixel backend: packets byte for byte against the ROBOTIS e-Manual examples
(docs/en/dxl/protocol2.md and protocol1.md) or against checksums computed by hand below."""

import pytest
import dynamixel_sdk

from gaitbot.bus import PortError, ServoTimeout
from gaitbot.bus.dynamixel import DynamixelBus, StuffingProtocol2PacketHandler
from gaitbot.bus.dry_run import DryRunPort
from gaitbot.servos.models import SERVO_MODELS

XM = SERVO_MODELS["XM430-W350"]  # same X-series layout as the XM430-W210 used in the e-Manual examples
AX = SERVO_MODELS["AX-12A"]


def h(text: str) -> bytes:
    return bytes.fromhex(text)


def reference_crc16(data: bytes) -> int:
    """CRC-16/0x8005 bit by bit, as the e-Manual's CRC page describes; checked on doc vectors below."""
    crc = 0
    for byte in data:
        for bit in range(7, -1, -1):
            top = (crc >> 15) ^ ((byte >> bit) & 1)
            crc = ((crc << 1) & 0xFFFF) ^ (0x8005 if top else 0)
    return crc


def with_crc(body: bytes) -> bytes:
    crc = reference_crc16(body)
    return body + bytes([crc & 0xFF, crc >> 8])


def open_bus(protocol, models, baudrate=1_000_000):
    port = DryRunPort("dynamixel", protocol, models)
    bus = DynamixelBus("mock", baudrate, protocol, models, port_handler=port)
    bus.open()
    return bus, port


@pytest.mark.parametrize("packet", [
    "FF FF FD 00 01 03 00 01 19 4E",  # ping
    "FF FF FD 00 01 07 00 55 00 06 04 26 65 5D",  # ping status
    "FF FF FD 00 01 09 00 03 74 00 00 02 00 00 CA 89",  # write
    "FF FF FD 00 FE 09 00 82 84 00 04 00 01 02 CE FA",  # sync read
    "FF FF FD 00 FE 11 00 83 74 00 04 00 01 96 00 00 00 02 AA 00 00 00 82 87",  # sync write
])
def test_reference_crc_reproduces_emanual_examples(packet):
    raw = h(packet)
    assert with_crc(raw[:-2]) == raw


def test_protocol2_sync_write_is_the_emanual_example():
    bus, port = open_bus(2.0, {1: XM, 2: XM})
    bus.write_goal_ticks({1: 150, 2: 170})
    assert port.tx_packets == [h("FF FF FD 00 FE 11 00 83 74 00 04 00 01 96 00 00 00 02 AA 00 00 00 82 87")]
    assert port.rx_packets == []  # sync write is broadcast: no status packet


def test_protocol2_sync_read_is_the_emanual_example():
    bus, port = open_bus(2.0, {1: XM, 2: XM})
    bus.write_goal_ticks({1: 166, 2: 2079})
    assert bus.read_present_ticks([1, 2]) == {1: 166, 2: 2079}
    assert port.tx_packets[-1] == h("FF FF FD 00 FE 09 00 82 84 00 04 00 01 02 CE FA")
    assert port.rx_packets == [h("FF FF FD 00 01 08 00 55 00 A6 00 00 00 8C C0"),
                               h("FF FF FD 00 02 08 00 55 00 1F 08 00 00 BA BE")]


def test_protocol2_ping_is_the_emanual_example():
    bus, port = open_bus(2.0, {1: XM})
    assert bus.ping(1) is True
    assert port.tx_packets == [h("FF FF FD 00 01 03 00 01 19 4E")]
    assert bus.ping(2) is False


def test_protocol2_torque_enable_write():
    bus, port = open_bus(2.0, {1: XM})
    bus.set_torque([1], True)
    # Write instruction, Torque Enable address 64 = 0x40 0x00, value 1; LEN = 1 + 2 + 1 + 2 = 6
    assert port.tx_packets == [with_crc(h("FF FF FD 00 01 06 00 03 40 00 01"))]
    assert port.rx_packets == [h("FF FF FD 00 01 04 00 55 00 A1 0C")]  # e-Manual write status example
    assert port.tables[1][64] == 1


def test_protocol2_byte_stuffing_reaches_the_wire():
    """FF FF FD inside the data must go out as FF FF FD FD, with LENGTH and CRC over the stuffed bytes."""
    port = DryRunPort("dynamixel", 2.0, {1: XM})
    handler = StuffingProtocol2PacketHandler()
    result, error = handler.writeTxRx(port, 1, 224, 3, [0xFF, 0xFF, 0xFD])  # Indirect Data 1..3
    assert (result, error) == (dynamixel_sdk.COMM_SUCCESS, 0)
    # INST 03, ADDR E0 00, data FF FF FD + stuffed FD: 7 bytes + CRC 2 -> LEN 9
    assert port.tx_packets == [with_crc(h("FF FF FD 00 01 09 00 03 E0 00 FF FF FD FD"))]
    assert bytes(port.tables[1][224:227]) == h("FF FF FD")  # the servo sees the unstuffed data


def test_protocol1_ping_is_the_emanual_example():
    bus, port = open_bus(1.0, {1: AX})
    assert bus.ping(1) is True
    assert port.tx_packets[0] == h("FF FF 01 02 01 FB")
    assert port.rx_packets[0] == h("FF FF 01 02 00 FC")
    # the SDK then reads the model number: READ addr 0, 2 bytes; checksum ~(01+04+02+00+02) = ~0x09 = 0xF6
    assert port.tx_packets[1] == h("FF FF 01 04 02 00 02 F6")


def test_protocol1_sync_write_checksum_by_hand():
    bus, port = open_bus(1.0, {1: AX, 2: AX})
    bus.write_goal_ticks({1: 0x010, 2: 0x220})
    # FE+0A+83+1E+02+01+10+00+02+20+02 = 0x1E0 -> ~0xE0 = 0x1F; LEN = (2+1)*2 + 4 = 0x0A
    assert port.tx_packets == [h("FF FF FE 0A 83 1E 02 01 10 00 02 20 02 1F")]


def test_protocol1_reads_each_servo():
    bus, port = open_bus(1.0, {1: AX, 2: AX})
    bus.write_goal_ticks({1: 0x010, 2: 0x220})
    assert bus.read_present_ticks([1, 2]) == {1: 0x010, 2: 0x220}
    # READ addr 36 (0x24) len 2: ~(01+04+02+24+02) = ~0x2D = 0xD2; id 2: 0xD1
    assert port.tx_packets[1:] == [h("FF FF 01 04 02 24 02 D2"), h("FF FF 02 04 02 24 02 D1")]
    # status id 1: ~(01+04+00+10+00) = ~0x15 = 0xEA
    assert port.rx_packets[0] == h("FF FF 01 04 00 10 00 EA")


def test_lost_status_packet_is_retried_not_fatal():
    bus, port = open_bus(2.0, {1: XM, 2: XM})
    port.drop_next_replies(1)
    assert bus.read_present_ticks([1, 2]) == {1: 2048, 2: 2048}
    assert len(port.tx_packets) == 2  # one sync read lost a status packet, the retry got both


def test_read_gives_up_after_bounded_retries():
    port = DryRunPort("dynamixel", 2.0, {1: XM})
    bus = DynamixelBus("mock", 1_000_000, 2.0, {1: XM}, port_handler=port, retries=2)
    bus.open()
    port.drop_next_replies(3)
    with pytest.raises(ServoTimeout) as info:
        bus.read_present_ticks([1])
    assert info.value.servo_id == 1
    assert len(port.tx_packets) == 3


def test_negative_present_position_is_twos_complement():
    bus, port = open_bus(2.0, {1: XM})
    port.tables[1][132:136] = h("FE FF FF FF")
    assert bus.read_present_ticks([1]) == {1: -2}


def test_goal_outside_model_range_is_refused():
    bus, _ = open_bus(2.0, {1: XM})
    with pytest.raises(ValueError, match="4096 ticks for servo 1"):
        bus.write_goal_ticks({1: 4096})


def test_models_with_different_layouts_cannot_share_a_bus():
    with pytest.raises(ValueError, match="different addresses"):
        DynamixelBus("mock", 1_000_000, 1.0, {1: XM, 2: AX}, port_handler=DryRunPort("dynamixel", 1.0, {}))


def test_protocol_the_servo_does_not_speak_is_refused():
    with pytest.raises(ValueError, match="does not speak protocol 2.0"):
        DynamixelBus("mock", 1_000_000, 2.0, {1: AX}, port_handler=DryRunPort("dynamixel", 2.0, {}))


def test_unsupported_baud_rate_is_a_port_error():
    port = DryRunPort("dynamixel", 2.0, {1: XM})
    with pytest.raises(PortError, match="12345 baud"):
        DynamixelBus("mock", 12345, 2.0, {1: XM}, port_handler=port).open()


def test_missing_serial_port_names_the_port_and_how_to_list_ports():
    bus = DynamixelBus("/dev/gaitbot-no-such-port", 1_000_000, 2.0, {1: XM})
    with pytest.raises(PortError, match="/dev/gaitbot-no-such-port.*list_ports"):
        bus.open()
