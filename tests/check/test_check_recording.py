"""gaitbot check on bus recordings: clean dry runs pass; each fault put in by hand is found where it was put.

Every recording is a real dry run (``gaitbot walk --dry-run --record``) of a shipped robot. The
faults are made here, packet by packet, and the expected line, time, id and gap come from the edit
(the line edited, its ``t``, the id removed, the delay added), never from the checker's output.
"""

from __future__ import annotations

import json
import re

import numpy as np
import pytest

from gaitbot.check.recording import (MAX_GAP_PERIODS, BusIssue, _frame_timing, _motion_samples, check_recording,
                                     match_config, read_log)
from gaitbot.bus.recording import RecordingError
from helpers import (PERIOD_S, ROBOTS, build_sync_write, config, goal_layout, goal_line_indices,
                                goal_row_near, read_lines, run_cli, split_sync_write, write_lines)


@pytest.fixture(scope="module")
def recordings(tmp_path_factory):
    """One clean dry-run recording per shipped robot, made through the real CLI."""
    from gaitbot.app.cli import main

    out = {}
    folder = tmp_path_factory.mktemp("recordings")
    for robot in ROBOTS:
        path = folder / f"{robot}.jsonl"
        assert main(["walk", "--dry-run", "--distance", "1", "--robot", robot, "--record", str(path)]) == 0
        out[robot] = path
    return out


def edited(tmp_path, recordings, robot, name="edited.jsonl"):
    rows = read_lines(recordings[robot])
    return rows, tmp_path / name


# ----------------------------------------------------------------------------------------- clean runs pass


@pytest.mark.parametrize("robot", ROBOTS)
def test_clean_dry_run_recording_passes(capsys, recordings, robot):
    code, out, err = run_cli(capsys, "check", recordings[robot])  # robot taken from the header
    assert code == 0, out + err
    assert "OK (0 errors" in out
    assert f"recording of {robot}" in out
    for joint in config(robot).joints:  # one table row per configured joint, verdict ok
        assert re.search(rf"^{joint.name}\s.*\sok$", out, re.M), joint.name


@pytest.mark.parametrize("robot", ROBOTS)
def test_clean_recording_json_and_timing(capsys, recordings, robot):
    code, out, _ = run_cli(capsys, "check", recordings[robot], "--robot", robot, "--json")
    assert code == 0
    doc = json.loads(out)
    assert doc["ok"] is True and doc["kind"] == "recording" and doc["bus_issues"] == []
    timing = doc["frame_timing"]
    # A dry run on the virtual clock sends exactly one frame per period.
    assert timing["mean_gap_s"] == pytest.approx(PERIOD_S, abs=1e-5)
    assert timing["worst_gap_s"] == pytest.approx(PERIOD_S, abs=1e-5)
    assert timing["n_frames"] == len(goal_line_indices(read_lines(recordings[robot]), robot))
    assert len(doc["joint_check"]["joints"]) == len(config(robot).joints)


# ----------------------------------------------------------------------------------------- corrupted byte


@pytest.mark.parametrize("robot", ROBOTS)
def test_one_corrupted_byte_in_a_goal_frame_is_named(capsys, tmp_path, recordings, robot):
    rows, path = edited(tmp_path, recordings, robot)
    k = goal_row_near(rows, robot, 5.0)
    raw = bytearray(bytes.fromhex(rows[k]["hex"]))
    raw[-4] ^= 0x10  # a goal byte of the last servo in the frame
    rows[k]["hex"] = raw.hex()
    write_lines(path, rows)
    code, out, _ = run_cli(capsys, "check", path)
    assert code == 1
    line_no = k + 1  # rows[0] is the header on line 1
    hits = [x for x in out.splitlines() if f"line {line_no}," in x and "malformed" in x]
    assert hits, out
    assert f"t={rows[k]['t']:.3f} s" in hits[0]
    assert raw.hex()[:20] in hits[0]  # the packet is quoted
    assert re.search(r"bad (checksum|CRC)", hits[0])


def test_corrupted_header_byte_and_non_hex_are_violations_not_unreadable(capsys, tmp_path, recordings):
    rows, path = edited(tmp_path, recordings, "xl430-biped")
    a, b = goal_row_near(rows, "xl430-biped", 3.0), goal_row_near(rows, "xl430-biped", 6.0)
    rows[a]["hex"] = "00" + rows[a]["hex"][2:]  # first header byte lost
    rows[b]["hex"] = rows[b]["hex"][:10] + "zz" + rows[b]["hex"][12:]  # not hex any more
    write_lines(path, rows)
    code, out, _ = run_cli(capsys, "check", path)
    assert code == 1
    assert f"line {a + 1}, t={rows[a]['t']:.3f} s: tx packet malformed" in out
    assert f"line {b + 1}, t={rows[b]['t']:.3f} s: tx packet malformed: bytes are not valid hex" in out


