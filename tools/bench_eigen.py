"""Eigen-gait figures: fit on flat walks at 8 step lengths, synthesise the lengths in between, compare with the walker.

    python tools/bench_eigen.py [--robot xl430-biped]

For each pose-PCA rule (the default, and the paper's variance rule alone at 95/97/99%) prints the
pose axes and eigen-motions kept with the variance each explains, then per held-out step length:
the RMS joint-angle error of the model's cycle against the walker's own cycle (degrees), the mean
steady step length of a synthesised walk and its error, and the least swing clearance of its
synthesised steps (the walker's rule: whole sole, 20-80% of each swing), at the two joins with the
walker's start and stop, and the walker's own.
"""

from __future__ import annotations

import argparse
import platform
import sys
import time
from dataclasses import replace
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from gaitbot.gait import generate_walk  # noqa: E402
from gaitbot.gait.eigen import FitOptions, cycles_from_trajectory, fit_model, synthesize_walk, walk_label  # noqa: E402
from gaitbot.gait.footfall import swing_clearances  # noqa: E402
from gaitbot.robot.walk_settings import leg_geometry, walk_settings  # noqa: E402
from gaitbot.app.options import load_robot  # noqa: E402

TRAIN_M = (0.02, 0.03, 0.04, 0.05, 0.06, 0.07, 0.08, 0.09)
HELD_OUT_M = (0.025, 0.045, 0.065, 0.085)
RULES = {"default (95%, then <= 0.5 deg)": FitOptions(),
         "95% alone (paper)": FitOptions(pose_tolerance_deg=float("inf")),
         "97% alone": FitOptions(pose_variance=0.97, pose_tolerance_deg=float("inf")),
         "99% alone": FitOptions(pose_variance=0.99, pose_tolerance_deg=float("inf"))}
SYNTH_CYCLES = 3


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


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--robot", default="xl430-biped")
    args = p.parse_args(argv)
    config = load_robot(args.robot)
    geometry, settings = leg_geometry(config), walk_settings(config)
    examples = library(geometry, settings)
    truth = {s: cycles_from_trajectory(generate_walk(geometry, [s] * 6, settings), geometry)[0] for s in HELD_OUT_M}
    walker_clearance = {s: min(c for _, c in swing_clearances(geometry, generate_walk(geometry, [s] * 6, settings)))
                        for s in HELD_OUT_M}
    print(f"{platform.node()} ({platform.machine()}, Python {platform.python_version()})")
    print(f"{config.name}: {len(examples)} example cycles from flat walks at {', '.join(map(str, TRAIN_M))} m; "
          f"configured clearance {1000 * settings.clearance:.0f} mm; held out {', '.join(map(str, HELD_OUT_M))} m")
    for name, options in RULES.items():
        start = time.perf_counter()
        model = fit_model(examples, geometry, settings.rate_hz, options)
        fit_s = time.perf_counter() - start
        pose_share = model.pose_eigenvalues / model.pose_eigenvalues.sum()
        print(f"\npose rule {name}: {model.pose_dims} of 6 pose axes ({100 * pose_share[:model.pose_dims].sum():.2f}% "
              f"of the pose variance; per axis {', '.join(f'{100 * v:.2f}' for v in pose_share)} %); "
              f"{model.n_components} eigen-motions ({', '.join(f'{100 * v:.2f}' for v in model.variance_explained[:4])} "
              f"% for the first four); fit {fit_s:.2f} s")
        print(f"{'step m':>7} {'RMS deg':>8} {'synth step m':>12} {'error %':>8} {'clearance mm':>12} {'joins mm':>8} "
              f"{'walker mm':>9}")
        for step, cycle in truth.items():
            walk = synthesize_walk(model, settings, step, cycles=SYNTH_CYCLES)
            inner = synthesised_steps(walk)
            lengths = np.diff([h.x_m for h in inner])
            inner_times = {h.t_s for h in inner[1:]}
            swings = swing_clearances(geometry, walk)
            clearance = min(c for h, c in swings if h.t_s in inner_times)
            at_joins = min(c for h, c in swings if h.t_s in {walk.heel_strikes[2].t_s, walk.heel_strikes[-2].t_s})
            print(f"{step:7.3f} {model_cycle_rms_deg(model, step, cycle):8.2f} {lengths.mean():12.4f} "
                  f"{100 * np.abs(lengths - step).max() / step:8.1f} {1000 * clearance:12.1f} {1000 * at_joins:8.1f} "
                  f"{1000 * walker_clearance[step]:9.1f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
