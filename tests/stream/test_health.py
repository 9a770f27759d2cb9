"""Servo health in a session: the config's [health] thresholds (refused past a servo's own limits), the monitor's
warnings and stops, and a walk that stops safely (the bus-fault ramp, exit 1) when a servo gets too hot or its
supply too low. The servos are the mock chain's, whose temperature and voltage registers the tests set."""

from __future__ import annotations

import re

import numpy as np
import pytest

from gaitbot.bus.factory import make_dry_run_bus
from gaitbot.servos.health import HealthReading, default_thresholds
from gaitbot.stream.clock import VirtualClock
from gaitbot.stream.health import HealthMonitor, ServoHealthStop
from gaitbot.stream.session import walk_session
from helpers import CONFIG_DIR, config, gaitbot

XL = "XL430-W250"


def with_health(tmp_path, text: str):
    body = (CONFIG_DIR / "xl430-biped.toml").read_text() + "\n[health]\n" + text + "\n"
    path = tmp_path / "bot.toml"
    path.write_text(body)
    return path


@pytest.mark.parametrize("text, words", [
    ("stop_temperature_c = 75.0", "health.stop_temperature_c: 75 C is above the XL430-W250's own shutdown temperature "
                                  "72 C (allowed: up to 72)"),
    ("warn_temperature_c = 70.0", "health.warn_temperature_c: 70 C is above the stop temperature 67 C"),
    ("stop_voltage_v = 5.5", "health.stop_voltage_v: 5.5 V is under the XL430-W250's own minimum input voltage 6 V"),
    ("warn_load_pct = 120.0", "health.warn_load_pct: 120 is above 100 %"),
    ("stop_temprature_c = 60.0", "health.stop_temprature_c: unknown key (did you mean 'stop_temperature_c'?"),
])
def test_a_threshold_past_the_servos_own_limit_is_one_line_and_exit_2(tmp_path, text, words):
    proc = gaitbot("walk", "--robot", str(with_health(tmp_path, text)), "--dry-run", "--record",
                   str(tmp_path / "run.jsonl"))
    assert proc.returncode == 2
    assert words in proc.stderr and proc.stderr.count("\n") == 1, proc.stderr
    assert not (tmp_path / "run.jsonl").exists()  # nothing sent


def test_overrides_apply_to_every_servo_within_its_limits(tmp_path):
    from gaitbot.robot.config import load_robot_config
    from gaitbot.robot.health import health_thresholds

    robot = load_robot_config(with_health(tmp_path, "stop_temperature_c = 72.0\nwarn_voltage_v = 11.0"))
    t = health_thresholds(robot)[1]
    assert (t.stop_temperature_c, t.warn_voltage_v, t.warn_temperature_c, t.stop_voltage_v) == (72.0, 11.0, 62.0, 6.5)


def test_the_monitor_warns_once_per_servo_and_kind_and_stops_at_a_stop_threshold():
    warnings = []
    monitor = HealthMonitor({1: default_thresholds(XL)}, {1: "knee"}, {1: XL}, warnings.append)
    monitor.observe(HealthReading(1, 2048, 50.0, 12.0, 10.0))
    monitor.observe(HealthReading(1, 2048, 63.0, 12.0, 85.0))
    monitor.observe(HealthReading(1, 2048, 64.0, 12.0, 85.0))
    assert warnings == ["servo 1 (knee) at 63 °C (warning at 62, stop at 67 °C)",
                        "servo 1 (knee) load 85 % (warning at 80 %)"]
    with pytest.raises(ServoHealthStop, match=r"servo 1 \(knee\) is at 67 °C, at or above its stop temperature 67 °C; "
                                              r"the XL430-W250 shuts itself down at 72 °C"):
        monitor.observe(HealthReading(1, 2048, 67.0, 12.0, 85.0))
    with pytest.raises(ServoHealthStop, match=r"6.5 V input voltage, at or under its stop voltage 6.5 V") as caught:
        monitor.observe(HealthReading(1, 2048, 40.0, 6.5, 0.0))
    assert caught.value.kind == "voltage"
    assert (monitor.hottest.value, monitor.lowest_voltage.value, monitor.peak_load.value) == (67.0, 6.5, 85.0)


def hot_bus(robot, servo_id, temperature_c=None, voltage_v=None):
    bus = make_dry_run_bus(robot.bus.backend, robot.bus.protocol, robot.models_by_id)
    table = bus.port.tables[servo_id]
    if temperature_c is not None:
        table[146] = int(temperature_c)
    if voltage_v is not None:
        table[144:146] = int(voltage_v * 10).to_bytes(2, "little")
    return bus, table


def walk(robot, bus, monitor):
    frames = np.tile(np.full(len(robot.ids), 2048), (120, 1))
    frames[:, 1] += np.arange(120) * 2  # the knee moves: the stop ramp has something to brake
    return walk_session(bus, robot.ids, frames, np.full(len(robot.ids), 2048), max_velocity_ticks_per_s=3000,
                        max_accel_ticks_per_s2=50000, clock=VirtualClock(), handle_sigterm=False, health=monitor)


def test_a_servo_heating_mid_walk_stops_it_with_the_bus_fault_ramp(monkeypatch):
    """The knee heats up after 40 of the walk's per-frame reads. Since the merge with the faults work those
    reads are the budgeted read-backs (``Bus.read_back`` of the health block, ``set_read_back_blocks``), not
    ``read_health`` (now only the once-per-servo check before torque on), so the reads counted are those."""
    robot = config("xl430-biped")
    bus, table = hot_bus(robot, 2, temperature_c=40)
    monitor = HealthMonitor.for_robot(robot)
    reads = {"n": 0}
    original = bus.read_back

    def heating(servo_id, budget_s):
        reads["n"] += 1
        if reads["n"] == 40:
            table[146] = 67  # the knee reaches its stop temperature
        return original(servo_id, budget_s)

    monkeypatch.setattr(bus, "read_back", heating)
    result = walk(robot, bus, monitor)
    assert reads["n"] > 40  # it heated mid-walk, read back in the walk's own frames
    assert (result.outcome, result.exit_code) == ("health_stop", 1)
    assert "servo 2 (knee_pitch_left) is at 67 °C" in result.message() and "ramped to the stand pose" in result.message()
    assert result.reached_stand
    assert monitor.hottest.servo_id == 2


def test_a_robot_too_hot_or_under_powered_does_not_start():
    robot = config("xl430-biped")
    for kwargs, words in (({"temperature_c": 70}, "is at 70 °C"), ({"voltage_v": 6.2}, "6.2 V input voltage")):
        bus, table = hot_bus(robot, 4, **kwargs)
        result = walk(robot, bus, HealthMonitor.for_robot(robot))
        assert result.outcome == "health_stop" and words in str(result.error)
        assert not result.torque_off and table[64] == 0  # torque never went on
        assert not [p for p in bus.port.tx_packets if p[7] == 0x83]  # no goal was sent


def test_walk_dry_run_prints_the_health_summary():
    proc = gaitbot("walk", "--dry-run", "--steps", "0.05")
    assert proc.returncode == 0, proc.stderr
    # the mock chain's registers as they start: 30 C, 12.0 V
    assert re.search(r"servo health over \d+ reads: hottest servo \d \(\w+\) 30 °C, lowest voltage 12.0 V", proc.stdout)
