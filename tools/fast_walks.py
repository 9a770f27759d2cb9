"""Where a faster walk's steps land, and how soft the servos may be for it (docs/walk-faster.md).

    python tools/fast_walks.py              # the three tables, as text (about a minute on a 2-core machine)
    python tools/fast_walks.py --markdown   # docs/walk-faster.md's figures (tools/figures.py)

Every walk is ``gaitbot walk --sim --json --robot CONFIG --distance 2 ARGS`` (feedback as the robot's IMU
allows: full on the op3), run in this process through gaitbot's own command line:

- the op3's walks from the shipped one to 0.2 m/s (``walks``) on gaitbot's own model: the settings the speed fit
  chose for each (gaitbot.gait.balance.speed_fit), the distance travelled and the steps' mean length as
  landed (the heel strikes' spacing) against the plan's;
- the shipped walk's cycle and step walked with its own settings, with one setting of the speed fit's next
  candidate at a time, and with that candidate (a copy of config/op3.toml with ``[balance]`` and
  ``[gait]`` set to them; at this slow cycle each fits, so the walk takes them as they are): which setting
  makes a step land short;
- the same walks on MuJoCo Menagerie's OP3 (tools/op3_menagerie.py, config/sim-maps/op3-menagerie.toml) as it
  is, and with its servos or floor changed (MENAGERIE_VARIANTS): another author's robot, softer or stiffer.

Exit 0 whatever the walks do (the tables are a measurement); a walk the command line refuses stops the script
with its message (exit 1).
"""

from __future__ import annotations

import argparse
import contextlib
import io
import json
import sys
import tempfile
from dataclasses import replace
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tools"))

import op3_menagerie  # noqa: E402
from robustness_feedback import sub_once  # noqa: E402

from gaitbot.app.cli import main as gaitbot  # noqa: E402
from gaitbot.gait.balance.speed_fit import candidates  # noqa: E402
from gaitbot.robot.balanced_walk import balanced_gait_settings, fitted_settings  # noqa: E402
from gaitbot.robot.config import load_robot_config, resolve_config  # noqa: E402

OP3 = ROOT / "config" / "op3.toml"
MENAGERIE_MAP = ROOT / "config" / "sim-maps" / "op3-menagerie.toml"
DISTANCE_M = 2.0
FASTER = ((1.0, 0.05), (1.4, 0.07), (0.8, 0.06), (0.8, 0.08))
"""The faster walks, (cycle s, step m): 0.1 m/s two ways, 0.15 and 0.2 m/s; after the shipped one (the config's)."""
SHIPPED_CANDIDATE = 2
"""The speed fit's candidate the shipped walk takes (gaitbot.gait.balance.speed_fit.candidates; checked)."""
SINGLE_CHANGES = {"the shipped walk's, progression done at 100%": (0.10, 1.0, 0.005),
                  "the shipped walk's, clearance 3 mm": (0.10, 0.9, 0.003)}
"""label -> (double support share, progression end, clearance m): the next candidate's progression, then its
clearance, one at a time on the shipped walk's settings."""
MENAGERIE_VARIANTS = {"as it is (kp 21.1 N m/rad, 5 N m, damping 1.084)": {},
                      "servos 1.5 x stiffer (kp 31.7)": {"kp": 1.5},
                      "servos 0.7 x as stiff (kp 14.8)": {"kp": 0.7},
                      "force limit 3 N m": {"force_nm": 3.0},
                      "joint damping x 2": {"damping": 2.0},
                      "floor friction 0.6": {"friction": 0.6}}
"""Menagerie's OP3 and the changes made to it (its actuators' kp scaled, force limit, joint damping scaled,
every geom's sliding friction)."""


def walks() -> dict[str, tuple[float, float]]:
    """label -> (cycle s, step m): the op3's shipped walk (its config's ``[gait]``), then FASTER."""
    gait = load_robot_config(OP3).gait
    speed = gait.max_step_m / (gait.cycle_s / 2)
    out = {f"shipped (cycle {gait.cycle_s:g} s, {100 * gait.max_step_m:g} cm steps; {speed:.2g} m/s)":
           (gait.cycle_s, gait.max_step_m)}
    for cycle_s, step_m in FASTER:
        out[f"{step_m / (cycle_s / 2):.2g} m/s (cycle {cycle_s:g} s, {100 * step_m:g} cm)"] = (cycle_s, step_m)
    return out


