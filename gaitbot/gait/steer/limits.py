"""A robot's steering limits (its config's ``[steer]`` table): how far and how much one step may go.

Per step, in the stance foot's frame: the most forward, backward and sideways displacement of the body,
the most turn, the least gap between the soles' inner edges at any moment, and how much the walk's
per-step displacement may change from one step to the next (the command's acceleration). A command
asking for more is clipped (gaitbot.gait.steer.planner). docs/robot-config.md gives each key; the
op3 and bioloid configs say how their values were derived.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields


@dataclass(frozen=True)
class SteerLimits:
    """max_forward_m / max_backward_m: the most the body moves forward / backward in one step (m);
    max_side_m: the most the leading foot steps sideways beyond the stance width in one step (m);
    max_turn_deg: the most the leading foot turns in one step (deg; the torso turns half of it per step);
    min_gap_m: the least gap between the two soles, planned, at any moment of a step (m);
    max_change_forward_m, max_change_side_m, max_change_turn_deg: the most the forward, sideways and
    turning displacement per step may change from one step to the next."""

    max_forward_m: float
    max_backward_m: float
    max_side_m: float
    max_turn_deg: float
    min_gap_m: float
    max_change_forward_m: float
    max_change_side_m: float
    max_change_turn_deg: float

    def __post_init__(self) -> None:
        for f in fields(self):
            value = getattr(self, f.name)
            lo, hi = RANGES[f.name]
            if not (isinstance(value, (int, float)) and math.isfinite(value) and lo <= value <= hi):
                raise ValueError(f"{f.name} must lie in {lo:g}..{hi:g}, got {value!r}")

    @classmethod
    def field_names(cls) -> tuple[str, ...]:
        return tuple(f.name for f in fields(cls))


RANGES = {"max_forward_m": (0.0, 0.5), "max_backward_m": (0.0, 0.5), "max_side_m": (0.0, 0.3),
          "max_turn_deg": (0.0, 60.0), "min_gap_m": (0.0, 0.1), "max_change_forward_m": (1e-4, 0.5),
          "max_change_side_m": (1e-4, 0.3), "max_change_turn_deg": (0.1, 60.0)}
"""Each key's allowed range (beyond it no small humanoid steps; the robot's own values sit well inside)."""
