"""The servo emulator at the byte level, against the protocol documents (no driver code involved).

Expected bytes are the ROBOTIS e-Manual's examples or checksums worked by hand, not the
emulator's own output. The emulated chain is fed instruction packets directly and its
scheduled replies are read back, so these tests cost no wall-clock time.
"""

from __future__ import annotations

import os
import select
import signal
import time

import pytest

from gaitbot.servos import wire
from gaitbot.bus.recording import decode_goal_frames
from gaitbot.servos.models import servo_model
import gaitbot.emulator as se
from gaitbot.app import emulator as emulator_cli
from helpers import REPO_ROOT

ROOT = REPO_ROOT


XL430, AX12, STS, SCS = (servo_model(n) for n in ("XL430-W250", "AX-12A", "STS3215", "SCS0009"))


def h(text: str) -> bytes:
    return bytes.fromhex(text.replace(" ", ""))


def chain(backend, protocol, model, ids=(1,), faults=None, **kwargs):
    config = se.EmulatorConfig(backend, protocol, {i: model for i in ids}, faults=faults or se.Faults(), **kwargs)
    return se.EmulatedChain(config)


def ask(c, packet: bytes, now_s: float = 1.0) -> list[bytes]:
    c.receive(packet, now_s)
    return c.due(now_s + 10.0)


def test_protocol2_ping_answer_is_the_emanual_example():
    # e-Manual Protocol 2.0 ping example: ID 1, model 1060 (0x0424), firmware 0x26 -> CRC 65 5D
    c = chain("dynamixel", 2.0, XL430)
    c.tables[1][6] = 0x26
    replies = ask(c, h("FF FF FD 00 01 03 00 01 19 4E"))
    frame = wire.parse(replies[0], "v2", status=True)
    assert frame.checksum_ok and frame.packet_id == 1 and frame.error == 0
    assert frame.params[:2] == (1060).to_bytes(2, "little")


def test_protocol2_read_present_position_example_and_crc():
    # e-Manual read example: ID 1, address 132, 4 bytes; status carries the 4 bytes with a valid CRC
    c = chain("dynamixel", 2.0, XL430)
    (reply,) = ask(c, h("FF FF FD 00 01 07 00 02 84 00 04 00 1D 15"))
    assert reply[:9] == h("FF FF FD 00 01 08 00 55 00")
    assert int.from_bytes(reply[9:13], "little") == 2048
    assert wire.crc16(reply[:-2]) == reply[-2] | reply[-1] << 8


def test_protocol2_stuffs_what_it_sends_and_unstuffs_what_it_accepts():
    c = chain("dynamixel", 2.0, XL430)
    # FF FF FD 00 written to address 200 (X series Indirect Data): the data would look like a header
    packet = wire.build_v2(1, wire.INST_WRITE, bytes([200, 0x00]) + h("FF FF FD 00"))
    assert h("FF FF FD FD") in packet  # the instruction as sent on the wire is stuffed
    ask(c, packet)
    assert bytes(c.tables[1][200:204]) == h("FF FF FD 00")  # accepted unstuffed
    (reply,) = ask(c, wire.build_v2(1, wire.INST_READ, bytes([200, 0, 4, 0])))
    assert h("FF FF FD FD 00") in reply[7:]  # the status is stuffed


def test_protocol2_sync_read_answers_in_requested_order_and_bulk_read():
    c = chain("dynamixel", 2.0, XL430, ids=(1, 2, 3))
    # e-Manual sync read example layout: addr 132, len 4, ids 3, 1
    replies = ask(c, wire.build_v2(0xFE, wire.INST_SYNC_READ, bytes([132, 0, 4, 0, 3, 1])))
    assert [r[4] for r in replies] == [3, 1]
    # bulk read: id 2 model number (addr 0, 2 bytes), id 1 present position
    replies = ask(c, wire.build_v2(0xFE, 0x92, bytes([2, 0, 0, 2, 0, 1, 132, 0, 4, 0])), now_s=2.0)
    frames = [wire.parse(r, "v2", status=True) for r in replies]
    assert [(f.packet_id, f.params) for f in frames] == [(2, (1060).to_bytes(2, "little")),
                                                         (1, (2048).to_bytes(4, "little"))]


def test_replies_wait_the_return_delay_and_follow_each_other():
    c = chain("dynamixel", 2.0, XL430, ids=(1, 2))
    c.receive(wire.build_v2(0xFE, wire.INST_SYNC_READ, bytes([132, 0, 4, 0, 1, 2])), 1.0)
    assert c.due(1.0 + 499e-6) == []  # Return Delay Time 250 x 2 us
    assert len(c.due(1.0 + 501e-6)) == 1
    assert c.due(1.0 + 0.00065) == [] and len(c.due(1.0 + 0.0012)) == 1  # 15 bytes at 1 Mbaud, then 500 us


