"""The balanced walk's settings (a robot config's optional ``[balance]`` table), with why each matters.

The defaults are the operating point found for the ROBOTIS OP3 in the free-floating simulation and
checked on other people's models of it (docs/balance.md gives the sweep, docs/balance-robustness.md the robustness table).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields


@dataclass(frozen=True)
class BalanceSettings:
    """crouch_knee_deg: knee bend of the walking crouch; it sets the centre of mass height the
    cart-table model uses and gives the knee room to lift the swing foot.
    double_support_share: the part of each step with both feet down (the ZMP moves across then).
    zmp_forward_m / zmp_inward_m: the ZMP reference's offset from the stance sole's centre, forward
    and towards the midline (a forward offset balances the backward lean of soft servos' sag).
    preview_horizon_s: how far ahead the preview controller looks; preview_jerk_weight: R against
    Qe = 1 on the ZMP error (Kajita 2003).
    sag_feedforward: add each joint's gravity torque over the servo's stiffness to its goal.
    progression_end: share of the swing by which the swing foot is over its foothold (the rest only
    sets it down, so a lagging servo still lands the full step)."""

    crouch_knee_deg: float = 60.0
    double_support_share: float = 0.15
    zmp_forward_m: float = 0.025
    zmp_inward_m: float = 0.0
    preview_horizon_s: float = 1.0
    preview_jerk_weight: float = 1e-6
    sag_feedforward: bool = True
    progression_end: float = 0.85

    def __post_init__(self) -> None:
        for name, (lo, hi) in LIMITS.items():
            value = getattr(self, name)
            if not (math.isfinite(value) and lo <= value <= hi):
                raise ValueError(f"{name} must lie in {lo:g}..{hi:g}, got {value!r}")

    @classmethod
    def field_names(cls) -> tuple[str, ...]:
        return tuple(f.name for f in fields(cls))


LIMITS = {"crouch_knee_deg": (5.0, 120.0), "double_support_share": (0.02, 0.8), "zmp_forward_m": (-0.1, 0.1),
          "zmp_inward_m": (-0.05, 0.05), "preview_horizon_s": (0.2, 5.0), "preview_jerk_weight": (1e-12, 1.0),
          "progression_end": (0.5, 1.0)}
"""Each numeric setting's allowed range (outside it the walk is not one this code was checked for)."""
