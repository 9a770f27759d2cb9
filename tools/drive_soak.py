"""Soak test of the live drive: N minutes of random commands in the free-floating simulation.

    python tools/drive_soak.py --minutes 10 --seed 1

For each robot (op3 and bioloid by default), random commands (seeded; changing every 2-5 s, uniform within the
robot's [steer] limits on each axis, 15% of them stops) are written to a commands file and driven by
``gaitbot drive --sim --input commands:FILE --json``; the table gives falls, the distance walked (planned
steps), the steps the drive's step check refused, the frames its frame check brought inside a limit by a
hair, the worst torso tilt (roll or pitch, deg), how long the
drive ran (simulated seconds: a refused frame ends it early), the IMU feedback used (the robot's default), and
the frames' work p50/p99 (tools/bench_drive.py's measure of the same commands, without the physics).
"""

from __future__ import annotations

import argparse
import json
import math
import os
import subprocess
import sys
import tempfile
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from bench_drive import measure, random_commands  # noqa: E402

from gaitbot.app.options import load_robot  # noqa: E402

REPO = Path(__file__).resolve().parents[1]


def soak(robot: str, minutes: float, seed: int, work: bool = True) -> dict:
    commands = random_commands(load_robot(robot), minutes, seed)
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "commands.jsonl"
        path.write_text("".join(c.to_json() + "\n" for c in commands))
        env = dict(os.environ, OMP_NUM_THREADS="1", OPENBLAS_NUM_THREADS="1")
        done = subprocess.run([sys.executable, "-m", "gaitbot", "drive", "--robot", robot, "--sim", "--input",
                               f"commands:{path}", "--json"], capture_output=True, text=True, cwd=REPO, env=env)
    if not done.stdout.strip():
        raise SystemExit(f"{robot}: drive failed: {done.stderr.strip()}")
    report = json.loads(done.stdout)
    work = measure(robot, minutes, seed) if work else {"frame_p50_ms": math.nan, "frame_p99_ms": math.nan}
    return {"robot": robot, "fell": report["fell"], "fall_reason": report.get("fall_reason"),
            "distance_m": report["distance_m"], "steps": report["steps"], "tilt_deg": report["worst_tilt_deg"],
            "p50_ms": work["frame_p50_ms"], "p99_ms": work["frame_p99_ms"], "exit": report["exit_status"],
            "driven_s": report["frames"] / 60.0, "feedback": report["feedback"], "outcome": report["outcome"],
            "step_refusals": report["step_refusals"], "refused": report["refused"],
            "frames_clipped": report["frames_clipped"]}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--robot", action="append", help="robot config (repeatable; default op3 and bioloid)")
    parser.add_argument("--minutes", type=float, default=10.0)
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--markdown", action="store_true", help="the table as the docs' figure block drive-soak "
                        "(without the frames' work: CPU time is not a checked figure)")
    parser.add_argument("--figure", default="drive-soak", help="the figure block's name with --markdown "
                        "(default drive-soak; the docs' ten-minute soak is drive-soak-ten)")
    args = parser.parse_args()
    columns = ("| robot | feedback | driven s | falls | distance m | steps | steps refused | frames clipped | "
               "worst tilt deg |")
    if args.markdown:
        print(f"<!-- figure {args.figure} -->")
        print(columns)
        print("|---|---|---|---|---|---|---|---|---|")
    else:
        print(columns + " frame work p50 ms | p99 ms | exit |")
        print("|---|---|---|---|---|---|---|---|---|---|---|---|")
    for robot in args.robot or ["op3", "bioloid"]:
        r = soak(robot, args.minutes, args.seed, work=not args.markdown)
        fall = f"1 ({r['fall_reason']})" if r["fell"] else "0"
        row = (f"| {robot} | {r['feedback']} | {r['driven_s']:.0f} | {fall} | {r['distance_m']:.2f} | {r['steps']} | "
               f"{r['step_refusals']} | {r['frames_clipped']} | {r['tilt_deg']:.1f} |")
        print(row if args.markdown else row + f" {r['p50_ms']:.3f} | {r['p99_ms']:.3f} | {r['exit']} |", flush=True)
        if r["refused"]:
            print(f"{robot}: {r['refused']}", file=sys.stderr, flush=True)
    if args.markdown:
        print("<!-- /figure -->")


if __name__ == "__main__":
    main()
