"""The simulated robot's figures: the balanced op3 free-floating, flat walks of the pitch-only robots on the
boom, and what the two walking settings of their configs are worth (the sim extra).

    python tools/sim_figures.py               # the figures, as text
    python tools/sim_figures.py --markdown    # the figures of docs/simulation.md (tools/figures.py)

Every figure is a ``gaitbot walk --sim --json`` run through the command line itself: the op3 walks of
OP3_WALKS and the bioloid's of BIOLOID_WALKS (the balanced walk's targets); per pitch-only robot, 1 m with the
pitch held and with it free; the same walks with the ankle at the heel (``heel_back_m = 0``), at the servos'
factory gains (no ``[servo] full_torque_error_deg``), and both; and toe drag (``--clearance 0``) at factory
and at the shipped gains. The simulation is deterministic on one machine; another CPU or MuJoCo release moves the figures within
the simulated figures' tolerance (docs/figures.md, "Simulated figures").
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
from gaitbot.app.progress import progress  # noqa: E402

ROBOTS = ("xl430-biped", "sts3215-biped", "ax12a-biped")
DISTANCE = "1.0"
#: The balanced op3 walks of docs/simulation.md: (what the row says, gaitbot walk's arguments).
OP3_WALKS = (
    ("`--distance 2`", ["--distance", "2"]),
    ("`--distance 2 --max-step 0.04 --perturb 0.01 --seed 1` (varied)",
     ["--distance", "2", "--max-step", "0.04", "--perturb", "0.01", "--seed", "1"]),
    ("`--steps 0.05,0.03,...` (25 pairs, asymmetric)", ["--steps", ",".join(["0.05,0.03"] * 25)]),
    ("`--distance 2 --cycle 0.8 --max-step 0.08` (0.2 m/s)", ["--distance", "2", "--cycle", "0.8", "--max-step", "0.08"]),
    ("`--distance 2 --push 0.7`", ["--distance", "2", "--push", "0.7"]),
    ("`--distance 2 --push -0.7`", ["--distance", "2", "--push", "-0.7"]),
)
#: The balanced bioloid walks of docs/simulation.md: the op3's scaled to its legs (0.149 / 0.220 m), its
#: fastest walk within the AX-12A's 300 deg/s, pushes of the op3's velocity change (0.34 N s), the largest
#: it survives both ways (0.65) and the op3's 0.7 N s (docs/balance-robustness.md, "The bioloid").
BIOLOID_WALKS = (
    ("`--distance 2`", ["--distance", "2"]),
    ("`--distance 2 --max-step 0.03 --perturb 0.007 --seed 1` (varied)",
     ["--distance", "2", "--max-step", "0.03", "--perturb", "0.007", "--seed", "1"]),
    ("`--steps 0.035,0.02,...` (36 pairs, asymmetric)", ["--steps", ",".join(["0.035,0.02"] * 36)]),
    ("`--distance 2 --cycle 0.8 --max-step 0.05` (0.125 m/s)", ["--distance", "2", "--cycle", "0.8", "--max-step", "0.05"]),
    ("`--distance 2 --push 0.34`", ["--distance", "2", "--push", "0.34"]),
    ("`--distance 2 --push -0.34`", ["--distance", "2", "--push", "-0.34"]),
    ("`--distance 2 --push 0.65`", ["--distance", "2", "--push", "0.65"]),
    ("`--distance 2 --push -0.65`", ["--distance", "2", "--push", "-0.65"]),
    ("`--distance 2 --push 0.7`", ["--distance", "2", "--push", "0.7"]),
    ("`--distance 2 --push -0.7`", ["--distance", "2", "--push", "-0.7"]),
)


def variant(name: str, folder: Path, ankle_at_heel: bool, factory_gains: bool) -> str:
    """The shipped config of ``name`` with the ankle at the heel and/or without its stiffness setting."""
    text = (ROOT / "config" / f"{name}.toml").read_text()
    if ankle_at_heel:
        text = re.sub(r"(?m)^heel_back_m = .*$", "heel_back_m = 0.0", text)
    if factory_gains:
        text = re.sub(r"(?m)^\[servo\]\nfull_torque_error_deg = .*\n", "", text)
    path = folder / f"{name}-{int(ankle_at_heel)}{int(factory_gains)}.toml"
    path.write_text(text)
    return str(path)


def sim(*args: str) -> dict:
    out = io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(io.StringIO()):
        gaitbot(["walk", "--sim", "--json", *args])  # exit 1 for a fall: the JSON says so too
    return json.loads(out.getvalue())


def measure() -> dict:
    runs = {}
    total = 7 * len(ROBOTS) + len(OP3_WALKS) + len(BIOLOID_WALKS)
    with tempfile.TemporaryDirectory() as tmp, progress("simulated walks", total=total, unit="walk") as bar:
        folder = Path(tmp)
        for label, args in OP3_WALKS:
            runs["op3", label] = sim("--robot", "op3", *args)
            bar.update(1)
        for label, args in BIOLOID_WALKS:
            runs["bioloid", label] = sim("--robot", "bioloid", *args)
            bar.update(1)
        for name in ROBOTS:
            def run(key, *args):
                runs[name, key] = sim(*args)
                bar.update(1)

            run("shipped", "--robot", name, "--distance", DISTANCE)
            run("free pitch", "--robot", name, "--distance", DISTANCE, "--free-pitch")
            for key, heel, factory in (("neither", True, True), ("ankle only", False, True), ("stiff only", True, False)):
                run(key, "--robot", variant(name, folder, heel, factory), "--distance", DISTANCE)
            run("drag, factory", "--robot", variant(name, folder, False, True), "--distance", DISTANCE, "--clearance", "0")
            run("drag, shipped", "--robot", name, "--distance", DISTANCE, "--clearance", "0")
    return runs


def _travelled(r: dict) -> str:
    return f"{r['distance_travelled_m']:.3f} ({100 * r['distance_travelled_m'] / r['distance_planned_m']:.0f}%)"


def op3_table(runs: dict, robot: str = "op3", walks=OP3_WALKS) -> str:
    """The balanced walks of ``robot``; a walk that fell shows its fall's time and way alone (what a body
    does while it tumbles is chaotic, not a figure of the gait)."""
    rows = ["| ARGS | travelled of planned m | drift cm | yaw end / max deg | roll RMS / max deg | "
            "pitch RMS / max deg | max foothold error mm | simulated s |", "|---|---|---|---|---|---|---|---|"]
    for label, _ in walks:
        r = runs[robot, label]
        if r["fell"]:
            rows.append(f"| {label} | FELL {r['fall_direction']} at {r['fell_at_s']:.1f} s of "
                        f"{r['distance_planned_m']:.3f} | - | - | - | - | - | {r['simulated_s']:.1f} |")
            continue
        rows.append(f"| {label} | {_travelled(r)} of {r['distance_planned_m']:.3f} | "
                    f"{100 * r['lateral_drift_m']:.1f} | {r['yaw_deg']:.1f} / {r['max_abs_yaw_deg']:.1f} | "
                    f"{r['torso_roll_rms_deg']:.2f} / {r['torso_roll_max_deg']:.1f} | "
                    f"{r['torso_pitch_rms_deg']:.2f} / {r['torso_pitch_max_deg']:.1f} | "
                    f"{1000 * r['max_foothold_error_m']:.0f} | {r['simulated_s']:.1f} |")
    return "\n".join(rows)


def markdown(runs: dict) -> str:
    flat = ["| robot | planned m | travelled m | fell | scuff | max slip mm | max torque / stall | "
            "max tracking error deg | free pitch |", "|---|---|---|---|---|---|---|---|---|"]
    for name in ROBOTS:
        r, free = runs[name, "shipped"], runs[name, "free pitch"]
        fell = f"fell at {free['fell_at_s']:.2f} s" if free["fell"] else "stayed up"
        flat.append(f"| {name} | {r['distance_planned_m']:.3f} | {_travelled(r)} | {'yes' if r['fell'] else 'no'} | "
                    f"{100 * r['scuff_fraction']:.1f}% | {1000 * r['max_slip_m']:.1f} | {r['max_torque_fraction']:.2f} | "
                    f"{r['max_tracking_error_deg']:.1f} | {fell} |")
    settings = ["| robot | neither | ankle a third into the foot only | stiff servos only | both (shipped) |",
                "|---|---|---|---|---|"]
    for name in ROBOTS:
        settings.append(f"| {name} | " + " | ".join(_travelled(runs[name, key]) for key in
                                                    ("neither", "ankle only", "stiff only", "shipped")) + " |")
    drag = "; ".join(f"{name} {runs[name, 'drag, factory']['distance_travelled_m']:.3f} m, scuffing "
                     f"{100 * runs[name, 'drag, factory']['scuff_fraction']:.0f}% of the swing time" for name in ROBOTS)
    stiff = "; ".join(f"{name} {runs[name, 'drag, shipped']['distance_travelled_m']:.3f} m, "
                      f"{100 * runs[name, 'drag, shipped']['scuff_fraction']:.1f}%" for name in ROBOTS)
    first = runs["op3", OP3_WALKS[0][0]]
    readme = (f"On the free-floating simulated OP3 (`gaitbot walk --sim --robot op3 --distance 2`) the balanced walk "
              f"travels {_travelled(first)} of {first['distance_planned_m']:.3f} m, "
              f"{'falling' if first['fell'] else 'without falling'}, {abs(100 * first['lateral_drift_m']):.1f} cm "
              f"of drift, yaw within {first['max_abs_yaw_deg']:.1f} deg, torso roll and pitch RMS "
              f"{first['torso_roll_rms_deg']:.2f} and {first['torso_pitch_rms_deg']:.2f} deg.")
    blocks = {"sim-op3-summary": readme, "sim-op3": op3_table(runs),
              "sim-bioloid": op3_table(runs, "bioloid", BIOLOID_WALKS), "sim-flat": "\n".join(flat), "sim-settings": "\n".join(settings),
              "sim-toe-drag": (f"With the swing clearance turned off (`--clearance 0`), at factory gains, of "
                               f"{DISTANCE} m: {drag}. With the shipped stiff servos: {stiff}.")}
    return "\n".join(f"<!-- figure {k} -->\n{v}\n<!-- /figure -->" for k, v in blocks.items())


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--markdown", action="store_true", help="print the docs' figures (tools/figures.py)")
    args = parser.parse_args(argv)
    runs = measure()
    if args.markdown:
        print(markdown(runs))
        return 0
    print(op3_table(runs))
    print(op3_table(runs, "bioloid", BIOLOID_WALKS))
    for (name, key), r in runs.items():
        if name in ("op3", "bioloid"):
            continue
        print(f"{name:14s} {key:14s} planned {r['distance_planned_m']:.3f} m, travelled {_travelled(r)}, "
              f"fell {r['fell']} {r['fell_at_s']}, scuff {100 * r['scuff_fraction']:.1f}%, slip "
              f"{1000 * r['max_slip_m']:.1f} mm, torque {r['max_torque_fraction']:.2f}, tracking "
              f"{r['max_tracking_error_deg']:.1f} deg")
    return 0


if __name__ == "__main__":
    sys.exit(main())
