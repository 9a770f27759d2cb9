"""The op3's robustness table rerun through the whole session, with the IMU feedback off and on side by side.

    python tools/robustness_feedback.py            # the table, as text (about 2 minutes on a 2-core machine)
    python tools/robustness_feedback.py --quick    # its first row (the 2 m walk on our model) and the route check
    python tools/robustness_feedback.py --json     # one JSON object per walk
    python tools/robustness_feedback.py --markdown # docs/robustness-feedback.md's figures (tools/figures.py)

tools/robustness.py plays the planned walk open loop, outside the session: no IMU, no feedback. Here every
walk is ``gaitbot walk --sim --json --robot op3 ARGS --sim-model ROBOT.xml --sim-map MAP.toml --feedback
none|full`` (run in this process through gaitbot's own command line): the shipped config plans the walk, the
session streams its goals (the sag feedforward for the 6 deg gaitbot writes) through the simulated bus, and the
simulated OpenCR IMU (noise, bias, one frame of delay; ``--imu-seed`` 0) feeds the feedback. The robot each
row differs in is the ``--sim-model``:
- our own model (gaitbot.sim.model3d, the one ``gaitbot walk --sim`` builds and ``gaitbot robot export --mjcf``
  writes) with its position servos at the row's stiffness: the gain gaitbot writes (6 deg), the factory gain
  (12.4 deg: a robot whose gain write did not take), or 8 and 10 deg; built from the shipped config or one whose
  link masses or CoM distances are 20% off (tools/robustness.py ``perturbed``), on a floor of friction 1 or 0.6;
  mapped joint for joint by an identity map (``[joints]`` each joint on itself, ``[imu] body = "torso"``);
- MuJoCo Menagerie's OP3 (tools/op3_menagerie.py, config/sim-maps/op3-menagerie.toml), its own soft servos.
On a --sim-model the gains the session writes change nothing (gaitbot.sim.foreign): the servos are the model's.
Pushes are ``--push 0.7`` and ``--push -0.7`` (sideways, in the middle of the step half-way through the walk).
Pass: tools/robustness.py's (no fall, travelled within 10%, drift under 5 cm, yaw under 5 deg, torso roll and
pitch RMS under 2 deg; a push: no fall). The route is checked on the unperturbed model against plain
``gaitbot walk --sim --robot op3`` (the figure robustness-feedback-route). Exit 0 whatever the verdicts (the
table is a measurement); a walk the command line refuses stops the script with its message (exit 1).
"""

from __future__ import annotations

import argparse
import contextlib
import io
import json
import re
import sys
import tempfile
import time
from dataclasses import dataclass, replace
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tools"))

import op3_menagerie  # noqa: E402
import robustness  # noqa: E402

from gaitbot.app.cli import main as gaitbot  # noqa: E402
from gaitbot.robot.config import RobotConfig, load_robot_config, resolve_config  # noqa: E402
from gaitbot.sim.model import joint_drives, substeps_per_frame  # noqa: E402
from gaitbot.sim.model3d import build_mjcf_3d  # noqa: E402

MENAGERIE_MAP = ROOT / "config" / "sim-maps" / "op3-menagerie.toml"
MODES = ("none", "full")
WRITTEN, FACTORY = robustness.WRITTEN_DEG, robustness.FACTORY_DEG
STIFFNESS_DEG = (8.0, 10.0)  # tools/robustness.py's stiffness rows; its 12.4 deg row is the factory rows here
PUSH_N_S = 0.7


@dataclass(frozen=True)
class Robot:
    """The simulated robot of a row: ours (servos at ``error_deg``, the config ``perturbation`` of
    tools/robustness.py or "") or Menagerie's (``error_deg`` None), on a floor of ``friction``."""

    label: str
    error_deg: float | None
    perturbation: str = ""
    friction: float = 1.0


OURS_WRITTEN = Robot(f"ours, servos at the gain written ({WRITTEN:.3g} deg)", WRITTEN)
OURS_FACTORY = Robot(f"ours, servos at the factory gain ({FACTORY:.3g} deg)", FACTORY)
MENAGERIE = Robot("Menagerie OP3, its own servos", None)


@dataclass(frozen=True)
class Row:
    group: str
    walk: str
    robot: Robot
    args: tuple[str, ...]
    push: float = 0.0


