"""The cases of issue 13 and of the hostile-input corpus's findings (FINDINGS.md of the issue-13 probe), one
row each, through the real command line in a bounded forked child: exit 2 (or the documented status),
ONE line on stderr naming the file, field or argument, nothing on stdout, no traceback or warning,
within 20 s and 1.5 GiB, and nothing sent: a dry run's ``--record`` holds no write of any kind.

Each row: an id, the arguments (``{d}`` is a scratch folder holding the files the row writes), the words
the error line must hold (any one of ``a|b``), and the files to write first.
"""

from __future__ import annotations

import io
import json
import os
import re
from pathlib import Path

import numpy as np
import pytest

from gaitbot.servos import wire
from helpers import CONFIG_DIR, assert_cli_behaves, cli, isolated

XL430 = (CONFIG_DIR / "xl430-biped.toml").read_text()
KERB = (CONFIG_DIR / "terrain" / "kerb.toml").read_text()
BIG = "1" + "0" * 400


def robot(key: str, value: str) -> str:
    """The xl430 config with the first ``key = ...`` line set to ``value``."""
    text, count = re.subn(rf"(?m)^{re.escape(key)}\s*=.*$", f"{key} = {value}", XL430, count=1)
    assert count == 1, key
    return text


def course(key: str, value: str, text: str = KERB) -> str:
    out, count = re.subn(rf"(?m)^{re.escape(key)}\s*=.*$", f"{key} = {value}", text, count=1)
    assert count == 1, key
    return out


def rows(t_s, angle: float = 5.0) -> str:
    header = ("t_s,hip_pitch_left_deg,knee_pitch_left_deg,ankle_pitch_left_deg,hip_pitch_right_deg,"
              "knee_pitch_right_deg,ankle_pitch_right_deg,root_x_m,root_y_m")
    return header + "\n" + "".join(f"{t},{angle},{angle},0,0,0,0,0,0.2\n" for t in t_s)


def npz(**arrays) -> bytes:
    buffer = io.BytesIO()
    np.savez(buffer, **arrays)
    return buffer.getvalue()


N = 60
GOOD_NPZ = dict(t_s=np.arange(N) / 60, angles_deg=np.zeros((N, 6)), root_m=np.zeros((N, 2)),
                heel_strikes=np.array([[0.0, 0, 0.0], [0.5, 1, 0.05]]))


def traj_npz(**changes) -> bytes:
    return npz(**{**GOOD_NPZ, **changes})


def rec_header(**changes) -> str:
    header = {"format": "gaitbot-bus-log", "version": 1, "backend": "dynamixel", "protocol": 2.0,
              "baudrate": 1000000, "robot": "xl430-biped",
              "joints": {"hip_pitch_left": 1, "knee_pitch_left": 2, "ankle_pitch_left": 3, "hip_pitch_right": 4,
                         "knee_pitch_right": 5, "ankle_pitch_right": 6},
              "models": {str(i): "XL430-W250" for i in range(1, 7)}, **changes}
    goal = wire.build_v2(0xFE, wire.INST_SYNC_WRITE, bytes([116, 0, 4, 0]) + b"".join(
        bytes([i]) + (2048).to_bytes(4, "little") for i in range(1, 7)))
    return json.dumps(header) + "\n" + "".join(json.dumps({"t": k / 60, "dir": "tx", "hex": goal.hex()}) + "\n"
                                                for k in range(3))


def raw_header(text: str) -> str:
    return text + "\n" + rec_header().split("\n", 1)[1]


