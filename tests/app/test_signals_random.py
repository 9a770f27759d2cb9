"""SIGINT and SIGTERM at random moments of a walk (issue 26): whatever starts a stop ramp (a signal, a
silent servo, a servo's error bits, a health stop), and whenever signals arrive, the ramp ends at the stand
pose within every limit, and ``gaitbot check`` passes the recording.

Each run is ``gaitbot walk --dry-run --record`` in this process (the virtual clock: deterministic, a run
takes about a second), with the signals sent from inside the mock port while the SDK is in the middle
of an exchange (the hostile case: a handler that raised there would leave the exchange half done), at
tx packets drawn from a seeded random generator. Faults are made in the mock chain after a fixed packet;
the servos start 120 ticks away from the walk's first pose, so every walk has a start ramp. The signals
of a fault scenario are drawn from the fault onward (detection, then the fault's stop ramp); the others'
from the whole run (start ramp, walk, final ramp). The long version (more seeds) is marked slow.
"""

from __future__ import annotations

import json
import os
import signal

import numpy as np
import pytest

from gaitbot.bus import dry_run as mock
from gaitbot.bus.recording import decode_goal_frames
from gaitbot.robot.calibration import standing_ticks, tick_limits
from helpers import config, run_cli

ROBOTS = ("xl430-biped", "ax12a-biped")  # Dynamixel 2.0 and 1.0
SCENARIOS = ("healthy", "silent", "error-bits", "hot")
VICTIM = {"xl430-biped": 3, "ax12a-biped": 13}
FAULT_AT_PACKET = 150  # in the walk (the start ramp and the gain writes are over by then)
START_OFFSET_TICKS = 120
WALK = ["--steps", "0.03"]


