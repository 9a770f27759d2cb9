"""The IMU feedback's figures on MuJoCo Menagerie's OP3 at its own servo stiffness (docs/feedback.md).

    python tools/feel_figures.py               # the figures, as text
    python tools/feel_figures.py --markdown    # the figures of docs/feedback.md (tools/figures.py)

Every figure is a ``gaitbot walk --sim --json --robot op3 --sim-model op3-menagerie.xml --sim-map
config/sim-maps/op3-menagerie.toml`` run through the command line itself (the model written by
tools/op3_menagerie.py into a temporary folder):

- feel-menagerie: the issue's walks (2 m at 0.2 m/s; 1 m at 0.1 m/s, alone and with a push of 1.0 and 1.5 N s
  sideways and 1.5 N s forwards in its middle) with each feedback level;
- feel-why: why the 0.2 m/s walk fell on this model open loop, one thing changed at a time: the model's
  servos at the stiffness gaitbot writes (kp = 4.1 N m over 6 deg, its 5 N m force limit kept), its joint
  damping (the XM430's back-EMF, 1.084 N m s/rad) cut to 0.3, the sag feedforward computed for the model's
  own kp; then the feedback's roll attitude term, which carries soft servos (this model per IMU seed, and
  gaitbot's own model at factory gains) but makes gaitbot's own model at the stiffness it writes drift or
  fall: why config/op3.toml gives it by the servos' stiffness.

The simulation is deterministic on one machine; another CPU or MuJoCo release moves the figures within the
simulated figures' tolerance (docs/figures.md, "Simulated figures").
"""

from __future__ import annotations

import argparse
import contextlib
import io
import json
import math
import re
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "tools"))

from gaitbot.app.cli import main as gaitbot  # noqa: E402
from op3_menagerie import menagerie_mjcf  # noqa: E402

MAP = str(ROOT / "config" / "sim-maps" / "op3-menagerie.toml")
FAST = ("--distance", "2", "--max-step", "0.08", "--cycle", "0.8")
PUSHED = ("--distance", "2", "--push", "0.7")  # tools/robustness_feedback.py's push row
SLOW = ("--distance", "1", "--max-step", "0.05", "--cycle", "1.0")
#: The issue's walks: (what the row says, gaitbot walk's arguments).
WALKS = (
    ("`--distance 2 --max-step 0.08 --cycle 0.8` (0.2 m/s)", FAST),
    ("`--distance 1 --max-step 0.05 --cycle 1.0` (0.1 m/s)", SLOW),
    ("the same `--push 1.0` (sideways, left)", (*SLOW, "--push", "1.0")),
    ("the same `--push 1.5` (sideways, left)", (*SLOW, "--push", "1.5")),
    ("the same `--push 1.5@0` (forwards)", (*SLOW, "--push", "1.5@0")),
)
MODES = ("none", "gyro", "full")
#: The attitude terms tried (docs/feedback.md, "The OP3's gains"): a roll gain whatever the servos' stiffness.
FLAT_ROLL = {"attitude_roll_gain_by_servo_error": "[[6.0, 0.4]]"}
STRONG_ROLL = {"attitude_roll_gain_by_servo_error": "[[6.0, 0.0], [10.0, 0.5]]"}
QUIET_ROLL = {"attitude_roll_gain_by_servo_error": "[[6.0, 0.3]]"}
FACTORY, HALF_WAY = {"full_torque_error_deg": "12.4"}, {"full_torque_error_deg": "8.0"}  # XM430: factory gain 800
QUIET_IMU = {"gyro_noise_dps": "0.0", "gyro_bias_dps": "0.0", "acc_noise_g": "0.0"}
XM430_STALL_NM, WRITTEN_ERROR_DEG = 4.1, 6.0  # config/op3.toml: the XM430-W350's stall torque, [servo] written


def sim(*args: str) -> dict:
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        code = gaitbot(["walk", "--sim", "--json", *args])
    if code not in (0, 1):
        raise SystemExit(f"gaitbot walk {' '.join(args)} failed (exit {code}): {err.getvalue().strip()}")
    return json.loads(out.getvalue())