def test_protocol1_ping_and_read_are_the_emanual_examples():
    c = chain("dynamixel", 1.0, AX12)
    assert ask(c, h("FF FF 01 02 01 FB")) == [h("FF FF 01 02 00 FC")]
    # read present position (36) of id 1: checksum ~(01+04+02+24+02) = D2; status 00 02 -> ~(01+04+00+00+02)=F8
    assert ask(c, h("FF FF 01 04 02 24 02 D2"), now_s=2.0) == [h("FF FF 01 04 00 00 02 F8")]


def test_protocol1_sync_write_moves_the_servo_at_its_no_load_speed():
    c = chain("dynamixel", 1.0, AX12, ids=(1, 2))
    ask(c, h("FF FF 01 04 03 18 01 DE"))  # torque on for id 1: ~(01+04+03+18+01) = DE
    # sync write goal (30, 2 bytes): id 1 -> 0x0300, id 2 -> 0x0300; checksum by hand
    body = bytes([0xFE, 0x0A, 0x83, 0x1E, 0x02, 1, 0x00, 0x03, 2, 0x00, 0x03])
    ask(c, h("FF FF") + body + bytes([~sum(body) & 0xFF]), now_s=1.0)
    (reply,) = ask(c, h("FF FF 01 04 02 24 02 D2"), now_s=1.1)
    ticks = int.from_bytes(wire.parse(reply, "v1", status=True).params, "little")
    speed = 59 * 360 / 60 * 1023 / 300  # 59 rpm in ticks/s
    assert ticks == 512 + round(0.1 * speed)  # moving, not yet at 0x300
    (reply,) = ask(c, h("FF FF 02 04 02 24 02 D1"), now_s=1.2)
    assert int.from_bytes(wire.parse(reply, "v1", status=True).params, "little") == 512  # torque off: still


def test_feetech_scs_reads_high_byte_first_and_sts_answers_sync_read():
    c = chain("feetech", 1.0, SCS)
    (reply,) = ask(c, h("FF FF 01 04 02 38 02 BE"))  # ~(01+04+02+38+02) = BE
    assert reply == h("FF FF 01 04 00 02 00") + bytes([~(1 + 4 + 0 + 2 + 0) & 0xFF])  # 512 = 02 00 big-endian
    s = chain("feetech", 1.0, STS, ids=(1, 2))
    replies = ask(s, wire.build_v1(0xFE, wire.INST_SYNC_READ, bytes([56, 2, 2, 1])))
    assert [r[2] for r in replies] == [2, 1]
    assert ask(s, wire.build_v1(1, wire.INST_READ, bytes([3, 2])), now_s=2.0)[0][5:7] == (777).to_bytes(2, "little")


def test_damaged_and_broadcast_instructions_get_no_status_and_unknown_ones_an_instruction_error():
    c = chain("dynamixel", 1.0, AX12)
    assert ask(c, h("FF FF 01 02 01 FA")) == []  # bad checksum
    assert ask(c, wire.build_v1(0xFE, wire.INST_WRITE, bytes([25, 1]))) == []  # broadcast write
    assert c.tables[1][25] == 1
    (reply,) = ask(c, wire.build_v1(1, 0x77))
    assert reply[4] == 0x40  # Protocol 1.0 instruction error bit


def test_status_return_level_one_answers_reads_but_not_writes():
    c = chain("dynamixel", 2.0, XL430)
    c.tables[1][68] = 1
    assert ask(c, wire.build_v2(1, wire.INST_WRITE, bytes([65, 0, 1]))) == []
    assert len(ask(c, wire.build_v2(1, wire.INST_READ, bytes([65, 0, 1, 0])), now_s=2.0)) == 1


@pytest.mark.parametrize("backend, protocol, model, kind, byte", [
    ("dynamixel", 1.0, AX12, "overheating", 0x04), ("feetech", 1.0, STS, "voltage", 0x01),
    ("dynamixel", 2.0, XL430, "overload", 0x80)])