CASES = [
    # 5. resources
    ("robot-cycle-1e9", ["walk", "--dry-run", "--robot", "{d}/r.toml"], "gait.cycle_s", {"r.toml": robot("cycle_s", "1e9")}),
    ("robot-max-step-1e-9", ["walk", "--dry-run", "--robot", "{d}/r.toml"], "gait.max_step_m",
     {"r.toml": robot("max_step_m", "1e-9")}),
    ("plan-distance-1e6", ["plan", "--distance", "1e6"], "--distance", {}),
    ("plan-distance-1e308", ["plan", "--distance", "1e308"], "--distance", {}),
    ("plan-max-step-1e-9", ["plan", "--distance", "1", "--max-step", "1e-9"], "--max-step", {}),
    ("plan-rate-1e9", ["plan", "--distance", "0.3", "--rate", "1e9"], "--rate", {}),
    ("course-end-1e6", ["plan", "--terrain", "{d}/c.toml"], "course.end_m", {"c.toml": course("end_m", "1e6")}),
    ("course-end-1e308", ["plan", "--terrain", "{d}/c.toml"], "course.end_m", {"c.toml": course("end_m", "1e308")}),
    ("course-start-minus-1e308", ["plan", "--terrain", "{d}/c.toml"], "course.start_m",
     {"c.toml": course("start_m", "-1e308")}),
    ("course-max-step-tiny", ["plan", "--terrain", "{d}/c.toml"], "course.max_step_m",
     {"c.toml": KERB.replace("[course]", "[course]\nmax_step_m = 1e-9", 1)}),
    ("synth-cycles-1e8", ["eigen", "synth", "{d}/m.npz", "--step-length", "0.05", "--cycles", "100000000", "-o",
                          "{d}/o.csv"], "--cycles", {}),
    ("fit-samples-1e9", ["eigen", "fit", "{d}/w.csv", "-o", "{d}/m.npz", "--samples", "1000000000"], "samples",
     {"w.csv": rows(np.arange(60) / 60)}),
    ("record-duration-1e308", ["record", "--dry-run", "--duration", "1e308", "-o", "{d}/r.csv"], "--duration", {}),
    ("robot-deep-dotted-key", ["walk", "--dry-run", "--robot", "{d}/r.toml"], "r.toml",
     {"r.toml": "x." + ".".join(["a"] * 30_000) + " = 1\n" + XL430}),
    ("course-deep-dotted-key", ["plan", "--terrain", "{d}/c.toml"], "c.toml",
     {"c.toml": "x." + ".".join(["a"] * 30_000) + " = 1\n" + KERB}),
    ("check-dev-zero-link", ["check", "{d}/zero.jsonl"], "zero.jsonl", {"zero.jsonl": "->/dev/zero"}),
    ("course-dev-zero-link", ["plan", "--terrain", "{d}/zero.toml"], "zero.toml", {"zero.toml": "->/dev/zero"}),
    ("check-fifo", ["check", "{d}/f.jsonl"], "f.jsonl", {"f.jsonl": "fifo"}),
    ("course-fifo", ["plan", "--terrain", "{d}/f.toml"], "f.toml", {"f.toml": "fifo"}),
    # 4. rates and jumps
    ("robot-rate-0.001", ["walk", "--dry-run", "--robot", "{d}/r.toml", "--record", "{d}/rec.jsonl"], "gait.rate_hz",
     {"r.toml": robot("rate_hz", "0.001")}),
    ("walk-rate-1e-9", ["walk", "--dry-run", "--rate", "1e-9", "--record", "{d}/rec.jsonl"], "--rate", {}),
    ("walk-trajectory-at-0.001-hz", ["walk", "--dry-run", "--trajectory", "{d}/w.csv", "--record", "{d}/rec.jsonl"],
     "--trajectory", {"w.csv": rows(np.arange(4) * 1000.0)}),
    ("walk-time-1e308", ["walk", "--dry-run", "--trajectory", "{d}/w.csv", "--record", "{d}/rec.jsonl"], "w.csv",
     {"w.csv": rows([0, 1e308])}),
    ("check-45-degree-jump-at-0.001-hz", ["check", "{d}/w.csv"], None,
     {"w.csv": rows([0, 1000], angle=0).replace("1000,0,0", "1000,45,0")}),
    ("walk-reply-timeout-1e308", ["walk", "--dry-run", "--reply-timeout-ms", "1e308", "--record", "{d}/rec.jsonl"],
     "--reply-timeout-ms", {}),
    # 6. tracebacks before
    ("robot-bigint", ["walk", "--dry-run", "--robot", "{d}/r.toml"], "geometry.thigh_m",
     {"r.toml": robot("thigh_m", BIG)}),
    ("robot-deep-array", ["walk", "--dry-run", "--robot", "{d}/r.toml"], "r.toml",
     {"r.toml": XL430 + "\nx = " + "[" * 100_000 + "]" * 100_000 + "\n"}),
    ("csv-cell-over-131072", ["check", "{d}/w.csv"], "w.csv", {"w.csv": rows([0, 1]).replace(",0.2\n", "," + "9" * 131_073 + "\n", 1)}),
    ("npz-t_s-0d", ["check", "{d}/w.npz"], "t_s", {"w.npz": traj_npz(t_s=np.array(1.0))}),
    ("npz-angles-strings", ["check", "{d}/w.npz"], "angles_deg", {"w.npz": traj_npz(angles_deg=np.full((N, 6), "a"))}),
    ("npz-angles-complex", ["walk", "--dry-run", "--trajectory", "{d}/w.npz", "--record", "{d}/rec.jsonl"],
     "angles_deg", {"w.npz": traj_npz(angles_deg=np.zeros((N, 6)) + 1j)}),
    ("npz-t_s-column", ["check", "{d}/w.npz"], "t_s", {"w.npz": traj_npz(t_s=(np.arange(N) / 60).reshape(-1, 1))}),
    ("npz-heel-strikes-nan", ["check", "{d}/w.npz"], "heel_strikes",
     {"w.npz": traj_npz(heel_strikes=np.array([[0.0, np.nan, 0.0]]))}),
    ("npz-heel-strikes-2x2", ["check", "{d}/w.npz"], "heel_strikes", {"w.npz": traj_npz(heel_strikes=np.zeros((2, 2)))}),
    ("rec-baudrate-fast", ["check", "{d}/r.jsonl"], "baudrate", {"r.jsonl": rec_header(baudrate="fast")}),
    ("rec-baudrate-null", ["check", "{d}/r.jsonl"], "baudrate", {"r.jsonl": rec_header(baudrate=None)}),
    ("rec-baudrate-infinity", ["check", "{d}/r.jsonl"], "baudrate",
     {"r.jsonl": raw_header(json.dumps(json.loads(rec_header().split("\n")[0]) | {"baudrate": 1}).replace(
         '"baudrate": 1', '"baudrate": Infinity'))}),
    ("rec-deep-header", ["check", "{d}/r.jsonl"], "r.jsonl", {"r.jsonl": raw_header("[" * 100_000 + "]" * 100_000)}),
    ("rec-t-bigint", ["check", "{d}/r.jsonl"], "r.jsonl",
     {"r.jsonl": rec_header().replace('"t": 0.0', '"t": ' + BIG, 1)}),
    ("course-invalid-utf8", ["plan", "--terrain", "{d}/c.toml"], "c.toml", {"c.toml": b"\xff\xfe[course]\n"}),
    ("course-tread-list", ["plan", "--terrain", "{d}/c.toml"], "tread", {"c.toml": KERB + "\ntread = [1, 2]\n"}),
    ("fit-roughness-nan", ["eigen", "fit", "{d}/w.csv", "-o", "{d}/m.npz", "--roughness", "nan"], "roughness",
     {"w.csv": rows(np.arange(60) / 60)}),
    ("record-to-a-folder", ["walk", "--dry-run", "--record", "{d}"], "--record", {}),
    ("record-to-a-missing-folder", ["walk", "--dry-run", "--record", "{d}/no/r.jsonl"], "--record", {}),
    ("record-to-dev-full", ["walk", "--dry-run", "--record", "/dev/full"], "--record", {}),
    ("generate-to-dev-full", ["generate", "--distance", "0.1", "-o", "{d}/full.csv"], "-o", {"full.csv": "->/dev/full"}),
    ("generate-to-a-missing-folder", ["generate", "--distance", "0.1", "-o", "{d}/no/w.csv"], "-o", {}),
    ("plot-to-a-folder", ["plot", "{d}/w.csv", "-o", "{d}"], "-o", {"w.csv": rows(np.arange(60) / 60)}),
    ("plot-unknown-suffix", ["plot", "{d}/w.csv", "-o", "{d}/p.xyz"], "-o", {"w.csv": rows(np.arange(60) / 60)}),
    ("seed-negative", ["plan", "--distance", "0.3", "--perturb", "0.01", "--seed", "-1"], "--seed", {}),
    # 7. messages
    ("baudrate-1000001", ["walk", "--dry-run", "--robot", "{d}/r.toml"], "bus.baudrate", {"r.toml": robot("baudrate", "1000001")}),
    ("baudrate-10e30", ["walk", "--dry-run", "--robot", "{d}/r.toml"], "bus.baudrate", {"r.toml": robot("baudrate", "1" + "0" * 30)}),
    ("port-dev-null", ["walk", "--port", "/dev/null", "--distance", "0.1"], "--port", {}),
    ("port-regular-file", ["walk", "--port", "{d}/file", "--distance", "0.1"], "--port", {"file": "x"}),
    ("robot-empty-name", ["walk", "--dry-run", "--robot", "", "--record", "{d}/rec.jsonl"], "--robot", {}),
    ("robot-foot-10", ["walk", "--dry-run", "--robot", "{d}/r.toml"], "geometry.foot_m", {"r.toml": robot("foot_m", "10")}),
    ("robot-thigh-1e-300", ["walk", "--dry-run", "--robot", "{d}/r.toml"], "geometry", {"r.toml": robot("thigh_m", "1e-300")}),
    ("robot-ankle-height-10", ["walk", "--dry-run", "--robot", "{d}/r.toml"], "geometry.ankle_height_m",
     {"r.toml": robot("ankle_height_m", "10")}),
    ("robot-cycle-1e-9", ["walk", "--dry-run", "--robot", "{d}/r.toml"], "gait.cycle_s", {"r.toml": robot("cycle_s", "1e-9")}),
    ("robot-clearance-0.5", ["walk", "--dry-run", "--robot", "{d}/r.toml"], "gait.clearance_m",
     {"r.toml": robot("clearance_m", "0.5")}),
    ("robot-max-step-beyond-reach", ["walk", "--dry-run", "--robot", "{d}/r.toml"], "gait.max_step_m",
     {"r.toml": robot("max_step_m", "1.0")}),
    ("robot-max-deg-1e308", ["walk", "--dry-run", "--robot", "{d}/r.toml"], "max_deg", {"r.toml": robot("max_deg", "1e308")}),
    ("usage-error-one-line", ["plan", "--distance", "far"], "--distance", {}),
    ("usage-nothing-to-plan", ["plan"], "--steps|--distance", {}),
    ("synth-to-step-length-negative", ["eigen", "synth", "{d}/m.npz", "--step-length", "0.05", "--to-step-length", "-1",
                                       "-o", "{d}/o.csv"], "--to-step-length", {}),
    ("synth-pose-time-alone", ["eigen", "synth", "{d}/m.npz", "--step-length", "0.05", "--pose-time", "0.5", "-o",
                               "{d}/o.csv"], "--pose-time", {}),
]


