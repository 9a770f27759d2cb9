"""The balanced op3 walk on robots that differ from the one it was planned for: the robustness table.

    python tools/robustness.py            # the whole table (docs/balance-robustness.md quotes it), about 2 minutes
    python tools/robustness.py --quick    # the subset tests/sim/test_sim_balance.py runs
    python tools/robustness.py --json     # one JSON object per row
    python tools/robustness.py --robot bioloid   # the same for the BIOLOID Type A (its own walks, no Menagerie)

Every walk is planned once, from the shipped config/op3.toml, exactly as ``gaitbot generate`` plans it
(gaitbot.app.planned_walk), then played open loop, each frame's goals held 1/60 s, on:
- our model (gaitbot.sim, free-floating) with the servos at the gain gaitbot writes (6 deg) and the goals
  with sag feedforward, or at the factory gain (12.4 deg) with the plain planned angles;
- our model built from a config whose masses, or every link's centre of mass distance from its joint
  (the "CoM heights"), are off by 20%, or on a floor of friction 0.6;
- servo stiffness from the factory gain to ours, with the feedforward computed for ours;
- MuJoCo Menagerie's OP3 (tools/op3_menagerie.py: other authors' masses, axes and soft servos) with the
  plain planned angles: what a user playing ``gaitbot generate`` output on another model sends it;
- a 0.7 N s sideways push in the middle of a step half-way through the walk (both ways).
Pass: the balanced walk's targets (no fall, travelled within 10% of the plan, lateral drift under 5 cm, yaw
under 5 deg, torso roll and pitch RMS under 2 deg); for pushes, no fall. Goals here are floats (the
CLI's walk --sim sends them as servo ticks through the bus: figures differ in the last digit).
Exit status 1 if any row fails.

``--robot bioloid`` (config/bioloid.toml, ROBOTIS BIOLOID Premium Type A, 12 AX-12A): the same rows with
its own walks (BIOLOID_WALKS: steps scaled by its leg, 0.7 of the op3's), servos at the compliance slope
gaitbot writes and at the factory slope 32 (9.4 deg), the stiffness rows at the slopes in between, and
pushes of 0.34 N s (the op3's 0.7 N s scaled by mass: the same velocity change); there is no other
author's model of it to play (no Menagerie rows).
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from dataclasses import dataclass, replace
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

import op3_menagerie  # noqa: E402

from gaitbot.app.planned_walk import planned_walk  # noqa: E402
from gaitbot.robot.config import load_robot_config, resolve_config  # noqa: E402
from gaitbot.sim import import_mujoco  # noqa: E402

RATE_HZ = 60.0
WRITTEN_DEG = 6.0
FACTORY_DEG = 885 * 128 * 360 / 4096 / 800  # XM430-W350 Position P Gain 800 (gaitbot.servos.models): 12.4 deg
WALKS = {
    "2 m": ["--distance", "2"],
    "2 m varied (4 +- 1 cm)": ["--distance", "2", "--max-step", "0.04", "--perturb", "0.01", "--seed", "1"],
    "2 m asymmetric 5/3 cm": ["--steps", ",".join(["0.05,0.03"] * 25)],
    "0.2 m/s (cycle 0.8, 8 cm)": ["--distance", "2", "--cycle", "0.8", "--max-step", "0.08"],
}
#: The bioloid's walks: the op3's scaled by leg length (0.149 / 0.220 m, about 0.7): varied 3 +- 0.7 cm,
#: asymmetric 3.5 / 2 cm (its max_step_m and 0.6 of it, as the op3's 5 / 3 cm), and its fastest walk
#: that meets the targets (docs/balance-robustness.md, "The bioloid").
BIOLOID_WALKS = {
    "2 m": ["--distance", "2"],
    "2 m varied (3 +- 0.7 cm)": ["--distance", "2", "--max-step", "0.03", "--perturb", "0.007", "--seed", "1"],
    "2 m asymmetric 3.5/2 cm": ["--steps", ",".join(["0.035,0.02"] * 36)],
    "0.125 m/s (cycle 0.8, 5 cm)": ["--distance", "2", "--cycle", "0.8", "--max-step", "0.05"],
}
AX_SLOPE_DEG = 300 / 1023  # AX-12A compliance slope unit (gaitbot.servos.models): slope 32 = 9.38 deg


@dataclass(frozen=True)
class RobotRows:
    """What the table plays for one robot: its walks, the stiffness gaitbot writes and the factory's, the
    stiffness rows' errors, the push impulses (N s) and whether Menagerie's model of it exists."""

    walks: dict
    written_deg: float
    factory_deg: float
    stiffness_deg: tuple
    push_n_s: float
    menagerie: bool


def robot_rows(robot: str) -> RobotRows:
    if robot == "op3":
        return RobotRows(WALKS, WRITTEN_DEG, FACTORY_DEG, (8.0, 10.0, FACTORY_DEG), 0.7, True)
    if robot == "bioloid":
        from gaitbot.robot.balanced_walk import full_torque_error_deg

        config = load_robot_config(resolve_config("bioloid"))
        written = full_torque_error_deg(config, "knee_pitch_left")  # the slope step the register obtains
        stiffness = tuple(s * AX_SLOPE_DEG for s in (4, 8, 16, 32) if s * AX_SLOPE_DEG > written * 1.01)
        return RobotRows(BIOLOID_WALKS, written, 32 * AX_SLOPE_DEG, stiffness, 0.34, False)
    raise SystemExit(f"robustness.py: no table for robot {robot!r} (op3, bioloid)")


def plan_arguments(args: list[str], robot: str = "op3") -> argparse.Namespace:
    """``gaitbot generate``'s options for ``args`` (e.g. ["--distance", "2"]), as its parser leaves them."""
    parsed = argparse.Namespace(robot=robot, steps=None, distance=None, max_step=None, perturb=0.0, seed=None,
                                cycle=None, rate=None, clearance=None, thigh=None, shank=None, foot=None,
                                terrain=None, trajectory=None, calibration=None)
    i = 0
    while i < len(args):
        key = args[i][2:].replace("-", "_")
        value = args[i + 1]
        setattr(parsed, key, value if key == "steps" else (int(value) if key == "seed" else float(value)))
        i += 2
    return parsed


