"""A walk over a terrain: the flat walker's segments on level ground, Zhang's elsewhere.

Steps whose three footholds (rear, stance, target) lie on one surface with no edge between
are the flat walker's ``StepSegment`` (the Boulic style), lifted to that surface's height by
``LevelSegment``. Every other step is a ``TerrainStepSegment`` (step.py: feet in the world,
swing.py: the swing foot's path), and consecutive terrain steps form a ``TerrainRun`` (run_pelvis.py:
Zhang's Bezier pelvis through MS and MDS points, the MDS points chosen by the two-level grid
search). Every leg angle of a terrain step comes from 2-link IK, pelvis to ankle.

A run's pelvis path starts from the state the previous segment handed over (position and
velocity, so joint velocities are continuous at the switch) and ends at a hand-over point at the
run's last heel strike, from which the next segment (flat step, settle) takes over through
``WalkState``. The flat walker's classes are used unchanged: ``LevelSegment`` adds the surface
height to their root, since they assume the ground at y = 0.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np

from ..contact import grounded_ankle
from ..geometry import LegGeometry
from ..walk_segments import CrouchSegment, GaitContext, GaitGenerationError, SettleSegment, StepSegment, WalkState
from ..trajectory import HeelStrike, Trajectory
from .envelope import StepEnvelope
from .footholds import Foothold, FootholdLimits, plan_footholds
from .legs import LegRange
from .model import Terrain
from .run_pelvis import MdsProblem, TerrainRun
from .search import SearchResult
from .step import TerrainStepSegment

_H = 1e-6


@dataclass(frozen=True)
class TerrainSettings:
    """How to walk a terrain. Lengths in metres, angles in radians.

    envelope: what one step can do between surfaces (envelope.py). weights: the search cost's
    weights of hip, knee and ankle (Zhang 2008: by default the joints' ranges normalised to the
    largest). joint_lo/joint_hi: the leg's joint limits (hip, knee, ankle), or None for no limits
    besides reach; joint_speed/joint_accel likewise for the joints' speed and acceleration limits.
    """

    envelope: StepEnvelope
    margin: float = 0.01
    clearance: float = 0.012
    weights: tuple[float, float, float] = (1.0, 1.0, 1.0)
    joint_lo: tuple[float, float, float] | None = None
    joint_hi: tuple[float, float, float] | None = None
    joint_speed: tuple[float, float, float] | None = None  # rad/s
    joint_accel: tuple[float, float, float] | None = None  # rad/s^2


def default_weights(joint_lo, joint_hi) -> tuple[float, float, float]:
    """Zhang's default weights: each joint's range over the largest range."""
    if joint_lo is None or joint_hi is None:
        return (1.0, 1.0, 1.0)
    ranges = np.asarray(joint_hi) - np.asarray(joint_lo)
    return tuple(float(r) for r in ranges / ranges.max())


class LevelSegment:
    """A flat-walker segment on a surface at ``height``: its root lifted by that height."""

    def __init__(self, inner, height: float) -> None:
        self.inner, self.height = inner, height
        self.n_frames = inner.n_frames

    def evaluate(self, u):
        angles, root = self.inner.evaluate(u)
        return angles, root + np.array([0.0, self.height])

    def end_state(self) -> WalkState:
        return self.inner.end_state()


def root_and_velocity(g: LegGeometry, state: WalkState, ground: float, duration_hint: float = 1.0):
    """World pelvis position and velocity implied by a WalkState on a surface at ``ground``."""
    pitch, rate = float(state.foot_stance[2]), float(state.foot_rate_stance[2])
    ankle = grounded_ankle(g, state.anchor_stance, pitch, ground)
    if rate != 0.0:
        side = 1.0 if pitch > 0 or (pitch == 0 and rate > 0) else -1.0
        a2 = grounded_ankle(g, state.anchor_stance, pitch + side * _H, ground)
        ankle_rate = (a2 - ankle) / (side * _H) * rate
    else:
        ankle_rate = np.zeros(2)
    return ankle - state.foot_stance[:2], ankle_rate - state.foot_rate_stance[:2]


@dataclass(frozen=True)
class TerrainStep:
    """One heel strike of a terrain walk (for the plan)."""

    index: int
    leg: str
    length_m: float
    start_s: float
    end_s: float
    foothold_m: float
    height_m: float
    method: str  # "flat" (the Boulic walker) or "terrain" (Zhang 2008)
    lift_m: float
    closing: bool = False

    def to_dict(self) -> dict:
        return dict(self.__dict__)


@dataclass
class TerrainWalk:
    """A whole terrain walk: segments, the plan, the search reports and the trajectory."""

    ctx: GaitContext
    terrain: Terrain
    settings: TerrainSettings
    footholds: list[Foothold]
    segments: list = field(default_factory=list)
    steps: list[TerrainStep] = field(default_factory=list)
    heel_strikes: list[HeelStrike] = field(default_factory=list)
    runs: list[TerrainRun] = field(default_factory=list)
    trajectory: Trajectory | None = None

    @property
    def planned_steps(self) -> list[TerrainStep]:
        return self.steps

    @property
    def search_reports(self) -> list[SearchResult]:
        return [r.result for run in self.runs for r in run.reports]

    @property
    def search_problems(self) -> list[MdsProblem]:
        """Every MDS point's search problem (region, cost, reachability), to run other searches on."""
        return [r.problem for run in self.runs for r in run.reports]