def materialise(d: Path, files: dict) -> None:
    for name, content in files.items():
        path = d / name
        if content == "fifo":
            os.mkfifo(path)
        elif isinstance(content, str) and content.startswith("->"):
            path.symlink_to(content[2:])
        else:
            path.write_bytes(content if isinstance(content, bytes) else content.encode())


def sent_writes(record: Path) -> int:
    """Write packets of any kind in a dry run's recording (0 when there is none)."""
    if not record.exists() or not record.stat().st_size:
        return 0
    count = 0
    for line in record.read_text().splitlines()[1:]:
        packet = json.loads(line)
        data = bytes.fromhex(packet["hex"])
        if packet["dir"] == "tx" and len(data) > 7 and data[7] in (wire.INST_WRITE, wire.INST_SYNC_WRITE):
            count += 1
    return count


@pytest.mark.parametrize("case_id, argv, mentions, files", CASES, ids=[c[0] for c in CASES])
def test_hostile_case(case_id, argv, mentions, files, tmp_path):
    materialise(tmp_path, files)
    args = [a.replace("{d}", str(tmp_path)) for a in argv]
    result = cli(*args)
    if mentions is None:  # a check that finds the fault: exit 1, its report on stdout
        assert result["outcome"] == "ok" and result["value"] == 1, result
        assert "Traceback" not in result["stderr"]
        return
    assert_cli_behaves(result, allowed=(2,))
    line = result["stderr"].strip()
    assert any(word in line for word in mentions.split("|")), line
    assert result["elapsed_s"] < 20
    assert sent_writes(tmp_path / "rec.jsonl") == 0


def test_a_recording_made_at_30_hz_checks_at_30_hz(tmp_path):
    """Issue 13 case 8: the recording carries its rate, so check judges its timing at that rate."""
    record = tmp_path / "r.jsonl"
    assert cli("walk", "--dry-run", "--rate", "30", "--distance", "0.2", "--record", record)["value"] == 0
    assert json.loads(record.read_text().splitlines()[0])["rate_hz"] == 30.0
    result = cli("check", record)
    assert result["value"] == 0, result["stdout"][-800:]
    assert "at 30 Hz" in result["stdout"]


def test_the_emulator_refuses_faults_on_servos_not_on_its_chain():
    from gaitbot.app.emulator import main as emulator_main

    for flags in (["--late", "9:100"], ["--error", "9:overload"], ["--silent", "9"], ["--corrupt", "0.5:9"]):
        result = isolated(emulator_main, ["--robot", str(CONFIG_DIR / "xl430-biped.toml"), *flags], capture=True)
        assert result["value"] == 2, result
        lines = [x for x in result["stderr"].splitlines() if x.strip()]
        assert len(lines) == 1 and "servo 9 is not on the chain" in lines[0], lines
