"""Steered walks judged by physics: generated as ``gaitbot generate --robot op3`` makes them, played open loop
on the OP3 model by other authors (tools/op3_menagerie.py) and on gaitbot's own free-floating simulation.

For each walk: the command's end pose, the plan's, and the robot's (x, y in metres from the start, heading
in degrees, unwrapped); whether it fell; and the least gap between the soles from the Menagerie model's own
forward kinematics of the emitted angles (its box feet, projected on the floor: a conservative measure,
a swing foot above the other counts as touching). docs/steering.md shows the table; tests/sim/
test_steer_physics.py checks the bars (no fall, pose within 15% of the plan, plan within 25% of the command,
soles >= 5 mm apart).

    python tools/steer_judge.py [--robot op3] [--goals] [WALK ...] [--markdown]

With ``--markdown`` the table is printed as the docs' figure block (docs/figures.md): ``steer-judge``, or
``steer-judge-goals`` with ``--goals``.
"""

from __future__ import annotations

import argparse
import math
import os
import sys
import tempfile
from dataclasses import dataclass

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import op3_menagerie  # noqa: E402

SQUARE = "\n".join(
    line for k in range(4) for line in (
        f'{{"t": {k * 22.0:g}, "vx": 0.04, "vy": 0.0, "wz": 0.0}}',
        f'{{"t": {k * 22.0 + 12.5:g}, "vx": 0.0, "vy": 0.0, "wz": 0.0}}',
        f'{{"t": {k * 22.0 + 13.0:g}, "vx": 0.0, "vy": 0.0, "wz": 10.0}}',
    )) + '\n{"t": 88.0, "stop": true}\n'
"""A square of 0.5 m sides: 12.5 s at 0.04 m/s, a pause, a quarter turn at 10 deg/s (9 s), four times."""

WALKS = {
    "forward": ["--velocity", "0.04,0,0", "--duration", "10"],
    "turn360": ["--velocity", "0,0,10", "--duration", "36"],
    "side_left": ["--velocity", "0,0.03,0", "--duration", "10"],
    "side_right": ["--velocity=0,-0.03,0", "--duration", "10"],
    "backward": ["--velocity=-0.04,0,0", "--duration", "8"],
    "arc": ["--velocity", "0.04,0,8", "--duration", "15"],
    "square": ["--commands", "SQUARE"],
}


@dataclass
class Judged:
    name: str
    commanded: tuple
    planned: tuple
    actual: tuple
    fell: bool
    min_gap_m: float


def steered_args(robot: str, walk: list[str], commands_dir: str):
    from gaitbot.app.cli import build_parser

    walk = [os.path.join(commands_dir, "square.jsonl") if a == "SQUARE" else a for a in walk]
    return build_parser().parse_args(["generate", "--robot", robot, *walk, "-o", os.path.join(commands_dir, "w.csv")])


def plan_walk(robot: str, name: str, commands_dir: str):
    """(plan, trajectory) of a named walk, as gaitbot generate plans it."""
    from gaitbot.app.planned_walk import planned_walk

    with open(os.path.join(commands_dir, "square.jsonl"), "w") as f:
        f.write(SQUARE)
    walk = planned_walk(steered_args(robot, WALKS[name], commands_dir))
    return walk.plan, walk.planned


def menagerie_sole_gap_m(trajectory) -> float:
    """The least gap (m) between the left and right box feet of the Menagerie model posed kinematically at
    every frame's angles (its own joint axes and link frames), projected on the floor."""
    import mujoco
    from scipy.spatial import ConvexHull

    from gaitbot.gait.steer.soles import polygon_gap

    model = mujoco.MjModel.from_xml_string(op3_menagerie.menagerie_mjcf())
    data = mujoco.MjData(model)
    names = list(op3_menagerie.SIM_MAP.joints)  # every leg joint the map drives
    theirs = [op3_menagerie.their_joint(n) for n in names]
    qadr = np.array([model.joint(t).qposadr[0] for t, _ in theirs])
    signs = np.array([s for _, s in theirs], dtype=float)
    angles = trajectory.angles_of(names)
    feet = {side: [g for g in range(model.ngeom) if model.geom_bodyid[g] == model.body(f"{side}_ank_roll_link").id]
            for side in ("l", "r")}
    corners = np.array([[a, b, c] for a in (-1, 1) for b in (-1, 1) for c in (-1, 1)], dtype=float)
    gap = math.inf
    for k in range(0, len(angles), 2):
        data.qpos[3:7] = (1, 0, 0, 0)
        data.qpos[qadr] = signs * angles[k]
        mujoco.mj_kinematics(model, data)
        hulls = {}
        for side, geoms in feet.items():
            pts = np.concatenate([data.geom_xpos[g] + (corners * model.geom_size[g]) @ data.geom_xmat[g].reshape(3, 3).T
                                  for g in geoms])[:, :2]
            hull = ConvexHull(pts)
            hulls[side] = [tuple(pts[v]) for v in hull.vertices]  # counter-clockwise
        gap = min(gap, polygon_gap(hulls["l"], hulls["r"]))
    return gap