def config_variant(folder: Path, name: str, **values: str) -> str:
    """config/op3.toml with some ``key = value`` lines changed (each key must be in the file once)."""
    text = (ROOT / "config" / "op3.toml").read_text()
    for key, value in values.items():
        text, count = re.subn(rf"^{key} = .*$", f"{key} = {value}", text, flags=re.M)
        if count != 1:
            raise SystemExit(f"config/op3.toml: {key} is not set once")
    path = folder / f"{name}.toml"
    path.write_text(text)
    return str(path)


def model_variant(folder: Path, name: str, **attributes: str) -> str:
    """The Menagerie model with some default attributes changed (kp, damping)."""
    text = menagerie_mjcf()
    for key, value in attributes.items():
        text, count = re.subn(rf'\b{key}="[^"]*"', f'{key}="{value}"', text, count=1)
        if count != 1:
            raise SystemExit(f"the Menagerie model has no {key}")
    path = folder / f"{name}.xml"
    path.write_text(text)
    return str(path)


def measure() -> dict:
    runs = {}
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        model = model_variant(folder, "op3-menagerie")
        on = ("--robot", "op3", "--sim-model", model, "--sim-map", MAP)
        for label, args in WALKS:
            for mode in MODES:
                runs[label, mode] = sim(*on, *args, "--feedback", mode)
        written_kp = XM430_STALL_NM / math.radians(WRITTEN_ERROR_DEG)
        stiff = model_variant(folder, "stiff", kp=f"{written_kp:.1f}")
        runs["why", "stiff"] = sim("--robot", "op3", "--sim-model", stiff, "--sim-map", MAP, *FAST, "--feedback", "none")
        damped = model_variant(folder, "damping", damping="0.3")
        runs["why", "damping"] = sim("--robot", "op3", "--sim-model", damped, "--sim-map", MAP, *FAST, "--feedback", "none")
        their_error_deg = math.degrees(XM430_STALL_NM / 21.1)  # the model's kp, in the config's terms
        soft = config_variant(folder, "soft", full_torque_error_deg=f"{their_error_deg:.2f}")
        runs["why", "soft"] = sim("--robot", soft, "--sim-model", model, "--sim-map", MAP, *FAST, "--feedback", "none")
        for seed in (1, 2):
            runs["why", f"seed {seed}"] = sim(*on, *FAST, "--imu-seed", str(seed))
        runs["why", "own"] = sim("--robot", "op3", *FAST)
        runs["why", "flat own"] = sim("--robot", config_variant(folder, "flat", **FLAT_ROLL), *FAST)
        runs["why", "quiet own"] = sim("--robot", config_variant(folder, "quiet", **QUIET_ROLL, **QUIET_IMU), *FAST)
        factory = config_variant(folder, "factory", **FACTORY)
        runs["why", "factory gyro"] = sim("--robot", factory, *FAST, "--feedback", "gyro")
        runs["why", "factory"] = sim("--robot", factory, *FAST)
        strong = config_variant(folder, "strong", **STRONG_ROLL)
        runs["why", "factory strong"] = sim("--robot", config_variant(folder, "factory-strong", **FACTORY, **STRONG_ROLL),
                                            *FAST)
        runs["why", "half way"] = sim("--robot", config_variant(folder, "half-way", **HALF_WAY), *FAST)
        runs["why", "pushed"] = sim(*on, *PUSHED)
        runs["why", "pushed strong"] = sim("--robot", strong, *on[2:], *PUSHED)
    return runs


def verdict(r: dict) -> str:
    """A walk's outcome; a fall shows its time and way alone (what a body does while it tumbles is chaos)."""
    if r["fell"]:
        return f"FELL {r['fall_direction']} at {r['fell_at_s']:.2f} s, {r['distance_travelled_m']:.2f} m"
    share = 100 * r["distance_travelled_m"] / r["distance_planned_m"]
    return (f"{r['distance_travelled_m']:.3f} m of {r['distance_planned_m']:.3f} ({share:.0f}%), torso roll / pitch "
            f"RMS {r['torso_roll_rms_deg']:.2f} / {r['torso_pitch_rms_deg']:.2f} deg")