def plan(args: list[str], robot: str = "op3"):
    walk = planned_walk(plan_arguments(args, robot=robot))
    return walk.plan, walk.planned, walk.goals


def perturbed(config, kind: str):
    """The config the simulated robot is built from, off from the one the walk was planned with."""
    links = dict(config.links)
    if kind.startswith("mass"):
        factor = 1.2 if "+" in kind else 0.8
        links = {k: v.scaled(mass_factor=factor) for k, v in links.items()}
    elif kind.startswith("CoM"):
        factor = 1.2 if "+" in kind else 0.8
        links = {k: v.scaled(com_factor=factor) for k, v in links.items()}
    return replace(config, links=tuple(links.items()))


def play_ours(config, walker, planned, trajectory, error_deg: float, friction: float = 1.0, push_n_s: float = 0.0):
    """Our simulated robot (gaitbot.sim, free-floating) walking ``trajectory`` open loop; its SimReport."""
    from gaitbot.sim.metrics import WalkMeter
    from gaitbot.sim.physics import SimRobot
    from gaitbot.sim.walk import Pusher, mid_walk_push, walk_plan

    robot = SimRobot(config, RATE_HZ, support="free")
    robot.model.geom_friction[:, 0] = friction
    wp = walk_plan(walker, planned)
    robot.place(wp.start_angles_rad, wp.start_root_m)
    for i in range(len(robot.joint_names)):
        robot.set_full_torque_error(i, error_deg)
        robot.set_torque(i, True)
    meter = WalkMeter(robot, wp)
    robot.observers.append(meter)
    push = None
    if push_n_s:
        push = mid_walk_push(wp, push_n_s)
        robot.observers.append(Pusher(push, robot.frame_s))
    goals = trajectory.angles_of(robot.joint_names)
    frames = len(goals) + round(1.0 * RATE_HZ)
    for k in range(frames):
        for i, angle in enumerate(goals[min(k, len(goals) - 1)]):
            robot.set_goal(i, float(angle))
        robot.advance_to((k + 1) / RATE_HZ)
    r = meter.report(wp, False, push.to_dict() if push else None)
    return dict(fell=r.fell, fell_at_s=r.fell_at_s, fall_direction=r.fall_direction, travel=r.travel_share,
                drift_m=r.lateral_drift_m, yaw_deg=r.max_abs_yaw_deg, roll_rms_deg=r.torso_roll_rms_deg,
                pitch_rms_deg=r.torso_pitch_rms_deg)


def play_menagerie(walker, planned, friction: float = 1.0, push_n_s: float = 0.0):
    from gaitbot.sim.walk import mid_walk_push, walk_plan

    push_at = mid_walk_push(walk_plan(walker, planned), push_n_s).start_s if push_n_s else 0.0
    r = op3_menagerie.play(planned, RATE_HZ, friction, push_n_s, push_at)
    return dict(fell=r.fell, fell_at_s=r.fell_at_s, fall_direction=r.fall_direction,
                travel=r.distance_travelled_m / r.distance_planned_m, drift_m=r.lateral_drift_m,
                yaw_deg=r.max_abs_yaw_deg, roll_rms_deg=r.torso_roll_rms_deg, pitch_rms_deg=r.torso_pitch_rms_deg)


def passes(row: dict) -> bool:
    if row["push"]:
        return not row["fell"]
    return (not row["fell"] and abs(row["travel"] - 1.0) <= 0.10 and abs(row["drift_m"]) < 0.05
            and row["yaw_deg"] < 5.0 and row["roll_rms_deg"] < 2.0 and row["pitch_rms_deg"] < 2.0)


