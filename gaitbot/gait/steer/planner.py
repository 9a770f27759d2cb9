"""The footstep planner: a velocity command -> the next foothold, one step at a time (docs/steering.md).

Incremental by design: ``FootstepPlanner.next_step(command, swing_side)`` plans ONE step from where the
feet stand and the latest command, in a few hundred microseconds, so a live drive can plan each step as
it starts, and an offline walk is the same calls in a loop (``plan_footsteps``). The planner's state is
small (the feet, the walk frame, the per-step displacement) and ``copy()`` is cheap, so a caller can plan
steps ahead under the current command (the preview controller looks ~1 s ahead) and plan them again from
a copy when the command changes.

The walk frame F (x, y, yaw) is where the feet stand when side by side: ankles at +-hip_width/2 across
it. A step moves F by the displacement (dx, dy, dtheta) and lands the swing foot at its side of the new
F. Forward (dx) moves every step; a sidestep (dy) and a turn (dtheta) move only on the steps of the foot
on the side they go (it leads, the other foot follows and closes beside it), so a turn opens the outer
foot first and the feet never cross. Per step, in this order: the command becomes a displacement per
step (dx = vx T, dy = 2 vy T, dtheta = 2 wz T over the two steps of a cycle, T a step's duration),
clipped to the ``[steer]`` limits (the three together inside the limits' ellipsoid), then moved at most
the change limits from the last step's; the foothold is then pushed outward until the soles' gap over
the whole swing (gaitbot.gait.steer.soles) is at least min_gap_m (the turn halved if a push cannot).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

from gaitbot.gait.balance.zmp_reference import FootPlacement
from gaitbot.gait.body import SIDE_SIGN, BodyGeometry
from gaitbot.gait.steer.command import STILL, VelocityCommand
from gaitbot.gait.steer.limits import SteerLimits
from gaitbot.gait.steer.soles import swept_gap_m, swept_gap_where

PUSH_MARGIN_M = 5e-4  # pushed this much beyond min_gap_m (the gap is checked on a grid of swing poses)
MAX_PUSHES = 8
MIN_PUSH_SHARE = 0.25
"""A gap least early in the swing is pushed for as if it were at least this share of the way (bounded pushes)."""
MAX_HALVINGS = 4
SETTLED = 1e-12  # a displacement or a foot offset below this is zero


@dataclass(frozen=True)
class Footstep:
    """One planned step: the swing foot's foothold (world), its displacement from the stance foot in the
    stance foot's frame (dx_m forward, dy_m left, dtheta_deg counter-clockwise), the walk's displacement
    per step it carries (forward_m, side_m, turn_deg, after the limits), the command it was planned from,
    whether the limits clipped that command, and the least gap between the soles over the swing (m: the
    planner keeps it at least min_gap_m, and says here what it got, its last resort included)."""

    foothold: FootPlacement
    dx_m: float
    dy_m: float
    dtheta_deg: float
    forward_m: float
    side_m: float
    turn_deg: float
    command: VelocityCommand
    clipped: bool
    gap_m: float = math.inf

    @property
    def length_m(self) -> float:
        """The step's length as the straight walk counts it (its forward displacement)."""
        return self.forward_m


@dataclass(frozen=True)
class WalkFrame:
    x_m: float
    y_m: float
    yaw_rad: float

    def moved(self, dx: float, dy: float, dtheta: float) -> "WalkFrame":
        c, s = math.cos(self.yaw_rad), math.sin(self.yaw_rad)
        return WalkFrame(self.x_m + c * dx - s * dy, self.y_m + s * dx + c * dy, self.yaw_rad + dtheta)

    def foot(self, side: str, half_width_m: float, outward_m: float = 0.0) -> FootPlacement:
        c, s = math.cos(self.yaw_rad), math.sin(self.yaw_rad)
        left = SIDE_SIGN[side] * (half_width_m + outward_m)
        return FootPlacement(side, self.x_m + c * 0.0 - s * left, self.y_m + s * 0.0 + c * left, self.yaw_rad)


def frame_of(feet: dict) -> WalkFrame:
    """The walk frame of feet standing side by side: between the ankles, turned as the feet."""
    left, right = feet["left"], feet["right"]
    return WalkFrame(0.5 * (left.x_m + right.x_m), 0.5 * (left.y_m + right.y_m), 0.5 * (left.yaw_rad + right.yaw_rad))


def leading_side(command: VelocityCommand) -> str:
    """The foot that steps first for a command: the side it goes sideways, else the side it turns, else
    the right (as the straight walk)."""
    if command.vy_m_s != 0.0:
        return "left" if command.vy_m_s > 0 else "right"
    if command.wz_deg_s != 0.0:
        return "left" if command.wz_deg_s > 0 else "right"
    return "right"


