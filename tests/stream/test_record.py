"""``gaitbot record`` on the real bus classes over the mock port, with a virtual clock.

A "hand" is played by the test itself: after each sample it writes the next pose into the mock
servos' present-position registers. Expected rows come from those ticks through the calibration
formula written out here, and packets are read back from the mock port's log, so the tests say
what reached the servos, not what the recorder meant to send.
"""

from __future__ import annotations

import numpy as np
import pytest

pytest.importorskip("dynamixel_sdk")

from gaitbot.servos import wire  # noqa: E402
from gaitbot.bus.factory import make_bus  # noqa: E402
from gaitbot.bus.guard import LimitGuard  # noqa: E402
from gaitbot.app.cli import main  # noqa: E402
from gaitbot.stream.clock import VirtualClock  # noqa: E402
from gaitbot.gait.trajectory import Trajectory  # noqa: E402
from gaitbot.stream.record import record_session  # noqa: E402
from gaitbot.app.record import QUESTION, TrajectorySink  # noqa: E402
from gaitbot.robot.calibration import tick_limits  # noqa: E402
from gaitbot.app.options import load_robot  # noqa: E402
from gaitbot.stream import Terminated  # noqa: E402

CFG = load_robot("xl430-biped")
IDS = CFG.ids
PERIOD_S = 1.0 / CFG.gait.rate_hz
TORQUE_ADDR, PRESENT_ADDR = 64, 132  # XL430-W250 control table (ROBOTIS e-Manual)
TICKS_PER_DEG = 4096 / 360.0


def guarded_mock_bus():
    bus = make_bus("dynamixel", 2.0, "mock", 1_000_000, CFG.models_by_id, interface="dry-run")
    return LimitGuard(bus, tick_limits(CFG), {j.id: j.name for j in CFG.joints})


def set_present(bus, ticks) -> None:
    for servo_id, tick in zip(IDS, ticks):
        bus.inner.port.tables[servo_id][PRESENT_ADDR:PRESENT_ADDR + 4] = int(tick).to_bytes(4, "little", signed=True)


def hand_ticks(n: int) -> np.ndarray:
    """A motion inside the limits: every joint swinging by up to 20 deg around standing."""
    phase = 2 * np.pi * np.arange(n) / 50
    deg = np.column_stack([20 * np.sin(phase + j) + (15 if j % 3 == 1 else 0) for j in range(6)])
    deg[:, 1::3] = np.abs(deg[:, 1::3])  # knees stay bent forward
    direction = np.array([j.direction for j in CFG.joints])
    return np.rint(2048 + direction * deg * TICKS_PER_DEG).astype(np.int64)


def instructions(bus) -> list[tuple[int, int, bytes]]:
    """(instruction, packet id, params) of every packet the host sent."""
    out = []
    for raw in bus.inner.port.tx_packets:
        frame = wire.parse(raw, "v2", status=False)
        out.append((frame.instruction, frame.packet_id, bytes(frame.params)))
    return out


def torque_writes(bus) -> list[tuple[int, int]]:
    return [(pid, p[2]) for inst, pid, p in instructions(bus)
            if inst == wire.INST_WRITE and p[0] | p[1] << 8 == TORQUE_ADDR]


class HandSink(TrajectorySink):
    """The trajectory sink, with the test's hand moving the servos after each sample is stored."""

    def __init__(self, path, bus, ticks, stop_at=None, stop_with=None, warnings=None):
        self.warnings = [] if warnings is None else warnings
        super().__init__(CFG, path, self.warnings.append)
        self.bus, self.ticks, self.k = bus, ticks, 0
        self.stop_at, self.stop_with = stop_at, stop_with

    def open(self):
        super().open()
        set_present(self.bus, self.ticks[0])  # the hand takes the legs

    def add(self, t_s, ticks):
        super().add(t_s, ticks)
        self.k += 1
        if self.stop_at is not None and self.k == self.stop_at:
            raise self.stop_with
        set_present(self.bus, self.ticks[min(self.k, len(self.ticks) - 1)])


