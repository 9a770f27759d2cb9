"""gaitbot's balanced walk beside Rhoban's PlaCo (docs/placo.md). Run: python tools/bench_placo.py

The same robot: the URDF ``gaitbot robot export op3 --urdf`` writes (PlaCo's HumanoidRobot reads its
``trunk``, ``left_foot`` and ``right_foot`` frames). The same footsteps and timing: gaitbot's footstep
planner turns each scenario's command into footholds (gaitbot.robot.steered_walk); PlaCo's
WalkPatternGenerator (its ZMP QP over a LIPM, https://github.com/Rhoban/placo) plans the CoM over those same
footholds (the sole frames under gaitbot's ankle points) with gaitbot's single and double support times,
CoM height and swing height, and its KinematicsSolver with WalkTasks follows that plan at 60 Hz (joint
velocity limits on, as its walk example does). The scenarios: a straight 2 m walk, a turn in place, a
sidestep.

Measured, each with one yardstick for both (gaitbot's, so that a difference is the walks' and not the
measures'): planning time (wall, this machine: gaitbot's whole offline plan per step and per frame;
PlaCo's WalkPatternGenerator.plan per step and its IK per frame); the smallest margin of the multibody ZMP
and of the CoM's ground point to the support polygon (gaitbot.check.balance on the joint angles each
sends: signed distance, positive inside); the peak joint velocity; and each trajectory played open loop
(goals held a frame) in gaitbot's free-floating simulation and on MuJoCo Menagerie's OP3
(tools/op3_menagerie.py): distance along the plan, drift off it, heading error, fall.

Fixed inputs, one thread for BLAS and OpenMP (set before numpy loads); timings vary from machine to machine
and run to run, the rest does not. ``--quick``: the scenarios shortened (used by the tests).
"""

from __future__ import annotations

import os

for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import argparse  # noqa: E402
import contextlib  # noqa: E402
import io  # noqa: E402
import math  # noqa: E402
import sys  # noqa: E402
import tempfile  # noqa: E402
import time  # noqa: E402
from dataclasses import dataclass  # noqa: E402
from pathlib import Path  # noqa: E402

import numpy as np  # noqa: E402

sys.path.insert(0, str(Path(__file__).resolve().parent))
import op3_menagerie  # noqa: E402

from gaitbot.check.balance import balance_trace, signed_distance  # noqa: E402
from gaitbot.check.preflight import robot_angles_deg  # noqa: E402
from gaitbot.gait.joints import LEG_JOINTS  # noqa: E402
from gaitbot.gait.steer.command import VelocityCommand  # noqa: E402
from gaitbot.gait.steer.schedule import CommandSchedule  # noqa: E402
from gaitbot.gait.trajectory import Trajectory  # noqa: E402
from gaitbot.robot.config import load_robot_config, resolve_config  # noqa: E402
from gaitbot.robot.steered_walk import footstep_planner, plan_steered, steering_timing  # noqa: E402

ROBOT = "op3"
RATE_HZ = 60.0
IK_SUBSTEPS = 4  # PlaCo's IK at 240 Hz (its walk example runs at 200 Hz), sampled at the 60 Hz frames
SETTLE_S = 1.0  # the simulations run on this long after the last frame
FALL_TILT_DEG = 45.0


@dataclass(frozen=True)
class Scenario:
    name: str
    command: VelocityCommand
    duration_s: float


def scenarios(config, quick: bool) -> list[Scenario]:
    """A straight 2 m walk, a turn in place (90 deg), a sidestep (0.2 m left), at the robot's [steer] limits."""
    step_s = footstep_planner(config).step_s
    limits = config.steer
    forward = VelocityCommand(limits.max_forward_m / step_s, 0.0, 0.0)
    turn = VelocityCommand(0.0, 0.0, limits.max_turn_deg / (2 * step_s))
    side = VelocityCommand(0.0, limits.max_side_m / (2 * step_s), 0.0)
    scale = 0.25 if quick else 1.0
    return [Scenario("straight 2 m", forward, scale * 2.0 / forward.vx_m_s),
            Scenario("turn in place 90 deg", turn, scale * 90.0 / turn.wz_deg_s),
            Scenario("sidestep 0.2 m", side, scale * 0.2 / side.vy_m_s)]