class FootstepPlanner:
    """Plans steps one at a time (see the module docstring). ``feet``: where the feet stand now (side ->
    FootPlacement, side by side); ``step_s``: one step's duration (s)."""

    def __init__(self, geometry: BodyGeometry, limits: SteerLimits, step_s: float, feet: dict) -> None:
        self.geometry = geometry
        self.limits = limits
        self.step_s = step_s
        self.feet = dict(feet)
        self.frame = frame_of(feet)
        self.per_step = (0.0, 0.0, 0.0)  # forward (m), side (m, per leading step), turn (rad, per leading step)
        self.clip_reported = False

    def copy(self) -> "FootstepPlanner":
        other = FootstepPlanner.__new__(FootstepPlanner)
        other.__dict__.update(self.__dict__)
        other.feet = dict(self.feet)
        return other

    @property
    def half_width_m(self) -> float:
        return self.geometry.hip_width_m / 2

    def standing(self) -> bool:
        """True when the walk has come to rest: no displacement left and the feet side by side in F."""
        if any(abs(v) > SETTLED for v in self.per_step):
            return False
        return all(_same(self.feet[s], self.frame.foot(s, self.half_width_m)) for s in SIDE_SIGN)

    def wanted(self, command: VelocityCommand) -> tuple[tuple[float, float, float], bool]:
        """The per-step displacement a command asks for, inside the limits' box and ellipsoid, and whether
        it was clipped."""
        lim, t = self.limits, self.step_s
        raw = (command.vx_m_s * t, 2 * command.vy_m_s * t, math.radians(2 * command.wz_deg_s * t))
        top = (lim.max_forward_m if raw[0] >= 0 else lim.max_backward_m, lim.max_side_m, math.radians(lim.max_turn_deg))
        boxed = [max(-m, min(m, v)) for v, m in zip(raw, top)]
        size = math.sqrt(sum((v / m) ** 2 for v, m in zip(boxed, top) if m > 0))
        if size > 1.0:
            boxed = [v / size for v in boxed]
        clipped = any(abs(b - r) > 1e-12 * max(1.0, abs(r)) for b, r in zip(boxed, raw))
        return tuple(boxed), clipped

    def _ramped(self, wanted) -> tuple[float, float, float]:
        lim = self.limits
        steps = (lim.max_change_forward_m, lim.max_change_side_m, math.radians(lim.max_change_turn_deg))
        return tuple(p + max(-d, min(d, w - p)) for p, w, d in zip(self.per_step, wanted, steps))

    def next_step(self, command: VelocityCommand, swing_side: str) -> Footstep:
        """Plan the next step of foot ``swing_side`` under ``command`` (STILL: slow down and close the feet)."""
        wanted, clipped = self.wanted(command)
        forward, side, turn = self._ramped(wanted)
        forward, side, turn = (0.0 if abs(v) <= SETTLED else v for v in (forward, side, turn))
        self.per_step = (forward, side, turn)
        sign = SIDE_SIGN[swing_side]
        lateral = side if side * sign > 0 else 0.0
        dtheta = turn if turn * sign > 0 else 0.0
        frame, foothold, gap = self._clear_foothold(swing_side, forward, lateral, dtheta)
        self.frame = frame
        stance = self.feet["right" if swing_side == "left" else "left"]
        self.feet[swing_side] = foothold
        c, s = math.cos(stance.yaw_rad), math.sin(stance.yaw_rad)
        ex, ey = foothold.x_m - stance.x_m, foothold.y_m - stance.y_m
        return Footstep(foothold, c * ex + s * ey, -s * ex + c * ey, math.degrees(foothold.yaw_rad - stance.yaw_rad),
                        forward, side, math.degrees(turn), command, clipped, gap)

    def _clear_foothold(self, swing_side: str, forward: float, lateral: float,
                        dtheta: float) -> tuple[WalkFrame, FootPlacement, float]:
        """The new walk frame, the foothold, pushed outward (or the sideways step and turn halved) until
        the soles keep min_gap_m over the whole swing, and that swing's least gap: last, with no sideways
        step and no turn, pushed outward too. The last resort (not even that) is measured as well: a caller
        refuses it if it still comes too close."""
        g, lim = self.geometry, self.limits
        stance = self.feet["right" if swing_side == "left" else "left"]
        old = self.feet[swing_side]
        tries = [(lateral / 2 ** k, dtheta / 2 ** k) for k in range(MAX_HALVINGS + 1)] + [(0.0, 0.0)]
        for n, (side_m, turn) in enumerate(tries):
            frame = self.frame.moved(forward, side_m, turn)
            outward = 0.0
            for _ in range(MAX_PUSHES):
                foothold = frame.foot(swing_side, self.half_width_m, outward)
                gap, share = swept_gap_where(g, stance, old, foothold)
                if gap >= lim.min_gap_m:
                    return frame, foothold, gap
                # the last try (no sideways step, no turn): where the gap is least the sole moves outward by
                # share x the push (a toe turning in early in the swing), so push that much more
                last = n == len(tries) - 1
                outward += (lim.min_gap_m - gap + PUSH_MARGIN_M) / (max(share, MIN_PUSH_SHARE) if last else 1.0)
                if outward > lim.max_side_m + lim.min_gap_m:
                    break
        frame = self.frame.moved(forward, 0.0, 0.0)  # last resort: no sideways step, no turn, no push
        foothold = frame.foot(swing_side, self.half_width_m)
        return frame, foothold, swept_gap_m(g, stance, old, foothold)


def _same(a: FootPlacement, b: FootPlacement) -> bool:
    return abs(a.x_m - b.x_m) <= 1e-9 and abs(a.y_m - b.y_m) <= 1e-9 and abs(a.yaw_rad - b.yaw_rad) <= 1e-9


def with_limits(planner: FootstepPlanner, limits: SteerLimits) -> FootstepPlanner:
    """The same planner state under other limits (a drive changing its speed scale)."""
    other = planner.copy()
    other.limits = replace(limits)
    return other


__all__ = ["Footstep", "FootstepPlanner", "WalkFrame", "frame_of", "leading_side", "STILL"]