def menagerie_variant(kp: float = 1.0, force_nm: float = 5.0, damping: float = 1.0, friction: float = 1.0) -> str:
    """Menagerie's OP3 (tools/op3_menagerie.py) with its position servos' kp and the joints' damping scaled,
    the servos' force limit ``force_nm`` and the floor's (every geom's) sliding friction ``friction``."""
    text = op3_menagerie.menagerie_mjcf(friction)
    text = sub_once(r'<position kp="([\d.]+)"', lambda m: f'<position kp="{kp * float(m.group(1)):.6g}"', text)
    text = sub_once(r'forcerange="-5 5"', f'forcerange="{-force_nm:g} {force_nm:g}"', text)
    return sub_once(r'<joint damping="([\d.]+)"', lambda m: f'<joint damping="{damping * float(m.group(1)):.6g}"',
                    text)


def settings_config(crouch_knee_deg: float, double_support_share: float, progression_end: float,
                    clearance_m: float) -> str:
    """config/op3.toml with these ``[balance]`` and ``[gait]`` settings."""
    text = OP3.read_text()
    for key, value in (("crouch_knee_deg", crouch_knee_deg), ("double_support_share", double_support_share),
                       ("progression_end", progression_end), ("clearance_m", clearance_m)):
        text = sub_once(rf"(?m)^{key} = .*$", f"{key} = {value!r}", text)
    return text


def walk(robot: Path | str, cycle_s: float, step_m: float, *model: str) -> dict:
    """``gaitbot walk --sim --json`` of DISTANCE_M at this cycle and step: its report (a fall is exit 1)."""
    args = ["walk", "--sim", "--json", "--robot", str(robot), "--distance", f"{DISTANCE_M:g}", "--cycle",
            f"{cycle_s:g}", "--max-step", f"{step_m:g}", *model]
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        code = gaitbot(args)
    if code not in (0, 1):
        raise SystemExit(f"gaitbot {' '.join(args)} failed (exit {code}): {err.getvalue().strip()}")
    return json.loads(out.getvalue())


def landed_share(report: dict) -> float:
    """The steps' length as landed over the plan's: the heel strikes' spacing, over the steps that moved on."""
    strikes = report["heel_strikes"]
    landed = np.diff([s["x_m"] for s in strikes])
    planned = np.diff([s["planned_x_m"] for s in strikes])
    moving = planned > 1e-6  # the closing step lands beside the other foot
    return float(landed[moving].sum() / planned[moving].sum())


def outcome(report: dict) -> str:
    if report["fell"]:
        return f"FELL at {report['fell_at_s']:.1f} s"
    return f"{100 * report['distance_travelled_m'] / report['distance_planned_m']:.1f}%"


def settings_text(balance, gait) -> str:
    return (f"crouch {balance.crouch_knee_deg:g} deg, double support {100 * balance.double_support_share:g}%, "
            f"progression done at {100 * balance.progression_end:g}%, clearance {1000 * gait.clearance_m:g} mm")


def steps_table() -> str:
    """The op3's walks on gaitbot's own model: the fit's settings, the distance, the steps as landed."""
    config = load_robot_config(resolve_config("op3"))
    lines = ["| walk | settings the speed fit chose | travelled | steps landed / planned | largest slip |",
             "|---|---|---|---|---|"]
    for label, (cycle_s, step_m) in walks().items():
        fit = fitted_settings(config, balanced_gait_settings(config, cycle_s=cycle_s, max_step_m=step_m))
        report = walk("op3", cycle_s, step_m)
        lines.append(f"| {label} | {settings_text(fit.balance, fit.gait)} | {outcome(report)} | "
                     f"{100 * landed_share(report):.1f}% | {1000 * report['max_slip_m']:.1f} mm |")
    return "\n".join(lines)


