"""Options of a simulated walk shared by ``walk --sim`` (and ``drive --sim``): another author's model with its
joint map (``--sim-model``, ``--sim-map``) and the push (``--push IMPULSE[@DIRECTION]``)."""

from __future__ import annotations

import argparse
import math

from gaitbot.app.options import UsageError, file_option

MAX_PUSH_NS = 20.0
"""The largest --push (N s): far beyond what knocks over any small humanoid (docs/simulation.md)."""

DEFAULT_PUSH_AT_S = 3.0
"""A drive has no planned middle: its --push comes this long after the start unless --push-at says."""

PUSH_LEFT_DEG = 90.0
"""Without @DIRECTION a push is sideways, to the left (a negative impulse: to the right)."""


def add_sim_model_options(p: argparse.ArgumentParser,
                          when: str = "in the middle of a step half-way through the walk") -> None:
    p.add_argument("--push", metavar="N_S[@DEG]", help=f"--sim: push the torso with this impulse (N s) {when}; "
                   "@DEG: its direction in degrees from forward, counter-clockwise "
                   "(default 90: to the left; a negative impulse pushes the opposite way)")
    p.add_argument("--imu-fault", choices=("frozen", "noisy", "absent"), help="--sim: break the simulated IMU 1 s "
                   "into the walk (docs/feedback.md says what the walk does then)")
    p.add_argument("--imu-seed", type=int, default=0, metavar="N", help="--sim: seed of the simulated IMU's noise "
                   "and bias (default 0)")
    p.add_argument("--sim-model", metavar="FILE.xml", help="--sim: walk another author's MuJoCo model of the robot "
                   "(its own servos, floor and inertias) instead of the one built from the config; needs --sim-map")
    p.add_argument("--sim-map", metavar="MAP.toml", help="--sim-model: which model joint is which gaitbot joint "
                   "(docs/simulation.md)")


def parse_push(text: str | float | None) -> tuple[float | None, float]:
    """``--push`` as (impulse N s or None, direction deg); UsageError (one line) for anything else."""
    if text is None:
        return None, PUSH_LEFT_DEG
    impulse_text, _, direction_text = str(text).partition("@")
    try:
        impulse = float(impulse_text)
        direction = float(direction_text) if direction_text else PUSH_LEFT_DEG
    except ValueError:
        raise UsageError(f"--push must be IMPULSE[@DIRECTION] (N s, degrees from forward, counter-clockwise), "
                         f"e.g. 1.5 or 1.5@180, got {text!r}") from None
    if not (math.isfinite(impulse) and impulse != 0 and abs(impulse) <= MAX_PUSH_NS):
        raise UsageError(f"--push must be a non-zero impulse of at most {MAX_PUSH_NS:g} N s (positive to the left), "
                         f"got {impulse_text!r}")
    if not (math.isfinite(direction) and -360.0 <= direction <= 360.0):
        raise UsageError(f"--push: the direction must be degrees from forward within -360..360, got {direction_text!r}")
    return impulse, direction


def add_push_phase_option(p: argparse.ArgumentParser) -> None:
    """``walk``'s --push-phase: where in the step half-way through the walk the push comes."""
    p.add_argument("--push-phase", type=float, metavar="P", help="--sim --push: where in that step the push "
                   "comes: 0 as its foot lifts, 1 as the next foot lifts (its swing, then the double support "
                   "after it; default: the middle of its swing). tools/push_survival.py's pushes, one by one")


def check_push_phase(args) -> None:
    """--push-phase: a share 0..1 of the step, and only with --sim --push; UsageError (one line) otherwise."""
    phase = getattr(args, "push_phase", None)
    if phase is None:
        return
    if not getattr(args, "sim", False) or getattr(args, "push", None) is None:
        raise UsageError("--push-phase: only with --sim and --push (when in the step the push comes)")
    if not (math.isfinite(phase) and 0.0 <= phase <= 1.0):
        raise UsageError(f"--push-phase must be a share of the step from 0 (its foot lifts) to 1 (the next foot "
                         f"lifts), got {phase!r}")


def check_sim_model(args) -> None:
    """--sim-model and --sim-map go together, with --sim, free-floating; the files must be readable."""
    model, mapping = getattr(args, "sim_model", None), getattr(args, "sim_map", None)
    if model is None and mapping is None:
        return
    if not getattr(args, "sim", False):
        raise UsageError(f"--{'sim-model' if model else 'sim-map'}: only with --sim (a simulated walk)")
    if model is None or mapping is None:
        raise UsageError("--sim-model and --sim-map go together: the model and which of its joints is which")
    if getattr(args, "boom", False) or getattr(args, "free_pitch", False):
        raise UsageError("--sim-model: another author's model stands free; it has no boom")
    file_option(model, "--sim-model")
    file_option(mapping, "--sim-map")


def foreign_model(args):
    """(model file, SimMap) for gaitbot.sim.walk.SimWalk, or None without --sim-model."""
    if getattr(args, "sim_model", None) is None:
        return None
    from gaitbot.sim.sim_map import load_sim_map

    return args.sim_model, load_sim_map(args.sim_map)