def expected_deg(ticks) -> np.ndarray:
    direction = np.array([j.direction for j in CFG.joints])
    return (np.asarray(ticks) - 2048) / (direction * TICKS_PER_DEG)


def test_a_refusal_sends_nothing_but_pings_and_reads_and_writes_no_file(tmp_path):
    bus = guarded_mock_bus()
    asked = []
    out = tmp_path / "demo.csv"
    result = record_session(bus, IDS, PERIOD_S, TrajectorySink(CFG, out, print),
                            confirm=lambda n: asked.append(n) or False, n_samples=10, clock=VirtualClock())
    assert result.outcome == "declined" and result.exit_code == 0 and asked == [6]
    assert {inst for inst, _, _ in instructions(bus)} <= {wire.INST_PING, wire.INST_SYNC_READ}
    assert not out.exists()


def test_recording_reads_the_hand_exactly_after_torque_off(tmp_path):
    bus = guarded_mock_bus()
    ticks = hand_ticks(120)
    out = tmp_path / "demo.csv"
    result = record_session(bus, IDS, PERIOD_S, HandSink(out, bus, ticks), confirm=lambda n: True,
                            n_samples=120, clock=VirtualClock())
    assert result.outcome == "completed" and result.exit_code == 0 and result.torque == "off"
    assert torque_writes(bus) == [(i, 0) for i in IDS]  # torque off on every servo, nothing after
    sent = instructions(bus)
    first_read_after = next(k for k, (inst, pid, p) in enumerate(sent) if inst == wire.INST_WRITE) + len(IDS)
    assert sent[first_read_after][0] == wire.INST_SYNC_READ  # reads start after the last torque-off
    rec = Trajectory.load(out)
    assert len(rec) == 120
    np.testing.assert_allclose(rec.t_s, np.arange(120) * PERIOD_S, atol=1e-9)
    np.testing.assert_allclose(rec.angles_deg, expected_deg(ticks), atol=1e-6)
    assert not any(inst == wire.INST_SYNC_WRITE for inst, _, _ in sent)  # no goal was ever written


def test_reads_keep_absolute_deadlines_when_reads_and_writes_cost_time(tmp_path):
    """Reads start on the grid k * period even though each sample costs up to 80% of a period."""
    bus = guarded_mock_bus()
    clock = VirtualClock(start_s=50.0)
    costs = np.random.default_rng(5).uniform(0.0, 0.8 * PERIOD_S, 300)
    starts = []
    inner_read = bus.read_present_ticks

    def timed_read(ids):
        starts.append(clock.now())
        return inner_read(ids)

    class CostlySink(HandSink):
        def add(self, t_s, ticks):
            clock.advance(costs[self.k])
            super().add(t_s, ticks)

    bus.read_present_ticks = timed_read
    result = record_session(bus, IDS, PERIOD_S, CostlySink(tmp_path / "d.csv", bus, hand_ticks(300)),
                            confirm=lambda n: True, n_samples=300, clock=clock)
    assert result.outcome == "completed"
    reads = np.array(starts[1:])  # the first read is prepare()'s, before the question
    np.testing.assert_allclose(reads - reads[0], np.arange(300) * PERIOD_S, atol=1e-9)
    assert max(result.timing.lateness_s) < 1e-9


@pytest.mark.parametrize("stop, outcome, code", [(KeyboardInterrupt(), "stopped", 0),
                                                 (Terminated("signal 15"), "terminated", 143)])
def test_ctrl_c_and_sigterm_leave_every_sample_in_a_readable_file_and_torque_off(tmp_path, stop, outcome, code):
    bus = guarded_mock_bus()
    ticks = hand_ticks(200)
    out = tmp_path / "demo.csv"
    result = record_session(bus, IDS, PERIOD_S, HandSink(out, bus, ticks, stop_at=77, stop_with=stop),
                            confirm=lambda n: True, clock=VirtualClock())
    assert (result.outcome, result.exit_code, result.torque) == (outcome, code, "off")
    assert torque_writes(bus) == [(i, 0) for i in IDS]
    rec = Trajectory.load(out)
    np.testing.assert_allclose(rec.angles_deg, expected_deg(ticks[:77]), atol=1e-6)


