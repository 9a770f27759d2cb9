"""Eigen-gait figures: fit on flat walks at 8 step lengths, synthesise the lengths in between, compare with the walker.

    python tools/bench_eigen.py [--robot xl430-biped]
    python tools/bench_eigen.py --markdown      # the figures of docs/eigen-gaits.md (tools/figures.py)

For each pose-PCA rule (the default, and the paper's variance rule alone at 95/97/99%) prints the
pose axes and eigen-motions kept with the variance each explains, then per held-out step length:
the RMS joint-angle error of the model's cycle against the walker's own cycle (degrees), the mean
steady step length of a synthesised walk and its error, and the least swing clearance of its
synthesised steps (the walker's lift rule: whole sole, 20-80% of each swing), at the two joins with the
walker's start and stop, and the walker's own. Then the forced-pose example of docs/eigen-gaits.md
(the pose a 0.065 m walk takes 0.57 s after a left heel strike, forced on a 0.05 m walk through
``gaitbot eigen synth`` itself, with the fewest eigen-motions that reach it), and the non-periodic
(B-spline) model of the walker's starts from standing.
"""

from __future__ import annotations

import argparse
import contextlib
import io
import platform
import re
import sys
import tempfile
import time
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from gaitbot.app.cli import main as gaitbot  # noqa: E402
from gaitbot.app.options import load_robot  # noqa: E402
from gaitbot.app.progress import progress  # noqa: E402
from gaitbot.gait import generate_walk  # noqa: E402
from gaitbot.gait.eigen import (ExampleCycle, FitOptions, cycles_from_trajectory, fit_model,  # noqa: E402
                                synthesize_walk, walk_label)
from gaitbot.gait.footfall import swing_clearances  # noqa: E402
from gaitbot.robot.walk_settings import leg_geometry, walk_settings  # noqa: E402

TRAIN_M = (0.02, 0.03, 0.04, 0.05, 0.06, 0.07, 0.08, 0.09)
HELD_OUT_M = (0.025, 0.045, 0.065, 0.085)
RULES = {"default (95%, then 0.5 deg)": FitOptions(),
         "95% alone (the paper's)": FitOptions(pose_tolerance_deg=float("inf")),
         "97% alone": FitOptions(pose_variance=0.97, pose_tolerance_deg=float("inf")),
         "99% alone": FitOptions(pose_variance=0.99, pose_tolerance_deg=float("inf"))}
SYNTH_CYCLES = 3
POSE_FROM_M, POSE_TIME_S, POSE_ON_M = 0.065, 0.57, 0.05  # the forced-pose example of docs/eigen-gaits.md


@dataclass
class RuleResult:
    name: str
    pose_dims: int
    pose_share: np.ndarray
    motion_share: np.ndarray
    n_components: int
    fit_s: float
    rows: list  # (step, rms deg, mean synthesised step, worst step error, least clearance, at joins, walker's)


def library(geometry, settings):
    examples = []
    for step in TRAIN_M:
        cycles = cycles_from_trajectory(generate_walk(geometry, [step] * 6, settings), geometry, f"walk {step}")
        examples += [replace(c, step_length_m=walk_label(cycles)) for c in cycles]
    return examples


def model_cycle_rms_deg(model, step, cycle) -> float:
    """The model's cycle at ``step``, sampled at the walker cycle's own frames, against it."""
    _, warp, _ = model.timing_for(step)
    n = len(cycle.angles_rad)
    q = model.poses(model.aligned_phase(np.arange(n) / n, warp), model.coefficients_for(step))
    return float(np.degrees(np.sqrt(np.mean((q - cycle.angles_rad) ** 2))))


def synthesised_steps(walk):
    """Heel strikes of the synthesised cycles only (the walker's start and stop left out)."""
    strikes = walk.heel_strikes
    return strikes[2:len(strikes) - 2]


def measure_rule(name, options, examples, truth, walker_clearance, geometry, settings) -> RuleResult:
    start = time.perf_counter()
    model = fit_model(examples, geometry, settings.rate_hz, options)
    fit_s = time.perf_counter() - start
    rows = []
    for step, cycle in truth.items():
        walk = synthesize_walk(model, settings, step, cycles=SYNTH_CYCLES)
        inner = synthesised_steps(walk)
        lengths = np.diff([h.x_m for h in inner])
        inner_times = {h.t_s for h in inner[1:]}
        found = swing_clearances(geometry, walk)
        clearance = min(c for h, c in found if h.t_s in inner_times)
        at_joins = min(c for h, c in found if h.t_s in {walk.heel_strikes[2].t_s, walk.heel_strikes[-2].t_s})
        rows.append((step, model_cycle_rms_deg(model, step, cycle), lengths.mean(),
                     np.abs(lengths - step).max() / step, clearance, at_joins, walker_clearance[step]))
    return RuleResult(name, model.pose_dims, model.pose_eigenvalues / model.pose_eigenvalues.sum(),
                      model.variance_explained, model.n_components, fit_s, rows)