def test_corrupted_status_packet_is_an_error_too(capsys, tmp_path, recordings):
    rows, path = edited(tmp_path, recordings, "ax12a-biped")
    k = next(i for i, r in enumerate(rows[1:], start=1) if r["dir"] == "rx")
    raw = bytearray(bytes.fromhex(rows[k]["hex"]))
    raw[-1] ^= 0xFF
    rows[k]["hex"] = raw.hex()
    write_lines(path, rows)
    code, out, _ = run_cli(capsys, "check", path)
    assert code == 1
    assert f"line {k + 1}, t={rows[k]['t']:.3f} s: rx packet malformed: bad checksum" in out


# ----------------------------------------------------------------------------------------- ids


@pytest.mark.parametrize("robot", ROBOTS)
def test_missing_id_in_one_frame_is_named(capsys, tmp_path, recordings, robot):
    rows, path = edited(tmp_path, recordings, robot)
    header = rows[0]
    k = goal_row_near(rows, robot, 4.0)
    address, length, entries = split_sync_write(header, bytes.fromhex(rows[k]["hex"]))
    knee_id = header["joints"]["knee_pitch_left"]
    entries = [(i, d) for i, d in entries if i != knee_id]
    rows[k]["hex"] = build_sync_write(header, address, length, entries).hex()  # valid CRC: only the id is gone
    write_lines(path, rows)
    code, out, _ = run_cli(capsys, "check", path, "--json")
    assert code == 1
    doc = json.loads(out)
    ids = [i for i in doc["bus_issues"] if i["kind"] == "ids"]
    assert len(ids) == 1
    assert ids[0]["line_no"] == k + 1 and ids[0]["t_s"] == pytest.approx(rows[k]["t"])
    assert f"lacks id {knee_id} (knee_pitch_left)" in ids[0]["message"]
    assert not [i for i in doc["bus_issues"] if i["kind"] == "packet"]


def test_unknown_id_in_a_frame_and_in_a_ping(capsys, tmp_path, recordings):
    from gaitbot.servos import wire

    rows, path = edited(tmp_path, recordings, "sts3215-biped")
    header = rows[0]
    k = goal_row_near(rows, "sts3215-biped", 2.0)
    address, length, entries = split_sync_write(header, bytes.fromhex(rows[k]["hex"]))
    rows[k]["hex"] = build_sync_write(header, address, length, entries + [(42, entries[0][1])]).hex()
    rows.insert(1, {"t": 0.0, "dir": "tx", "hex": wire.build_v1(77, wire.INST_PING).hex()})
    write_lines(path, rows)
    code, out, _ = run_cli(capsys, "check", path)
    assert code == 1
    assert "line 2, t=0.000 s: tx packet addresses id 77, not in the config" in out
    assert f"line {k + 2}, t={rows[k + 1]['t']:.3f} s: goal frame addresses unknown id 42" in out


# ----------------------------------------------------------------------------------------- timing


@pytest.mark.parametrize("robot", ROBOTS)
def test_frame_delayed_three_periods_is_named(capsys, tmp_path, recordings, robot):
    """The run stalls before one frame: it and everything after are 3 periods later."""
    rows, path = edited(tmp_path, recordings, robot)
    k = goal_row_near(rows, robot, 7.0)
    previous = max(i for i in goal_line_indices(rows, robot) if i < k)
    for row in rows[k:]:
        row["t"] = round(row["t"] + 3 * PERIOD_S, 6)
    write_lines(path, rows)
    code, out, _ = run_cli(capsys, "check", path)
    assert code == 1
    gap_ms = (rows[k]["t"] - rows[previous]["t"]) * 1000  # 4 periods: the usual one plus the delay
    assert gap_ms == pytest.approx(4000 * PERIOD_S, abs=0.01)
    hits = [x for x in out.splitlines() if "goal frame late" in x]
    assert len(hits) == 1, out
    assert f"line {k + 1}, t={rows[k]['t']:.3f} s: goal frame late: {gap_ms:.2f} ms (4.00 periods)" in hits[0]
    assert f"(line {previous + 1}, t={rows[previous]['t']:.3f} s)" in hits[0]
    assert f"worst {gap_ms:.2f} ms" in out