def settings_rows(config) -> list[tuple[str, object, object]]:
    """(label, balance, gait): the speed fit's candidate the shipped walk takes (the robot's own values and the
    next keep no servo margin even at the shipped cycle), SINGLE_CHANGES, and the first candidate with both
    at the shipped crouch (the fit's last resort but one; the deeper one keeps no margin at the shipped cycle)."""
    gait = balanced_gait_settings(config)
    found = candidates(gait, config.balance)
    shipped_balance, shipped_gait = found[SHIPPED_CANDIDATE]
    singles = [(label, replace(shipped_balance, double_support_share=ds, progression_end=pe),
                replace(shipped_gait, clearance_m=cl)) for label, (ds, pe, cl) in SINGLE_CHANGES.items()]
    both = next(i for i, (b, g) in enumerate(found) if b.progression_end >= 1.0 and g.clearance_m < shipped_gait.clearance_m
                and b.crouch_knee_deg == shipped_balance.crouch_knee_deg)
    return [(f"the shipped walk's (the fit's candidate {SHIPPED_CANDIDATE})", shipped_balance, shipped_gait), *singles,
            (f"the fit's candidate {both} (both, and a shorter double support)", *found[both])]


def settings_table(folder: Path) -> str:
    """The shipped walk's cycle and step with each candidate's settings, the steps as landed."""
    config = load_robot_config(resolve_config("op3"))
    cycle_s, step_m = config.gait.cycle_s, config.gait.max_step_m
    if fitted_settings(config, balanced_gait_settings(config)).relaxed != SHIPPED_CANDIDATE:
        raise SystemExit(f"the shipped walk no longer takes the speed fit's candidate {SHIPPED_CANDIDATE}")
    lines = ["| settings | at the shipped cycle and step | travelled | steps landed / planned |", "|---|---|---|---|"]
    for i, (label, balance, gait) in enumerate(settings_rows(config)):
        path = folder / f"settings{i}.toml"
        path.write_text(settings_config(balance.crouch_knee_deg, balance.double_support_share,
                                        balance.progression_end, gait.clearance_m))
        fit = fitted_settings(load_robot_config(path), balanced_gait_settings(config))
        if fit.relaxed != 0 or not fit.fits:
            raise SystemExit(f"{label}: the speed fit changed its settings at the shipped walk (candidate "
                             f"{fit.relaxed}); the table would not show what it says")
        report = walk(path, cycle_s, step_m)
        lines.append(f"| {label} | {settings_text(balance, gait)} | {outcome(report)} | "
                     f"{100 * landed_share(report):.1f}% |")
    return "\n".join(lines)


def _short(label: str) -> str:
    """A walk's label as a column's: its speed and cycle ("0.1 m/s, 1.4 s"; the shipped walk "shipped")."""
    speed, _, rest = label.partition(" (")
    return speed if speed == "shipped" else f"{speed}, {rest.split()[1]} s"


def servos_table(folder: Path) -> str:
    """Menagerie's OP3, as it is and changed, at each walk: the distance travelled, or when it fell."""
    chosen = walks()
    lines = ["| Menagerie's OP3 | " + " | ".join(_short(label) for label in chosen) + " |",
             "|---" * (len(chosen) + 1) + "|"]
    for i, (label, change) in enumerate(MENAGERIE_VARIANTS.items()):
        path = folder / f"menagerie{i}.xml"
        path.write_text(menagerie_variant(**change))
        cells = [outcome(walk("op3", cycle_s, step_m, "--sim-model", str(path), "--sim-map", str(MENAGERIE_MAP)))
                 for cycle_s, step_m in chosen.values()]
        lines.append(f"| {label} | " + " | ".join(cells) + " |")
    return "\n".join(lines)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--markdown", action="store_true", help="the figures of docs/walk-faster.md (tools/figures.py)")
    args = parser.parse_args(argv)
    with tempfile.TemporaryDirectory() as tmp:
        tables = {"fast-walk-steps": steps_table(), "fast-walk-settings": settings_table(Path(tmp)),
                  "fast-walk-servos": servos_table(Path(tmp))}
    for name, table in tables.items():
        if args.markdown:
            print(f"<!-- figure {name} -->\n{table}\n<!-- /figure -->")
        else:
            print(table + "\n")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
