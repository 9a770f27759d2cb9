"""Eigen-gait figures of a robot whose legs roll (op3): fit on its balanced walks, synthesise, compare, check.

    python tools/bench_eigen3d.py [--robot op3] [--steps-per-walk 8]
    python tools/bench_eigen3d.py --markdown      # the figures of docs/eigen-gaits.md (tools/figures.py)

Runs what a user runs, in a temporary folder: ``gaitbot generate --robot op3`` at the training step lengths,
``gaitbot eigen fit``, ``gaitbot eigen synth`` at every step length from the shortest to the longest
(the training ones and those between them) and ``gaitbot check`` on each synthesised walk. Each
synthesised walk's middle cycle (left heel strike to left heel strike) is compared frame by frame with the
balanced walker's own steady cycle at that step length (the middle cycle of a 10-step walk, computed apart
from the model): the largest error of each joint kind (degrees, both legs), the root's largest error in y
(sideways sway) and z (height), and in x relative to the cycle's start (millimetres). Also the balance
check's closest ZMP margin (mm inside the support polygon) of the synthesised walk and of the walker's own
walk of the same steps, and how far the root from contact lies from the examples' own root on their own
angles (the contact rule's error, before any learning). Then the forced-pose example: the pose the walker
takes POSE_TIME_S after a left heel strike at POSE_FROM_M (not an example), forced on a POSE_ON_M walk
through ``gaitbot eigen synth --pose-deg`` with the fewest eigen-motions that reach it, checked. Last,
what the choices of docs/eigen-gaits.md are worth: the same walk joined to the walker's start and stop
with only angle and velocity continuous (the planar robots' joins), and how far each shipped robot's walk
stands from where every other shipped robot's legs put it (``eigen fit``'s one-robot rule).
"""

from __future__ import annotations

import argparse
import contextlib
import io
import re
import sys
import tempfile
from dataclasses import dataclass
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from gaitbot.app.cli import main as gaitbot  # noqa: E402
from gaitbot.app.options import load_robot  # noqa: E402
from gaitbot.app.progress import progress  # noqa: E402
from gaitbot.check.balance import balance_trace  # noqa: E402
from gaitbot.check.preflight import preflight, robot_angles_deg  # noqa: E402
from gaitbot.gait.eigen import EigenGaitModel  # noqa: E402
from gaitbot.gait.footfall3d import root_from_contact_3d  # noqa: E402
from gaitbot.gait.joints import LEG_JOINT_KINDS, LEG_JOINTS  # noqa: E402
from gaitbot.gait.trajectory import Trajectory  # noqa: E402
from gaitbot.robot.balanced_walk import plan_balanced  # noqa: E402

TRAIN_M = (0.03, 0.04, 0.05)
BETWEEN_M = (0.035, 0.045)
REFERENCE_STEPS = 10  # the walker's walk whose middle cycle is the truth at a step length
SYNTH_CYCLES = 3
POSE_FROM_M, POSE_TIME_S, POSE_ON_M = 0.045, 0.6, 0.04  # the forced-pose example of docs/eigen-gaits.md


@dataclass
class Row:
    step_m: float
    trained: bool
    joint_error_deg: dict  # joint kind -> largest |error| over both legs and the cycle
    root_error_mm: tuple  # (x from the cycle's start, y, z) largest |error|
    mean_step_m: float  # mean of the synthesised walk's steps between heel strikes inside its cycles
    cycle_margin_mm: float  # the closest ZMP margin inside the synthesised walk's middle cycle
    margin_mm: float  # the balance check's closest ZMP margin on the whole synthesised walk (negative: outside)
    near_join: bool  # that closest margin lies within a step of a join with the walker's start or stop
    walker_margin_mm: float  # the same on the walker's own walk of the same steps
    check_exit: int


def run(*argv) -> tuple[int, str]:
    out = io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(io.StringIO()):
        code = gaitbot([str(a) for a in argv])
    return code, out.getvalue()