@dataclass
class Walk:
    """One planner's walk of a scenario: the goals it sends (Trajectory, LEG_JOINTS), the body pose it plans
    (for the balance yardstick), and its planning costs (ms)."""

    goals: Trajectory
    planned: Trajectory
    steps: int
    plan_ms_per_step: float
    ms_per_frame: float
    own_zmp_m: np.ndarray  # (n, 2) the ZMP the planner planned (gaitbot: multibody; PlaCo: its LIPM's)


def gaitbot_walk(config, scenario: Scenario) -> tuple[Walk, list, object]:
    schedule = CommandSchedule.steady(scenario.command, scenario.duration_s)
    start = time.perf_counter()
    plan, steps = plan_steered(config, schedule)
    total_ms = (time.perf_counter() - start) * 1e3
    walk = plan.walk
    rpy = None
    if walk.yaw_rad is not None:
        rpy = np.zeros((len(walk.t_s), 3))
        rpy[:, 2] = walk.torso_yaw_rad
    goals = Trajectory(walk.t_s, walk.goals_rad, walk.root_m, joints=LEG_JOINTS, torso_rpy_rad=rpy)
    planned = Trajectory(walk.t_s, walk.q_rad, walk.root_m, joints=LEG_JOINTS, torso_rpy_rad=rpy)
    walked = Walk(goals, planned, len(steps), total_ms / len(steps), total_ms / len(walk.t_s), walk.zmp_plan_m)
    return walked, steps, plan


def sole_frame(config, foothold) -> np.ndarray:
    """The 4x4 pose of a foot's sole frame (the URDF's left_foot/right_foot) over gaitbot's foothold."""
    g = config.body.geometry
    x, y = foothold.to_world(0.0, (1 if foothold.side == "left" else -1) * g.sole_outward_m)
    c, s = math.cos(foothold.yaw_rad), math.sin(foothold.yaw_rad)
    return np.array([[c, -s, 0, x], [s, c, 0, y], [0, 0, 1, 0], [0, 0, 0, 1.0]])


def placo_parameters(placo, config, plan):
    """PlaCo's walk parameters from gaitbot's: its timing, CoM height, swing height, feet."""
    g = config.body.geometry
    timing = steering_timing(config, plan.fit.gait)
    p = placo.HumanoidParameters()
    p.single_support_timesteps = 10
    p.single_support_duration = timing.ss_frames / timing.rate_hz
    p.double_support_ratio = timing.ds_frames / timing.ss_frames
    p.startend_double_support_ratio = 2.0
    p.planned_timesteps = 48
    walk = plan.walk
    p.walk_com_height = float(np.median(walk.com_m[:, 2]))
    p.walk_foot_height = float(walk.ankles_m[:, :, 2].max() - g.ankle_height_m)
    p.walk_trunk_pitch = 0.0
    p.walk_foot_rise_ratio = 0.2
    p.foot_length, p.foot_width = g.foot_m, g.foot_width_m
    p.feet_spacing = 2 * (g.hip_width_m / 2 + g.sole_outward_m)
    p.zmp_margin = 0.0
    p.walk_max_dtheta = math.radians(config.steer.max_turn_deg)
    p.walk_max_dy = config.steer.max_side_m
    p.walk_max_dx_forward = config.steer.max_forward_m
    p.walk_max_dx_backward = config.steer.max_backward_m
    return p


