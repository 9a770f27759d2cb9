"""Recorder and decoder: round trip, whole status packets per rx line, and clear rejections."""

import json

import numpy as np
import pytest

from gaitbot.bus import make_bus
from gaitbot.bus.recording import (BusRecorder, RecordingError, decode_goal_frames, parse_recording,
                                   read_recording)
from gaitbot.servos.models import SERVO_MODELS

JOINTS = {"hip_pitch_left": 2, "hip_pitch_right": 1}  # header order differs from id order on purpose


def fake_clock(step_s=0.01):
    ticks = iter(range(10_000))
    return lambda: next(ticks) * step_s


def record_run(path, backend="dynamixel", protocol=2.0, name="XL430-W250", frames=((1000, 2000), (1010, 1990))):
    model = SERVO_MODELS[name]
    recorder = BusRecorder(path, robot="testbot", joints=JOINTS, clock=fake_clock())
    bus = make_bus(backend, protocol, "/dev/ttyUSB0", 1_000_000, {1: model, 2: model}, interface="dry-run",
                   recorder=recorder)
    with bus:
        bus.set_torque([1, 2], True)
        for right, left in frames:
            bus.write_goal_ticks({1: right, 2: left})
            bus.read_present_ticks([1, 2])
    return bus


def test_round_trip_goal_frames_in_header_joint_order(tmp_path):
    path = tmp_path / "run.jsonl"
    record_run(path)
    header, t_s, ticks = decode_goal_frames(path)
    assert header["robot"] == "testbot" and header["joints"] == JOINTS
    assert header["models"] == {"1": "XL430-W250", "2": "XL430-W250"}
    assert (header["backend"], header["protocol"], header["baudrate"]) == ("dynamixel", 2.0, 1_000_000)
    np.testing.assert_array_equal(ticks, [[2000, 1000], [1990, 1010]])  # columns: left (id 2), right (id 1)
    assert t_s.shape == (2,) and np.all(np.diff(t_s) > 0)


def test_rx_lines_are_whole_status_packets_and_match_the_wire(tmp_path):
    path = tmp_path / "run.jsonl"
    bus = record_run(path)
    _, packets = read_recording(path)
    assert [p.data for p in packets if p.direction == "rx"] == bus.port._inner.rx_packets
    assert [p.data for p in packets if p.direction == "tx"] == bus.port._inner.tx_packets
    _, parsed = parse_recording(path)
    assert all(p.checksum_ok for p in parsed)


def test_parse_results_expose_sync_write_fields(tmp_path):
    path = tmp_path / "run.jsonl"
    record_run(path)
    _, parsed = parse_recording(path)
    sync = [p for p in parsed if p.direction == "tx" and p.instruction == 0x83]
    assert sync[0].ids == (1, 2) and sync[0].address == 116 and sync[0].data_length == 4
    assert sync[0].per_id_data == {1: (1000).to_bytes(4, "little"), 2: (2000).to_bytes(4, "little")}
    torque = [p for p in parsed if p.direction == "tx" and p.instruction == 0x03][0]
    assert (torque.ids, torque.address, torque.data) == ((1,), 64, b"\x01")


def test_scs_recording_decodes_high_byte_first(tmp_path):
    path = tmp_path / "scs.jsonl"
    record_run(path, backend="feetech", protocol=1.0, name="SCS0009", frames=((300, 700),))
    _, _, ticks = decode_goal_frames(path)
    np.testing.assert_array_equal(ticks, [[700, 300]])


def test_every_line_is_on_disk_before_close(tmp_path):
    path = tmp_path / "live.jsonl"
    model = SERVO_MODELS["STS3215"]
    recorder = BusRecorder(path, robot="testbot", joints={"a": 1}, clock=fake_clock())
    bus = make_bus("feetech", 1.0, "p", 1_000_000, {1: model}, interface="dry-run", recorder=recorder)
    bus.open()
    bus.write_goal_ticks({1: 100})
    lines = path.read_text().splitlines()  # bus still open, recorder not closed
    assert len(lines) == 2 and json.loads(lines[1])["dir"] == "tx"
    bus.close()


def _rewrite_line(path, line_no, change):
    lines = path.read_text().split("\n")
    lines[line_no - 1] = change(lines[line_no - 1])
    path.write_text("\n".join(lines))


def test_corrupted_byte_is_rejected_with_file_and_line(tmp_path):
    path = tmp_path / "run.jsonl"
    record_run(path)
    lines = path.read_text().splitlines()
    line_no = next(n for n, line in enumerate(lines, 1) if '"hex":"fffffd00fe11' in line)
    def flip(line):
        obj = json.loads(line)
        data = bytearray.fromhex(obj["hex"])
        data[10] ^= 0x01  # one bit of the goal data
        obj["hex"] = data.hex()
        return json.dumps(obj)
    _rewrite_line(path, line_no, flip)
    with pytest.raises(RecordingError, match=rf"run\.jsonl:{line_no}: .*bad CRC"):
        decode_goal_frames(path)


def test_missing_header_is_rejected(tmp_path):
    path = tmp_path / "run.jsonl"
    record_run(path)
    path.write_text("\n".join(path.read_text().split("\n")[1:]))
    with pytest.raises(RecordingError, match=r"run\.jsonl:1: no gaitbot-bus-log header"):
        read_recording(path)


def test_bad_json_in_the_middle_names_the_line(tmp_path):
    path = tmp_path / "run.jsonl"
    record_run(path)
    _rewrite_line(path, 3, lambda line: line[:-3])
    with pytest.raises(RecordingError, match=r"run\.jsonl:3: bad JSON"):
        read_recording(path)


def test_truncated_last_line_is_reported_and_can_be_dropped_on_request(tmp_path):
    path = tmp_path / "run.jsonl"
    record_run(path)
    text = path.read_text()
    path.write_text(text[:-12])  # the run died while writing its last line
    n_lines = text.count("\n")
    with pytest.raises(RecordingError, match=rf"run\.jsonl:{n_lines}: truncated last line"):
        read_recording(path)
    _, packets = read_recording(path, allow_partial_last_line=True)
    assert len(packets) == n_lines - 2  # header and the partial line are not packets
