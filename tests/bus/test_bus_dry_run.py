"""The mock port: a healthy chain under the real backend classes, answering in virtual time."""

import time

import pytest
import dynamixel_sdk
import scservo_sdk

from gaitbot.bus import make_bus, make_dry_run_bus
from gaitbot.bus.dynamixel import DynamixelBus
from gaitbot.bus.feetech import FeetechBus
from gaitbot.bus.dry_run import DryRunPort
from gaitbot.servos.models import SERVO_MODELS

CASES = [("dynamixel", 2.0, "XL430-W250"), ("dynamixel", 1.0, "XM430-W350"), ("dynamixel", 2.0, "XL-320"),
         ("dynamixel", 1.0, "AX-12A"), ("feetech", 1.0, "STS3215"), ("feetech", 1.0, "SCS0009")]


@pytest.mark.parametrize("backend, protocol, name", CASES)
def test_reads_answer_centre_then_last_goal(backend, protocol, name):
    model = SERVO_MODELS[name]
    with make_dry_run_bus(backend, protocol, {3: model, 4: model}) as bus:
        assert bus.read_present_ticks([3, 4]) == {3: model.centre_tick, 4: model.centre_tick}
        bus.write_goal_ticks({3: model.min_tick + 7, 4: model.max_tick})
        assert bus.read_present_ticks([4, 3]) == {4: model.max_tick, 3: model.min_tick + 7}
        assert bus.scan(range(1, 7)) == [3, 4]


def test_dry_run_is_the_real_backend_class_on_a_mock_port():
    models = {1: SERVO_MODELS["XL430-W250"]}
    dry = make_bus("dynamixel", 2.0, "/dev/ttyUSB0", 1_000_000, models, interface="dry-run")
    real = make_bus("dynamixel", 2.0, "/dev/ttyUSB0", 1_000_000, models, interface="serial")
    assert type(dry) is type(real) is DynamixelBus
    assert isinstance(dry.port, DryRunPort)
    assert type(real.port) is dynamixel_sdk.PortHandler  # constructed, not opened
    sts = make_bus("feetech", 1.0, "/dev/ttyUSB0", 1_000_000, {1: SERVO_MODELS["STS3215"]}, interface="serial")
    assert type(sts) is FeetechBus and type(sts.port) is scservo_sdk.PortHandler


def test_unknown_backend_is_refused():
    with pytest.raises(ValueError, match="unknown bus backend 'herkulex'"):
        make_bus("herkulex", 1.0, "x", 115200, {}, interface="dry-run")


def test_missing_servo_costs_no_wall_clock_time(monkeypatch):
    """Timeouts are virtual: with every clock broken, a ping of an absent servo still returns."""
    with make_dry_run_bus("dynamixel", 2.0, {1: SERVO_MODELS["XL430-W250"]}) as bus:
        def no_clock(*_):
            raise AssertionError("the mock consulted a real clock")
        for name in ("time", "monotonic", "perf_counter", "sleep"):
            monkeypatch.setattr(time, name, no_clock)
        assert bus.ping(9) is False


def test_damaged_instruction_gets_no_answer():
    port = DryRunPort("dynamixel", 1.0, {1: SERVO_MODELS["AX-12A"]})
    port.writePort(bytes.fromhex("FF FF 01 02 01 FA"))  # ping with checksum FA instead of FB
    assert port.getBytesAvailable() == 0
    assert port.rejected and "checksum" in port.rejected[0][1]
    port.writePort(bytes.fromhex("FF FF 01 02 01 FB"))
    assert port.readPort(100) == bytes.fromhex("FF FF 01 02 00 FC")


def test_protocol2_status_with_ff_ff_fd_in_data_is_stuffed():
    port = DryRunPort("dynamixel", 2.0, {1: SERVO_MODELS["XL430-W250"]})
    port.tables[1][132:136] = bytes.fromhex("FF FF FD 00")
    port.writePort(bytes.fromhex("FF FF FD 00 01 07 00 02 84 00 04 00 1D 15"))  # e-Manual read example
    reply = port.readPort(100)
    # INST 55, ERR 00, data FF FF FD [FD] 00: 7 payload bytes + CRC -> LEN 9
    assert reply[:14] == bytes.fromhex("FF FF FD 00 01 09 00 55 00 FF FF FD FD 00")


def test_reply_timeout_option_replaces_the_sdk_timeout():
    """--reply-timeout-ms: the SDK's timeout is packet bytes at the baud rate + 2 x 16 ms + 2 ms;
    with the option it is packet bytes at the baud rate + the given milliseconds."""
    from gaitbot.bus.factory import make_bus
    from gaitbot.servos.models import servo_model

    model = servo_model("XL430-W250")
    bus = make_bus("dynamixel", 2.0, "/dev/null-not-opened", 1_000_000, {1: model}, interface="serial",
                   reply_timeout_ms=250.0)
    handler = bus.port
    handler.tx_time_per_byte = 0.01  # ms per byte at 1 Mbaud, as setBaudRate would set it
    handler.setPacketTimeout(10)
    assert handler.packet_timeout == 10 * 0.01 + 250.0