def rows(quick: bool = False) -> list[Row]:
    """The rows of tools/robustness.py's op3 table, each walked through the session (``quick``: the first)."""
    two_m = tuple(robustness.WALKS["2 m"])
    if quick:
        return [Row("walks", "2 m", OURS_WRITTEN, two_m)]
    out = [Row("walks", name, robot, tuple(args))
           for name, args in robustness.WALKS.items() for robot in (OURS_WRITTEN, OURS_FACTORY, MENAGERIE)]
    for kind in ("mass +20%", "mass -20%", "CoM heights +20%", "CoM heights -20%", "friction 0.6"):
        robots = [OURS_WRITTEN, OURS_FACTORY] + ([MENAGERIE] if kind.startswith("friction") else [])
        for robot in robots:
            changed = replace(robot, friction=0.6) if kind.startswith("friction") else replace(robot, perturbation=kind)
            out.append(Row("model errors (2 m)", kind, changed, two_m))
    for error_deg in STIFFNESS_DEG:
        out.append(Row("stiffness (2 m)", f"servos at {error_deg:.3g} deg", Robot("ours", error_deg), two_m))
    for impulse in (PUSH_N_S, -PUSH_N_S):
        for robot in (OURS_WRITTEN, OURS_FACTORY, MENAGERIE):
            out.append(Row("push mid-step (2 m)", f"{impulse:+.2g} N s", robot, two_m, impulse))
    return out


# --------------------------------------------------------------------------- the models and the map

def session_mjcf(config: RobotConfig, error_deg: float, friction: float = 1.0) -> str:
    """Our simulated robot of ``config`` as MJCF (gaitbot.sim.model3d, free-floating, at the config's frame rate)
    with every servo's stiffness full torque at ``error_deg`` and every geom's sliding friction ``friction``
    (MuJoCo takes the larger of two geoms' frictions: the floor's and the soles' both). The timestep is written
    to full precision so that a frame stays whole steps (the route then steps as ``gaitbot walk --sim`` does)."""
    rate = config.gait.rate_hz
    drives = tuple(replace(d, full_torque_error_deg=error_deg) for d in joint_drives(config, config.joints))
    text = build_mjcf_3d(config, drives, rate, "free")
    text = sub_once(r'timestep="[^"]*"', f'timestep="{1.0 / (rate * substeps_per_frame(rate))!r}"', text)
    return sub_once(r'(<default>\s*<geom [^>]*friction=")[^ "]+', rf"\g<1>{friction!r}", text)


def sub_once(pattern: str, replacement, text: str) -> str:
    """``text`` with the one match of ``pattern`` replaced (a string or a function of the match, as re.sub takes;
    RuntimeError when there is none: the text it edits, a model or a config, changed under the tool)."""
    text, count = re.subn(pattern, replacement, text, count=1)
    if count != 1:
        raise RuntimeError(f"no {pattern!r} to change")
    return text


def identity_map(config: RobotConfig) -> str:
    """The --sim-map of our own model: every joint of the config on the model's joint of the same name (the
    model's joints are gaitbot's, signs and all), the IMU on the torso."""
    lines = ["[joints]", *(f'{j.name} = "{j.name}"' for j in config.joints), "", "[imu]", 'body = "torso"', ""]
    return "\n".join(lines)


class Models:
    """Each row's --sim-model and --sim-map, written once into ``folder``."""

    def __init__(self, folder: Path) -> None:
        self.folder = folder
        self.config = load_robot_config(resolve_config("op3"))
        self.identity = folder / "identity.toml"
        self.identity.write_text(identity_map(self.config))
        self.written: dict[Robot, Path] = {}

    def model_and_map(self, robot: Robot) -> tuple[Path, Path]:
        key = replace(robot, label="")
        if key not in self.written:
            path = self.folder / f"model{len(self.written)}.xml"
            if robot.error_deg is None:
                path.write_text(op3_menagerie.menagerie_mjcf(robot.friction))
            else:
                config = robustness.perturbed(self.config, robot.perturbation) if robot.perturbation else self.config
                path.write_text(session_mjcf(config, robot.error_deg, robot.friction))
            self.written[key] = path
        return self.written[key], (MENAGERIE_MAP if robot.error_deg is None else self.identity)


# --------------------------------------------------------------------------- the walks

def walk(*args: str) -> dict:
    """``gaitbot walk --sim --json ARGS`` in this process: its report (exit 0 or 1, a fall; else an error)."""
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        code = gaitbot(["walk", "--sim", "--json", "--robot", "op3", *args])
    if code not in (0, 1):
        raise SystemExit(f"gaitbot walk {' '.join(args)} failed (exit {code}): {err.getvalue().strip()}")
    return json.loads(out.getvalue())


def outcome(report: dict, push: float) -> dict:
    """tools/robustness.py's measures of a walk's report, and its verdict."""
    r = dict(fell=report["fell"], fell_at_s=report["fell_at_s"], fall_direction=report["fall_direction"],
             travel=report["distance_travelled_m"] / report["distance_planned_m"], drift_m=report["lateral_drift_m"],
             yaw_deg=report["max_abs_yaw_deg"], roll_rms_deg=report["torso_roll_rms_deg"],
             pitch_rms_deg=report["torso_pitch_rms_deg"], push=push)
    r["pass"] = robustness.passes(r)
    return r


