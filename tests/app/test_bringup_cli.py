"""The bring-up commands' own edges, in process or on the mock bus: help texts, scan on a dry run (reads only),
bad input refused in one line with exit 2 before anything is sent, and the emulator's new options."""

from __future__ import annotations

import json

import pytest

from gaitbot.app import emulator as emulator_cli
from gaitbot.app.cli import build_parser
from gaitbot.bus.factory import make_probe_bus
from gaitbot.bus.bringup import describe_servo, survey
from gaitbot.servos import wire
from helpers import config, gaitbot, run_cli


@pytest.mark.parametrize("command", ["setup", "calibrate", "scan"])
def test_every_new_command_has_a_description_an_example_and_help_for_every_option(command):
    sub = build_parser()._subparsers._group_actions[0].choices[command]
    assert sub.description and "examples:" in sub.epilog and f"gaitbot {command}" in sub.epilog
    for action in sub._actions:
        if action.dest != "help":
            assert action.help, (command, action.dest)


@pytest.mark.parametrize("robot", ["xl430-biped", "ax12a-biped", "sts3215-biped"])
def test_scan_on_the_dry_run_bus_lists_the_config_and_writes_nothing(robot, capsys):
    code, out, err = run_cli(capsys, "scan", "--robot", robot, "--dry-run", "--json")
    assert code == 0, err
    result = json.loads(out)
    cfg = config(robot)
    assert [s["id"] for s in result["servos"]] == sorted(cfg.ids)
    assert {s["joint"] for s in result["servos"]} == set(cfg.joint_names)
    assert result["missing_joints"] == [] and result["baud_rates"][0] >= result["baud_rates"][-1]
    probe = make_probe_bus(cfg.bus.backend, cfg.bus.protocol, "mock", dry_run=True, models=cfg.models_by_id,
                           baudrate=cfg.bus.baudrate)
    with probe:
        for found in (s for r in survey(probe, (cfg.bus.baudrate, 57_600)) for s in r.found):
            describe_servo(probe, found)
    framing = wire.framing_for(cfg.bus.backend, cfg.bus.protocol)
    sent = [wire.parse(p, framing, status=False).instruction for p in probe._inner_port.tx_packets]
    assert set(sent) <= {wire.INST_PING, wire.INST_READ}  # a scan only asks


def test_scan_text_names_a_missing_joint_and_exits_1(monkeypatch, capsys):
    import gaitbot.app.scan as scan

    def without_servo_5(backend, protocol, port, *, models=None, **kwargs):
        return make_probe_bus(backend, protocol, port, models={i: m for i, m in models.items() if i != 5}, **kwargs)

    monkeypatch.setattr(scan, "make_probe_bus", without_servo_5)
    code, out, _ = run_cli(capsys, "scan", "--robot", "xl430-biped", "--dry-run", "--baud", "1000000")
    assert code == 1
    assert "missing: knee_pitch_right (id 5, XL430-W250, 1,000,000 baud) did not answer" in out
    assert out.count("XL430-W250    46") == 5  # the five that answered, with their firmware


@pytest.mark.parametrize("argv, words", [
    (["setup", "--robot", "xl430-biped", "--joint", "elbow_left", "--port", "/dev/null"], "--joint elbow_left: no such joint"),
    (["scan", "--robot", "xl430-biped", "--baud", "1234", "--dry-run"], "--baud 1234: the dynamixel SDK does not offer it"),
    (["calibrate", "--robot", "xl430-biped", "-o", "cal.json", "--port", "/dev/null"], "must end in .toml"),
    (["setup", "--robot", "xl430-biped", "--port", "/dev/nonexistent-port"], "--port /dev/nonexistent-port: no such"),
])
def test_bad_input_is_one_line_and_exit_2(argv, words, tmp_path):
    proc = gaitbot(*argv)
    assert proc.returncode == 2 and words in proc.stderr and proc.stderr.count("\n") == 1, proc.stderr


def test_setup_refuses_a_config_baud_rate_the_servos_cannot_hold(tmp_path):
    path = tmp_path / "bot.toml"
    path.write_text(config("xl430-biped").path.read_text().replace("baudrate = 1000000", "baudrate = 500000"))
    proc = gaitbot("setup", "--robot", str(path), "--port", "/dev/null")
    assert proc.returncode == 2, proc.stderr
    assert "bus.baudrate: a XL430-W250 (hip_pitch_left) cannot run at 500,000 baud" in proc.stderr


def parse(*argv):
    return emulator_cli.config_from_args(emulator_cli.build_parser().parse_args(list(argv)))


def test_emulator_options_for_bring_up(tmp_path):
    fresh = parse("--robot", "ax12a-biped", "--factory-fresh", "--one-at-a-time")
    assert len(fresh.fresh) == 8 and fresh.one_at_a_time and fresh.models == {}
    assert len(parse("--protocol", "feetech-sts", "--factory-fresh", "3").fresh) == 3
    heat = parse("--robot", "xl430-biped", "--load", "3:60", "--temperature", "3:50", "--heat-rate", "2",
                 "--supply-v", "11.1", "--voltage-sag", "0.5")
    assert (heat.loads_pct, heat.temperatures_c, heat.heat.heat_c_per_s, heat.supply_v, heat.voltage_sag_v_per_s) == \
        ({3: 60.0}, {3: 50.0}, 2.0, 11.1, 0.5)
    hand = tmp_path / "hand.csv"
    hand.write_text("1,2\n2000,2100\n2050,2100\n")
    assert parse("--protocol", "dxl2", "--ids", "1-2", "--hand-ticks", str(hand)).hand.ticks == {1: [2000, 2050],
                                                                                                  2: [2100, 2100]}
    for argv, words in ((["--protocol", "dxl2", "--baudrate", "500000"], "cannot run at it"),
                        (["--protocol", "dxl2", "--one-at-a-time"], "needs --factory-fresh"),
                        (["--protocol", "dxl2", "--load", "1:150"], "within 0..100"),
                        (["--protocol", "dxl2", "--hand-ticks", str(hand), "--hand", str(hand)], "one of --hand")):
        with pytest.raises(ValueError, match=words):
            parse(*argv)