def left_strike_frames(trajectory: Trajectory) -> list[int]:
    return [int(round(h.t_s * 60)) for h in trajectory.heel_strikes if h.leg == "left"]


def steady_cycle(config, step_m: float):
    """The walker's middle cycle of a REFERENCE_STEPS walk: (angles (n, 12), root (n, 3)), and the walk."""
    walk = plan_balanced(config, [step_m] * REFERENCE_STEPS).walk.trajectory()
    lefts = left_strike_frames(walk)
    a, b = lefts[len(lefts) // 2 - 1], lefts[len(lefts) // 2]
    return walk.angles_rad[a:b], walk.root_m[a:b]


def middle_cycle(synth: Trajectory, rate_hz: float) -> tuple[int, int]:
    """Frames of the synthesised walk's middle cycle: its cycles start at the body's left heel strikes (the
    head has none, the tail's closing step is a right one)."""
    lefts = [int(round(h.t_s * rate_hz)) for h in synth.heel_strikes if h.leg == "left"]
    return lefts[SYNTH_CYCLES // 2], lefts[SYNTH_CYCLES // 2 + 1]


def compare(config, synth: Trajectory, step_m: float, rate_hz: float):
    """Largest errors of the synthesised walk's middle cycle against the walker's steady cycle."""
    q_ref, root_ref = steady_cycle(config, step_m)
    a, _ = middle_cycle(synth, rate_hz)
    n = len(q_ref)
    q, root = synth.angles_rad[a:a + n], synth.root_m[a:a + n]
    error = np.degrees(np.abs(q - q_ref))
    by_kind = {kind: float(max(error[:, LEG_JOINTS.index(f"{kind}_{side}")].max() for side in ("left", "right")))
               for kind in LEG_JOINT_KINDS}
    rel = (root[:, 0] - root[0, 0]) - (root_ref[:, 0] - root_ref[0, 0])
    root_mm = (1000 * float(np.abs(rel).max()), 1000 * float(np.abs(root[:, 1] - root_ref[:, 1]).max()),
               1000 * float(np.abs(root[:, 2] - root_ref[:, 2]).max()))
    return by_kind, root_mm


def margin_mm(config, trajectory: Trajectory) -> float:
    return float(preflight(config, trajectory).balance.closest_margin_mm)


def closest_near_join(config, synth: Trajectory, rate_hz: float) -> bool:
    """Whether the whole walk's closest ZMP margin lies within a step (half a cycle) of a join: the first and
    the last synthesised left heel strike."""
    lefts = [h.t_s for h in synth.heel_strikes if h.leg == "left"]
    t = preflight(config, synth).balance.closest_t_s
    return min(abs(t - lefts[0]), abs(t - lefts[SYNTH_CYCLES])) <= 0.5 * config.gait.cycle_s


def cycle_margin_mm(config, synth: Trajectory, rate_hz: float) -> float:
    a, b = middle_cycle(synth, rate_hz)
    trace = balance_trace(config, synth, robot_angles_deg(config, synth))
    return 1000 * float(trace.margin_m[a:b].min())


def contact_rule_error_mm(config, paths) -> float:
    """Largest distance (any axis) between the examples' own root and the root from contact of their angles."""
    worst = 0.0
    for path in paths:
        tr = Trajectory.load(path)
        root, _ = root_from_contact_3d(config.body.geometry, tr.angles_rad, tr.root_m[0, :2])
        worst = max(worst, 1000 * float(np.abs(root - tr.root_m).max()))
    return worst


def measure(robot: str, steps_per_walk: int, folder: Path, bar, fit_options=()) -> tuple[list, dict]:
    config = load_robot(robot)
    paths = []
    for step in TRAIN_M:
        path = folder / f"{robot}_ex_{step}.npz"
        code, _ = run("generate", "--robot", robot, "--steps", ",".join([str(step)] * steps_per_walk), "-o", path)
        assert code == 0, f"generate {step}"
        paths.append(path)
    model_path = folder / f"{robot}_model.npz"  # the names of docs/eigen-gaits.md
    code, out = run("eigen", "fit", *paths, "--robot", robot, "-o", model_path, *fit_options)
    assert code == 0, out
    model = EigenGaitModel.load(model_path)
    bar.update(1)
    rows = []
    for step in sorted(TRAIN_M + BETWEEN_M):
        csv = folder / f"synth_{step}.npz"
        code, out = run("eigen", "synth", model_path, "--step-length", step, "--cycles", SYNTH_CYCLES, "-o", csv)
        assert code in (0, 1), out
        synth = Trajectory.load(csv)
        check_exit, _ = run("check", "--robot", robot, csv)
        by_kind, root_mm = compare(config, synth, step, model.rate_hz)
        listed = [float(v) for v in re.search(r"heel strikes ([-\d., ]+) m", out).group(1).split(",")]
        walker = plan_balanced(config, [step] * (2 + 2 * SYNTH_CYCLES)).walk.trajectory()
        rows.append(Row(step, step in TRAIN_M, by_kind, root_mm, float(np.mean(listed[2:-2])),
                        cycle_margin_mm(config, synth, model.rate_hz), margin_mm(config, synth),
                        closest_near_join(config, synth, model.rate_hz),
                        margin_mm(config, walker), check_exit))
        bar.update(1)
    pose = forced_pose(config, model_path, folder)
    with contextlib.redirect_stderr(io.StringIO()):
        others = other_robots_mm()
    bar.update(1)
    info = {"pose": pose, "first_order_mm": first_order_join_mm(robot, model_path, TRAIN_M[1]),
            "others_mm": others, "cycles": len(model.labels), "pose_dims": model.pose_dims,
            "components": model.n_components,
            "variance": float(model.variance_explained[:model.n_components].sum()),
            "contact_mm": contact_rule_error_mm(config, paths), "robot": config.name}
    return rows, info


def forced_pose(config, model_path: Path, folder: Path) -> dict:
    """The forced-pose example: the command, how closely the pose is reached, the steps it brings, the check."""
    walk = plan_balanced(config, [POSE_FROM_M] * REFERENCE_STEPS).walk.trajectory()
    lefts = left_strike_frames(walk)
    k = lefts[len(lefts) // 2] + round(POSE_TIME_S * 60)
    pose = ",".join(f"{v + 0.0:.1f}" for v in walk.angles_deg[k])
    model = EigenGaitModel.load(model_path)
    out_path = folder / f"{config.name}_posed.npz"
    for components in range(1, len(model.eigenvalues) + 1):
        argv = ["eigen", "synth", model_path.name, "--step-length", str(POSE_ON_M), "--components", str(components),
                f"--pose-deg={pose}", "--pose-time", str(POSE_TIME_S), "-o", f"{config.name}_posed.csv"]
        code, out = run(*argv[:2], model_path, *argv[3:-1], out_path)
        if code in (0, 1):
            break
    reached = re.search(r"pose reached to ([\d.e-]+) deg", out).group(1)
    listed = [float(v) for v in re.search(r"heel strikes ([-\d., ]+) m", out).group(1).split(",")]
    check, _ = run("check", "--robot", config.name, out_path)
    return {"argv": argv, "components": components, "reached": reached, "steps": float(np.mean(listed[2:-2])),
            "synth_exit": code, "check_exit": check}


def first_order_join_mm(robot: str, model_path: Path, step_m: float) -> float:
    """The closest ZMP margin of the walk at ``step_m`` joined with angle and velocity continuous only."""
    from gaitbot.app.eigen import model_robot, walk_ends
    from gaitbot.gait.eigen import synthesize_walk
    from gaitbot.robot.walk_settings import walk_settings

    model = EigenGaitModel.load(model_path)
    args = argparse.Namespace(robot=robot, calibration=None, thigh=None, shank=None, foot=None)
    config, source, legs = model_robot(args, model, str(model_path))
    ends = walk_ends(config, source)
    walk = synthesize_walk(model, walk_settings(config), step_m, cycles=SYNTH_CYCLES, legs=legs,
                           ends=type(ends)(ends.walk, ends.steps, join_order=1))
    return margin_mm(config, walk)


def other_robots_mm() -> tuple[float, float]:
    """The least and largest root height offset (mm) of one shipped robot's walk read with another's legs,
    among robots that walk with the same joints (the planar ones, the 3D ones)."""
    from gaitbot.app.eigen import robot_legs
    from gaitbot.app.options import gait_source
    from gaitbot.app.planned_walk import planned_walk

    walks, legs = {}, {}
    for name in ("xl430-biped", "sts3215-biped", "ax12a-biped", "op3", "bioloid"):
        args = argparse.Namespace(robot=name, steps="0.03,0.03,0.03,0.03", distance=None, max_step=None,
                                  perturb=None, seed=None, calibration=None)
        walks[name] = planned_walk(args).planned
        legs[name] = robot_legs(gait_source(args), load_robot(name))
    offsets = [1000 * legs[a].root_height_error_m(walks[b]) for a in walks for b in walks
               if a != b and legs[a].joints == tuple(walks[b].joints)]
    return min(offsets), max(offsets)


def _range(values, fmt: str) -> str:
    lo, hi = min(values), max(values)
    return f"{lo:{fmt}}" if f"{lo:{fmt}}" == f"{hi:{fmt}}" else f"{lo:{fmt}} to {hi:{fmt}}"


def markdown(rows, info, steps_per_walk: int) -> str:
    kinds = [k for k in LEG_JOINT_KINDS if any(r.joint_error_deg[k] > 0 for r in rows)]
    header = ("| step m | | " + " | ".join(k.replace("_", " ") + " deg" for k in kinds)
              + " | root x, y, z mm | steps m | ZMP margin mm: cycle, walk (walker's) | check |")
    lines = [header, "|" + "---|" * (len(kinds) + 6)]
    for r in rows:
        errors = " | ".join(f"{r.joint_error_deg[k]:.2f}" for k in kinds)
        lines.append(f"| {r.step_m:g} | {'example' if r.trained else 'between'} | {errors} | "
                     f"{', '.join(f'{v:.1f}' for v in r.root_error_mm)} | {r.mean_step_m:.4f} | "
                     f"{r.cycle_margin_mm:.1f}, {r.margin_mm:.1f} ({r.walker_margin_mm:.1f}) | "
                     f"{'passes' if r.check_exit == 0 else 'fails'} |")
    table = "\n".join(lines)
    contact = ("within a micrometre of" if info["contact_mm"] < 1e-3
               else f"within {info['contact_mm']:.3f} mm of")
    near = sum(r.near_join for r in rows)
    joins = "within a step of a join with the walker's start or stop"
    where = {len(rows): f"in every walk {joins}", 0: "in every walk inside the synthesised cycles"}.get(
        near, f"in {near} of {len(rows)} walks {joins}")
    plural = "s" if info["components"] > 1 else ""
    summary = (f"Fitted on {info['robot']}'s walks of {steps_per_walk} steps at {', '.join(map(str, TRAIN_M))} m "
               f"({info['cycles']} cycles): {info['pose_dims']} pose axes of 12, {info['components']} eigen-motion"
               f"{plural} ({100 * info['variance']:.1f}% of the variance). The root rebuilt from contact of the "
               f"examples' own angles lies {contact} their root. The synthesised walks' ZMP stays "
               f"{_range([r.cycle_margin_mm for r in rows], '.1f')} mm inside the support polygon in their middle "
               f"cycle and {_range([r.margin_mm for r in rows], '.1f')} mm over the whole walk (the least {where}), "
               f"the walker's own walks "
               f"{_range([r.walker_margin_mm for r in rows], '.1f')} mm; "
               f"{sum(r.check_exit == 0 for r in rows)} of {len(rows)} pass `gaitbot check --robot {info['robot']}`.")
    joins = (f"The {TRAIN_M[1]:g} m walk joined with angle and velocity continuous only: the ZMP comes "
             f"{abs(info['first_order_mm']):.1f} mm {'outside' if info['first_order_mm'] < 0 else 'inside'} the "
             f"support polygon's edge.")
    others = (f"A shipped robot's walk read with another shipped robot's legs (of the same joints) stands "
              f"{info['others_mm'][0]:.0f} to {info['others_mm'][1]:.0f} mm above or below the floor.")
    pose = info["pose"]
    verdict = "passes" if pose["check_exit"] == 0 else "fails"
    example = (f"```sh\ngaitbot {' '.join(pose['argv'])}\n```\n\nThe pose op3's walker takes {POSE_TIME_S:g} s after a "
               f"left heel strike at {POSE_FROM_M:g} m, forced on a {POSE_ON_M:g} m walk with the fewest eigen-motions "
               f"that reach it ({pose['components']}), is reached to {pose['reached']} deg in every synthesised cycle, "
               f"lengthens the steps to {pose['steps']:.3f} m, and the walk {verdict} `gaitbot check --robot "
               f"{info['robot']}`.")
    blocks = {"eigen3d-accuracy": table, "eigen3d-summary": summary, "eigen3d-pose": example,
              "eigen3d-joins": joins, "eigen3d-robots": others}
    return "\n".join(f"<!-- figure {name} -->\n{text}\n<!-- /figure -->" for name, text in blocks.items())


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--robot", default="op3", help="a robot whose legs roll (default op3)")
    p.add_argument("--steps-per-walk", type=int, default=8, help="steps of each example walk (default 8)")
    p.add_argument("--fit", default="", help="more options for gaitbot eigen fit, e.g. '--components 2'")
    p.add_argument("--markdown", action="store_true", help="print the docs' figures (tools/figures.py)")
    args = p.parse_args(argv)
    with tempfile.TemporaryDirectory() as tmp, \
            progress("eigen 3D figures", total=2 + len(TRAIN_M) + len(BETWEEN_M), unit="part") as bar:
        rows, info = measure(args.robot, args.steps_per_walk, Path(tmp), bar, args.fit.split())
    if args.markdown:
        print(markdown(rows, info, args.steps_per_walk))
        return 0
    print(f"{info['robot']}: {info['cycles']} example cycles from walks of {args.steps_per_walk} steps at "
          f"{', '.join(map(str, TRAIN_M))} m; {info['pose_dims']} pose axes, {info['components']} eigen-motions "
          f"({100 * info['variance']:.2f}%); root from contact of the examples' angles within "
          f"{info['contact_mm']:.2g} mm of theirs")
    kinds = LEG_JOINT_KINDS
    print(f"{'step m':>7} {'':>8} " + " ".join(f"{k:>11}" for k in kinds)
          + f" {'root x/y/z mm':>17} {'steps m':>8} {'ZMP cycle':>9} {'walk':>6} {'walker':>7} check")
    for r in rows:
        print(f"{r.step_m:7.3f} {'example' if r.trained else 'between':>8} "
              + " ".join(f"{r.joint_error_deg[k]:11.3f}" for k in kinds)
              + f" {'/'.join(f'{v:.2f}' for v in r.root_error_mm):>17} {r.mean_step_m:8.4f} {r.cycle_margin_mm:9.1f} "
              f"{r.margin_mm:6.1f} "
              f"{r.walker_margin_mm:7.1f} {r.check_exit}")
    pose = info["pose"]
    print(f"\nforced pose ({pose['components']} eigen-motions): gaitbot {' '.join(pose['argv'])}\nreached to "
          f"{pose['reached']} deg, steps {pose['steps']:.4f} m, synth exit {pose['synth_exit']}, check exit "
          f"{pose['check_exit']}")
    print(f"joined with angle and velocity continuous only, the {TRAIN_M[1]:g} m walk's closest ZMP margin: "
          f"{info['first_order_mm']:.1f} mm; another shipped robot's walk on these legs: "
          f"{info['others_mm'][0]:.1f} to {info['others_mm'][1]:.1f} mm off")
    return 0


if __name__ == "__main__":
    sys.exit(main())