def test_a_bus_error_stops_with_exit_1_the_file_complete_and_torque_off(tmp_path):
    bus = guarded_mock_bus()
    ticks = hand_ticks(100)
    out = tmp_path / "demo.csv"

    class DyingSink(HandSink):
        def add(self, t_s, ticks_now):
            super().add(t_s, ticks_now)
            if self.k == 40:
                self.bus.inner.port.drop_next_replies(10_000)  # the chain goes silent

    result = record_session(bus, IDS, PERIOD_S, DyingSink(out, bus, ticks), confirm=lambda n: True,
                            n_samples=100, clock=VirtualClock())
    assert result.outcome == "bus_error" and result.exit_code == 1
    assert "did not return its present position" in result.message()
    assert torque_writes(bus) == [(i, 0) for i in IDS]  # nothing tried after the error
    np.testing.assert_allclose(Trajectory.load(out).angles_deg, expected_deg(ticks[:40]), atol=1e-6)


def test_hold_writes_the_present_pose_as_goal_then_torque_on(tmp_path):
    bus = guarded_mock_bus()
    ticks = hand_ticks(60)
    result = record_session(bus, IDS, PERIOD_S, HandSink(tmp_path / "d.csv", bus, ticks), confirm=lambda n: True,
                            n_samples=60, clock=VirtualClock(), hold_at_end=True)
    assert result.torque == "holding", result.message()
    sent = instructions(bus)
    goal_at = max(k for k, (inst, _, _) in enumerate(sent) if inst == wire.INST_SYNC_WRITE)
    torque_on = [k for k, (inst, pid, p) in enumerate(sent)
                 if inst == wire.INST_WRITE and p[0] | p[1] << 8 == TORQUE_ADDR and p[2] == 1]
    assert len(torque_on) == len(IDS) and min(torque_on) > goal_at  # goal first, then torque on
    for servo_id, tick in zip(IDS, ticks[59]):
        goal = bus.inner.port.tables[servo_id][116:120]
        assert int.from_bytes(goal, "little", signed=True) == tick


def test_hold_refuses_a_pose_outside_the_limits_and_leaves_torque_off(tmp_path):
    bus = guarded_mock_bus()
    ticks = hand_ticks(30)
    ticks[-1, 1] = 2048 + int(120 * TICKS_PER_DEG)  # left knee at 120 deg, past its 110 deg limit
    warnings = []
    out = tmp_path / "d.csv"
    result = record_session(bus, IDS, PERIOD_S, HandSink(out, bus, ticks, warnings=warnings),
                            confirm=lambda n: True, n_samples=30, clock=VirtualClock(), hold_at_end=True)
    assert result.torque == "off" and "outside its limits" in result.message()
    assert not any(inst == wire.INST_SYNC_WRITE for inst, _, _ in instructions(bus))  # no goal reached a servo
    assert [v for _, v in torque_writes(bus)] == [0] * (2 * len(IDS))  # off, and off again
    rec = Trajectory.load(out)
    assert rec.angles_deg[-1, 1] == pytest.approx(120.0, abs=0.1)  # recorded faithfully
    assert len(warnings) == 1 and "knee_pitch_left" in warnings[0] and "110" in warnings[0]


def test_out_of_limit_recordings_fail_check_and_are_refused_by_walk(tmp_path, capsys):
    bus = guarded_mock_bus()
    ticks = hand_ticks(60)
    ticks[30:40, 0] = 2048 + int(70 * TICKS_PER_DEG)  # left hip at 70 deg (limit 60) for ten samples
    out = tmp_path / "d.csv"
    record_session(bus, IDS, PERIOD_S, HandSink(out, bus, ticks), confirm=lambda n: True, n_samples=60,
                   clock=VirtualClock())
    assert main(["check", str(out), "--robot", "xl430-biped"]) == 1
    capsys.readouterr()
    assert main(["walk", "--dry-run", "--trajectory", str(out)]) == 1  # refused: a limit is broken
    err = capsys.readouterr().err
    assert "refused before anything moved" in err and "hip_pitch_left" in err


