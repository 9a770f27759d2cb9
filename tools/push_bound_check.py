"""The capturability bound against the simulation: the pushes it calls lost, walked in gaitbot's own simulation.

    python tools/push_bound_check.py              # the pushes tools/push_capturability.py cannot catch under the
                                                  # step limits, each walked with feedback full (about 15 s)
    python tools/push_bound_check.py --all        # every push walked with feedback none and full, counted by
                                                  # what the bound needs to catch it (about 2.5 min)
    python tools/push_bound_check.py --markdown   # docs/capturability.md's figure (with --all: the other one)

A bound on what any controller could catch must not be beaten by a controller: a push it calls lost that the
simulated robot survives shows what the bound's model leaves out. Each push is walked as tools/push_survival.py
walks it (same draw, same IMU seed, the whole session through the simulated bus); its verdicts under the step
limits, without and with the hips' allowance, are tools/push_capturability.py's. ``--all`` asks the other way
round: of the pushes the bound catches with the ankles alone, or with one step, how many does the simulated
robot survive (where the feedback falls short of what the bound allows)?
"""

from __future__ import annotations

import argparse
import sys

import push_capturability
import push_survival


def rows(feedbacks: tuple[str, ...], every: bool = False) -> list[dict]:
    """The pushes the bound loses under the step limits (``every``: all of them): the bound's verdicts, and
    whether the simulated walk survived with each feedback (``survived``: {feedback: bool})."""
    args = argparse.Namespace(robot="op3", pushes=100, seed=23, max_impulse=2.0)
    draws = push_capturability.draws(args.pushes, args.seed, args.max_impulse)
    out = []
    for row in push_capturability.table_rows(args):
        if row["a"]["capturable"] and not every:
            continue
        n = row["push"]
        impulse, direction, phase = draws[n - 1]
        walk = push_survival.WALKS[args.robot]
        survived = {f: push_survival.one_push(args.robot, walk, impulse, direction, phase, n, f)["survived"]
                    for f in feedbacks}
        out.append({**row, "survived": survived})
    return out


def markdown(found: list[dict], feedback: str) -> str:
    """The figure push-bound-check: each push lost under the step limits, its verdicts and its walk."""
    lines = [f"| push | impulse N s | direction deg | phase | (a) step limits | (a) and the hips | simulated, feedback "
             f"{feedback} |", "|---|---|---|---|---|---|---|"]
    for r in found:
        lines.append(f"| {r['push']} | {r['impulse_n_s']:.2f} | {r['direction_deg']:.0f} | {r['phase']:.2f} | lost | "
                     f"{'caught' if r['a_hip']['capturable'] else 'lost'} | "
                     f"{'survived' if r['survived'][feedback] else 'fell'} |")
    beaten = sum(r["survived"][feedback] for r in found)
    beaten_hips = sum(r["survived"][feedback] and not r["a_hip"]["capturable"] for r in found)
    lines += ["", f"Of the {len(found)} pushes lost under the step limits, {beaten} survived in the simulation; "
              f"of those lost with the hips as well, {beaten_hips}."]
    return "<!-- figure push-bound-check -->\n" + "\n".join(lines) + "\n<!-- /figure -->"


NEEDS = ("the ankles alone (0 steps)", "one step", "two or more steps", "nothing: lost")


def need(row: dict) -> str:
    """What the bound needs to catch a push under the step limits (one of NEEDS)."""
    a = row["a"]
    if not a["capturable"]:
        return NEEDS[3]
    return NEEDS[min(a["steps"], 2)]


def by_need(found: list[dict], feedbacks: tuple[str, ...]) -> str:
    """The figure push-bound-by-need: every push, counted by what the bound needs to catch it, and survived."""
    last = feedbacks[-1]
    lines = ["| the bound catches it under the step limits with | pushes | "
             + " | ".join(f"survived, feedback {f}" for f in feedbacks)
             + f" | the smallest lost with feedback {last} (N s) |", "|---|---|" + "---|" * (len(feedbacks) + 1)]

    def row(label: str, picked: list[dict]) -> str:
        lost = [r["impulse_n_s"] for r in picked if not r["survived"][last]]
        counts = " | ".join(str(sum(r["survived"][f] for r in picked)) for f in feedbacks)
        return f"| {label} | {len(picked)} | {counts} | {f'{min(lost):.2f}' if lost else '-'} |"

    for kind in NEEDS:
        picked = [r for r in found if need(r) == kind]
        if picked:
            lines.append(row(kind, picked))
    lines.append(row("all", found))
    return "<!-- figure push-bound-by-need -->\n" + "\n".join(lines) + "\n<!-- /figure -->"


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--feedback", default="full", choices=("none", "gyro", "full", "step"))
    parser.add_argument("--all", action="store_true",
                        help="walk every push with feedback none and --feedback; count them by what the bound needs")
    parser.add_argument("--markdown", action="store_true", help="print the docs' figure (tools/figures.py)")
    args = parser.parse_args(argv)
    if args.all:
        feedbacks = tuple(dict.fromkeys(("none", args.feedback)))
        text = by_need(rows(feedbacks, every=True), feedbacks)
    else:
        text = markdown(rows((args.feedback,)), args.feedback)
    print(text if args.markdown else text.split("\n", 1)[1].rsplit("\n", 1)[0])  # without the figure's marks
    return 0


if __name__ == "__main__":
    sys.exit(main())