def placo_walk(placo, urdf: Path, config, steps, plan) -> Walk:
    robot = placo.HumanoidRobot(str(urdf))
    p = placo_parameters(placo, config, plan)
    solver = placo.KinematicsSolver(robot)
    solver.enable_velocity_limits(True)
    solver.dt = 1.0 / (RATE_HZ * IK_SUBSTEPS)
    tasks = placo.WalkTasks()
    tasks.initialize_tasks(solver, robot)
    start_feet = footstep_planner(config).feet
    # reach_initial_pose takes the left sole's frame; the right one is feet_spacing to its right
    tasks.reach_initial_pose(sole_frame(config, start_feet["left"]), p.feet_spacing, p.walk_com_height,
                             p.walk_trunk_pitch)
    for side in ("right", "left"):  # the support frame where the feet now stand (it starts at the origin)
        robot.update_support_side(side)
    footsteps = placo.Footsteps()
    for foothold in [start_feet[steps[0].foothold.side], start_feet[_other(steps[0].foothold.side)]] + \
            [s.foothold for s in steps]:
        f = placo.Footstep(p.foot_width, p.foot_length)
        f.side = getattr(placo.HumanoidRobot_Side, foothold.side)
        f.frame = sole_frame(config, foothold)
        footsteps.append(f)
    supports = placo.FootstepsPlanner.make_supports(footsteps, 0.0, True, p.has_double_support(), True)
    generator = placo.WalkPatternGenerator(robot, p)
    start = time.perf_counter()
    trajectory = generator.plan(supports, robot.com_world(), 0.0)
    plan_ms = (time.perf_counter() - start) * 1e3
    n = int(math.floor((trajectory.t_end - trajectory.t_start) * RATE_HZ)) + 1
    q, root, yaw, ik_s = np.empty((n, 12)), np.empty((n, 3)), np.empty(n), 0.0
    omega = placo.LIPM.compute_omega(p.walk_com_height)
    own_zmp = np.array([trajectory.get_p_world_ZMP(trajectory.t_start + k / RATE_HZ, omega) for k in range(n)])
    for k in range(n):
        start = time.perf_counter()
        for i in range(IK_SUBSTEPS if k else 1):
            t = trajectory.t_start + (k - 1 + (i + 1) / IK_SUBSTEPS) / RATE_HZ if k else trajectory.t_start
            tasks.update_tasks_from_trajectory(trajectory, t)
            robot.update_kinematics()
            solver.solve(True)
            if not trajectory.support_is_both(t):
                robot.update_support_side(str(trajectory.support_side(t)))
                robot.ensure_on_floor()
        ik_s += time.perf_counter() - start
        q[k] = [robot.get_joint(name) for name in LEG_JOINTS]
        base = robot.get_T_world_frame("base_link")
        root[k] = base[:3, 3]
        yaw[k] = math.atan2(base[1, 0], base[0, 0])
    rpy = np.zeros((n, 3))
    rpy[:, 2] = np.unwrap(yaw)
    goals = Trajectory(np.arange(n) / RATE_HZ, q, root, joints=LEG_JOINTS, torso_rpy_rad=rpy)
    return Walk(goals, goals, len(steps), plan_ms / len(steps), ik_s * 1e3 / n, own_zmp)


def _other(side: str) -> str:
    return "right" if side == "left" else "left"


def margins(config, walk: Walk) -> tuple[float, float, float, float]:
    """Signed distances to the support polygon (m, positive inside) over the walk: the smallest of the
    planner's own ZMP, the smallest and the 5th percentile of the multibody ZMP of the angles sent, and the
    smallest of the CoM's ground point (the polygon: the soles on the floor in the angles' kinematics)."""
    trace = balance_trace(config, walk.planned, robot_angles_deg(config, walk.planned))
    n = len(trace.support)
    com = min(signed_distance(trace.com_m[k, :2], trace.support[k]) for k in range(n))
    own = min(signed_distance(walk.own_zmp_m[k], trace.support[k]) for k in range(min(n, len(walk.own_zmp_m))))
    return float(own), float(trace.margin_m.min()), float(np.percentile(trace.margin_m, 5)), float(com)


def peak_velocity_dps(walk: Walk) -> float:
    return float(np.degrees(np.abs(np.diff(walk.goals.angles_rad, axis=0)).max() * RATE_HZ))


def planned_motion(walk: Walk) -> tuple[float, float, float]:
    """The plan's pelvis displacement (forward, left m, in the start's frame) and turn (deg)."""
    d = walk.planned.root_m[-1, :2] - walk.planned.root_m[0, :2]
    rpy = walk.planned.torso_rpy_rad
    turn = 0.0 if rpy is None else float(rpy[-1, 2] - rpy[0, 2])
    return float(d[0]), float(d[1]), math.degrees(turn)


def play_gaitbot_sim(config, walk: Walk) -> tuple[float, float, float, bool]:
    """Open loop in gaitbot's free-floating simulation: (x, y m, heading deg) moved, fell."""
    from gaitbot.sim.physics import SimRobot

    robot = SimRobot(config, RATE_HZ, support="free")
    goals = walk.goals.angles_of(robot.joint_names)
    robot.place(dict(zip(robot.joint_names, (float(a) for a in goals[0]))), tuple(walk.goals.root_m[0]))
    for i in range(len(robot.joint_names)):
        robot.set_torque(i, True)
    start, yaw0 = robot.torso_xyz_m(), float(robot.torso_rpy_rad()[2])
    yaws, fell = [yaw0], False
    for k in range(len(goals) + round(SETTLE_S * RATE_HZ)):
        for i, angle in enumerate(goals[min(k, len(goals) - 1)]):
            robot.set_goal(i, float(angle))
        robot.advance_to((k + 1) / RATE_HZ)
        roll, pitch, yaw = robot.torso_rpy_rad()
        yaws.append(float(yaw))
        if math.degrees(math.acos(math.cos(roll) * math.cos(pitch))) > FALL_TILT_DEG or \
                robot.torso_xyz_m()[2] < 0.5 * start[2]:
            fell = True
            break
    d = robot.torso_xyz_m() - start
    return float(d[0]), float(d[1]), math.degrees(np.unwrap(yaws)[-1] - yaw0), fell


