"""The CoM correction's figures (``--feedback zmp`` against ``full``) on both OP3 models (docs/feedback.md).

    python tools/zmp_figures.py               # the figures, as text
    python tools/zmp_figures.py --markdown    # the figures of docs/feedback.md (tools/figures.py)

- zmp-models: tools/feel_figures.py's walks (2 m at 0.2 m/s; 1 m at 0.1 m/s, alone and pushed with 1.0 and 1.5
  N s sideways and 1.5 N s forwards in its middle) with feedback full and zmp, on MuJoCo Menagerie's OP3 (its
  own soft servos; the model written by tools/op3_menagerie.py into a temporary folder, mapped by
  config/sim-maps/op3-menagerie.toml) and on gaitbot's own op3 model;
- zmp-plan: the unpushed 0.15 m/s walk of tools/push_survival.py on gaitbot's own model, per IMU seed: how far
  the frames walked (before the gyro damping) leave the plan's goals, in ticks, with the correction
  (``zmp``) and with the online walk alone (``step``, which moves no foothold when nothing pushes).

Each walk is ``gaitbot walk --sim --json`` run through the command line itself.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "tools"))

import gaitbot.app.walk as app_walk  # noqa: E402
import feel_figures  # noqa: E402  (the Menagerie walks, their model and their verdicts)
from push_survival import WALKS  # noqa: E402  (the pushed walk: the op3's 0.15 m/s)
from gaitbot.robot.calibration import trajectory_ticks  # noqa: E402

MODES = ("full", "zmp")
SEEDS = (1, 2, 3)


def models_table() -> str:
    import tempfile

    rows = ["| model | ARGS | feedback | outcome |", "|---|---|---|---|"]
    with tempfile.TemporaryDirectory() as tmp:
        model = feel_figures.model_variant(Path(tmp), "op3-menagerie")
        menagerie = ("--sim-model", model, "--sim-map", feel_figures.MAP)
        for name, extra in (("Menagerie's OP3", menagerie), ("gaitbot's op3", ())):
            for label, args in feel_figures.WALKS:
                for mode in MODES:
                    r = feel_figures.sim("--robot", "op3", *extra, *args, "--feedback", mode)
                    rows.append(f"| {name} | {label} | {mode} | {feel_figures.verdict(r)} |")
    return "\n".join(rows)


def ticks_from_plan(mode: str, seed: int) -> int:
    """The largest |frame - plan| (ticks) of the unpushed walk's frames as the stepping source gave them."""
    seen: dict = {}
    original = app_walk.stepping_source

    def source(walk, config, feedback):
        frames = original(walk, config, feedback)
        seen["plan"] = trajectory_ticks(config, walk.plan.walk.trajectory(goals=True))
        seen["frames"] = []
        step = type(frames).__next__

        def recorded(self):
            row = step(self)
            seen["frames"].append(row)
            return row

        frames.__class__ = type("Recorded", (type(frames),), {"__next__": recorded})
        return frames

    app_walk.stepping_source = source
    try:
        r = feel_figures.sim("--robot", "op3", *WALKS["op3"].split(), "--feedback", mode, "--imu-seed", str(seed))
    finally:
        app_walk.stepping_source = original
    if r["fell"]:
        raise SystemExit(f"the unpushed walk fell with --feedback {mode}")
    frames, plan = np.array(seen["frames"]), seen["plan"]
    return int(np.abs(frames - plan).max())


def plan_sentence() -> str:
    zmp = [ticks_from_plan("zmp", s) for s in SEEDS]
    step = [ticks_from_plan("step", s) for s in SEEDS]
    return (f"Unpushed, `--imu-seed` {', '.join(map(str, SEEDS))}: the frames leave the plan's goals by at most "
            f"{', '.join(map(str, zmp))} ticks with `zmp`, {', '.join(map(str, step))} with the online walk "
            "alone (`step`, no foothold moved).")


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--markdown", action="store_true", help="print the docs' figures (tools/figures.py)")
    args = parser.parse_args(argv)
    feel_figures.print_figures({"zmp-models": models_table(), "zmp-plan": plan_sentence()}, args.markdown)
    return 0


if __name__ == "__main__":
    sys.exit(main())