def terrain_limits(ctx: GaitContext, settings: TerrainSettings, flat_max_step: float) -> FootholdLimits:
    return FootholdLimits(ctx.geometry.foot, settings.margin, flat_max_step, settings.envelope)


def plan_terrain_walk(ctx: GaitContext, terrain: Terrain, start: float, end: float, settings: TerrainSettings,
                      flat_max_step: float, on_progress=None) -> TerrainWalk:
    """Footholds, segments and the trajectory for walking the course from ``start`` to ``end``.

    ``on_progress(k, n)``, if given, is told after each of the n steps and the trajectory (a progress bar:
    a course of stairs takes seconds)."""
    report = on_progress or (lambda k, n: None)
    footholds = plan_footholds(terrain, start, end, terrain_limits(ctx, settings, flat_max_step))
    start_hold = Foothold(start, float(terrain.height_at(start)), int(terrain.surface_index(start)))
    walk = TerrainWalk(ctx, terrain, settings, footholds)
    crouch = CrouchSegment(ctx, start, bend=True)
    _push(walk, LevelSegment(crouch, start_hold.height))
    state, t = crouch.end_state(), crouch.n_frames / ctx.rate_hz
    targets = [*footholds, footholds[-1]]  # the last one: the trailing foot closes beside the leading one
    methods = step_methods(ctx, terrain, [start_hold, start_hold, *targets], flat_max_step)
    stance, rear = start_hold, start_hold  # footholds under the stance and the rear foot
    pending: list[TerrainStepSegment] = []
    pending_start = None
    made = []
    for i, (target, method) in enumerate(zip(targets, methods)):
        closing = i == len(targets) - 1
        leg = "right" if state.stance_left else "left"
        if method == "flat":
            if pending:  # close the pending run first: its end knot hands over to the flat walker
                _close_run(walk, pending, pending_start)
                pending = []
                state = walk.segments[-1].end_state()
            seg = StepSegment(ctx, state, target.heel_x - state.anchor_stance)
            _push(walk, LevelSegment(seg, target.height))
            state = seg.end_state()
        else:
            if not pending:
                pending_start = root_and_velocity(ctx.geometry, state, stance.height) + (t,)
            seg = TerrainStepSegment(ctx, state, stance, rear, target, terrain, settings.clearance,
                                     _legs(ctx, settings), t, closing)
            pending.append(seg)
            state = seg.provisional_end_state()
        made.append(seg)
        t_end = t + seg.n_frames / ctx.rate_hz
        walk.steps.append(TerrainStep(i + 1, leg, target.heel_x - stance.heel_x, t, t_end, target.heel_x,
                                      target.height, method, 0.0, closing))
        walk.heel_strikes.append(HeelStrike(t_end, leg, target.heel_x))
        t = t_end
        rear, stance = stance, target
        if not pending:
            report(i + 1, len(targets) + 1)
    if pending:
        _close_run(walk, pending, pending_start)
        state = walk.segments[-1].end_state()
    walk.steps = [replace(step, lift_m=float(seg.lift)) for step, seg in zip(walk.steps, made)]
    settle = SettleSegment(ctx, state)
    _push(walk, LevelSegment(settle, stance.height))
    last = CrouchSegment(ctx, state.anchor_stance, bend=False)
    _push(walk, LevelSegment(last, stance.height))
    walk._final = LevelSegment(last, stance.height)
    report(len(targets), len(targets) + 1)
    walk.trajectory = _trajectory(walk)
    _verify_limits(walk)
    report(len(targets) + 1, len(targets) + 1)
    return walk


