"""Push survival in gaitbot's own simulation, with the IMU's noise, bias and one-frame delay: feedback off vs on.

    python tools/push_survival.py                    # 100 pushes, op3, feedback none and full (about 2 min)
    python tools/push_survival.py --pushes 10        # fewer
    python tools/push_survival.py --robot bioloid --max-impulse 1.0
    python tools/push_survival.py --json             # one JSON object per push
    python tools/push_survival.py --markdown         # docs/feedback.md's figure: survived per quarter of the range
    python tools/push_survival.py --modes step       # capture-point stepping (--feedback step)
    python tools/push_survival.py --modes full,zmp   # the CoM error fed to the preview controller (--feedback zmp)
    python tools/push_survival.py --walk="--distance 1"   # another walk of the robot (here its default speed)

Each push is drawn from a seeded generator (--seed): an impulse uniform in 0..--max-impulse N s, a direction
uniform in 0..360 deg (from forward, counter-clockwise), a phase uniform over the middle step (its share of
the way from the start of that step's swing window to the next one's: ``--push-phase``). The walk: ``gaitbot
walk --sim`` of WALKS (op3: 1 m at 0.15 m/s, cycle 0.8 s, steps of 6 cm) or of ``--walk``'s arguments,
through the whole session and the simulated bus, the IMU seeded by the push's number (``--imu-seed N``), so
that push N is rerun alone by

    gaitbot walk --sim --robot op3 --distance 1 --cycle 0.8 --max-step 0.06 --feedback full --imu-seed N \\
        --push IMPULSE@DIRECTION --push-phase PHASE

with its row's numbers as --json prints them (the walk is given the same digits). The IMU's figures are the
robot config's ([imu]: op3 0.5 deg/s noise, 1 deg/s bias, one frame). A push survived: no fall
(gaitbot.sim.metrics) to the end of the walk. Prints a table of every push and the share survived per
feedback mode. A walk that fails to run stops it with one line: exit 2 when the walk refused its arguments
(``--walk``, or an option of OWN_OPTIONS in it), else 1.
"""

from __future__ import annotations

import argparse
import contextlib
import io
import json
import sys

import numpy as np

from gaitbot.app.cli import main

WALKS = {"op3": "--distance 1 --cycle 0.8 --max-step 0.06", "bioloid": "--distance 0.8 --cycle 0.8 --max-step 0.04"}
OWN_OPTIONS = ("--sim", "--json", "--robot", "--feedback", "--imu-seed", "--push", "--push-phase")
"""gaitbot walk's options this tool sets for every push: refused inside --walk (they would be overridden, or
would walk another robot than the one the table names)."""


class WalkFailed(RuntimeError):
    """A walk that did not run (``gaitbot walk``'s exit status and its last line of error)."""

    def __init__(self, code: int, line: str) -> None:
        self.code = code
        super().__init__(f"walk failed (exit {code}): {line}")


def drawn_pushes(pushes: int, seed: int, max_impulse: float) -> list[tuple[float, float, float]]:
    """The pushes (impulse N s, direction deg, phase), drawn from the seeded generator (module docstring)."""
    rng = np.random.default_rng(seed)
    return [(rng.uniform(0, max_impulse), rng.uniform(0, 360), rng.uniform(0, 1)) for _ in range(pushes)]


def one_push(robot: str, walk: str, impulse: float, direction: float, phase: float, seed: int, feedback: str) -> dict:
    """One simulated walk with one push; the row of the table."""
    out, err = io.StringIO(), io.StringIO()
    args = ["walk", "--sim", "--json", "--robot", robot, *walk.split(), "--feedback", feedback,
            "--imu-seed", str(seed)]
    if impulse > 0:
        args += ["--push", f"{impulse:.3f}@{direction:.1f}", "--push-phase", f"{phase:.6f}"]
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        try:
            code = main(args)
        except SystemExit as refused:  # argparse's refusal of a malformed argument: its line is in err
            code = refused.code
    if code not in (0, 1):
        raise WalkFailed(code, err.getvalue().strip().splitlines()[-1] if err.getvalue().strip() else "")
    report = json.loads(out.getvalue())
    return {"impulse_n_s": round(impulse, 3), "direction_deg": round(direction, 1), "phase": round(phase, 6),
            "feedback": feedback, "survived": not report["fell"], "fell_at_s": report["fell_at_s"],
            "fall_direction": report["fall_direction"], "noticed_after_s": noticed_after_s(report),
            "least_load_g": report.get("imu_least_load_g")}