def play(models: Models, row: Row, mode: str) -> dict:
    model, mapping = models.model_and_map(row.robot)
    push = ("--push", f"{row.push:g}") if row.push else ()
    report = walk(*row.args, *push, "--sim-model", str(model), "--sim-map", str(mapping), "--feedback", mode)
    return outcome(report, row.push)


def measure(models: Models, on_row=None, quick: bool = False) -> list[dict]:
    results = []
    for row in rows(quick):
        result = dict(group=row.group, walk=row.walk, robot=row.robot.label,
                      **{mode: play(models, row, mode) for mode in MODES})
        results.append(result)
        if on_row is not None:
            on_row(result)
    return results


def route_check(models: Models, results: list[dict]) -> list[tuple[str, str, dict]]:
    """The unperturbed 2 m walk, plain ``gaitbot walk --sim`` against the route (the table's first row)."""
    plain = [("plain `gaitbot walk --sim --robot op3 --distance 2`", mode,
              outcome(walk("--distance", "2", "--feedback", mode), 0.0)) for mode in MODES]
    route = [("the same through the route (our model at 6 deg, identity map)", mode, results[0][mode])
             for mode in MODES]
    return plain + route


# --------------------------------------------------------------------------- the tables

def cell(r: dict) -> str:
    """One walk's outcome; a fall shows its time and way alone (a tumbling body's figures are chaos)."""
    if r["fell"]:
        return f"FELL at {r['fell_at_s']:.1f} s, {r['fall_direction']}"
    return (f"{100 * r['travel']:.1f}%, drift {100 * r['drift_m']:+.1f} cm, yaw {r['yaw_deg']:.1f} deg, "
            f"RMS {r['roll_rms_deg']:.2f} / {r['pitch_rms_deg']:.2f} deg")


def yes_no(r: dict) -> str:
    return "yes" if r["pass"] else "no"


HEADER = ("| group | walk / error | robot | pass, feedback none | pass, feedback full | feedback none | feedback full |\n"
          "|---|---|---|---|---|---|---|")


def table_row(result: dict) -> str:
    """The verdicts first (plain yes / no), then each walk's outcome: tools/figures.py compares a line that fell
    in both texts up to its FELL, so both verdicts stay compared."""
    none, full = result["none"], result["full"]
    return (f"| {result['group']} | {result['walk']} | {result['robot']} | {yes_no(none)} | {yes_no(full)} | "
            f"{cell(none)} | {cell(full)} |")


def summary(results: list[dict]) -> str:
    parts = []
    for mode in MODES:
        walks = [r[mode] for r in results]
        parts.append(f"feedback {mode}: {sum(w['pass'] for w in walks)}/{len(walks)} pass, "
                     f"{sum(w['fell'] for w in walks)} falls")
    return "; ".join(parts) + "."


def route_table(check: list[tuple[str, str, dict]]) -> str:
    lines = ["| walk | feedback | travelled | drift cm | max yaw deg | roll RMS deg | pitch RMS deg |",
             "|---|---|---|---|---|---|---|"]
    for label, mode, r in check:
        lines.append(f"| {label} | {mode} | {100 * r['travel']:.1f}% | {100 * r['drift_m']:+.1f} | "
                     f"{r['yaw_deg']:.1f} | {r['roll_rms_deg']:.2f} | {r['pitch_rms_deg']:.2f} |")
    return "\n".join(lines)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--json", action="store_true", help="one JSON object per row")
    parser.add_argument("--quick", action="store_true", help="the first row and the route check (about 15 s)")
    parser.add_argument("--markdown", action="store_true",
                        help="the figures of docs/robustness-feedback.md (tools/figures.py)")
    args = parser.parse_args(argv)
    start = time.perf_counter()
    with tempfile.TemporaryDirectory() as tmp:
        models = Models(Path(tmp))
        if args.markdown:
            results = measure(models)
            check = route_check(models, results)
            print(f"<!-- figure robustness-feedback-route -->\n{route_table(check)}\n<!-- /figure -->")
            body = "\n".join([HEADER, *map(table_row, results), "", summary(results)])
            print(f"<!-- figure robustness-feedback -->\n{body}\n<!-- /figure -->")
            return 0
        if not args.json:
            print(HEADER)
        results = measure(models, lambda row: print(json.dumps(row) if args.json else table_row(row), flush=True),
                          args.quick)
        check = route_check(models, results)
        if args.json:
            for label, mode, r in check:
                print(json.dumps(dict(route=label, feedback=mode, **r)))
        else:
            print(f"\n{summary(results)}\n\n{route_table(check)}\n\n{time.perf_counter() - start:.0f} s.")
    return 0


if __name__ == "__main__":
    sys.exit(main())
