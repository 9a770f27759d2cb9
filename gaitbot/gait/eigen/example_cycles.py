"""Example cycles from trajectory files (Li et al. 2009 section 3: cycle segmentation).

A cycle runs from a left heel strike to the next left heel strike (two steps, docs/gait-model.md
section 1). Trajectory ``.npz`` files carry their heel strikes; CSV files (and recordings) do not,
so heel strikes are detected from foot contact with forward kinematics (gait/footfall.py, the rule
``gaitbot plot`` uses too; footfall3d.py for legs that roll): a leg's foot is in the air while its
lowest sole point is more than ``contact_tol_m`` above the other foot's; its heel strike is the first
frame at which it comes back down to (nearly) the other foot's level. A cycle holds the joints of the
legs it is cut for (legs.py: the six pitch joints, or all twelve leg joints).

Only the steady part of a walk gives examples: a generated walk starts from standing (its first
step starts at rest) and ends with a closing step, so cycles that start at the first heel strike
or end at the last one are dropped. A walk's label is its step length: the mean distance between
consecutive heel strikes inside the cycles kept (world x of the heel at each strike).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from gaitbot.errors import UserError

from ..footfall import CONTACT_TOL_FRACTION, detect_heel_strikes, foot_heights_in_body, heel_world_x
from ..geometry import LegGeometry
from ..trajectory import Trajectory
from .legs import PlanarLegs

__all__ = ["CONTACT_TOL_FRACTION", "ExampleCycle", "ExampleError", "cycles_from_trajectory", "detect_heel_strikes",
           "foot_heights_in_body", "heel_world_x", "walk_label"]


class ExampleError(UserError, ValueError):
    """An example file cannot give example cycles; the message names the file and why."""


@dataclass(frozen=True)
class ExampleCycle:
    """One cycle: frames (n, J) joint angles in radians at phases k/n (the joints of the legs it was cut
    for, legs.py), its duration, the phase of the right heel strike inside it, and its label (step length,
    metres)."""

    angles_rad: np.ndarray
    duration_s: float
    right_strike_phase: float
    step_length_m: float
    source: str = ""


def _frame_of(trajectory: Trajectory, t_s: float) -> int:
    return int(np.argmin(np.abs(trajectory.t_s - t_s)))


def cycles_from_trajectory(trajectory: Trajectory, legs, source: str = "",
                           keep_ends: bool = False) -> list[ExampleCycle]:
    """The steady cycles of a walk (left heel strike to left heel strike), labelled by step length.
    ``legs``: a legs.py object, or a LegGeometry for the planar legs (six pitch joints)."""
    legs = PlanarLegs(legs) if isinstance(legs, LegGeometry) else legs
    angles = trajectory.angles_of(legs.joints)
    strikes = list(trajectory.heel_strikes) or legs.detect_heel_strikes(trajectory)
    if not keep_ends:
        strikes = strikes[1:-1]  # the first step starts from rest, the last one closes the feet
    lefts = [i for i, h in enumerate(strikes) if h.leg == "left"]
    cycles = []
    for a, b in zip(lefts, lefts[1:]):
        inner = strikes[a:b + 1]
        rights = [h for h in inner if h.leg == "right"]
        if len(inner) != 3 or len(rights) != 1:
            continue  # not two alternating steps
        k0, k1 = _frame_of(trajectory, inner[0].t_s), _frame_of(trajectory, inner[-1].t_s)
        if k1 - k0 < 8:
            continue
        duration = float(trajectory.t_s[k1] - trajectory.t_s[k0])
        phase = float((rights[0].t_s - inner[0].t_s) / duration)
        step = float(np.mean(np.diff([h.x_m for h in inner])))
        cycles.append(ExampleCycle(angles[k0:k1].copy(), duration, phase, step, source))
    if not cycles:
        raise ExampleError(f"{source or 'trajectory'}: no complete steady cycle (left heel strike, right, left) "
                           f"found among {len(trajectory.heel_strikes) or 'the detected'} heel strikes")
    return cycles


def walk_label(cycles: list[ExampleCycle]) -> float:
    """A walk's step length: the mean over its steady cycles."""
    return float(np.mean([c.step_length_m for c in cycles]))
