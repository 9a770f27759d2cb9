"""The largest push a walk holds, by direction, on MuJoCo Menagerie's OP3 and on gaitbot's own (docs/feedback.md).

    python tools/push_margin.py               # the table, as text (about 2 minutes on one core)
    python tools/push_margin.py --markdown    # the figure of docs/feedback.md (tools/figures.py)

Why: the issue's pushes (1.5 N s sideways and forwards in the middle of a 0.1 m/s walk) fall on Menagerie's
model with every feedback level (tools/feel_figures.py); this says how far short of them each model and level
is, gyro beside full showing what the attitude term adds or costs. The walk is feel_figures' 0.1 m/s one
(``--distance 1 --max-step 0.05 --cycle 1.0``), each run through the command line (``gaitbot walk --sim --json
... --push J@DIRECTION --feedback MODE``), pushed as ``--push`` pushes without ``--push-phase`` (in the middle of
the walk's middle swing, for 0.1 s). For each direction the impulses GRID_N_S are walked from the smallest up
until one falls: a cell says the largest held, every smaller one on the grid held too, and the one that fell
("-": the smallest fell; "2.00+": none fell). Survival need not be monotone in the impulse: a larger push than
the first that fell may be held, and the grid does not look.
"""

from __future__ import annotations

import argparse
import sys
import tempfile
from collections.abc import Callable
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tools"))

from feel_figures import MAP, SLOW, model_variant, print_figures, sim  # noqa: E402

GRID_N_S = tuple(0.25 * k for k in range(1, 9))
"""The impulses tried (N s), in order: 0.25 to 2.0, the range of the issue's 100 pushes."""
DIRECTIONS = (("forwards", 0), ("to the left", 90), ("backwards", 180), ("to the right", 270))
MODES = ("none", "gyro", "full")


def held_impulse(falls: Callable[[float], bool], grid=GRID_N_S) -> tuple[float, float | None]:
    """(the largest impulse of ``grid`` held before the first that falls, 0 if the first falls; that first one,
    None if none falls), ``falls(impulse)`` walking one push."""
    held = 0.0
    for impulse in grid:
        if falls(impulse):
            return held, impulse
        held = impulse
    return held, None


def cell(held: float, fell: float | None) -> str:
    if fell is None:
        return f"{held:.2f}+"
    return f"{held:.2f} (falls at {fell:.2f})" if held else f"- (falls at {fell:.2f})"


def measure() -> dict:
    """{(model, mode, direction): (held, fell)} for both models, each of MODES, every direction."""
    out = {}
    with tempfile.TemporaryDirectory() as tmp:
        models = {"Menagerie's OP3 (its own servos)": ("--sim-model", model_variant(Path(tmp), "op3-menagerie"),
                                                       "--sim-map", MAP),
                  "gaitbot's own op3 (servos at 6 deg)": ()}
        for model, on in models.items():
            for mode in MODES:
                for _, degrees in DIRECTIONS:
                    def falls(impulse: float) -> bool:
                        run = sim("--robot", "op3", *on, *SLOW, "--push", f"{impulse:g}@{degrees}", "--feedback", mode)
                        return bool(run["fell"])
                    out[model, mode, degrees] = held_impulse(falls)
    return out


def table(results: dict) -> str:
    rows = ["| model | feedback | " + " | ".join(f"pushed {name}" for name, _ in DIRECTIONS) + " |",
            "|---|---|" + "---|" * len(DIRECTIONS)]
    for model, mode in dict.fromkeys((m, f) for m, f, _ in results):
        cells = " | ".join(cell(*results[model, mode, degrees]) for _, degrees in DIRECTIONS)
        rows.append(f"| {model} | {mode} | {cells} |")
    return "\n".join(rows)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--markdown", action="store_true", help="print the docs' figure (tools/figures.py)")
    args = parser.parse_args(argv)
    print_figures({"push-margin": table(measure())}, args.markdown)
    return 0


if __name__ == "__main__":
    sys.exit(main())
