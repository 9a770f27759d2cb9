"""A walk over a terrain: the flat walker's segments on level ground, seed 003's elsewhere.

Steps whose three footholds (rear, stance, target) lie on one surface with no edge between
are the flat walker's ``StepSegment`` (the Boulic style), lifted to that surface's height by
``LevelSegment``. Every other step is a ``TerrainStepSegment``:

- the stance foot settles from its landing pitch to flat (through ``flat_pause``, so the pivot
  changes from heel to toe only at zero pitch rate) and then stays parallel to its tread;
- the rear foot stays pinned on its tread and rolls onto its toe (TOE_OFF_RAD), coming to rest
  at lift-off (LIFT_OFF_U of the step);
- the swing foot moves in the world from rest to rest, the level change happening while over
  the higher surface, lifted by the least amount that keeps the sole ``clearance`` above every
  tread edge it passes and above the terrain from 20% to 80% of the swing; it lands flat on its
  tread. Once the pelvis is known its sole tips (smoothly) where a level sole would bend the
  ankle past its range, and the lift is found again for the tipped sole;
- a terrain step lasts TERRAIN_STEP_TIME flat steps (higher lifts at the same joint speeds);
- the pelvis is seed 003's Bezier path (pelvis.py) through MS points (over the stance ankle at
  the crouch height) and MDS points chosen by the two-level grid search (search.py) that
  minimises the supporting legs' weighted squared joint accelerations;
- every leg angle comes from 2-link IK, pelvis to ankle.

Consecutive terrain steps form a *run*: one pelvis path from the state the previous segment
handed over (position and velocity, so joint velocities are continuous at the switch) to an
end knot at the run's last heel strike, from which the next segment (flat step, settle) takes
over through ``WalkState``. The flat walker's classes are used unchanged: ``LevelSegment`` adds
the surface height to their root, since they assume the ground at y = 0.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..contact import grounded_ankle, heel_pinned_ankle
from ..geometry import LegGeometry, foot_points, leg_ik
from ..segments import (MIN_KNEE_RAD, CrouchSegment, GaitContext, GaitGenerationError, SettleSegment, StepSegment,
                        WalkState, crouch_leg_scale, flat_pause, flat_pause_inverse, flat_pause_slope)
from ..smooth import hermite_segment, plateau, smootherstep
from ..trajectory import HeelStrike, Trajectory
from .footholds import Foothold, FootholdLimits, plan_footholds
from .model import Terrain
from .pelvis import Knot, PelvisPath
from .search import SearchResult, two_level_search

SWING_HOLD = 0.0  # share of the swing at each end with no horizontal motion
LIFT_RISE = 0.25  # share of the swing over which the lift rises (and falls)
SWING_PITCH_SHARE = 0.35  # the sole levels out over this share of the swing
CLEARANCE_WINDOW = (0.2, 0.8)
MS_SOLE_SHARE = 0.5  # at mid-stance the pelvis is over this share of the sole ahead of the ankle
MS_KNEE_RAD = np.radians(25.0)  # stance knee at mid-stance: the pelvis's highest point (seed 003's MS)
TERRAIN_STEP_TIME = 1.5  # a terrain step takes this many flat steps' time: higher lifts at the same joint speeds
LIFT_OFF_U = 0.25  # share of a terrain step in double support (the rear foot lifts off here)
TOE_OFF_RAD = np.radians(20.0)  # the rear foot rolls onto its toe by this pitch before it lifts
COST_SAMPLES = 60
LIMIT_SPARE_RAD = np.radians(1.0)  # the search keeps this far inside the joint limits (frames fall between samples)
_H = 1e-6


@dataclass(frozen=True)
class TerrainSettings:
    """How to walk a terrain. Lengths in metres, angles in radians.

    weights: the search cost's weights of hip, knee and ankle (seed 003: by default the joints'
    ranges normalised to the largest). joint_lo/joint_hi: the leg's joint limits (hip, knee,
    ankle), or None for no limits besides reach.
    """

    margin: float = 0.01
    clearance: float = 0.012
    max_step: float = 0.165
    max_rise: float = 0.055
    max_travel: float = 0.22
    weights: tuple[float, float, float] = (1.0, 1.0, 1.0)
    joint_lo: tuple[float, float, float] | None = None
    joint_hi: tuple[float, float, float] | None = None
    mds_depth_share: float = 0.2  # the MDS region reaches this many leg lengths below the lower MS


def default_weights(joint_lo, joint_hi) -> tuple[float, float, float]:
    """Seed 003's default weights: each joint's range over the largest range."""
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


def _rest_pitch_target(p0: float, rate_u: float, limit: float) -> float:
    """Where a pinned rear foot comes to rest before lifting: rolled onto its toe by TOE_OFF_RAD (or
    further if it came in rolling faster), never past the pitch limit. Rolling onto the toe raises the
    ankle towards the hip: what lets a short leg take a stair-long step."""
    return float(max(min(-TOE_OFF_RAD, p0 + rate_u / 3.0), -max(limit, TOE_OFF_RAD)))


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


class TerrainStepSegment:
    """One step off the flat: from a heel strike (or the crouch) to the next heel strike on ``target``."""

    def __init__(self, ctx: GaitContext, state: WalkState, ground_stance: float, ground_rear: float,
                 target: Foothold, terrain: Terrain, settings: TerrainSettings, t0: float, closing: bool = False):
        self.ctx, self.state, self.terrain, self.settings = ctx, state, terrain, settings
        self.ground_stance, self.ground_rear = ground_stance, ground_rear
        self.target, self.t0, self.closing = target, t0, closing
        self.n_frames = int(round(ctx.step_frames * TERRAIN_STEP_TIME))
        self.duration = self.n_frames / ctx.rate_hz
        self.u_lo = LIFT_OFF_U
        self.foothold = target.heel_x
        self.step_length = target.heel_x - state.anchor_stance
        self.what = f"step to x = {target.heel_x:.3f} m (height {target.height:.3f} m)"
        g = ctx.geometry
        raw = flat_pause_inverse(state.foot_stance[2])
        slope = float(flat_pause_slope(raw))
        self._stance_raw0 = raw
        self._stance_raw_rate0 = (state.foot_rate_stance[2] / slope if slope > 1e-9 else 0.0) * self.duration * self.u_lo
        rear_rate_u = state.pitch_rate_rear * self.duration * self.u_lo
        self._rear0, self._rear_rate0 = state.pitch_rear, rear_rate_u
        self._rear_lo = _rest_pitch_target(state.pitch_rear, rear_rate_u, ctx.pitch_limit_rad)
        lift_off = self._pinned(np.array([self.u_lo]))[0]
        self._lift_off = lift_off
        self._landing = np.array([*heel_pinned_ankle(g, self.foothold, 0.0, target.height), 0.0])
        self.pelvis: PelvisPath | None = None
        self._ankle_room = None
        self.lift = 0.0
        self._plan_swing()

    # --- feet in the world ---------------------------------------------------------------------
    def stance_world(self, u):
        u = np.atleast_1d(np.asarray(u, dtype=float))
        x = np.clip(u / self.u_lo, 0.0, 1.0)
        raw = hermite_segment(x, np.array([self._stance_raw0]), np.array([self._stance_raw_rate0]),
                              np.zeros(1), np.zeros(1))[:, 0]
        pitch = flat_pause(raw)
        ankle = grounded_ankle(self.ctx.geometry, self.state.anchor_stance, pitch, self.ground_stance)
        return np.column_stack([ankle, pitch])

    def _pinned(self, u):
        x = np.clip(u / self.u_lo, 0.0, 1.0)
        pitch = hermite_segment(x, np.array([self._rear0]), np.array([self._rear_rate0]), np.array([self._rear_lo]),
                                np.zeros(1))[:, 0]
        ankle = grounded_ankle(self.ctx.geometry, self.state.anchor_rear, pitch, self.ground_rear)
        return np.column_stack([ankle, pitch])

    def _swing_shape(self, s):
        """Ankle (x, y) and pitch of the swing foot at swing progress s, without the lift."""
        s = np.atleast_1d(np.asarray(s, dtype=float))
        p0, p1 = self._lift_off, self._landing
        xs = p0[0] + (p1[0] - p0[0]) * smootherstep((s - SWING_HOLD) / (1 - 2 * SWING_HOLD))
        dy = p1[1] - p0[1]
        level = smootherstep(s / 0.5) if dy > 0 else smootherstep((s - 0.5) / 0.5)
        ys = p0[1] + dy * level
        share = np.clip(s / SWING_PITCH_SHARE, 0.0, 1.0)
        pitch = p0[2] * (1 - smootherstep(share))
        out = np.column_stack([xs, ys, pitch])
        if self._ankle_room is not None:
            out[:, 2] = self._ankle_room(s, out, self.lift)
        return out

    def _plan_swing(self) -> None:
        """The least lift keeping the sole clear: clearance over edges passed and in the window, above ground always.

        The sole height is linear in the lift, so one pass finds it exactly on the samples; aiming 2%
        high keeps the frames between samples clear too."""
        g, cl = self.ctx.geometry, self.settings.clearance
        s = np.linspace(0.0, 1.0, 801)
        shape = self._swing_shape(s)
        heel, toe = foot_points(g, shape[:, :2], shape[:, 2])
        lo_x = min(self._lift_off[0], self._landing[0]) - g.heel_back
        hi_x = max(self._lift_off[0], self._landing[0]) + g.toe_forward
        edges = [(x, top) for x, top in self.terrain.edges() if lo_x - 1e-9 < x < hi_x + 1e-9]
        inside = (s >= CLEARANCE_WINDOW[0]) & (s <= CLEARANCE_WINDOW[1])
        aim_window = np.where(inside, cl * 1.02 + 1e-6, 0.0)
        need = np.maximum(self.terrain.height_at(heel[:, 0]) + aim_window - heel[:, 1],
                          self.terrain.height_at(toe[:, 0]) + aim_window - toe[:, 1])
        span_x = toe[:, 0] - heel[:, 0]
        for x, top in edges:
            over = (heel[:, 0] <= x) & (x <= toe[:, 0])
            share = np.where(np.abs(span_x) > 1e-12, (x - heel[:, 0]) / np.where(np.abs(span_x) > 1e-12, span_x, 1), 0)
            sole_y = heel[:, 1] + share * (toe[:, 1] - heel[:, 1])
            need = np.where(over, np.maximum(need, top + cl * 1.02 + 1e-6 - sole_y), need)
        shape_lift = plateau(s, LIFT_RISE)
        usable = shape_lift > 1e-9
        bad = (need > 1e-9) & ~usable
        if bad.any():
            raise GaitGenerationError(f"{self.what}: the swing foot would touch the terrain where it cannot be lifted")
        short = (need > 1e-9) & usable
        self.lift = max(0.0, float((need[short] / shape_lift[short]).max())) if short.any() else 0.0
        self.edges_passed = edges

    def swing_world(self, u):
        u = np.atleast_1d(np.asarray(u, dtype=float))
        s = np.clip((u - self.u_lo) / (1.0 - self.u_lo), 0.0, 1.0)
        pose = self._swing_shape(s)
        pose[:, 1] += self.lift * plateau(s, LIFT_RISE)
        return pose

    def fit_swing_to_pelvis(self, ankle_lo: float, ankle_hi: float, rounds: int = 12) -> None:
        """Once the pelvis is known: tip the swing sole where a level sole would bend the ankle past its
        range (a knee flexed to lift the foot leans the shank back), smoothly saturating the ankle angle
        inside [ankle_lo, ankle_hi]; then lift again for the new sole. A few rounds settle both."""
        g = self.ctx.geometry

        def room(s, pose, lift):
            u = self.u_lo + s * (1.0 - self.u_lo)
            root = self.pelvis(self.t0 + u * self.duration)
            ankle = pose[:, :2].copy()
            ankle[:, 1] += lift * plateau(s, LIFT_RISE)
            q = leg_ik(g, ankle - root, pose[:, 2])
            shank = q[:, 0] - q[:, 1]
            fitted = shank + smooth_clamp(pose[:, 2] - shank, ankle_lo + ANKLE_SPARE_RAD, ankle_hi - ANKLE_SPARE_RAD)
            return pose[:, 2] + plateau(s, 0.1) * (fitted - pose[:, 2])  # untouched at lift-off and landing

        self._ankle_room = room
        for _ in range(rounds):
            before = self.lift
            self._plan_swing()
            self.lift = max(self.lift, before)  # never lower: the sequence rises to a lift that holds
            if self.lift - before < 1e-6 * g.leg_length:
                break

    def other_world(self, u):
        u = np.atleast_1d(np.asarray(u, dtype=float))
        return np.where((u <= self.u_lo)[:, None], self._pinned(u), self.swing_world(u))

    def feet_world(self, u):
        """(stance pose, other pose, other supporting?) in the world for progress u."""
        u = np.atleast_1d(np.asarray(u, dtype=float))
        return self.stance_world(u), self.other_world(u), u <= self.u_lo

    # --- the segment ---------------------------------------------------------------------------
    def evaluate(self, u):
        u = np.atleast_1d(np.asarray(u, dtype=float))
        root = self.pelvis(self.t0 + u * self.duration)
        stance, other, _ = self.feet_world(u)
        g = self.ctx.geometry
        qs, qo = _ik(g, stance, root, self.what), _ik(g, other, root, self.what)
        left, right = (qs, qo) if self.state.stance_left else (qo, qs)
        return np.concatenate([left, right], axis=-1), root

    def end_state(self) -> WalkState:
        t1 = self.t0 + self.duration
        root, vel = self.pelvis(t1)[0], self.pelvis.velocity(t1)[0]
        return WalkState(
            stance_left=not self.state.stance_left,
            anchor_stance=self.foothold,
            anchor_rear=self.state.anchor_stance,
            foot_stance=np.array([*(self._landing[:2] - root), 0.0]),
            foot_rate_stance=np.array([*(-vel), 0.0]),
            pitch_rear=0.0,
            pitch_rate_rear=0.0,
            step_length=self.step_length,
        )


ANKLE_SPARE_RAD = np.radians(1.0)  # the swing ankle keeps this far from its limits
ANKLE_SOFT_RAD = np.radians(10.0)  # the swing ankle's saturation starts this far inside its range


def smooth_clamp(x, lo: float, hi: float, soft: float = ANKLE_SOFT_RAD):
    """Identity inside [lo + soft, hi - soft]; beyond, approaches lo or hi smoothly (tanh), never reaching them."""
    x = np.asarray(x, dtype=float)
    a, b = hi - soft, lo + soft
    up = a + soft * np.tanh((x - a) / soft)
    down = b + soft * np.tanh((x - b) / soft)
    return np.where(x > a, up, np.where(x < b, down, x))


def _ik(g: LegGeometry, pose, root, what: str):
    try:
        return leg_ik(g, pose[:, :2] - root, pose[:, 2])
    except ValueError:
        raise GaitGenerationError(f"{what}: a foot is out of the leg's reach") from None


@dataclass
class RunReport:
    """What the grid search did for one MDS point of a run."""

    step_index: int
    result: SearchResult


class TerrainRun:
    """Consecutive terrain steps sharing one pelvis path (seed 003)."""

    def __init__(self, ctx: GaitContext, settings: TerrainSettings, segments, start_root, start_vel, t_start: float):
        self.ctx, self.settings, self.segments = ctx, settings, segments
        g = ctx.geometry
        self.height_ms = g.leg_length * crouch_leg_scale(g, MS_KNEE_RAD)
        self.reach = g.leg_length * crouch_leg_scale(g, MIN_KNEE_RAD)
        knee_max = settings.joint_hi[1] if settings.joint_hi is not None else np.radians(150.0)
        self.reach_min = g.leg_length * crouch_leg_scale(g, knee_max)
        self.reports: list[RunReport] = []
        self._plan(np.asarray(start_root, float), np.asarray(start_vel, float), t_start)

    def _ms_knot(self, seg: TerrainStepSegment, t: float) -> Knot:
        ankle = seg.stance_world(np.array([1.0]))[0]
        g = self.ctx.geometry
        mid_sole = seg.state.anchor_stance + g.heel_back + MS_SOLE_SHARE * (g.foot - g.heel_back)
        above = np.sqrt(self.height_ms**2 - (mid_sole - ankle[0]) ** 2)  # the crouch's hip-to-ankle distance
        return Knot(t, (float(mid_sole), float(ankle[1] + above)), (0.0, 0.0), "MS")

    def _plan(self, root0, vel0, t_start: float) -> None:
        segs = self.segments
        start = Knot(t_start, tuple(root0), tuple(vel0), "start")
        ms = [self._ms_knot(s, s.t0 + s.duration * (1 + s.u_lo) / 2) for s in segs]
        last = segs[-1]
        t_end = last.t0 + last.duration
        stance_end = last.stance_world(np.array([1.0]))[0]
        landed = last._landing
        x_end = 0.5 * (stance_end[0] + landed[0])
        r_end = 0.97 * self.ctx.geometry.leg_length * crouch_leg_scale(self.ctx.geometry, np.radians(10.0))
        y_reach = min(a[1] + np.sqrt(max(r_end**2 - (x_end - a[0]) ** 2, 0.0)) for a in (stance_end, landed))
        y_end = min(max(stance_end[1], landed[1]) + self.height_ms, y_reach)
        chain = [start, *ms]
        # horizontal velocities at MS knots: central differences of the knot positions
        x_after = [k.pos[0] for k in ms[1:]] + [x_end]
        t_after = [k.t for k in ms[1:]] + [t_end]
        x_before = [k.pos[0] for k in chain[:-1]]
        t_before = [k.t for k in chain[:-1]]
        ms = [Knot(k.t, k.pos, ((xa - xb) / (ta - tb), 0.0), "MS")
              for k, xa, ta, xb, tb in zip(ms, x_after, t_after, x_before, t_before)]
        v_end = (x_end - ms[-1].pos[0]) / (t_end - ms[-1].t)
        end = Knot(t_end, (float(x_end), float(y_end)), (float(v_end), 0.0), "end")
        knots = [start]
        for k, seg in enumerate(segs):
            prev, nxt = knots[-1], ms[k]
            t_mds = seg.t0 + seg.duration * seg.u_lo / 2
            mds = self._search_mds(k, prev, nxt, t_mds)
            knots += [mds, nxt]
        knots.append(end)
        self.knots = knots
        self.path = PelvisPath(knots)
        lo, hi = self.settings.joint_lo, self.settings.joint_hi
        ankle_lo, ankle_hi = (lo[2], hi[2]) if lo is not None else (-np.radians(60.0), np.radians(60.0))
        for seg in segs:
            seg.pelvis = self.path
            seg.fit_swing_to_pelvis(ankle_lo, ankle_hi)

    # --- seed 003's search -------------------------------------------------------------------
    def _feet(self, t):
        """World poses (n, 3) of both feet (as left, right), and whether each supports, at times t."""
        t = np.atleast_1d(np.asarray(t, dtype=float))
        left, right = np.empty((len(t), 3)), np.empty((len(t), 3))
        sup_l, sup_r = np.zeros(len(t), bool), np.zeros(len(t), bool)
        for seg in self.segments:
            inside = (t >= seg.t0 - 1e-12) & (t <= seg.t0 + seg.duration + 1e-12)
            if not inside.any():
                continue
            u = (t[inside] - seg.t0) / seg.duration
            stance, other, other_sup = seg.feet_world(u)
            if seg.state.stance_left:
                left[inside], right[inside], sup_l[inside], sup_r[inside] = stance, other, True, other_sup
            else:
                right[inside], left[inside], sup_r[inside], sup_l[inside] = stance, other, True, other_sup
        return left, right, sup_l, sup_r

    def _angles(self, pose, root, support=None):
        """Leg angles, or None where out of reach or joint range (a swing ankle is fitted later: not checked)."""
        rel = pose[:, :2] - root
        d = np.hypot(rel[:, 0], rel[:, 1])
        if np.any(d > self.reach) or np.any(d < self.reach_min):
            return None
        q = leg_ik(self.ctx.geometry, rel, pose[:, 2])
        s = self.settings
        if s.joint_lo is not None:
            bad = (q < np.asarray(s.joint_lo) + LIMIT_SPARE_RAD) | (q > np.asarray(s.joint_hi) - LIMIT_SPARE_RAD)
            if support is not None:
                bad[:, 2] &= support
            if bad.any():
                return None
        return q

    def _search_mds(self, k: int, prev: Knot, nxt: Knot, t_mds: float) -> Knot:
        vx = (nxt.pos[0] - prev.pos[0]) / (nxt.t - prev.t)
        depth = self.settings.mds_depth_share * self.ctx.geometry.leg_length
        y_hi = max(prev.pos[1], nxt.pos[1])
        region = (prev.pos[0], nxt.pos[0], min(prev.pos[1], nxt.pos[1]) - depth, y_hi)
        t = np.linspace(prev.t, nxt.t, COST_SAMPLES)
        dt = t[1] - t[0]
        left, right, sup_l, sup_r = self._feet(t)
        at_mds = self._feet(np.array([t_mds]))
        w = np.asarray(self.settings.weights, dtype=float)

        def reachable(p) -> bool:
            root = np.asarray(p, dtype=float)[None, :]
            return all(self._angles(pose, root, sup) is not None for pose, sup in zip(at_mds[:2], at_mds[2:]))

        def cost(p) -> float:
            path = PelvisPath([prev, Knot(t_mds, (float(p[0]), float(p[1])), (vx, 0.0), "MDS"), nxt])
            root = path(t)
            total = 0.0
            for pose, sup in ((left, sup_l), (right, sup_r)):
                q = self._angles(pose, root, sup)
                if q is None:
                    return np.inf
                acc = (q[2:] - 2 * q[1:-1] + q[:-2]) / dt**2
                total += float(((acc**2 @ w) * sup[1:-1]).sum() * dt)
            return total

        result = two_level_search(region, cost, reachable)
        seg = self.segments[k]
        if not np.isfinite(result.cost):
            raise GaitGenerationError(f"{seg.what}: no pelvis height in double support lets both legs reach "
                                      f"their feet within the joint limits (rise or step too large for this leg)")
        self.reports.append(RunReport(k, result))
        self.cost_inputs = getattr(self, "cost_inputs", []) + [(region, cost, reachable)]
        return Knot(t_mds, result.point, (vx, 0.0), "MDS")


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
    method: str  # "flat" (the Boulic walker) or "terrain" (seed 003)
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


def terrain_limits(ctx: GaitContext, settings: TerrainSettings, flat_max_step: float) -> FootholdLimits:
    return FootholdLimits(ctx.geometry.foot, settings.margin, min(flat_max_step, settings.max_step),
                          settings.max_step, settings.max_rise, settings.max_travel)


def plan_terrain_walk(ctx: GaitContext, terrain: Terrain, start: float, end: float, settings: TerrainSettings,
                      flat_max_step: float) -> TerrainWalk:
    """Footholds, segments and the trajectory for walking the course from ``start`` to ``end``."""
    footholds = plan_footholds(terrain, start, end, terrain_limits(ctx, settings, flat_max_step))
    start_hold = Foothold(start, float(terrain.height_at(start)), int(terrain.surface_index(start)))
    walk = TerrainWalk(ctx, terrain, settings, footholds)
    crouch = CrouchSegment(ctx, start, bend=True)
    _push(walk, LevelSegment(crouch, start_hold.height))
    state, t = crouch.end_state(), crouch.n_frames / ctx.rate_hz
    stance, rear = start_hold, start_hold  # footholds under the stance and the rear foot
    targets = [*footholds, footholds[-1]]  # the last one: the trailing foot closes beside the leading one
    pending: list[TerrainStepSegment] = []
    pending_start = None
    for i, target in enumerate(targets):
        closing = i == len(targets) - 1
        flat = (stance.surface == rear.surface == target.surface
                and terrain.level_between(min(rear.heel_x, stance.heel_x), max(target.heel_x, stance.heel_x)
                                          + ctx.geometry.foot))
        leg = "right" if state.stance_left else "left"
        if flat and not pending:
            seg = StepSegment(ctx, state, target.heel_x - state.anchor_stance)
            _push(walk, LevelSegment(seg, target.height))
            method, lift = "flat", float(seg.lift)
            state = seg.end_state()
        else:
            if flat:  # close the pending run first: its end knot hands over to the flat walker
                _close_run(walk, pending, pending_start)
                pending = []
                state = walk.segments[-1].end_state()
                seg = StepSegment(ctx, state, target.heel_x - state.anchor_stance)
                _push(walk, LevelSegment(seg, target.height))
                method, lift = "flat", float(seg.lift)
                state = seg.end_state()
            else:
                if not pending:
                    pending_start = root_and_velocity(ctx.geometry, state, stance.height) + (t,)
                seg = TerrainStepSegment(ctx, state, stance.height, rear.height, target, terrain, settings, t, closing)
                pending.append(seg)
                method, lift = "terrain", float(seg.lift)
                state = _provisional_state(seg)
        t_end = t + seg.n_frames / ctx.rate_hz
        walk.steps.append(TerrainStep(i + 1, leg, target.heel_x - stance.heel_x, t, t_end, target.heel_x,
                                      target.height, method, lift, closing))
        walk.heel_strikes.append(HeelStrike(t_end, leg, target.heel_x))
        t = t_end
        rear, stance = stance, target
    if pending:
        _close_run(walk, pending, pending_start)
        state = walk.segments[-1].end_state()
    settle = SettleSegment(ctx, state)
    _push(walk, LevelSegment(settle, stance.height))
    last = CrouchSegment(ctx, state.anchor_stance, bend=False)
    _push(walk, LevelSegment(last, stance.height))
    walk._final = LevelSegment(last, stance.height)
    walk.trajectory = _trajectory(walk)
    _verify_limits(walk)
    return walk


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


def _provisional_state(seg: TerrainStepSegment) -> WalkState:
    """The state after a terrain step as far as the next terrain step needs it before the pelvis exists."""
    return WalkState(not seg.state.stance_left, seg.foothold, seg.state.anchor_stance, np.zeros(3), np.zeros(3),
                     0.0, 0.0, seg.step_length)


def _close_run(walk: TerrainWalk, pending, start) -> None:
    root0, vel0, t0 = start
    run = TerrainRun(walk.ctx, walk.settings, pending, root0, vel0, t0)
    walk.runs.append(run)
    for seg in pending:
        _push(walk, seg)


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
    return Trajectory(t, angles, roots, tuple(walk.heel_strikes))