def noticed_after_s(report: dict) -> float | None:
    """How long after the simulated torso's true tilt crossed the fall threshold the IMU noticed the fall (s),
    or None (no fall noticed)."""
    fall = report.get("fall_noticed")
    if not fall or fall.get("true_tilt_crossed_s") is None:
        return None
    return round(fall["t_s"] - fall["true_tilt_crossed_s"], 4)


def markdown(args) -> str:
    """The figure of docs/feedback.md: how many of the pushes in each quarter of 0..max impulse survived."""
    draws = drawn_pushes(args.pushes, args.seed, args.max_impulse)
    modes = args.modes.split(",")
    edges = np.linspace(0, args.max_impulse, 5)
    counts = np.zeros((4, 1 + len(modes)), dtype=int)
    survived = {m: [] for m in modes}
    noticed = {m: [] for m in modes}
    least = {m: [] for m in modes}
    for n, (impulse, direction, phase) in enumerate(draws, start=1):
        quarter = min(int(impulse / args.max_impulse * 4), 3)
        counts[quarter, 0] += 1
        for i, m in enumerate(modes):
            row = one_push(args.robot, args.walk, impulse, direction, phase, n, m)
            survived[m].append(row["survived"])
            counts[quarter, 1 + i] += row["survived"]
            tally(row, noticed, least)
    rows = ["| impulse N s | pushes | " + " | ".join(f"survived, feedback {m}" for m in modes) + " |",
            "|---|---|" + "---|" * len(modes)]
    for q in range(4):
        rows.append(f"| {edges[q]:g} to {edges[q + 1]:g} | {counts[q, 0]} | "
                    + " | ".join(str(c) for c in counts[q, 1:]) + " |")
    rows.append(f"| all | {counts[:, 0].sum()} | " + " | ".join(str(c) for c in counts[:, 1:].sum(axis=0)) + " |")
    name = (f"push-{args.robot}" + "".join(f"-{m}" for m in ("step", "zmp") if m in modes)
            + ("-walk" if args.walk != WALKS[args.robot] else ""))
    return (f"<!-- figure {name} -->\n" + "\n".join(rows) + "\n<!-- /figure -->\n"
            f"<!-- figure {name}-by-way -->\n" + by_way(draws, survived, modes) + "\n<!-- /figure -->\n"
            f"<!-- figure {name}-noticed -->\n" + noticed_lines(noticed, least) + "\n<!-- /figure -->")


def tally(row: dict, noticed: dict, least: dict) -> None:
    """A push's row into the lists of noticed_lines: its fall's notice time, or a walk that stood's margin."""
    if row["noticed_after_s"] is not None:
        noticed[row["feedback"]].append(row["noticed_after_s"])
    if row["survived"] and row["least_load_g"] is not None:
        least[row["feedback"]].append(row["least_load_g"])


def noticed_lines(noticed: dict, least: dict) -> str:
    """How long after the true tilt crossed the fall threshold the IMU noticed each fall, per mode; and how close
    the walks that stood came to the load-lost test (their lowest accelerometer magnitude held over its window)."""
    lines = [f"feedback {m}: {len(v)} falls noticed by the IMU, {min(v) * 1e3:.0f} to {max(v) * 1e3:.0f} ms "
             f"after the true tilt crossed the threshold" for m, v in noticed.items() if v]
    lines += [f"feedback {m}: the {len(v)} walks that stood held the accelerometer at {min(v):.2f} g or more over "
              f"every load-lost window" for m, v in least.items() if v]
    return "\n".join(lines)