def gaitbot_stiffness(robot: str) -> float:
    """The leg servos' stiffness gaitbot writes (N m/rad; the same for every OP3 leg joint)."""
    from gaitbot.app.options import load_robot
    from gaitbot.robot.balanced_walk import servo_stiffness_nm_per_rad

    return float(np.mean(servo_stiffness_nm_per_rad(load_robot(robot))))


def judge(robot: str, name: str, goals: bool = False) -> Judged:
    from gaitbot.app.steer_walk import commanded_pose, planned_pose

    with tempfile.TemporaryDirectory() as tmp:
        plan, trajectory = plan_walk(robot, name, tmp)
    played = plan.walk.trajectory(goals=goals)
    r = op3_menagerie.play(played, plan.walker.rate_hz, kp_nm_per_rad=gaitbot_stiffness(robot))
    return Judged(name, commanded_pose(plan.schedule), planned_pose(plan), (r.final_x_m, r.final_y_m, r.heading_deg),
                  r.fell, menagerie_sole_gap_m(trajectory))


def play_own(robot: str, name: str) -> tuple[tuple, tuple, bool]:
    """(planned pose, simulated pose, fell) of a walk on gaitbot's own free-floating simulation, sent the
    goals at the stiffness gaitbot writes (as ``gaitbot walk --sim`` walks it)."""
    from gaitbot.app.options import load_robot
    from gaitbot.app.steer_walk import planned_pose
    from gaitbot.sim.metrics import WalkMeter
    from gaitbot.sim.physics import SimRobot
    from gaitbot.sim.walk import walk_plan

    with tempfile.TemporaryDirectory() as tmp:
        plan, _ = plan_walk(robot, name, tmp)
    return play_plan_own(robot, plan)


def play_plan_own(robot: str, plan) -> tuple[tuple, tuple, bool]:
    """play_own for a planned steered walk."""
    from gaitbot.app.options import load_robot
    from gaitbot.app.steer_walk import planned_pose
    from gaitbot.sim.metrics import WalkMeter
    from gaitbot.sim.physics import SimRobot
    from gaitbot.sim.walk import walk_plan

    config = load_robot(robot)
    rate = plan.walker.rate_hz
    goals = plan.walk.trajectory(goals=True)
    sim = SimRobot(config, rate, support="free")
    wp = walk_plan(plan, goals)
    sim.place(wp.start_angles_rad, wp.start_root_m)
    for i in range(len(sim.joint_names)):
        sim.set_full_torque_error(i, config.servo.full_torque_error_deg)
        sim.set_torque(i, True)
    meter = WalkMeter(sim, wp)
    sim.observers.append(meter)
    angles = goals.angles_of(sim.joint_names)
    for k in range(len(angles) + round(rate)):
        for i, angle in enumerate(angles[min(k, len(angles) - 1)]):
            sim.set_goal(i, float(angle))
        sim.advance_to((k + 1) / rate)
    r = meter.report(wp, False)
    return planned_pose(plan), (r.distance_travelled_m, r.lateral_drift_m + wp.lateral_m, r.heading_deg), r.fell


def row(j: Judged) -> str:
    def pose(p):
        return f"({p[0]:6.3f}, {p[1]:6.3f}, {p[2]:6.1f})"
    return (f"| {j.name} | {pose(j.commanded)} | {pose(j.planned)} | {pose(j.actual)} | {'yes' if j.fell else 'no'} | "
            f"{1000 * j.min_gap_m:.1f} |")


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("walks", nargs="*", help=f"walks to judge (default all: {', '.join(WALKS)})")
    p.add_argument("--robot", default="op3")
    p.add_argument("--goals", action="store_true", help="play the goals (sag feedforward) instead of the planned angles")
    p.add_argument("--markdown", action="store_true", help="print the table as the docs' figure block")
    args = p.parse_args(argv)
    if args.markdown:
        print(f"<!-- figure steer-judge{'-goals' if args.goals else ''} -->")
    print("| walk | commanded (x m, y m, heading deg) | planned | Menagerie OP3 | fell | least sole gap mm |")
    print("|---|---|---|---|---|---|")
    for name in args.walks or list(WALKS):
        print(row(judge(args.robot, name, args.goals)), flush=True)
    if args.markdown:
        print("<!-- /figure -->")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