def forced_pose(examples, geometry, settings, robot: str):
    """The documented ``eigen synth --pose-deg`` example, run through the command line: (argv, its output,
    the number of eigen-motions it needs)."""
    walk = generate_walk(geometry, [POSE_FROM_M] * 6, settings)
    left = next(h for h in walk.heel_strikes if h.leg == "left")
    k = int(round((left.t_s + POSE_TIME_S) * settings.rate_hz))
    pose = ",".join(f"{v:.1f}" for v in np.degrees(walk.angles_rad[k]))
    model = fit_model(examples, geometry, settings.rate_hz, robot=robot)
    with tempfile.TemporaryDirectory() as folder:
        model.save(Path(folder) / "model.npz")
        for components in range(model.n_components, len(model.eigenvalues) + 1):
            argv = ["eigen", "synth", "model.npz", "--step-length", f"{POSE_ON_M:g}", "--components", str(components),
                    "--pose-deg", pose, "--pose-time", f"{POSE_TIME_S:g}", "-o", "posed.csv"]
            out, err = io.StringIO(), io.StringIO()
            with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
                status = gaitbot([a if a != "model.npz" else str(Path(folder) / a) for a in argv[:-1]]
                                 + [str(Path(folder) / "posed.csv")])
            if status == 0:
                return argv, out.getvalue(), components
    raise RuntimeError(f"no number of eigen-motions reaches the pose {pose}")


def start_segment(geometry, settings, step):
    """The walker from standing to its second heel strike: a motion that does not repeat."""
    walk = generate_walk(geometry, [step] * 4, settings)
    k = int(np.argmin(np.abs(walk.t_s - walk.heel_strikes[1].t_s)))
    return walk.angles_rad[:k + 1], float(walk.t_s[k])


def non_periodic(geometry, settings) -> list[float]:
    """RMS error (deg) at each held-out step length of a B-spline model of the walker's starts from standing."""
    examples = []
    for step in TRAIN_M:
        q, duration = start_segment(geometry, settings, step)
        examples.append(ExampleCycle(q, duration, 0.5, step, f"start {step}"))
    model = fit_model(examples, geometry, settings.rate_hz, FitOptions(basis="bspline", n_basis=30), periodic=False)
    errors = []
    for step in HELD_OUT_M:
        q, _ = start_segment(geometry, settings, step)
        _, warp, _ = model.timing_for(step)
        synth = model.poses(model.aligned_phase(np.linspace(0.0, 1.0, len(q)), warp), model.coefficients_for(step))
        errors.append(float(np.degrees(np.sqrt(np.mean((synth - q) ** 2)))))
    return errors


def _range(values, fmt: str, unit: str) -> str:
    lo, hi = min(values), max(values)
    return f"{lo:{fmt}}{unit}" if f"{lo:{fmt}}" == f"{hi:{fmt}}" else f"{lo:{fmt}} to {hi:{fmt}}{unit}"