def test_root_is_reconstructed_from_the_lower_foot_standing_on_the_ground(tmp_path):
    bus = guarded_mock_bus()
    ticks = np.tile(np.full(6, 2048), (10, 1))
    out = tmp_path / "stand.csv"
    record_session(bus, IDS, PERIOD_S, HandSink(out, bus, ticks), confirm=lambda n: True, n_samples=10,
                   clock=VirtualClock())
    g = CFG.geometry
    rec = Trajectory.load(out)
    np.testing.assert_allclose(rec.root_m[:, 2], g.thigh_m + g.shank_m + g.ankle_height_m, atol=1e-9)
    np.testing.assert_allclose(rec.root_m[:, 0], 0.0, atol=1e-12)


# ---- command line ------------------------------------------------------------------------------

def test_cli_dry_run_records_the_standing_mock_robot(tmp_path, capsys):
    out = tmp_path / "demo.csv"
    assert main(["record", "--dry-run", "--yes", "--duration", "0.5", "-o", str(out)]) == 0
    stdout = capsys.readouterr().out
    assert "30 samples" in stdout and "torque stays off" in stdout
    rec = Trajectory.load(out)
    assert len(rec) == 30 and np.abs(rec.angles_deg).max() == 0.0


@pytest.mark.parametrize("answer, outcome", [("y\n", "completed"), ("n\n", "cancelled"), ("", "cancelled")])
def test_cli_asks_before_torque_off(tmp_path, capsys, monkeypatch, answer, outcome):
    import io

    monkeypatch.setattr("sys.stdin", io.StringIO(answer))
    out = tmp_path / "demo.csv"
    assert main(["record", "--dry-run", "--duration", "0.1", "-o", str(out)]) == 0
    captured = capsys.readouterr()
    assert QUESTION.format(n=6) in captured.out
    assert outcome in captured.out.lower()
    assert out.exists() == (outcome == "completed")


@pytest.mark.parametrize("args, words", [
    (["-o", "{tmp}/demo.npz", "--duration", "1"], ".csv"),
    (["-o", "{tmp}/demo.csv", "--duration", "-1"], "--duration"),
    (["-o", "{tmp}/demo.csv", "--duration", "0.01"], "fewer than 2 samples"),
    (["-o", "{tmp}/demo.csv"], "--dry-run needs --duration"),
    (["-o", "{tmp}/no/such/dir/demo.csv", "--duration", "1"], "cannot write"),
    (["-o", "{tmp}/demo.csv", "--duration", "1", "--robot", "{tmp}/nope.toml"], "nope.toml"),
])
def test_cli_bad_input_is_one_line_exit_2(tmp_path, capsys, args, words):
    argv = ["record", "--dry-run", "--yes"] + [a.format(tmp=tmp_path) for a in args]
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert words in err and len(err.strip().splitlines()) == 1 and "Traceback" not in err
    assert not (tmp_path / "demo.csv").exists()


def test_cli_real_port_that_does_not_exist_is_bad_input(tmp_path, capsys):
    assert main(["record", "--yes", "--port", str(tmp_path / "ttyNONE"), "-o", str(tmp_path / "d.csv")]) == 2
    assert "no such serial port" in capsys.readouterr().err


def test_a_file_that_cannot_be_written_any_more_stops_with_exit_1_and_torque_off(tmp_path):
    bus = guarded_mock_bus()

    class FullDisk(HandSink):
        def add(self, t_s, ticks):
            if self.k == 25:
                raise OSError(28, "No space left on device")
            super().add(t_s, ticks)

    out = tmp_path / "d.csv"
    result = record_session(bus, IDS, PERIOD_S, FullDisk(out, bus, hand_ticks(50)), confirm=lambda n: True,
                            n_samples=50, clock=VirtualClock(), hold_at_end=True)
    assert (result.outcome, result.exit_code, result.torque) == ("file_error", 1, "off")
    assert "No space left" in result.message()
    assert torque_writes(bus) == [(i, 0) for i in IDS]  # no hold after a failure
    assert len(Trajectory.load(out)) == 25