def test_one_frame_stamped_three_periods_late(capsys, tmp_path, recordings):
    """Only one line's time moved: late before it, time going backwards after it; the motion is unharmed."""
    robot = "xl430-biped"
    rows, path = edited(tmp_path, recordings, robot)
    goals = goal_line_indices(rows, robot)
    k = goal_row_near(rows, robot, 7.0)
    nxt = goals[goals.index(k) + 1]
    rows[k]["t"] = round(rows[k]["t"] + 3 * PERIOD_S, 6)
    write_lines(path, rows)
    code, out, _ = run_cli(capsys, "check", path, "--json")
    assert code == 1
    doc = json.loads(out)
    timing = [i for i in doc["bus_issues"] if i["kind"] == "timing"]
    assert [i["line_no"] for i in timing] == [k + 1, nxt + 1]
    assert "late" in timing[0]["message"] and "backwards" in timing[1]["message"]
    assert doc["joint_check"]["violations"] == []


def test_short_stall_within_tolerance_passes(capsys, tmp_path, recordings):
    """A frame 0.4 period late (gap 1.4 periods) is within MAX_GAP_PERIODS."""
    robot = "ax12a-biped"
    rows, path = edited(tmp_path, recordings, robot)
    k = goal_row_near(rows, robot, 3.0)
    for row in rows[k:]:
        row["t"] = round(row["t"] + 0.4 * PERIOD_S, 6)
    write_lines(path, rows)
    code, out, _ = run_cli(capsys, "check", path)
    assert code == 0, out
    assert "worst 23.33 ms (1.40 periods)" in out


# ----------------------------------------------------------------------------------------- joint limits in recordings


def test_goal_beyond_a_limit_in_a_recording_names_joint_time_line(capsys, tmp_path, recordings):
    """Knee goal set to 130 deg in one frame (xl430: zero 2048, 4096 ticks/turn, direction +1 on the left)."""
    robot = "xl430-biped"
    rows, path = edited(tmp_path, recordings, robot)
    header = rows[0]
    k = goal_row_near(rows, robot, 2.0)
    address, length, entries = split_sync_write(header, bytes.fromhex(rows[k]["hex"]))
    knee = config(robot).joint("knee_pitch_left")
    tick = round(knee.zero_tick + knee.direction * 130.0 * 4096 / 360.0)
    entries = [(i, tick.to_bytes(4, "little") if i == knee.id else d) for i, d in entries]
    rows[k]["hex"] = build_sync_write(header, address, length, entries).hex()
    write_lines(path, rows)
    code, out, _ = run_cli(capsys, "check", path)
    assert code == 1
    want = f"knee_pitch_left: position 130.0 deg at t={rows[k]['t']:.3f} s exceeds max_deg 110.0 (line {k + 1})"
    assert want in out


# ----------------------------------------------------------------------------------------- unreadable: exit 2


def test_truncated_recording_is_exit_2_and_allow_partial_checks_the_rest(capsys, tmp_path, recordings):
    text = recordings["sts3215-biped"].read_text()
    path = tmp_path / "cut.jsonl"
    path.write_text(text[: len(text) - 25])  # the crash cut the last line
    n_lines = text[: len(text) - 25].count("\n") + 1
    code, out, err = run_cli(capsys, "check", path)
    assert code == 2 and out == ""
    assert len(err.strip().splitlines()) == 1
    assert f"cut.jsonl:{n_lines}: truncated last line" in err
    report = check_recording(config("sts3215-biped"), path, allow_partial_last_line=True)
    assert report.ok
    assert [i.kind for i in report.warnings] == ["file"]


def test_recording_without_header_is_exit_2(capsys, tmp_path, recordings):
    rows = read_lines(recordings["xl430-biped"])
    path = write_lines(tmp_path / "nohead.jsonl", rows[1:])
    code, out, err = run_cli(capsys, "check", path)
    assert code == 2 and out == ""
    assert "nohead.jsonl:1: no gaitbot-bus-log header" in err and len(err.strip().splitlines()) == 1
    code, _, err = run_cli(capsys, "check", path, "--robot", "xl430-biped")
    assert code == 2 and "no gaitbot-bus-log header" in err