WAYS = ("forwards", "to the left", "backwards", "to the right")


def by_way(draws, survived: dict, modes) -> str:
    """The same pushes by the way they push (the quarter of directions centred on each) and the half of the
    step's phase they come in: pushes, and survived per mode."""
    rows = ["| pushed | phase | pushes | " + " | ".join(f"survived, feedback {m}" for m in modes) + " |",
            "|---|---|---|" + "---|" * len(modes)]
    for w, way in enumerate(WAYS):
        for half, phases in enumerate(("first half", "second half")):
            picked = [n for n, (_, direction, phase) in enumerate(draws)
                      if int(((direction + 45) % 360) // 90) == w and int(phase >= 0.5) == half]
            cells = " | ".join(str(sum(survived[m][n] for n in picked)) for m in modes)
            rows.append(f"| {way} | {phases} | {len(picked)} | {cells} |")
    return "\n".join(rows)


def main_(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--robot", default="op3", choices=sorted(WALKS))
    parser.add_argument("--pushes", type=int, default=100)
    parser.add_argument("--max-impulse", type=float, default=2.0)
    parser.add_argument("--seed", type=int, default=23)
    parser.add_argument("--modes", default="none,full", help="feedback modes, comma-separated: none, gyro, full, step, zmp")
    parser.add_argument("--json", action="store_true")
    parser.add_argument("--markdown", action="store_true", help="print the docs' figure (tools/figures.py)")
    parser.add_argument("--walk", help="gaitbot walk's arguments for the walk pushed, one string (default: WALKS of "
                        "the robot; a figure of another walk is named push-ROBOT...-walk)")
    args = parser.parse_args(argv)
    args.walk = args.walk if args.walk is not None else WALKS[args.robot]
    own = [word.split("=")[0] for word in args.walk.split() if word.split("=")[0] in OWN_OPTIONS]
    if own:
        print(f"push_survival.py: --walk {args.walk!r}: {own[0]} is set by this tool for every push (the robot: "
              f"--robot; the feedback: --modes)", file=sys.stderr)
        return 2
    try:
        return run(args)
    except WalkFailed as failed:
        print(f"push_survival.py: --walk {args.walk!r}: {failed}", file=sys.stderr)
        return 2 if failed.code == 2 else 1


def run(args) -> int:
    """The table (or the docs' figure) of args' pushes."""
    if args.markdown:
        print(markdown(args))
        return 0
    draws = drawn_pushes(args.pushes, args.seed, args.max_impulse)
    modes = args.modes.split(",")
    survived = {m: 0 for m in modes}
    noticed = {m: [] for m in modes}
    least = {m: [] for m in modes}
    if not args.json:
        print("| push | impulse N s | direction deg | phase | " + " | ".join(f"survived ({m})" for m in modes) + " |")
        print("|---|---|---|---|" + "---|" * len(modes))
    for n, (impulse, direction, phase) in enumerate(draws, start=1):
        rows = [one_push(args.robot, args.walk, impulse, direction, phase, n, m) for m in modes]
        for row in rows:
            survived[row["feedback"]] += row["survived"]
            tally(row, noticed, least)
            if args.json:
                print(json.dumps(row))
        if not args.json:
            cells = " | ".join("yes" if r["survived"] else f"no ({r['fall_direction']})" for r in rows)
            print(f"| {n} | {impulse:.2f} | {direction:.0f} | {phase:.2f} | {cells} |", flush=True)
    if not args.json:
        print(f"\n{args.robot} walking {args.walk}, {args.pushes} pushes of 0..{args.max_impulse:g} N s "
              f"(seed {args.seed}): "
              + "; ".join(f"feedback {m}: {survived[m]} survived" for m in modes))
        print(noticed_lines(noticed, least))
    return 0


if __name__ == "__main__":
    sys.exit(main_())
