"""Exit statuses are part of the interface (docs/command-line.md): every command, every status it can give.

0 done; 1 the robot or the check failed (a limit broken, a bus fault, a fall in the simulation, a missing
servo); 2 bad input (one line on stderr); 130 / 143 Ctrl-C / SIGTERM; 141 output closed early. Run in
process through gaitbot.app.cli.main. Elsewhere: signals during a walk (130, 143) in
tests/app/test_walk_signals.py; a recording's Ctrl-C (0), SIGTERM (143) and lost port (1) in
tests/app/test_record_emulator.py; bus faults during a walk (1) in tests/app/test_emulator_e2e.py; an
eigen synth walk that breaks a limit (1) in tests/gait/test_eigen.py; a closed output (141) in
tests/app/test_command_line.py.
"""

from __future__ import annotations

import io
import math
import re

import pytest

from gaitbot.app.cli import main
import gaitbot.emulator as se
from helpers import CONFIG_DIR, config, emulator_for, run_cli


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    """A walk, a walk that breaks the knee's limit, two example walks and an eigen-gait model."""
    folder = tmp_path_factory.mktemp("files")
    walk = folder / "walk.csv"
    assert main(["generate", "--distance", "0.5", "-o", str(walk)]) == 0
    broken = folder / "broken.csv"
    lines = walk.read_text().splitlines()
    row = lines[100].split(",")
    row[2] = "150.0"  # knee_pitch_left_deg far past its 110 deg limit
    broken.write_text("\n".join(lines[:100] + [",".join(row)] + lines[101:]) + "\n")
    examples = []
    for step in (0.03, 0.05, 0.07):
        path = folder / f"ex_{step}.npz"
        assert main(["generate", "--steps", ",".join([str(step)] * 6), "-o", str(path)]) == 0
        examples.append(str(path))
    model = folder / "model.npz"
    assert main(["eigen", "fit", *examples, "-o", str(model)]) == 0
    assert main(["robot", "export", "op3", "--urdf", str(folder / "op3.urdf")]) == 0
    tight = folder / "tight.toml"
    tight.write_text((CONFIG_DIR / "xl430-biped.toml").read_text().replace("max_deg = 110.0", "max_deg = 20.0"))
    commands = CONFIG_DIR / "commands" / "drive-demo.jsonl"
    return {"walk": walk, "broken": broken, "examples": examples, "model": model, "tight": tight, "out": folder,
            "commands": commands}


def _argv(template: str, files) -> list[str]:
    values = {k: str(v) for k, v in files.items() if k != "examples"}
    values["examples"] = " ".join(files["examples"])
    return template.format(**values).split()


CASES = [
    ("plan", "plan --distance 0.3", 0),
    ("plan", "plan --distance -1", 2),
    ("plan", "plan --terrain {out}/none.toml", 2),
    ("generate", "generate --steps 0.05 -o {out}/g.csv", 0),
    ("generate", "generate --steps 0.05 -o {out}/g.txt", 2),
    ("plot", "plot {walk} -o {out}/w.png", 0),
    ("plot", "plot {out}/none.csv -o {out}/w.png", 2),
    ("walk", "walk --dry-run --steps 0.05", 0),
    ("walk", "walk --dry-run --steps 0.05 --robot {tight}", 1),  # a limit broken: refused, nothing moves
    ("walk", "walk --trajectory {broken} --dry-run", 1),
    ("walk", "walk --sim --steps 0.05,0.05 --free-pitch", 1),  # the simulated robot falls
    ("walk", "walk --dry-run --steps 0.05 --rate 0", 2),
    ("check", "check {walk}", 0),
    ("check", "check {broken}", 1),
    ("check", "check {out}/none.csv", 2),
    ("eigen fit", "eigen fit {examples} -o {out}/m2.npz", 0),
    ("eigen fit", "eigen fit {walk} -o {out}/m2.npz --components 9", 2),
    ("eigen synth", "eigen synth {model} --step-length 0.05 -o {out}/s.csv", 0),
    ("eigen synth", "eigen synth {model} --step-length 0.05 --robot ax12a-biped -o {out}/s.csv", 2),
    ("record", "record --dry-run --duration 0.5 --yes -o {out}/r.csv", 0),
    ("record", "record --dry-run --yes -o {out}/r.csv", 2),
    ("scan", "scan --dry-run", 0),
    ("scan", "scan --dry-run --robot none-such", 2),
    ("setup", "setup --joint elbow_left --port /dev/null", 2),  # no such joint: refused before the port is opened
    ("calibrate", "calibrate -o {out}/cal.json --port /dev/null", 2),  # a calibration file is TOML
    ("robot", "robot export ax12a-biped --urdf {out}/ax12a.urdf", 0),
    ("robot", "robot export none-such --urdf {out}/x.urdf", 2),  # no such robot
    ("robot export", "robot export op3 --mjcf {out}/op3.xml", 0),
    ("robot export", "robot export op3", 2),  # no output named
    ("robot import", "robot import {out}/op3.urdf --like op3 -o {out}/mine.toml", 0),
    ("robot import", "robot import {walk} -o {out}/mine.toml", 2),  # a CSV is not a robot description
    ("robot new", "robot new mybot --legs 12 -o {out}/mybot.toml", 0),
    ("robot new", "robot new mybot --legs 12 -o {out}/mybot.csv", 2),  # a config is a .toml
    ("drive", "drive --robot op3 --dry-run --input commands:{commands}", 0),
    ("drive", "drive --robot xl430-biped --dry-run --input commands:{commands}", 2),  # no [steer]
]