def test_error_fault_sets_the_documented_bits_after_n_frames(backend, protocol, model, kind, byte):
    faults = se.Faults(errors={1: {kind}}, after_frames=1)
    c = chain(backend, protocol, model, faults=faults)
    framing = wire.framing_for(backend, protocol)
    read = wire.build_v2(1, wire.INST_READ, bytes([132, 0, 4, 0])) if framing == "v2" else \
        wire.build_v1(1, wire.INST_READ, bytes([model.addr_present_position, 2]))
    assert wire.parse(ask(c, read)[0], framing, status=True).error == 0
    goal = model.centre_tick.to_bytes(model.len_goal_position, model.byte_order)
    step = 2 if framing == "v2" else 1
    head = (model.addr_goal_position.to_bytes(step, "little") + model.len_goal_position.to_bytes(step, "little"))
    build = wire.build_v2 if framing == "v2" else wire.build_v1
    ask(c, build(0xFE, wire.INST_SYNC_WRITE, head + bytes([1]) + goal), now_s=2.0)
    assert wire.parse(ask(c, read, now_s=3.0)[0], framing, status=True).error == byte
    if framing == "v2":
        assert c.tables[1][70] == 0x20  # Hardware Error Status: overload bit
    if kind != "voltage":
        assert c.tables[1][model.addr_torque_enable] == 0  # shutdown


def test_silent_late_and_corrupt_faults():
    faults = se.Faults(silent={2}, late_s={3: 0.05}, corrupt_fraction=1.0, corrupt_ids={4})
    c = chain("dynamixel", 2.0, XL430, ids=(1, 2, 3, 4), faults=faults)
    c.receive(wire.build_v2(0xFE, wire.INST_SYNC_READ, bytes([132, 0, 4, 0, 1, 2, 3, 4])), 1.0)
    # 2 silent, 3 not yet (50 ms late); 4 answers in its turn: a servo slow to answer does not hold the line
    on_time = c.due(1.04)
    assert [r[4] for r in on_time] == [1, 4]
    assert not wire.parse(on_time[1], "v2", status=True).checksum_ok
    late = c.due(1.1)
    assert [r[4] for r in late] == [3]
    assert wire.parse(late[0], "v2", status=True).checksum_ok
    # a late servo asked again and again answers each question 50 ms after it, not 50 ms more each time
    for k in range(5):
        c.receive(wire.build_v2(3, wire.INST_READ, bytes([132, 0, 4, 0])), 2.0 + 0.01 * k)
    assert c.next_due_s() == pytest.approx(2.05, abs=2e-3)
    assert max(entry[0] for entry in c.outbox) == pytest.approx(2.09, abs=2e-3)  # (time, packet, line rate)


def test_goal_log_is_a_bus_recording(tmp_path):
    log = tmp_path / "goals.jsonl"
    c = chain("dynamixel", 2.0, XL430, ids=(1, 2), log_path=str(log), joints={"a": 2, "b": 1})
    ask(c, wire.build_v2(0xFE, wire.INST_SYNC_WRITE, bytes([116, 0, 4, 0, 1, 0x10, 0, 0, 0, 2, 0x20, 0, 0, 0])))
    c.close_log()
    _header, _t, ticks = decode_goal_frames(log)
    assert ticks.tolist() == [[0x20, 0x10]]