def markdown(results, walker_clearance, pose, bspline, settings) -> str:
    table = ["| pose rule | pose axes | eigen-motions (variance) | RMS joint error | steady step length | "
             "least swing clearance |", "|---|---|---|---|---|---|"]
    for r in results:
        shares = r.motion_share[:r.n_components] * 100
        motions = f"{r.n_components} ({' + '.join(f'{v:.1f}' for v in shares)} = {shares.sum():.1f}%)"
        axes = f"{r.pose_dims}" + ("" if r.pose_dims == 6 else f" ({100 * r.pose_share[:r.pose_dims].sum():.1f}%)")
        errors = [row[3] * 100 for row in r.rows]
        table.append(f"| {r.name} | {axes} | {motions} | {_range([row[1] for row in r.rows], '.2f', ' deg')} | "
                     f"within {max(errors):.1f}% | down to {1000 * min(row[4] for row in r.rows):.1f} mm |")
    default = results[0]
    axes = ", ".join(f"{100 * v:.1f}" for v in default.pose_share)
    walker = [1000 * v for v in walker_clearance.values()]
    argv, out, components = pose
    reached = re.search(r"pose reached to (\S+) deg", out).group(1)
    steps = [float(v) for v in re.search(r"heel strikes ([\d., ]+) m", out).group(1).split(",")]
    steady = float(np.mean(steps[2:-1]))
    blocks = {
        "eigen-heldout": "\n".join(table),
        "eigen-pose-axes": (f"Clearance is the walker's lift rule measured on the synthesised swings (the whole sole, "
                            f"20 to 80% of each swing's time): configured {1000 * settings.clearance:.0f} mm, the "
                            f"walker's own walks measure {_range(walker, '.1f', ' mm')} that way. Variance per pose "
                            f"axis (the default rule): {axes}%."),
        "eigen-pose-example": (f"```sh\ngaitbot {' '.join(argv)}\n```\n\nThe pose a {POSE_FROM_M:g} m walk takes "
                               f"{POSE_TIME_S:g} s after a left heel strike, forced on a {POSE_ON_M:g} m walk with the "
                               f"fewest eigen-motions that reach it ({components}), is reached to {reached} deg in "
                               f"every synthesised cycle and lengthens the steps to {steady:.3f} m."),
        "eigen-bspline": (f"the walker's start from standing at {len(TRAIN_M)} step lengths, held out between them, "
                          f"comes back within {_range(bspline, '.2f', ' deg')} RMS, starting standing."),
    }
    return "\n".join(f"<!-- figure {name} -->\n{text}\n<!-- /figure -->" for name, text in blocks.items())


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--robot", default="xl430-biped", help="robot config (default xl430-biped)")
    p.add_argument("--markdown", action="store_true", help="print the docs' figures (tools/figures.py)")
    args = p.parse_args(argv)
    config = load_robot(args.robot)
    geometry, settings = leg_geometry(config), walk_settings(config)
    with progress("eigen figures", total=len(RULES) + 4, unit="part") as bar:
        examples = library(geometry, settings)
        truth = {s: cycles_from_trajectory(generate_walk(geometry, [s] * 6, settings), geometry)[0] for s in HELD_OUT_M}
        walker_clearance = {s: min(c for _, c in swing_clearances(geometry, generate_walk(geometry, [s] * 6, settings)))
                            for s in HELD_OUT_M}
        bar.update(1)
        results = []
        for name, options in RULES.items():
            results.append(measure_rule(name, options, examples, truth, walker_clearance, geometry, settings))
            bar.update(1)
        pose = forced_pose(examples, geometry, settings, config.name)
        bar.update(1)
        bspline = non_periodic(geometry, settings)
        bar.update(2)
    if args.markdown:
        print(markdown(results, walker_clearance, pose, bspline, settings))
        return 0
    print(f"{platform.node()} ({platform.machine()}, Python {platform.python_version()})")
    print(f"{config.name}: {len(examples)} example cycles from flat walks at {', '.join(map(str, TRAIN_M))} m; "
          f"configured clearance {1000 * settings.clearance:.0f} mm; held out {', '.join(map(str, HELD_OUT_M))} m")
    for r in results:
        print(f"\npose rule {r.name}: {r.pose_dims} of 6 pose axes ({100 * r.pose_share[:r.pose_dims].sum():.2f}% "
              f"of the pose variance; per axis {', '.join(f'{100 * v:.2f}' for v in r.pose_share)} %); "
              f"{r.n_components} eigen-motions ({', '.join(f'{100 * v:.2f}' for v in r.motion_share[:4])} "
              f"% for the first four); fit {r.fit_s:.2f} s")
        print(f"{'step m':>7} {'RMS deg':>8} {'synth step m':>12} {'error %':>8} {'clearance mm':>12} {'joins mm':>8} "
              f"{'walker mm':>9}")
        for step, rms, mean, error, clearance, joins, walker in r.rows:
            print(f"{step:7.3f} {rms:8.2f} {mean:12.4f} {100 * error:8.1f} {1000 * clearance:12.1f} {1000 * joins:8.1f} "
                  f"{1000 * walker:9.1f}")
    argv_, out, components = pose
    print(f"\nforced pose ({components} eigen-motions): gaitbot {' '.join(argv_)}\n{out.rstrip()}")
    print(f"\nnon-periodic (B-spline) starts from standing, RMS at {', '.join(map(str, HELD_OUT_M))} m: "
          f"{', '.join(f'{v:.2f}' for v in bspline)} deg")
    return 0


if __name__ == "__main__":
    sys.exit(main())
