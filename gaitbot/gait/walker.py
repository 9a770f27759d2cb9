"""The walker of Jing et al.'s Algorithm 2: frames every 1/rate s from a queue of step lengths.

The same segments serve both uses:
- offline: ``generate_walk`` evaluates each segment on all its frames at once (vectorised);
- online: ``OnlineWalker`` plans a step when it is appended (a few milliseconds), and
  ``next_frame`` then hands out one precomputed frame: constant work per frame, and steps may
  be appended while walking. If the queue runs dry the walker closes the feet and stands,
  which is the safe thing for a robot.

A walk starts standing with feet together (zero step length), takes the queued steps, closes
the trailing foot beside the leading one (a zero-length step) and stands (Jing et al. 2015 section 2.4).
"""

from __future__ import annotations

import math
from collections import deque
from dataclasses import dataclass

import numpy as np

from .boulic import TABLE2_CYCLE_S
from .geometry import LegGeometry
from .planning import PlannedStep
from .walk_segments import CrouchSegment, GaitContext, SettleSegment, StepSegment
from .step_length import StepLengthError, StepLengthInverse
from .trajectory import HeelStrike, Trajectory


@dataclass(frozen=True)
class WalkSettings:
    """Gait settings; lengths in the geometry's unit (metres for a robot).

    cycle_s: duration of a cycle (two steps), fixed as in Jing et al. 2015 (Table 2: 1.346 s); rounded
    so that a step is a whole number of frames.
    clearance: least height of the whole swing sole from 20% to 80% of each swing.
    intermediate_steps: m of eq. 14, intermediate step lengths between consecutive steps.
    crouch_knee_deg: knee bend of the start and end crouch (see walk_segments.py for why).
    settle_s: duration of the stand -> crouch and crouch -> stand phases.
    pitch_limit_deg: the model's sole pitch is smoothly saturated to +- this (see walk_segments.foot_of).
    """

    cycle_s: float = TABLE2_CYCLE_S
    rate_hz: float = 60.0
    clearance: float = 0.02
    intermediate_steps: int = 2
    crouch_knee_deg: float = 25.0
    settle_s: float = 0.5
    pitch_limit_deg: float = 20.0

    def __post_init__(self) -> None:
        for name in ("cycle_s", "rate_hz", "settle_s", "crouch_knee_deg", "pitch_limit_deg"):
            value = getattr(self, name)
            if not (math.isfinite(value) and value > 0):
                raise ValueError(f"{name} must be a positive number, got {value!r}")
        if not (math.isfinite(self.clearance) and self.clearance >= 0):
            raise ValueError(f"clearance must be 0 or more, got {self.clearance!r}")
        if not (isinstance(self.intermediate_steps, int) and 0 <= self.intermediate_steps <= 20):
            raise ValueError(f"intermediate_steps must be an integer from 0 to 20, got {self.intermediate_steps!r}")


_INVERSE_CACHE: dict[tuple, StepLengthInverse] = {}


def _step_frames(settings: WalkSettings) -> int:
    return max(4, round(settings.cycle_s / 2.0 * settings.rate_hz))


def step_length_inverse(geometry: LegGeometry, settings: WalkSettings = WalkSettings()) -> StepLengthInverse:
    """The Boulic step-length inverse of this leg at the settings' whole-frame cycle (built once, cached)."""
    cycle_s = 2.0 * _step_frames(settings) / settings.rate_hz
    key = (geometry, cycle_s)
    if key not in _INVERSE_CACHE:
        _INVERSE_CACHE[key] = StepLengthInverse.build(geometry, cycle_s)
    return _INVERSE_CACHE[key]


def longest_step_m(geometry: LegGeometry, settings: WalkSettings = WalkSettings()) -> float:
    """The longest step this leg reaches at the settings' cycle (Boulic region A, RV < 0.5): the bound of
    the planar walker's steps, and of a balanced robot's, whose swing shapes come from it."""
    return step_length_inverse(geometry, settings).max_step_length


def make_context(geometry: LegGeometry, settings: WalkSettings = WalkSettings()) -> GaitContext:
    """Build (and cache) what every segment of a walk needs."""
    step_frames = _step_frames(settings)
    return GaitContext(
        geometry=geometry,
        inverse=step_length_inverse(geometry, settings),
        rate_hz=settings.rate_hz,
        step_frames=step_frames,
        clearance=settings.clearance,
        intermediate_steps=settings.intermediate_steps,
        crouch_knee_rad=math.radians(settings.crouch_knee_deg),
        settle_frames=max(2, round(settings.settle_s * settings.rate_hz)),
        pitch_limit_rad=math.radians(settings.pitch_limit_deg),
    )


