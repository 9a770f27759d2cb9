"""Timing of the fault policy (docs/bus-faults.md): each fault of the fault policy on the servo emulator, in real time.

    python tools/fault_timing.py                 # every robot, every fault, the fault at goal frame 120
    python tools/fault_timing.py --robot xl430-biped --repeat 3

For each run: the exit status, the servo named, how many goal frames went out from the fault to the
stop (detection), the time from the goal frame the fault started at to the last goal sent (detection
and the stop ramp), and the worst gap between goal frames after the fault (periods: 1.00 is on the
grid; the goal stream never waits on a read). Figures are from the recording the walk made itself.
"""

from __future__ import annotations

import argparse
import re
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

import gaitbot.emulator as se  # noqa: E402
from gaitbot.bus.recording import decode_goal_frames  # noqa: E402
from gaitbot.robot.config import load_robot_config  # noqa: E402

FAULT_FRAME = 120
VICTIM = {"xl430-biped": 3, "sts3215-biped": 3, "ax12a-biped": 13}
KINDS = ("late", "silent", "overload", "corrupt", "port")


def faults_for(kind: str, victim: int) -> se.Faults:
    after = FAULT_FRAME
    return {"late": se.Faults(late_s={victim: 0.1}, after_frames=after),
            "silent": se.Faults(silent={victim}, after_frames=after),
            "overload": se.Faults(errors={victim: {"overload"}}, after_frames=after),
            "corrupt": se.Faults(corrupt_fraction=1.0, corrupt_ids={victim}, after_frames=after),
            "port": se.Faults(close_after_frames=after)}[kind]


def run(robot: str, kind: str, workdir: Path) -> dict:
    config_path = ROOT / "config" / f"{robot}.toml"
    config = load_robot_config(config_path)
    record, emu_log = workdir / f"{robot}-{kind}.jsonl", workdir / f"{robot}-{kind}-emu.jsonl"
    emulator = se.ServoEmulator(se.EmulatorConfig(
        config.bus.backend, config.bus.protocol, config.models_by_id, config.bus.baudrate,
        faults_for(kind, VICTIM[robot]), str(emu_log), config.name, {j.name: j.id for j in config.joints}))
    with emulator:
        proc = subprocess.run([sys.executable, "-m", "gaitbot.app.cli", "walk", "--robot", str(config_path),
                               "--port", emulator.path, "--distance", "0.3", "--record", str(record)],
                              capture_output=True, text=True, cwd=ROOT, timeout=120)
    out = proc.stdout + proc.stderr
    walk_frames = re.search(r"Sent (\d+) frames", out)
    _, t_s, _ = decode_goal_frames(record, allow_partial_last_line=True)
    fault_t = t_s[FAULT_FRAME - 1]
    gaps = np.diff(t_s[FAULT_FRAME - 1:]) * config.gait.rate_hz
    return {"exit": proc.returncode, "named": sorted({int(x) for x in re.findall(r"servos? (\d+)", out)}),
            "detect_frames": int(walk_frames.group(1)) - FAULT_FRAME if walk_frames else None,
            "to_last_goal_ms": (t_s[-1] - fault_t) * 1e3, "worst_gap": float(gaps.max()) if len(gaps) else 0.0,
            "ramped": "ramped to the stand pose" in out}


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--robot", action="append", help="robot config name (default: the three shipped)")
    parser.add_argument("--kind", action="append", choices=KINDS)
    parser.add_argument("--repeat", type=int, default=1)
    args = parser.parse_args()
    robots = args.robot or list(VICTIM)
    print(f"{'robot':14s} {'fault':9s} exit named   detect  fault->last goal  worst gap  ramp")
    with tempfile.TemporaryDirectory() as tmp:
        for robot in robots:
            for kind in args.kind or KINDS:
                for _ in range(args.repeat):
                    r = run(robot, kind, Path(tmp))
                    print(f"{robot:14s} {kind:9s} {r['exit']:4d} {str(r['named']):7s} {r['detect_frames']!s:>4s} fr "
                          f"{r['to_last_goal_ms']:10.0f} ms {r['worst_gap']:10.2f} P  {'yes' if r['ramped'] else 'no'}",
                          flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