class Chain:
    """What the mock port does in one run: when its faults start, and the packets at which signals go off."""

    def __init__(self, robot: str, scenario: str, signals: dict[int, int]) -> None:
        robot_config = config(robot)
        stand = dict(zip(robot_config.ids, standing_ticks(robot_config).tolist()))
        # each servo starts up to START_OFFSET_TICKS from standing, towards the middle of its limits
        self.start_offset = {i: int(np.sign((lo + hi) / 2 - stand[i]) or 1) * min(START_OFFSET_TICKS, (hi - lo) // 4)
                             for i, (lo, hi) in tick_limits(robot_config).items()}
        self.victim = VICTIM[robot]
        self.scenario = scenario
        self.signals = signals  # tx packet index -> signal sent while that packet is being written
        self.tx = 0
        self.first_goal_packet: int | None = None  # the first SYNC WRITE (goal positions)

    @property
    def faulty(self) -> bool:
        return self.scenario != "healthy" and self.tx > FAULT_AT_PACKET


@pytest.fixture
def chain_patch(monkeypatch):
    """Install a Chain's behaviour on the mock port class; give back a function that sets the Chain."""
    state = {}
    initial_table, write_port, reply = mock.DryRunPort.initial_table, mock.DryRunPort.writePort, mock.DryRunPort._reply

    def shifted_table(model, servo_id, baudrate=None):
        table = initial_table(model, servo_id, baudrate)
        for address, length in ((model.addr_present_position, model.len_present_position),
                                (model.addr_goal_position, model.len_goal_position)):
            value = int.from_bytes(table[address:address + length], model.byte_order)
            value += state["chain"].start_offset[servo_id]
            table[address:address + length] = value.to_bytes(length, model.byte_order)
        return table

    def writing(self, packet):
        chain = state["chain"]
        instruction = bytes(packet)[7 if self.framing == "v2" else 4]
        if chain.first_goal_packet is None and instruction == 0x83:
            chain.first_goal_packet = chain.tx
        signum = chain.signals.get(chain.tx)
        chain.tx += 1
        if signum is not None:
            os.kill(os.getpid(), signum)  # delivered here, inside the SDK's exchange
        if chain.faulty and chain.scenario == "hot":
            model = self.models[chain.victim]
            address = model.control_table["Present Temperature"].address
            self.tables[chain.victim][address] = 95  # above every model's stop threshold
        return write_port(self, packet)

    def replying(self, servo_id, params):
        chain = state["chain"]
        if chain.faulty and servo_id == chain.victim and chain.scenario == "silent":
            return
        if chain.faulty and servo_id == chain.victim and chain.scenario == "error-bits":
            error = 0x80 if self.framing == "v2" else 0x20  # the Alert bit (2.0), Overload (1.0)
            packet = (mock.wire.build_v2(servo_id, mock.wire.INST_STATUS_V2, bytes([error]) + params)
                      if self.framing == "v2" else mock.wire.build_v1(servo_id, error, params))
            self.rx_packets.append(packet)
            self._rx_buffer += packet
            return
        reply(self, servo_id, params)

    monkeypatch.setattr(mock.DryRunPort, "initial_table", staticmethod(shifted_table))
    monkeypatch.setattr(mock.DryRunPort, "writePort", writing)
    monkeypatch.setattr(mock.DryRunPort, "_reply", replying)
    old = {s: signal.getsignal(s) for s in (signal.SIGINT, signal.SIGTERM)}
    yield lambda chain: state.__setitem__("chain", chain)
    for signum, handler in old.items():  # gaitbot ignores signals once a signalled command ends
        signal.signal(signum, handler)


def walk_and_check(capsys, tmp_path, chain_patch, robot: str, scenario: str, signals: dict[int, int]):
    """One walk with these signals; every promise checked. Returns the walk's exit status."""
    record = tmp_path / f"{robot}-{scenario}-{'-'.join(map(str, signals))}.jsonl"
    chain = Chain(robot, scenario, signals)
    chain_patch(chain)
    code, out, err = run_cli(capsys, "walk", "--robot", robot, *WALK, "--dry-run", "--record", record)
    text = out + err
    assert "Traceback" not in text and "abandoned" not in text and "in use" not in text, text
    first = signals[min(signals)] if signals and min(signals) < chain.tx else None
    expected = {None: {0}, signal.SIGINT: {130}, signal.SIGTERM: {143}}[first]
    if scenario != "healthy":
        expected = {1} | expected  # the first cause decides: the fault, or a signal before it was found
    assert code in expected, text
    robot_config = config(robot)
    _, _, ticks = decode_goal_frames(record)
    if chain.first_goal_packet is None or min(signals) < chain.first_goal_packet:
        assert len(ticks) == 0 and code in expected, text  # stopped before anything moved: nothing to ramp
        return code
    stand = standing_ticks(robot_config)
    assert np.abs(ticks[-1] - stand).max() <= 1, f"last goal {ticks[-1]} is not the stand pose {stand}\n{text}"
    check_code, check_out, check_err = run_cli(capsys, "check", record, "--json")
    report = json.loads(check_out)
    assert report["joint_check"]["ok"] and not report["joint_check"]["violations"], report["joint_check"]["violations"]
    if scenario == "hot":  # the recording shows the servo that was too hot, and check says so; nothing else
        findings, issues = report["servo_health"]["findings"], report["bus_issues"]
        assert all(f["servo_id"] == chain.victim for f in findings), findings
        assert findings or code != 1, "the walk stopped for a hot servo the recording does not show"
        assert all(i["kind"] == "health" and i["message"].startswith(f"servo {chain.victim} ") for i in issues), issues
        assert report["frame_timing"]["n_backwards"] == 0
    else:
        assert check_code == 0 and report["ok"], (check_out[:3000], check_err)
    return code


def packets_of(capsys, tmp_path, chain_patch, robot: str, scenario: str) -> Chain:
    """The run without signals: its tx packets (the window the signals are drawn from) and its first goal."""
    chain = Chain(robot, scenario, {})
    chain_patch(chain)
    code, out, err = run_cli(capsys, "walk", "--robot", robot, *WALK, "--dry-run")
    assert code == (0 if scenario == "healthy" else 1), out + err
    if scenario != "healthy":
        assert "ramped to the stand pose" in out + err, out + err
    return chain


def random_signals(rng: np.random.Generator, low: int, high: int) -> dict[int, int]:
    """One to three signals, SIGINT or SIGTERM each, at distinct packets in [low, high)."""
    count = int(rng.integers(1, 4))
    at = sorted(set(int(k) for k in rng.integers(low, high, size=count)))
    return {k: int(rng.choice([signal.SIGINT, signal.SIGTERM])) for k in at}


def run_seeds(capsys, tmp_path, chain_patch, robot: str, scenario: str, seeds: range) -> None:
    total = packets_of(capsys, tmp_path, chain_patch, robot, scenario).tx
    low = 0 if scenario == "healthy" else FAULT_AT_PACKET
    for seed in seeds:
        rng = np.random.default_rng([seed, ROBOTS.index(robot), SCENARIOS.index(scenario)])
        walk_and_check(capsys, tmp_path, chain_patch, robot, scenario, random_signals(rng, low, total))


@pytest.mark.parametrize("scenario", SCENARIOS)
@pytest.mark.parametrize("robot", ROBOTS)
def test_signals_at_random_moments_end_standing_and_the_recording_checks(capsys, tmp_path, chain_patch, robot,
                                                                           scenario):
    run_seeds(capsys, tmp_path, chain_patch, robot, scenario, range(2))


@pytest.mark.slow
@pytest.mark.parametrize("scenario", SCENARIOS)
@pytest.mark.parametrize("robot", ROBOTS)
def test_signals_at_many_random_moments(capsys, tmp_path, chain_patch, robot, scenario):
    run_seeds(capsys, tmp_path, chain_patch, robot, scenario, range(2, 14))


def test_a_signal_in_every_phase(capsys, tmp_path, chain_patch):
    """Not left to chance: one signal before anything moved (the checks before torque on), one in the start ramp
    (its fourth frame), one in the middle of the walk, one during the final ramp (the last frames), and one in
    each fault's stop ramp (its last packets)."""
    robot = "xl430-biped"
    healthy = packets_of(capsys, tmp_path, chain_patch, robot, "healthy")
    assert 10 < healthy.first_goal_packet < 40, healthy.first_goal_packet
    for k in (12, healthy.first_goal_packet + 7, healthy.tx // 2, healthy.tx - 8):
        walk_and_check(capsys, tmp_path, chain_patch, robot, "healthy", {k: signal.SIGINT})
    for scenario in SCENARIOS[1:]:
        total = packets_of(capsys, tmp_path, chain_patch, robot, scenario).tx
        walk_and_check(capsys, tmp_path, chain_patch, robot, scenario, {total - 10: signal.SIGTERM})