@pytest.mark.parametrize("command, template, status", CASES, ids=[f"{c[0]}-{c[2]}-{i}" for i, c in enumerate(CASES)])
def test_status(capsys, files, command, template, status):
    code, _, err = run_cli(capsys, *_argv(template, files))
    assert code == status, err
    if status == 2:
        assert err.count("\n") == 1 and "Traceback" not in err, err  # one line naming what is wrong


#: setup and calibrate (added with the bring-up work) have no dry run: their statuses 0 and 1 are run on the servo
#: emulator by test_bring_up_status. Each row: command, arguments ({port}: the emulator's pty), status, the servos
#: on the emulator's chain (ids of the xl430-biped config), the servos that are silent.
BRING_UP = [
    ("setup", "setup --joint hip_pitch_left --yes --reply-timeout-ms 5 --port {port}", 0, (1,), ()),  # already set up
    ("setup", "setup --joint hip_pitch_left --yes --reply-timeout-ms 5 --port {port}", 1, (1,), (1,)),  # nothing answers
    ("calibrate", "calibrate --yes --reply-timeout-ms 250 -o {out}/bot.calibration.toml --port {port}", 0,
     (1, 2, 3, 4, 5, 6), ()),
]


def test_every_command_is_covered():
    """Every command's 0 and 2 (setup and calibrate, added by the bring-up work, among them: BRING_UP)."""
    from gaitbot.app.cli import build_parser

    covered = {(c, s) for c, _, s in CASES} | {(c, s) for c, _, s, _, _ in BRING_UP}
    for command in build_parser().commands:
        if command != "eigen":
            assert {(command, 0), (command, 2)} <= covered, command
    for command in ("walk", "check"):  # 1 for scan below; for eigen synth and record: see the module docstring
        assert (command, 1) in covered, command


def test_scan_with_a_missing_servo_exits_1(capsys, tmp_path):
    """The missing servo is named in scan's own words since the bring-up work rewrote scan (every rate, a
    ``missing:`` line per configured joint that did not answer, docs/bring-up.md), not a MISSING table row."""
    cfg = CONFIG_DIR / "xl430-biped.toml"
    with emulator_for(cfg, tmp_path / "log.jsonl", se.Faults(silent={3})) as chain:
        # a 20 ms quiet window ends each rate's broadcast ping (the SDK's own window is 1.4 s at 57,600 baud)
        code, out, _ = run_cli(capsys, "scan", "--robot", cfg, "--port", chain.path, "--reply-timeout-ms", "20")
    assert code == 1
    assert "missing: ankle_pitch_left (id 3, XL430-W250, 1,000,000 baud) did not answer" in out
    assert not re.search(r"(?m)^\s+3 ", out)  # and not listed among the servos that answered


@pytest.mark.parametrize("command, template, status, ids, silent", BRING_UP,
                         ids=[f"{c[0]}-{c[2]}-{i}" for i, c in enumerate(BRING_UP)])
def test_bring_up_status(capsys, monkeypatch, files, command, template, status, ids, silent):
    cfg = config("xl430-biped")
    models = {i: m for i, m in cfg.models_by_id.items() if i in ids}
    hand = None
    if command == "calibrate":  # the person holds the zero pose (centre ticks), then bends each joint 30 deg
        bend = {j.id: round(math.radians(30) * j.model.ticks_per_rad) for j in cfg.joints}
        rows = [{i: cfg.models_by_id[i].centre_tick for i in ids}]
        rows += [{i: cfg.models_by_id[i].centre_tick + (bend[i] if i == bent else 0) for i in ids} for bent in ids]
        hand = se.Hand({i: [r[i] for r in rows] for i in ids})
        monkeypatch.setattr("sys.stdin", io.StringIO("\n" * len(rows)))  # Enter at each step
    emulator = se.ServoEmulator(se.EmulatorConfig(cfg.bus.backend, cfg.bus.protocol, models, cfg.bus.baudrate,
                                                  se.Faults(silent=set(silent)), hand=hand))
    with emulator:
        argv = template.format(port=emulator.path, out=files["out"]).split()
        code, _, err = run_cli(capsys, *argv, "--robot", cfg.path)
    assert code == status, err