def test_unparseable_json_line_is_exit_2(capsys, tmp_path, recordings):
    lines = recordings["xl430-biped"].read_text().splitlines()
    lines[40] = lines[40][:-1]  # the closing brace lost
    path = tmp_path / "badjson.jsonl"
    path.write_text("\n".join(lines) + "\n")
    code, _, err = run_cli(capsys, "check", path)
    assert code == 2 and "badjson.jsonl:41: bad JSON" in err


@pytest.mark.parametrize("robot, other", [("xl430-biped", "sts3215-biped"), ("ax12a-biped", "xl430-biped")])
def test_config_of_another_robot_is_exit_2(capsys, recordings, robot, other):
    code, out, err = run_cli(capsys, "check", recordings[robot], "--robot", other)
    assert code == 2 and out == ""
    assert "recording does not match robot config" in err and len(err.strip().splitlines()) == 1


def test_config_with_different_ids_is_exit_2(capsys, tmp_path, recordings):
    from gaitbot.robot.config import resolve_config

    text = resolve_config("xl430-biped").read_text()
    changed = re.sub(r"(\[joints\.knee_pitch_left\]\s*\nid\s*=\s*)2\b", r"\g<1>12", text)
    assert changed != text
    cfg = tmp_path / "renumbered.toml"
    cfg.write_text(changed)
    code, _, err = run_cli(capsys, "check", recordings["xl430-biped"], "--robot", cfg)
    assert code == 2
    assert "joint ids differ" in err and "knee_pitch_left=2" in err and "knee_pitch_left=12" in err


def test_unknown_robot_in_header_needs_robot(capsys, tmp_path, recordings):
    rows = read_lines(recordings["xl430-biped"])
    rows[0]["robot"] = "my-own-biped"
    path = write_lines(tmp_path / "own.jsonl", rows)
    code, _, err = run_cli(capsys, "check", path)
    assert code == 2 and "'my-own-biped', which is not a shipped config" in err and "--robot" in err
    code, out, _ = run_cli(capsys, "check", path, "--robot", "xl430-biped")
    assert code == 0 and "recorded as robot 'my-own-biped'" in out  # a warning only


def test_recording_without_goal_frames_is_exit_2(capsys, tmp_path, recordings):
    robot = "xl430-biped"
    rows = read_lines(recordings[robot])
    goals = set(goal_line_indices(rows, robot))
    path = write_lines(tmp_path / "scan.jsonl", [r for k, r in enumerate(rows) if k not in goals])
    code, _, err = run_cli(capsys, "check", path)
    assert code == 2 and "no goal-position frames" in err


# ----------------------------------------------------------------------------------------- units


def test_frame_timing_stats_by_hand():
    period = 0.02  # 50 Hz
    t = np.array([0.0, 0.02, 0.04, 0.10, 0.12, 0.11])  # a 3-period gap, then time going back 10 ms
    lines = np.array([2, 3, 4, 5, 6, 7])
    timing, issues = _frame_timing(50.0, t, lines)
    assert timing.worst_gap_s == pytest.approx(0.06) and timing.worst_gap_line == 5
    assert timing.mean_gap_s == pytest.approx(0.11 / 5)
    assert timing.max_gap_s == pytest.approx(MAX_GAP_PERIODS * period)
    assert (timing.n_late, timing.n_backwards) == (1, 1)
    assert [(i.line_no, i.kind) for i in issues] == [(5, "timing"), (7, "timing")]
    assert "60.00 ms (3.00 periods)" in issues[0].message and "backwards by 10.00 ms" in issues[1].message


def test_motion_samples_fill_missing_joints_and_supersede_same_time():
    cfg = config("xl430-biped")
    n = len(cfg.joints)
    rows = np.tile(np.arange(n, dtype=float) + 2000, (5, 1))
    rows[:, 0] = [100, 110, np.nan, 130, 140]  # joint 0 missing in frame 2: it keeps 110
    rows[0, 1] = np.nan  # missing in the first frame: takes its first known goal
    t = np.array([0.0, 0.0, 0.1, 0.2, 0.15])  # frame 1 supersedes frame 0; frame 4 goes back in time
    lines = np.array([10, 11, 12, 13, 14])
    ts, ls, ticks = _motion_samples(cfg, t, lines, rows)
    assert ts.tolist() == [0.0, 0.1, 0.2] and ls.tolist() == [11, 12, 13]
    assert ticks[:, 0].tolist() == [110, 110, 130]
    assert ticks[0, 1] == 2001