SHORT_STEP_SHARE = 0.5  # a flat step shorter than this share of the longest, next to a terrain step, is one too


def step_methods(ctx: GaitContext, terrain: Terrain, holds: list[Foothold], flat_max_step: float) -> list[str]:
    """"flat" or "terrain" for each step; ``holds`` are the footholds (start twice, then every target).

    A step is the flat walker's where its rear, stance and target footholds share one level surface
    with no edge between, except a short step (a closing step, a shuffle to the front of a tread)
    right before or after a terrain step, the step after a terrain run that ends with the feet side
    by side, and a lone flat step between two terrain steps: the flat walker brings its pelvis back
    over the feet at a closing step and sways it back a little when it starts from the feet side by
    side, which next to a terrain run would make the pelvis turn back (a loop in its path), and two
    hand-overs around one flat step leave neither side room; as part of the run it keeps moving
    forward."""
    methods = []
    for rear, stance, target in zip(holds, holds[1:], holds[2:]):
        flat = (rear.surface == stance.surface == target.surface
                and terrain.level_between(min(rear.heel_x, stance.heel_x), max(target.heel_x, stance.heel_x)
                                          + ctx.geometry.foot))
        methods.append("flat" if flat else "terrain")
    steps = [t.heel_x - s.heel_x for s, t in zip(holds[1:], holds[2:])]
    short = [abs(d) < SHORT_STEP_SHARE * flat_max_step for d in steps]
    last = len(methods) - 1
    for order in (range(last - 1, -1, -1), range(1, last)):  # before terrain steps, then after them
        for i in order:
            near = methods[i + 1] if order.step < 0 else methods[i - 1]
            if methods[i] == "flat" and short[i] and near == "terrain":
                methods[i] = "terrain"
    for i in range(1, last):  # the flat walker starting from feet side by side first sways back a little
        if methods[i] == "flat" and methods[i - 1] == "terrain" and abs(steps[i - 1]) < 1e-9:
            methods[i] = "terrain"
    for i in range(1, last):  # a lone flat step between two terrain steps: one run through it, not two hand-overs
        if methods[i] == "flat" and methods[i - 1] == methods[i + 1] == "terrain":
            methods[i] = "terrain"
    return methods


def _verify_limits(walk: TerrainWalk) -> None:
    """Refuse a walk whose terrain steps leave the joint ranges (the search samples, frames fall between)."""
    s = walk.settings
    if s.joint_lo is None:
        return
    q = walk.trajectory.angles_rad.reshape(len(walk.trajectory), 2, 3)
    lo, hi = np.asarray(s.joint_lo), np.asarray(s.joint_hi)
    bad = np.nonzero(((q < lo - 1e-9) | (q > hi + 1e-9)).any(axis=(1, 2)))[0]
    if len(bad):
        t = walk.trajectory.t_s[bad[0]]
        step = next((st for st in walk.steps if st.start_s <= t <= st.end_s), None)
        where = f"step {step.index} to x = {step.foothold_m:.3f} m" if step else f"t = {t:.2f} s"
        raise GaitGenerationError(f"{where}: the leg would leave its joint range (rise or step too large for this leg)")


def _close_run(walk: TerrainWalk, pending, start) -> None:
    root0, vel0, t0 = start
    run = TerrainRun(walk.ctx, _legs(walk.ctx, walk.settings), walk.settings.weights, pending, root0, vel0, t0)
    walk.runs.append(run)
    for seg in pending:
        _push(walk, seg)


def _legs(ctx: GaitContext, settings: TerrainSettings) -> LegRange:
    return LegRange(ctx.geometry, settings.joint_lo, settings.joint_hi, speed=settings.joint_speed,
                    accel=settings.joint_accel)


def _push(walk: TerrainWalk, segment) -> None:
    walk.segments.append(segment)


def _trajectory(walk: TerrainWalk) -> Trajectory:
    angles, roots = [], []
    for seg in walk.segments:
        a, r = seg.evaluate(np.arange(seg.n_frames) / seg.n_frames)
        angles.append(a)
        roots.append(r)
    a, r = walk._final.evaluate(1.0)
    angles.append(a)
    roots.append(r)
    angles, roots = np.concatenate(angles), np.concatenate(roots)
    t = np.arange(len(angles)) / walk.ctx.rate_hz
    return Trajectory.sagittal(t, angles, roots, walk.heel_strikes)