def menagerie_table(runs: dict) -> str:
    rows = ["| ARGS | feedback | outcome |", "|---|---|---|"]
    for label, _ in WALKS:
        rows += [f"| {label} | {mode} | {verdict(runs[label, mode])} |" for mode in MODES]
    return "\n".join(rows)


def why_table(runs: dict) -> str:
    written_kp = XM430_STALL_NM / math.radians(WRITTEN_ERROR_DEG)
    their_error_deg = math.degrees(XM430_STALL_NM / 21.1)
    own = "gaitbot's own op3 model"
    what = [
        ("the model as it is (kp 21.1 N m/rad, damping 1.084), feedback none", runs[FAST_LABEL, "none"]),
        (f"its servos at the stiffness gaitbot writes (kp {written_kp:.1f}), feedback none", runs["why", "stiff"]),
        ("its joint damping 0.3 instead of 1.084, feedback none", runs["why", "damping"]),
        (f"the sag feedforward for the model's kp (`full_torque_error_deg = {their_error_deg:.2f}`), feedback none",
         runs["why", "soft"]),
        ("feedback gyro (gyro damping alone)", runs[FAST_LABEL, "gyro"]),
        ("feedback full as shipped (and the roll attitude, 0.4 for these servos), `--imu-seed 0`",
         runs[FAST_LABEL, "full"]),
        *((f"the same, `--imu-seed {seed}`", runs["why", f"seed {seed}"]) for seed in (1, 2)),
        (f"{own} (servos at 6 deg), feedback full as shipped (no roll attitude at that stiffness)", runs["why", "own"]),
        (f"{own}, a roll gain of 0.4 whatever the stiffness (`{FLAT_ROLL_TEXT}`)", runs["why", "flat own"]),
        (f"{own}, a flat roll gain of 0.3, an IMU without noise or bias", runs["why", "quiet own"]),
        (f"{own} at the XM430's factory gain (`full_torque_error_deg = 12.4`), feedback gyro", runs["why", "factory gyro"]),
        (f"{own} at the factory gain, feedback full as shipped (roll attitude 0.4)", runs["why", "factory"]),
        (f"{own} at the factory gain, roll attitude 0.5 (`{STRONG_ROLL_TEXT}`)", runs["why", "factory strong"]),
        (f"{own} at 8 deg, feedback full as shipped (roll attitude 0.2)", runs["why", "half way"]),
        ("Menagerie's OP3, `--distance 2 --push 0.7` (the default speed), feedback full as shipped", runs["why", "pushed"]),
        ("the same with roll attitude 0.5", runs["why", "pushed strong"]),
    ]
    rows = ["| what changed (the 0.2 m/s walk, `--distance 2 --max-step 0.08 --cycle 0.8`, on Menagerie's OP3 unless "
            "said) | outcome | max torque / force limit | max tracking error deg |", "|---|---|---|---|"]
    for text, r in what:
        drift = "" if r["fell"] else f", drift {100 * r['lateral_drift_m']:.1f} cm, yaw {r['yaw_deg']:.1f} deg"
        rows.append(f"| {text} | {verdict(r)}{drift} | {r['max_torque_fraction']:.2f} | "
                    f"{r['max_tracking_error_deg']:.1f} |")
    return "\n".join(rows)


FAST_LABEL = WALKS[0][0]
FLAT_ROLL_TEXT = f"attitude_roll_gain_by_servo_error = {FLAT_ROLL['attitude_roll_gain_by_servo_error']}"
STRONG_ROLL_TEXT = f"attitude_roll_gain_by_servo_error = {STRONG_ROLL['attitude_roll_gain_by_servo_error']}"


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--markdown", action="store_true", help="print the docs' figures (tools/figures.py)")
    args = parser.parse_args(argv)
    runs = measure()
    print_figures({"feel-menagerie": menagerie_table(runs), "feel-why": why_table(runs)}, args.markdown)
    return 0


def print_figures(blocks: dict, markdown: bool) -> None:
    """The figures as text, or as the docs' figure regions (tools/figures.py reads them)."""
    if markdown:
        print("\n".join(f"<!-- figure {k} -->\n{v}\n<!-- /figure -->" for k, v in blocks.items()))
    else:
        print("\n\n".join(blocks.values()))


if __name__ == "__main__":
    sys.exit(main())