def test_cli_prints_the_device_path_first_and_the_pty_answers(tmp_path):
    import subprocess
    import sys

    proc = subprocess.Popen([sys.executable, str(ROOT / "tools" / "servo_emulator.py"), "--protocol", "dxl1",
                             "--ids", "1-2"], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        path = proc.stdout.readline().strip()
        assert path.startswith("/dev/")
        fd = os.open(path, os.O_RDWR | os.O_NOCTTY)
        try:
            import tty
            tty.setraw(fd)
            os.write(fd, h("FF FF 02 02 01 FA"))  # ping id 2: ~(02+02+01) = FA
            got = b""
            deadline = time.monotonic() + 5
            while len(got) < 6 and time.monotonic() < deadline:
                if select.select([fd], [], [], 0.1)[0]:
                    got += os.read(fd, 64)
            assert got == h("FF FF 02 02 00 FB")
        finally:
            os.close(fd)
    finally:
        proc.terminate()
        proc.wait(timeout=5)


def _ignore_sigint() -> None:
    signal.signal(signal.SIGINT, signal.SIG_IGN)  # as a script's background job (no job control) starts


@pytest.mark.parametrize("signum", [signal.SIGINT, signal.SIGTERM], ids=["SIGINT", "SIGTERM"])
def test_ctrl_c_or_sigterm_ends_it_even_when_started_with_sigint_ignored(tmp_path, signum):
    """The banner says Ctrl-C stops it: so it must, also when its parent left SIGINT ignored (Python then sets
    no handler; the docs' tests, run from a background job, found its Ctrl-C ignored). Exit 0, its goal log
    closed and reported, as after a Ctrl-C in a terminal."""
    import subprocess
    import sys

    log = tmp_path / "goals.jsonl"
    proc = subprocess.Popen([sys.executable, str(ROOT / "tools" / "servo_emulator.py"), "--robot",
                             str(ROOT / "config" / "xl430-biped.toml"), "--log", str(log)],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, preexec_fn=_ignore_sigint)
    try:
        assert proc.stdout.readline().strip().startswith("/dev/")
        proc.send_signal(signum)
        assert proc.wait(timeout=20) == 0
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
    assert "0 goal frames logged to" in proc.stderr.read()
    assert log.exists()


# --- the scripted hand (gaitbot record's test partner) ------------------------------------------

def present_of(replies, framing="v2"):
    return {wire.parse(r, framing, status=True).packet_id: int.from_bytes(
        bytes(wire.parse(r, framing, status=True).params), "little", signed=framing == "v2") for r in replies}


def test_the_hand_moves_servos_with_torque_off_one_sample_per_sync_read_cycle():
    hand = se.Hand({1: [2100, 2200, 2300], 2: [1900, 1800, 1700]})
    c = chain("dynamixel", 2.0, XL430, ids=(1, 2), hand=hand)
    sync_read = wire.build_v2(0xFE, wire.INST_SYNC_READ, bytes([132, 0, 4, 0, 1, 2]))
    assert present_of(ask(c, sync_read, 1.0)) == {1: 2048, 2: 2048}  # not grabbed before a torque-off
    ask(c, wire.build_v2(1, wire.INST_WRITE, bytes([64, 0, 0])), 2.0)  # torque off servo 1: the hand takes over
    got = [present_of(ask(c, sync_read, 3.0 + k)) for k in range(4)]
    assert got == [{1: 2100, 2: 1900}, {1: 2200, 2: 1800}, {1: 2300, 2: 1700}, {1: 2300, 2: 1700}]  # then holds


def test_the_hand_counts_one_read_per_servo_as_one_cycle_and_leaves_torqued_servos_alone():
    hand = se.Hand({1: [600, 610, 620], 2: [400, 390, 380]})
    c = chain("dynamixel", 1.0, AX12, ids=(1, 2), hand=hand)
    ask(c, wire.build_v1(1, wire.INST_WRITE, bytes([24, 0])), 1.0)  # torque off (already off: still a grab)
    ask(c, wire.build_v1(2, wire.INST_WRITE, bytes([24, 1])), 1.0)  # torque on servo 2: it holds its goal
    read = [wire.build_v1(i, wire.INST_READ, bytes([36, 2])) for i in (1, 2)]
    seen = []
    for k in range(3):
        row = {}
        for packet in read:
            row.update(present_of(ask(c, packet, 2.0 + k), "v1"))
        seen.append(row)
    assert [r[1] for r in seen] == [600, 610, 620]
    assert [r[2] for r in seen] == [512, 512, 512]  # torque on: the hand cannot move it


def test_a_hand_with_a_rate_follows_time_from_the_torque_off():
    c = chain("dynamixel", 2.0, XL430, ids=(1,), hand=se.Hand({1: list(range(2000, 2100))}, rate_hz=10.0))
    ask(c, wire.build_v2(1, wire.INST_WRITE, bytes([64, 0, 0])), 5.0)
    read = wire.build_v2(1, wire.INST_READ, bytes([132, 0, 4, 0]))
    assert present_of(ask(c, read, 5.35)) == {1: 2003}
    assert present_of(ask(c, read, 5.35)) == {1: 2003}  # time, not reads, moves it
    assert present_of(ask(c, read, 7.0)) == {1: 2020}


def test_hand_from_a_trajectory_file_on_the_command_line(tmp_path):
    from gaitbot.gait import generate_walk
    from gaitbot.robot.config import load_robot_config, resolve_config
    from gaitbot.robot.walk_settings import leg_geometry, walk_settings

    robot = load_robot_config(resolve_config("xl430-biped"))
    walk = generate_walk(leg_geometry(robot), [0.05, 0.05], walk_settings(robot))
    path = tmp_path / "hand.csv"
    walk.save(path)
    config = emulator_cli.config_from_args(emulator_cli.build_parser().parse_args(["--robot", "xl430-biped", "--hand", str(path)]))
    assert config.hand.samples == len(walk) and config.hand.rate_hz is None
    # right hip (id 4) is mirror-mounted: ticks = 2048 - deg * 4096 / 360
    assert config.hand.ticks[4][200] == round(2048 - walk.angles_deg[200, 3] * 4096 / 360)
    with pytest.raises(ValueError, match="needs --robot"):
        emulator_cli.config_from_args(emulator_cli.build_parser().parse_args(["--protocol", "dxl2", "--hand", str(path)]))