def play_menagerie(walk: Walk) -> tuple[float, float, float, bool]:
    r = op3_menagerie.play(walk.goals, RATE_HZ)
    return r.final_x_m, r.final_y_m, r.heading_deg, r.fell


def row(config, who: str, scenario: Scenario, walk: Walk) -> dict:
    own, zmp, zmp5, com = margins(config, walk)
    plan = planned_motion(walk)
    out = {"scenario": scenario.name, "who": who, "steps": walk.steps, "plan_ms_per_step": walk.plan_ms_per_step,
           "ms_per_frame": walk.ms_per_frame, "own_zmp_mm": own * 1e3, "zmp_margin_mm": zmp * 1e3,
           "zmp_p5_mm": zmp5 * 1e3, "com_margin_mm": com * 1e3,
           "peak_dps": peak_velocity_dps(walk), "planned": plan}
    for sim, play in (("ours", lambda: play_gaitbot_sim(config, walk)), ("menagerie", lambda: play_menagerie(walk))):
        x, y, heading, fell = play()
        out[sim] = (x, y, heading, fell)
    return out


def sim_cell(plan, result) -> str:
    x, y, heading, fell = result
    if fell:
        return "FELL"
    px, py, pturn = plan
    if abs(pturn) > 10:
        return f"{heading:.0f}/{pturn:.0f} deg, drift {math.hypot(x, y) * 1e3:.0f} mm"
    along = (x * px + y * py) / max(1e-9, math.hypot(px, py))
    across = (-x * py + y * px) / max(1e-9, math.hypot(px, py))
    return f"{along:.2f}/{math.hypot(px, py):.2f} m, drift {across * 1e3:+.0f} mm, {heading:+.1f} deg"


def print_table(rows: list[dict]) -> None:
    print("| scenario | planner | steps | plan ms/step | ms/frame | planned ZMP margin mm | angles' ZMP margin mm "
          "min (p5) | CoM margin mm | peak deg/s | gaitbot sim | Menagerie OP3 |")
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    for r in rows:
        print(f"| {r['scenario']} | {r['who']} | {r['steps']} | {r['plan_ms_per_step']:.1f} | {r['ms_per_frame']:.2f} "
              f"| {r['own_zmp_mm']:.1f} | {r['zmp_margin_mm']:.1f} ({r['zmp_p5_mm']:.1f}) | {r['com_margin_mm']:.1f} "
              f"| {r['peak_dps']:.0f} "
              f"| {sim_cell(r['planned'], r['ours'])} | {sim_cell(r['planned'], r['menagerie'])} |")


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="each scenario a quarter as long")
    args = parser.parse_args(argv)
    try:
        import placo
    except ImportError:
        print("bench_placo: needs pip install 'gaitbot[bench]' (placo)", file=sys.stderr)
        return 2
    from gaitbot.app.cli import main as gaitbot_main

    config = load_robot_config(resolve_config(ROBOT))
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        urdf = Path(tmp) / "op3.urdf"
        with contextlib.redirect_stdout(io.StringIO()):
            gaitbot_main(["robot", "export", ROBOT, "--urdf", str(urdf)])
        plan_steered(config, CommandSchedule.steady(VelocityCommand(0.01, 0.0, 0.0), 1.0))  # warm caches
        for scenario in scenarios(config, args.quick):
            ours, steps, plan = gaitbot_walk(config, scenario)
            rows.append(row(config, "gaitbot", scenario, ours))
            rows.append(row(config, "PlaCo", scenario, placo_walk(placo, urdf, config, steps, plan)))
    print(f"{ROBOT}, {RATE_HZ:g} Hz; margins by gaitbot.check.balance; sims open loop, {SETTLE_S:g} s settle")
    print_table(rows)
    return 0


if __name__ == "__main__":
    sys.exit(main())