def validate_steps(ctx: GaitContext, step_lengths) -> list[float]:
    """Check a list of step lengths (metres); raise StepLengthError naming the bad one."""
    steps = list(step_lengths)
    if not steps:
        raise StepLengthError("no steps given: give at least one step length")
    return [ctx.inverse.validate(sl, what=f"step {i + 1} length") for i, sl in enumerate(steps)]


class OnlineWalker:
    """Frame-by-frame walker. ``append_step`` plans; ``next_frame`` returns (t_s, angles_rad(6), root(2)).

    Returns None after the final standing frame.
    """

    def __init__(self, geometry: LegGeometry, settings: WalkSettings = WalkSettings(), anchor: float = 0.0) -> None:
        self.ctx = make_context(geometry, settings)
        self.segments: list = []
        self.heel_strikes: list[HeelStrike] = []
        self.planned_steps: list[PlannedStep] = []
        self._frames: deque = deque()
        self._frame_index = 0
        self._planned_frames = 0
        self._finished = False
        first = CrouchSegment(self.ctx, anchor, bend=True)
        self._push(first)
        self._state = first.end_state()

    @property
    def period_s(self) -> float:
        return 1.0 / self.ctx.rate_hz

    @property
    def finished(self) -> bool:
        return self._finished

    def append_step(self, step_length: float, closing: bool = False) -> StepSegment:
        """Queue one step of ``step_length`` metres (heel strike that far beyond the previous one)."""
        if self._finished:
            raise RuntimeError("the walk has already been closed; start a new walker")
        sl = self.ctx.inverse.validate(step_length, what="step length")
        segment = StepSegment(self.ctx, self._state, sl)
        start_t = self._planned_frames / self.ctx.rate_hz
        self._push(segment)
        strike_t = self._planned_frames / self.ctx.rate_hz
        leg = "right" if segment.state.stance_left else "left"
        self.heel_strikes.append(HeelStrike(strike_t, leg, segment.foothold))
        self.planned_steps.append(PlannedStep(len(self.planned_steps) + 1, leg, sl, segment.rvs[-1], start_t,
                                              strike_t, segment.foothold, closing))
        self._state = segment.end_state()
        return segment

    def finish(self) -> None:
        """Close the trailing foot beside the leading one, settle and stand."""
        if self._finished:
            return
        if self._state.step_length != 0.0 or len(self.heel_strikes) == 0:
            self.append_step(0.0, closing=True)
        settle = SettleSegment(self.ctx, self._state)
        self._push(settle)
        last = CrouchSegment(self.ctx, self._state.anchor_stance, bend=False)
        self._push(last)
        angles, root = last.evaluate(1.0)
        self._frames.append((angles[0], root[0]))
        self._planned_frames += 1
        self._finished = True

    def _push(self, segment) -> None:
        self.segments.append(segment)
        angles, root = segment.evaluate(np.arange(segment.n_frames) / segment.n_frames)
        self._frames.extend(zip(angles, root))
        self._planned_frames += segment.n_frames

    def next_frame(self):
        """The next frame (t_s, angles_rad (6,), root_m (2,)), or None when the walk is over."""
        if not self._frames and not self._finished:
            self.finish()  # queue ran dry: close the feet and stand
        if not self._frames:
            return None
        angles, root = self._frames.popleft()
        t = self._frame_index / self.ctx.rate_hz
        self._frame_index += 1
        return t, angles, root


def plan_walk(geometry: LegGeometry, step_lengths, settings: WalkSettings = WalkSettings()) -> OnlineWalker:
    """A closed walker holding every frame of the walk (standing, the steps, closing step, standing)."""
    walker = OnlineWalker(geometry, settings)
    for sl in validate_steps(walker.ctx, step_lengths):
        walker.append_step(sl)
    walker.finish()
    return walker


def trajectory_of(walker: OnlineWalker) -> Trajectory:
    """All remaining frames of a closed walker as one Trajectory."""
    frames = list(walker._frames)
    angles = np.array([f[0] for f in frames])
    root = np.array([f[1] for f in frames])
    t = (walker._frame_index + np.arange(len(frames))) / walker.ctx.rate_hz
    return Trajectory.sagittal(t, angles, root, walker.heel_strikes)


def generate_walk(geometry: LegGeometry, step_lengths, settings: WalkSettings = WalkSettings()) -> Trajectory:
    """The whole walk as arrays: standing, the given steps, closing step, standing."""
    return trajectory_of(plan_walk(geometry, step_lengths, settings))
