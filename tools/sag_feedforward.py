"""What the servo sag feedforward changes on the simulated OP3 (docs/balance.md; the sim extra).

    python tools/sag_feedforward.py              # the table
    python tools/sag_feedforward.py --markdown   # the docs' figure (tools/figures.py)

Two ``gaitbot walk --sim --json --robot op3 --distance 2`` runs through the command line itself: the shipped
config (``sag_feedforward = true``) and a copy with it set to false; everything else as shipped (servos at the
written gain, the IMU feedback as the config sets it). Simulated: another CPU or MuJoCo release moves the
numbers within the simulated figures' tolerance (docs/figures.md, "Simulated figures").
"""

from __future__ import annotations

import argparse
import contextlib
import io
import json
import re
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from gaitbot.app.cli import main as gaitbot  # noqa: E402

ARGS = ("--robot", "op3", "--distance", "2")


def sim(robot: str) -> dict:
    out = io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(io.StringIO()):
        gaitbot(["walk", "--sim", "--json", *ARGS[:1], robot, *ARGS[2:]])  # exit 1 for a fall: the JSON says so
    return json.loads(out.getvalue())


def without_feedforward(folder: Path) -> str:
    """The shipped op3 config with ``sag_feedforward = false``."""
    text = (ROOT / "config" / "op3.toml").read_text()
    changed, count = re.subn(r"(?m)^sag_feedforward = true$", "sag_feedforward = false", text)
    assert count == 1, "config/op3.toml no longer sets sag_feedforward = true"
    path = folder / "op3-plain.toml"
    path.write_text(changed)
    return str(path)


def step_errors_mm(run: dict) -> list[float]:
    """Each step's simulated length less its planned length (heel strike to heel strike along x), in mm."""
    strikes = run["heel_strikes"]
    return [1000 * ((b["x_m"] - a["x_m"]) - (b["planned_x_m"] - a["planned_x_m"])) for a, b in zip(strikes, strikes[1:])]


def column(run: dict) -> list[str]:
    if run["fell"]:
        return [f"FELL {run['fall_direction']} at {run['fell_at_s']:.1f} s"] + ["-"] * 5
    errors = step_errors_mm(run)
    mean = sum(errors) / len(errors)
    return [
        f"{run['distance_travelled_m']:.3f} m ({100 * run['distance_travelled_m'] / run['distance_planned_m']:.0f}%)",
        f"{1000 * run['max_foothold_error_m']:.0f} mm",
        f"{mean:+.1f} / {max(errors, key=abs):+.1f} mm",
        f"{run['torso_roll_rms_deg']:.2f} / {run['torso_roll_max_deg']:.1f} deg",
        f"{run['torso_pitch_rms_deg']:.2f} / {run['torso_pitch_max_deg']:.1f} deg",
        f"{100 * run['scuff_fraction']:.1f}%",
    ]


ROWS = ("travelled (of 2.000 m)", "largest heel-strike error against its foothold",
        "step length error, mean / largest (+ long)", "torso roll RMS / max", "torso pitch RMS / max",
        "swing sole touching the floor in its clearance window")


def markdown(with_ff: dict, plain: dict) -> str:
    lines = ["| | sag feedforward (shipped) | planned angles sent |", "|---|---|---|"]
    lines += [f"| {what} | {a} | {b} |" for what, a, b in zip(ROWS, column(with_ff), column(plain))]
    return "\n".join(lines)


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--markdown", action="store_true", help="print the docs' figure (tools/figures.py)")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        table = markdown(sim("op3"), sim(without_feedforward(Path(tmp))))
    print(f"<!-- figure sag-feedforward -->\n{table}\n<!-- /figure -->" if args.markdown else table)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
