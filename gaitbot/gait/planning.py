"""Step plans: lengths from a distance, small random perturbations, and the per-step timetable.

Jing et al. 2015 section 2.4 / docs/gait-model.md section 5: given a distance, the fewest equal steps that
cover it; small random perturbations so that the walk does not look mechanical; left and right
steps may differ (a plain list of step lengths expresses that).
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass

import numpy as np

from .step_length import StepLengthError


def steps_for_distance(distance: float, max_step: float) -> list[float]:
    """The fewest equal steps of at most ``max_step`` covering ``distance`` (same unit)."""
    for name, value in (("distance", distance), ("maximum step", max_step)):
        if not math.isfinite(value) or value <= 0:
            raise StepLengthError(f"{name} must be a positive finite number, got {value!r}")
    count = max(1, math.ceil(distance / max_step - 1e-12))
    return [distance / count] * count


def perturb_steps(steps, sigma: float, seed: int | None, max_step: float) -> list[float]:
    """Add zero-mean Gaussian noise of standard deviation ``sigma`` to each step length.

    Each step stays within [0, max_step] and the total distance is kept: what clipping takes
    from (or adds to) the total is spread over the steps that still have room. With a seed the
    result is reproducible.
    """
    if not math.isfinite(sigma) or sigma < 0:
        raise StepLengthError(f"perturbation sigma must be 0 or more, got {sigma!r}")
    steps = np.asarray(steps, dtype=float)
    if sigma == 0 or len(steps) == 0:
        return steps.tolist()
    total = float(steps.sum())
    out = np.clip(steps + np.random.default_rng(seed).normal(0.0, sigma, len(steps)), 0.0, max_step)
    for _ in range(len(steps) + 1):
        missing = total - float(out.sum())
        room = (max_step - out) if missing > 0 else out
        free = room > 1e-15
        if abs(missing) <= 1e-12 * max(1.0, total) or not free.any():
            break
        share = room[free] / room[free].sum()
        out[free] = np.clip(out[free] + missing * share, 0.0, max_step)
    return out.tolist()


@dataclass(frozen=True)
class PlannedStep:
    """One heel strike of the plan. ``leg`` is the leg that swings and lands."""

    index: int
    leg: str
    length_m: float
    rv: float
    start_s: float
    end_s: float
    foothold_m: float
    closing: bool = False

    def to_dict(self) -> dict:
        return asdict(self)