def test_status_error_is_a_warning(tmp_path, recordings):
    from gaitbot.servos import wire

    rows = read_lines(recordings["ax12a-biped"])
    k = next(i for i, r in enumerate(rows[1:], start=1) if r["dir"] == "rx")
    servo_id = bytes.fromhex(rows[k]["hex"])[2]
    rows[k]["hex"] = wire.build_v1(servo_id, 0x20).hex()  # overload bit set in the status
    path = write_lines(tmp_path / "status.jsonl", rows)
    report = check_recording(config("ax12a-biped"), path)
    assert report.ok
    assert [(i.kind, i.severity, i.line_no) for i in report.issues] == [("status", "warning", k + 1)]
    assert "reported error 0x20" in report.issues[0].message


def test_baudrate_difference_is_a_warning(recordings):
    header, _, _ = read_log(recordings["xl430-biped"])
    header = {**header, "baudrate": 57600}
    notes = match_config("x.jsonl", header, config("xl430-biped"))
    assert [n.kind for n in notes] == ["config"] and "57600" in notes[0].message


def test_missing_file_is_a_recording_error(tmp_path):
    with pytest.raises(RecordingError, match="no such file"):
        read_log(tmp_path / "none.jsonl")


def test_bus_issue_quotes_packet_shortly():
    issue = BusIssue("packet", "error", 12, 1.5, "tx packet malformed: bad CRC", "ab" * 40)
    text = issue.describe()
    assert text.startswith("line 12, t=1.500 s: tx packet malformed: bad CRC [")
    assert text.endswith("...]") and len(text) < 120


def test_goal_layouts_used_by_the_tests_match_the_models():
    assert goal_layout("xl430-biped") == (116, 4)
    assert goal_layout("ax12a-biped") == (30, 2)
    assert goal_layout("sts3215-biped") == (42, 2)



# ----------------------------------------------------------------------------------------- servo health reads


def test_check_reads_every_health_read_back_also_the_longer_ones_after_a_miss(tmp_path):
    """A walk's read-back reads a servo's health block; after a miss the servo is asked for the block and a byte
    more (the read-back's length rule, docs/bus-faults.md), and that answer is a health reading as well: check
    decodes exactly the readings the walk's monitor saw, the longer ones included."""
    from gaitbot.bus.factory import make_bus
    from gaitbot.bus.recording import BusRecorder
    from gaitbot.robot.calibration import standing_ticks
    from gaitbot.robot.walk_settings import joint_limits_ticks
    from gaitbot.servos import wire
    from gaitbot.servos.health import health_block
    from gaitbot.stream.clock import VirtualClock
    from gaitbot.stream.health import HealthMonitor
    from gaitbot.stream.session import walk_session

    robot = config("xl430-biped")
    clock = VirtualClock()
    path = tmp_path / "run.jsonl"
    recorder = BusRecorder(path, robot=robot.name, joints={j.name: j.id for j in robot.joints}, clock=clock.now,
                           rate_hz=robot.gait.rate_hz)
    bus = make_bus(robot.bus.backend, robot.bus.protocol, "mock", robot.bus.baudrate, robot.models_by_id,
                   interface="dry-run", recorder=recorder)
    mock = bus.port._inner  # the DryRunPort under the recording port
    monitor = HealthMonitor.for_robot(robot, clock=clock.now)

    def on_frame(k, _stats):
        if k in (20, 50):  # the next read-back's status packet is lost: that servo is asked again, longer
            mock.drop_next_replies(1)

    frames = np.tile(standing_ticks(robot), (90, 1))
    velocity, acceleration = joint_limits_ticks(robot)
    result = walk_session(bus, robot.ids, frames, standing_ticks(robot), max_velocity_ticks_per_s=velocity,
                          max_accel_ticks_per_s2=acceleration, period_s=1 / robot.gait.rate_hz, clock=clock,
                          on_frame=on_frame, handle_sigterm=False, health=monitor)
    recorder.close()
    assert result.outcome == "completed", result.message()
    block = health_block(robot.joints[0].model)
    reads = [wire.parse(p, mock.framing, status=False) for p in mock.tx_packets]
    lengths = [wire.address_length_and_rest(f.params, mock.framing)[1] for f in reads if f.instruction == wire.INST_READ]
    # the re-reads, and the reads of those servos for as long as the lost reply might still come, a byte longer
    assert lengths.count(block.length + 1) >= 2 and set(lengths) == {block.length, block.length + 1}
    report = check_recording(robot, path)
    assert report.health is not None and report.health.n_readings == monitor.readings