def rows(quick: bool, robot_name: str = "op3"):
    """(group, walk, robot, push N s, thunk) for every row of the table."""
    spec = robot_rows(robot_name)
    written, factory = spec.written_deg, spec.factory_deg
    config = load_robot_config(resolve_config(robot_name))
    plans = {name: plan(args, robot_name) for name, args in spec.walks.items()}
    ours_ff = (f"ours, gain written ({written:.3g} deg) + sag feedforward",
               lambda w, p, g, **kw: play_ours(config, w, p, g, written, **kw), True)
    ours_factory = (f"ours, factory gain ({factory:.3g} deg), plain angles",
                    lambda w, p, g, **kw: play_ours(config, w, p, p, factory, **kw), False)
    menagerie = ("Menagerie OP3, plain angles", lambda w, p, g, **kw: play_menagerie(w, p, **kw), False)
    players = (ours_ff, ours_factory, menagerie) if spec.menagerie else (ours_ff, ours_factory)
    out = []
    walks = ["2 m"] if quick else list(spec.walks)
    for walk in walks:
        for robot, play, _ in players:
            out.append(("walks", walk, robot, 0.0, lambda play=play, walk=walk: play(*plans[walk])))
    errors = ["mass +20%", "CoM heights -20%", "friction 0.6"] if quick else \
        ["mass +20%", "mass -20%", "CoM heights +20%", "CoM heights -20%", "friction 0.6"]
    for kind in errors:
        for error_deg, label, goals in ((written, ours_ff[0], True), (factory, ours_factory[0], False)):
            if quick and kind != "friction 0.6" and goals != (kind == "mass +20%"):
                continue

            def thunk(kind=kind, error_deg=error_deg, goals=goals):
                w, p, g = plans["2 m"]
                if kind.startswith("friction"):
                    return play_ours(config, w, p, g if goals else p, error_deg, friction=0.6)
                return play_ours(perturbed(config, kind), w, p, g if goals else p, error_deg)
            out.append(("model errors (2 m)", kind, label, 0.0, thunk))
    if not quick:
        if spec.menagerie:
            out.append(("model errors (2 m)", "friction 0.6", menagerie[0], 0.0,
                        lambda: play_menagerie(*plans["2 m"][:2], friction=0.6)))
        for error_deg in spec.stiffness_deg:
            out.append(("stiffness (2 m)", f"servos at {error_deg:.3g} deg", f"ours + sag feedforward for {written:.3g} deg",
                        0.0, lambda e=error_deg: play_ours(config, *plans["2 m"], e)))
    pushes = (spec.push_n_s,) if quick else (spec.push_n_s, -spec.push_n_s)
    for impulse in pushes:
        for robot, play, _ in (players[:1] if quick else players):
            out.append(("push mid-step (2 m)", f"{impulse:+.2g} N s", robot, impulse,
                        lambda play=play, impulse=impulse: play(*plans["2 m"], push_n_s=impulse)))
    return out


HEADER = ("| group | walk / error | robot | pass | fell | travelled | drift cm | max yaw deg | roll RMS deg | "
          "pitch RMS deg |\n|---|---|---|---|---|---|---|---|---|---|")


def table_row(row: dict) -> str:
    """One row of the table; a walk that fell shows its fall alone (a tumbling body's figures are chaotic)."""
    head = f"| {row['group']} | {row['walk']} | {row['robot']} | {'yes' if row['pass'] else '**no**'} | "
    if row["fell"]:
        return head + f"{row['fell_at_s']:.1f} s {row['fall_direction']} | - | - | - | - | - |"
    return head + (f"- | {100 * row['travel']:.0f}% | {100 * row['drift_m']:+.1f} | {row['yaw_deg']:.1f} | "
                   f"{row['roll_rms_deg']:.2f} | {row['pitch_rms_deg']:.2f} |")


def measure(quick: bool, robot_name: str, on_row=None) -> list[dict]:
    results = []
    for group, walk, robot, push, thunk in rows(quick, robot_name):
        row = dict(group=group, walk=walk, robot=robot, push=push, **thunk())
        row["pass"] = passes(row)
        results.append(row)
        if on_row is not None:
            on_row(row)
    return results


def summary(results: list[dict]) -> str:
    return f"{sum(r['pass'] for r in results)}/{len(results)} pass, {sum(r['fell'] for r in results)} falls."


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="the subset the tests run")
    parser.add_argument("--json", action="store_true", help="one JSON object per row")
    parser.add_argument("--robot", default="op3", choices=("op3", "bioloid"), help="whose table (default op3)")
    parser.add_argument("--markdown", action="store_true",
                        help="both robots' whole tables as the figures of docs/balance-robustness.md (tools/figures.py)")
    args = parser.parse_args(argv)
    import_mujoco()
    if args.markdown:
        for name in ("op3", "bioloid"):
            results = measure(False, name)
            body = "\n".join([HEADER, *map(table_row, results), "", summary(results)])
            print(f"<!-- figure robustness-{name} -->\n{body}\n<!-- /figure -->")
        return 0
    start = time.perf_counter()
    if not args.json:
        print(HEADER)
    results = measure(args.quick, args.robot, lambda row: print(json.dumps(row) if args.json else table_row(row),
                                                                  flush=True))
    if not args.json:
        print(f"\n{summary(results)} {time.perf_counter() - start:.0f} s.")
    return 0 if all(r["pass"] for r in results) else 1


if __name__ == "__main__":
    sys.exit(main())
