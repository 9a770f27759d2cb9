"""How well the drive's step check predicts the frames the walker then sends, and what it costs.

    python tools/step_check_accuracy.py --robot op3 --minutes 2 --seed 5

Random commands (tools/bench_drive.py's: changing every 2-5 s, within the robot's limits, stops included)
are driven on the drive's own clock (no physics). For every step the check passed, the legs' angles it
predicted (gaitbot.drive.step_check: the plan's ankles, an LIPM CoM from the ZMP reference) are compared with
the angles the walker computed for the same frames: the largest angle error per step (p50, p99, max), and
the peak velocity and acceleration of the step (as a share of the joint's limit) predicted over sent
(their range over the steps: the check's PREDICTION_SLACK must cover the largest). Then the CPU time of each
of the check's stages (one a frame), p50 and p99.

    python tools/step_check_accuracy.py --minutes 2 --seed 5 --markdown

prints the docs' figure block ``step-check-accuracy`` (docs/driving.md): the same table without the CPU times
(a timing is not a checked figure, docs/figures.md).
"""

from __future__ import annotations

import argparse
import os
import sys
import time
from pathlib import Path

os.environ.setdefault("OMP_NUM_THREADS", "1")
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

sys.path.insert(0, str(Path(__file__).resolve().parent))
import numpy as np  # noqa: E402
from bench_drive import random_commands  # noqa: E402

from gaitbot.app.options import load_robot  # noqa: E402
from gaitbot.drive import step_check  # noqa: E402
from gaitbot.drive.frames import DriveFrames  # noqa: E402
from gaitbot.gait.balance.walker import BalancedWalker  # noqa: E402
from gaitbot.inputs.scripted import ScriptedSource  # noqa: E402


def measure(robot: str, minutes: float, seed: int) -> dict:
    config = load_robot(robot)
    predicted: dict = {}
    costs: dict[str, list[float]] = {"preview": [], "balance": [], "limits": []}
    check = step_check.StepCheck
    originals = {"balance": check._balance, "limits": check._limits, "preview": BalancedWalker.preview_step}

    def timed(name):
        inner = originals[name]

        def call(*args, **kwargs):
            start = time.process_time()
            out = inner(*args, **kwargs)
            costs[name].append(time.process_time() - start)
            return out
        return call

    def limits(self, walker, arrays, first, end, foothold):
        start = time.process_time()
        out = originals["limits"](self, walker, arrays, first, end, foothold)
        costs["limits"].append(time.process_time() - start)
        if out is None:
            q, skip = self.predicted_angles(walker, arrays, first, end, foothold)
            # the step's first frame, counted from the walk's start (the online walker drops frames far
            # behind its output: plan_arrays starts at plan_start_frame)
            first_frame = walker.plan_start_frame + len(walker.plan_arrays()["zmp"])
            predicted[(id(walker), first_frame)] = (q[skip:], self)
        return out

    check._balance, check._limits = timed("balance"), limits
    BalancedWalker.preview_step = timed("preview")
    try:
        frames = DriveFrames(config, ScriptedSource(random_commands(config, minutes, seed)), say=lambda text: None)
        sent: dict = {}
        walker_seen = None
        while True:
            walker = frames._walker
            if walker is not walker_seen:
                walker_seen = walker
                inner = walker.next_frame

                def next_frame(walker=walker, inner=inner):
                    out = inner()
                    if out is not None:
                        sent[(id(walker), walker._out - 1 - walker.rise_frames)] = out[1]
                    return out
                walker.next_frame = next_frame
            try:
                next(frames)
            except StopIteration:
                break
    finally:
        check._balance, check._limits = originals["balance"], originals["limits"]
        BalancedWalker.preview_step = originals["preview"]
    errors, velocity, accel = [], [], []
    for (walker_id, start), (q, chk) in predicted.items():
        rows = [sent.get((walker_id, start + i)) for i in range(len(q))]
        if any(r is None for r in rows):
            continue
        actual = np.array(rows)
        errors.append(np.degrees(np.abs(actual - q).max()))
        ratios = []
        for angles in (q, actual):
            v = np.diff(angles, axis=0) / chk.period_s
            a = np.diff(v, axis=0) / chk.period_s
            ratios.append((np.abs(v).max(0) / (chk.max_velocity / step_check.PREDICTION_SLACK),
                           np.abs(a).max(0) / (chk.max_accel / step_check.PREDICTION_SLACK)))
        velocity.append(ratios[0][0].max() / ratios[1][0].max())
        accel.append(ratios[0][1].max() / ratios[1][1].max())
    return {"steps": len(errors), "error_deg": np.percentile(errors, [50, 99, 100]),
            "velocity": (min(velocity), max(velocity)), "accel": (min(accel), max(accel)),
            "costs_ms": {k: 1e3 * np.percentile(v, [50, 99]) for k, v in costs.items()}}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--robot", action="append", help="robot config (repeatable; default op3 and bioloid)")
    parser.add_argument("--minutes", type=float, default=2.0)
    parser.add_argument("--seed", type=int, default=5)
    parser.add_argument("--markdown", action="store_true", help="the table without the CPU times, as the docs' "
                        "figure block step-check-accuracy")
    args = parser.parse_args()
    columns = ("| robot | steps | angle error p50 / p99 / max deg | peak velocity predicted / sent | peak acceleration "
               "predicted / sent |")
    if args.markdown:
        print("<!-- figure step-check-accuracy -->\n" + columns + "\n|---|---|---|---|---|")
    else:
        print(columns + " preview p50 / p99 ms | balance p50 / p99 ms | limits p50 / p99 ms |")
        print("|---|---|---|---|---|---|---|---|")
    for robot in args.robot or ["op3", "bioloid"]:
        r = measure(robot, args.minutes, args.seed)
        e, c = r["error_deg"], r["costs_ms"]
        row = (f"| {robot} | {r['steps']} | {e[0]:.1f} / {e[1]:.1f} / {e[2]:.1f} | {r['velocity'][0]:.2f} to "
               f"{r['velocity'][1]:.2f} | {r['accel'][0]:.2f} to {r['accel'][1]:.2f} |")
        if not args.markdown:
            row += " " + " | ".join(f"{c[k][0]:.2f} / {c[k][1]:.2f}" for k in ("preview", "balance", "limits")) + " |"
        print(row, flush=True)
    if args.markdown:
        print("<!-- /figure -->")


if __name__ == "__main__":
    main()
