"""The capturability bound against the simulation: the pushes it calls lost, walked in gaitbot's own simulation.

    python tools/push_bound_check.py              # the pushes tools/push_capturability.py cannot catch under the
                                                  # step limits, each walked with feedback full (about 15 s)
    python tools/push_bound_check.py --markdown   # docs/capturability.md's figure

A bound on what any controller could catch must not be beaten by a controller: a push it calls lost that the
simulated robot survives shows what the bound's model leaves out. Each push is walked as tools/push_survival.py
walks it (same draw, same IMU seed, the whole session through the simulated bus); its verdicts under the step
limits, without and with the hips' allowance, are tools/push_capturability.py's.
"""

from __future__ import annotations

import argparse
import sys

import push_capturability
import push_survival


def rows(feedback: str) -> list[dict]:
    """Every push the bound loses under the step limits: its verdicts, and whether the simulated walk survived."""
    args = argparse.Namespace(robot="op3", pushes=100, seed=23, max_impulse=2.0)
    draws = push_capturability.draws(args.pushes, args.seed, args.max_impulse)
    out = []
    for row in push_capturability.table_rows(args):
        if row["a"]["capturable"]:
            continue
        n = row["push"]
        impulse, direction, phase = draws[n - 1]
        walk = push_survival.WALKS[args.robot]
        walked = push_survival.one_push(args.robot, walk, impulse, direction, phase, n, feedback)
        out.append({**row, "survived": walked["survived"]})
    return out


def markdown(found: list[dict], feedback: str) -> str:
    lines = [f"| push | impulse N s | direction deg | phase | (a) step limits | (a) and the hips | simulated, feedback "
             f"{feedback} |", "|---|---|---|---|---|---|---|"]
    for r in found:
        lines.append(f"| {r['push']} | {r['impulse_n_s']:.2f} | {r['direction_deg']:.0f} | {r['phase']:.2f} | lost | "
                     f"{'caught' if r['a_hip']['capturable'] else 'lost'} | "
                     f"{'survived' if r['survived'] else 'fell'} |")
    beaten = sum(r["survived"] for r in found)
    beaten_hips = sum(r["survived"] and not r["a_hip"]["capturable"] for r in found)
    lines += ["", f"Of the {len(found)} pushes lost under the step limits, {beaten} survived in the simulation; "
              f"of those lost with the hips as well, {beaten_hips}."]
    return "<!-- figure push-bound-check -->\n" + "\n".join(lines) + "\n<!-- /figure -->"


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--feedback", default="full", choices=("none", "gyro", "full", "step"))
    parser.add_argument("--markdown", action="store_true", help="print the docs' figure (tools/figures.py)")
    args = parser.parse_args(argv)
    text = markdown(rows(args.feedback), args.feedback)
    print(text if args.markdown else text.split("\n", 1)[1].rsplit("\n", 1)[0])  # without the figure's marks
    return 0


if __name__ == "__main__":
    sys.exit(main())
