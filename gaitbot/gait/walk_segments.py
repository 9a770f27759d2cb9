"""Pieces of a walk, each evaluated on arrays of progress u in [0, 1].

A walk is: stand -> crouch (both feet flat), one StepSegment per heel strike, a SettleSegment
back to the crouch with both feet flat, crouch -> stand. Each piece starts from the exact state
(foot poses, their rates, foot anchors) in which the previous one ended, so joint angles and
velocities are continuous across every boundary.

Bent knees. Straight knees are a singular pose for leg inverse kinematics: near it a small change
of hip-to-ankle distance needs a large knee velocity, and the Boulic model keeps the stance knee
at 3 degrees. So, as small servo bipeds do, the robot walks with bent knees: the model's foot
pose relative to the hip (ankle x, y and sole pitch, from the Boulic angles) is scaled by
``leg_scale`` < 1 towards the hip, and every leg angle comes from 2-link IK of that foot pose.
The style (foot path shape, sole pitch, timing) is the model's; the straight standing pose maps
to the crouch, which the walk reaches from standing (and leaves for standing) in joint space with
both feet flat.

Within a step (docs/gait-model.md section 3, "what the papers do not say"), foot poses relative to
the hip are corrected where contact geometry demands it:
- stance foot: the model's, plus a correction that fades out over the first half of the step
  (it absorbs the landing pose and velocity) and one that fades in over the second half and
  lowers the hip so that, at the next heel strike, the front heel touches the ground at its
  foothold while the rear foot is still on its toe (true double support);
- root: from the stance foot's rolling anchor, closed form (contact.py), never climbing;
- rear foot until its toe-off: pinned on the ground, pitch from the model;
- swing foot: the model's own path, corrected at both ends by cubic Hermite terms so it leaves
  from the pinned foot and lands with the heel at rest on the foothold, lifted by the least
  amount that keeps the whole sole ``clearance`` above ground from 20% to 80% of the swing
  (and above ground throughout).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from gaitbot.errors import UserError

from .blend import BoulicBlend
from .boulic import toe_off_phase
from .contact import ankle_in_body, grounded_ankle, heel_pinned_ankle, leg_pitch, lowest_sole_y
from .geometry import LegGeometry, leg_ik
from .smooth import hermite_segment, hermite_to_zero, plateau, smootherstep, smoothstep
from .step_length import StepLengthInverse

_H = 1e-5  # step of the one-sided finite differences used only when planning a segment
MIN_KNEE_RAD = np.radians(5.0)  # feet placed by IK keep at least this knee bend (away from the singularity)
PINNED_MIN_KNEE_RAD = np.radians(10.0)  # the pinned rear foot keeps more, leaving the swing room to saturate
CLEARANCE_WINDOW = (0.2, 0.8)  # share of each swing's duration where the clearance must hold


class GaitGenerationError(UserError, ValueError):
    """The requested motion cannot be generated for this leg (e.g. a foot out of the leg's reach)."""


@dataclass(frozen=True)
class GaitContext:
    """Everything the segments share: the leg, timing, the knee bend and the step-length inverse.

    step_frames: frames per step (half cycle); the cycle is rounded to a whole number of frames
    per step so that every heel strike falls exactly on a frame.
    leg_scale: hip-to-ankle distance of the crouch over the leg length (see the module docstring).
    """

    geometry: LegGeometry
    inverse: StepLengthInverse
    rate_hz: float
    step_frames: int
    clearance: float  # metres (geometry units)
    intermediate_steps: int  # m of eq. 14
    crouch_knee_rad: float
    settle_frames: int
    pitch_limit_rad: float = np.radians(20.0)

    @property
    def step_s(self) -> float:
        return self.step_frames / self.rate_hz

    @property
    def cycle_s(self) -> float:
        return 2.0 * self.step_s

    @property
    def toe_off_u(self) -> float:
        """Step progress at which the rear foot leaves the ground: (Ds/Dc - 0.5) * 2."""
        return 2.0 * toe_off_phase(self.cycle_s) - 1.0

    @property
    def leg_scale(self) -> float:
        return crouch_leg_scale(self.geometry, self.crouch_knee_rad)


def crouch_leg_scale(geometry: LegGeometry, knee_rad: float) -> float:
    """Hip-to-ankle distance with the knee bent ``knee_rad``, over the leg length."""
    a, b = geometry.thigh, geometry.shank
    return float(np.sqrt(a * a + b * b + 2 * a * b * np.cos(knee_rad)) / geometry.leg_length)


@dataclass(frozen=True)
class WalkState:
    """The state at a segment boundary: all the next segment needs to continue smoothly.

    Foot poses are (ankle x, ankle y, sole pitch) of the stance foot relative to the hip.
    """

    stance_left: bool  # which leg supports during the next segment
    anchor_stance: float  # rolling anchor (heel x when flat) of the supporting foot
    anchor_rear: float
    foot_stance: np.ndarray  # (3,) m, m, rad
    foot_rate_stance: np.ndarray  # (3,) per second
    pitch_rear: float  # rad
    pitch_rate_rear: float  # rad/s
    step_length: float  # length of the step that ended here (0 when standing)


def crouch_pose(geometry: LegGeometry, knee_rad):
    """Hip, knee, ankle with the knee bent ``knee_rad``, the foot flat and the hip over the ankle."""
    knee = np.asarray(knee_rad, dtype=float)
    hip = np.arctan2(geometry.shank * np.sin(knee), geometry.thigh + geometry.shank * np.cos(knee))
    return np.stack([hip, knee, knee - hip], axis=-1)


def foot_of(geometry: LegGeometry, q, scale: float = 1.0, pitch_limit: float = np.inf):
    """Foot pose (ankle x, y scaled towards the hip by ``scale``; sole pitch) of leg angles q (n, 3).

    The pitch passes through ``saturate`` so a long robot sole never points its toe far down:
    the model's toe-off pitch (-50 degrees and more) would hang a 12 cm foot's toe 9 cm below the
    ankle and force the knee past 100 degrees to clear the ground."""
    return np.column_stack([ankle_in_body(geometry, q) * scale, saturate(leg_pitch(q), pitch_limit)])


def saturate(x, limit: float):
    """Identity up to limit / 2 in size, then limit/2 + (limit/2) tanh(...): smooth (C2) and within +-limit."""
    x = np.asarray(x, dtype=float)
    if not np.isfinite(limit):
        return x
    knee = 0.5 * limit
    size = np.abs(x)
    out = np.where(size > knee, knee + knee * np.tanh((size - knee) / knee), size)
    return np.sign(x) * out


def angles_of(geometry: LegGeometry, foot, what: str):
    """Leg angles (n, 3) putting the ankle at foot[:, :2] (relative to the hip) with pitch foot[:, 2]."""
    try:
        return leg_ik(geometry, foot[:, :2], foot[:, 2])
    except ValueError:
        raise GaitGenerationError(f"{what}: the foot is out of the leg's reach (leg too short for this step)") from None


def root_of(geometry: LegGeometry, anchor: float, foot_stance):
    """Hip in the world that keeps the stance foot's rolling contact still (eq. 9, closed form)."""
    return grounded_ankle(geometry, anchor, foot_stance[:, 2]) - foot_stance[:, :2]


FLAT_FOOT_RAD = np.radians(3.0)  # width of the foot-flat pause where the stance sole crosses level


def flat_pause(raw_pitch, width: float = FLAT_FOOT_RAD):
    """Stance sole pitch from a raw pitch: p^3 / (p^2 + w^2).

    A flat sole changes its pivot from heel to toe where its pitch crosses 0; crossing with a
    non-zero pitch rate would jump the body's velocity by foot length x pitch rate. This map has
    zero slope at 0 (a brief foot-flat pause, as a real foot has) and tends to p away from it."""
    p = np.asarray(raw_pitch, dtype=float)
    return p**3 / (p * p + width * width)


def flat_pause_slope(raw_pitch, width: float = FLAT_FOOT_RAD):
    p = np.asarray(raw_pitch, dtype=float)
    return (p**4 + 3 * p * p * width * width) / (p * p + width * width) ** 2


def flat_pause_inverse(pitch: float, width: float = FLAT_FOOT_RAD) -> float:
    """The raw pitch whose flat_pause is ``pitch`` (Newton on the monotone cubic)."""
    raw = float(pitch) + (width * width / pitch if abs(pitch) > width else 0.0)
    if pitch == 0.0:
        return 0.0
    raw = raw if raw != 0.0 else pitch
    for _ in range(60):
        step = (float(flat_pause(raw, width)) - pitch) / max(float(flat_pause_slope(raw, width)), 1e-12)
        raw -= step
        if abs(step) < 1e-15:
            break
    return raw


def _raw_pitch_state(pitch: float, rate: float) -> tuple[float, float]:
    """Raw pitch and rate behind an actual stance pitch and rate (rate 0 at a flat foot)."""
    raw = flat_pause_inverse(pitch)
    slope = float(flat_pause_slope(raw))
    return raw, (rate / slope if slope > 1e-9 else 0.0)


def _lowering_needed(relative_xy, reach: float):
    """How much higher (relative to the hip) each foot point must be to lie within ``reach``."""
    x, y = relative_xy[:, 0], relative_xy[:, 1]
    inside = np.sqrt(np.maximum(reach * reach - x * x, 0.0))
    return np.maximum(0.0, -y - inside)


def _saturate_reach(relative_xy, start: float, limit: float):
    """Pull foot points beyond ``start`` from the hip smoothly back inside ``limit``.

    Identity up to ``start``; beyond it the distance follows start + w tanh((r - start) / w),
    w = limit - start, which joins with matching slope and curvature and never reaches the limit.
    Pulling towards the hip also raises the foot, so clearance only grows.
    """
    r = np.hypot(relative_xy[:, 0], relative_xy[:, 1])
    width = limit - start
    over = r > start
    if not over.any():
        return relative_xy
    scaled = np.where(over, start + width * np.tanh((r - start) / width), r)
    return relative_xy * (scaled / np.where(r > 0, r, 1.0))[:, None]


def _assemble(stance_left: bool, q_stance, q_other, root):
    left, right = (q_stance, q_other) if stance_left else (q_other, q_stance)
    return np.concatenate([left, right], axis=-1), root


def _rate_left(f, u: float):
    """d f / du at u from the left, second order; ``f`` maps an array of u to rows."""
    v = f(np.array([u, u - _H, u - 2 * _H]))
    return (3 * v[0] - 4 * v[1] + v[2]) / (2 * _H)


def _rate_right(f, u: float):
    v = f(np.array([u, u + _H, u + 2 * _H]))
    return (-3 * v[0] + 4 * v[1] - v[2]) / (2 * _H)


class CrouchSegment:
    """Both feet flat side by side; knees bend from straight to the crouch (or back) in joint space."""

    def __init__(self, ctx: GaitContext, anchor: float, bend: bool) -> None:
        self.ctx, self.anchor, self.bend = ctx, anchor, bend
        self.n_frames = ctx.settle_frames

    def evaluate(self, u):
        u = np.atleast_1d(np.asarray(u, dtype=float))
        share = smootherstep(u if self.bend else 1.0 - u)
        q = crouch_pose(self.ctx.geometry, share * self.ctx.crouch_knee_rad)
        root = root_of(self.ctx.geometry, self.anchor, foot_of(self.ctx.geometry, q))
        return _assemble(True, q, q, root)

    def end_state(self) -> WalkState:
        q = crouch_pose(self.ctx.geometry, np.array([self.ctx.crouch_knee_rad if self.bend else 0.0]))
        foot = foot_of(self.ctx.geometry, q)[0]
        return WalkState(True, self.anchor, self.anchor, foot, np.zeros(3), 0.0, 0.0, 0.0)


def settle_profile(u, rate0: float):
    """g(u) from 1 to 0 on [0, 1] that never passes 0, with g'(0) = rate0 and g'(1) = 0.

    (1 - u)^2 (1 + c u), c = rate0 + 2, stays >= 0 for rate0 >= -3 (it may first rise when
    rate0 > 0); steeper starts use (1 - u)^n, n = -rate0. A cubic Hermite with the same ends
    would pass 0 when rate0 < -3."""
    u = np.clip(np.asarray(u, dtype=float), 0.0, 1.0)
    rate0 = float(rate0)
    if rate0 >= -3.0:
        return (1.0 - u) ** 2 * (1.0 + (rate0 + 2.0) * u)
    return (1.0 - u) ** (-rate0)


def _settle_pitch(u, pitch0: float, rate0: float):
    """A sole pitch settling to level from pitch0 (rate0 per unit u) without passing level."""
    if pitch0 == 0.0:
        return np.zeros_like(np.asarray(u, dtype=float))
    return pitch0 * settle_profile(u, rate0 / pitch0)


class SettleSegment:
    """After the closing step: the front foot moves (relative to the hip) to the crouch while the
    rear foot, pinned on the ground, rolls flat. Ends with both feet flat side by side.

    Both sole pitches settle to level along ``settle_profile``: a cubic Hermite overshoots level
    after a long last step, which would switch the pivot (heel <-> toe) and rock the foot."""

    def __init__(self, ctx: GaitContext, state: WalkState) -> None:
        self.ctx, self.state = ctx, state
        self.n_frames = ctx.step_frames
        g = ctx.geometry
        self.foot_end = foot_of(g, crouch_pose(g, np.array([ctx.crouch_knee_rad])))[0]
        self._duration = self.n_frames / ctx.rate_hz
        self._rate0 = state.foot_rate_stance * self._duration

    def evaluate(self, u):
        u = np.atleast_1d(np.asarray(u, dtype=float))
        s, g = self.state, self.ctx.geometry
        foot = hermite_segment(u, s.foot_stance, self._rate0, self.foot_end, np.zeros(3))
        foot[:, 2] = _settle_pitch(u, float(s.foot_stance[2]), float(self._rate0[2]))
        root = root_of(g, s.anchor_stance, foot)
        pitch = _settle_pitch(u, s.pitch_rear, s.pitch_rate_rear * self._duration)
        rear = np.column_stack([grounded_ankle(g, s.anchor_rear, pitch) - root, pitch])
        return _assemble(s.stance_left, angles_of(g, foot, "settling"), angles_of(g, rear, "settling"), root)


class StepSegment:
    """One step: from a heel strike (or the crouch) to the next heel strike ``step_length`` ahead."""

    DECAY_U = 0.5  # the landing correction fades out over the first half of the step
    LOWER_FROM_U = 0.5  # the hip lowering for double support fades in over the second half

    def __init__(self, ctx: GaitContext, state: WalkState, step_length: float) -> None:
        self.ctx, self.state = ctx, state
        self.n_frames = ctx.step_frames
        self.step_length = step_length
        self.foothold = state.anchor_stance + step_length
        self.u_toe_off = ctx.toe_off_u
        self.what = f"step of {step_length:g}"
        m = ctx.intermediate_steps
        lengths = state.step_length + (step_length - state.step_length) * np.arange(m + 2) / (m + 1)
        self.rvs = tuple(ctx.inverse.rv(float(np.clip(sl, 0.0, ctx.inverse.max_step_length))) for sl in lengths)
        self.blend = BoulicBlend(self.rvs, ctx.cycle_s)
        duration = self.n_frames / ctx.rate_hz
        self._plan_landing_correction(duration)
        self._plan_rear_correction(duration)
        self._plan_double_support()
        self._plan_reach()
        self._plan_swing()

    # --- the model's own feet, relative to the hip ---------------------------------------------
    def model_stance(self, u):
        u = np.atleast_1d(np.asarray(u, dtype=float))
        return foot_of(self.ctx.geometry, self.blend.leg(u / 2.0, u), self.ctx.leg_scale, self.ctx.pitch_limit_rad)

    def model_other(self, u):
        u = np.atleast_1d(np.asarray(u, dtype=float))
        return foot_of(self.ctx.geometry, self.blend.leg(u / 2.0 + 0.5, u), self.ctx.leg_scale,
                       self.ctx.pitch_limit_rad)

    # --- planning ---------------------------------------------------------------------------
    def _plan_landing_correction(self, duration: float) -> None:
        s = self.state
        raw_pitch, raw_rate = _raw_pitch_state(s.foot_stance[2], s.foot_rate_stance[2])
        start = np.array([*s.foot_stance[:2], raw_pitch])
        start_rate = np.array([*s.foot_rate_stance[:2], raw_rate])
        self._delta0 = start - self.model_stance(0.0)[0]
        rate0 = start_rate * duration - _rate_right(self.model_stance, 0.0)
        self._delta_rate0 = rate0 * self.DECAY_U  # per unit of the decay window

    def _plan_rear_correction(self, duration: float) -> None:
        s = self.state
        model_pitch = lambda u: self.model_other(u)[:, 2]  # noqa: E731
        self._eps0 = s.pitch_rear - model_pitch(0.0)[0]
        self._eps_rate0 = (s.pitch_rate_rear * duration - _rate_right(model_pitch, 0.0)) * self.u_toe_off

    def _plan_double_support(self) -> None:
        g = self.ctx.geometry
        stance_end, front_end = self.model_stance(1.0)[0], self.model_other(1.0)[0]
        self.landing_pitch = max(float(front_end[2]), 0.0)  # heel first or flat, never toe first
        self.landing_ankle = heel_pinned_ankle(g, self.foothold, self.landing_pitch)
        self.root_at_strike = self.landing_ankle - front_end[:2]
        ankle = grounded_ankle(g, self.state.anchor_stance, flat_pause(stance_end[2]))
        self._gamma1 = np.array([*(ankle - self.root_at_strike - stance_end[:2]), 0.0])

    def _plan_reach(self) -> None:
        """Lower the hip mid-step where the pinned rear foot would otherwise be out of reach.

        After a long step followed by a short one the model expects the rear foot nearer than it
        is. The lowering is a sin^2 bump: zero value and slope at both ends of the step, so the
        heel-strike states are untouched."""
        self._reach_lowering = 0.0
        u = np.linspace(0.0, self.u_toe_off, 120)[1:]
        rel = self._pinned_target(u)[:, :2] - self.root(u)
        need = _lowering_needed(rel, self.ctx.geometry.leg_length * crouch_leg_scale(self.ctx.geometry, PINNED_MIN_KNEE_RAD))
        bump = np.sin(np.pi * u) ** 2
        self._reach_lowering = max(0.0, float((need / bump).max()))

    @property
    def _reach_limit(self) -> float:
        return self.ctx.geometry.leg_length * crouch_leg_scale(self.ctx.geometry, MIN_KNEE_RAD)

    def stance_foot(self, u):
        """Stance foot relative to the hip (n, 3): the model plus the landing, double-support and reach corrections."""
        u = np.atleast_1d(np.asarray(u, dtype=float))
        delta = hermite_to_zero(u / self.DECAY_U, self._delta0, self._delta_rate0)
        lower = smoothstep((u - self.LOWER_FROM_U) / (1.0 - self.LOWER_FROM_U))[:, None] * self._gamma1
        foot = self.model_stance(u) + delta + lower
        foot[:, 1] += self._reach_lowering * np.sin(np.pi * u) ** 2
        foot[:, 2] = flat_pause(foot[:, 2])
        return foot

    def root(self, u):
        return root_of(self.ctx.geometry, self.state.anchor_stance, self.stance_foot(u))

    def rear_pitch(self, u):
        u = np.atleast_1d(np.asarray(u, dtype=float))
        eps = hermite_to_zero(u / self.u_toe_off, np.array([self._eps0]), np.array([self._eps_rate0]))[:, 0]
        return self.model_other(u)[:, 2] + eps

    def _pinned_target(self, u):
        """World ankle (x, y) and pitch of the rear foot while it is still on the ground."""
        pitch = self.rear_pitch(u)
        return np.column_stack([grounded_ankle(self.ctx.geometry, self.state.anchor_rear, pitch), pitch])

    def _pinned_relative(self, u):
        target = self._pinned_target(u)
        target[:, :2] -= self.root(u)
        return target

    def _plan_swing(self) -> None:
        """Swing foot relative to the hip: the model's path plus Hermite end corrections, so it
        leaves the pinned foot with its velocity and lands, heel at rest, on the foothold.

        Blending relative to the hip (not in the world) keeps the path near the straight line
        between two reachable foot poses even when consecutive steps differ a lot in length."""
        g, u0 = self.ctx.geometry, self.u_toe_off
        span = 1.0 - u0
        start = self._pinned_relative(u0)[0]
        start_rate = _rate_left(self._pinned_relative, u0)
        pitch_rate_end = _rate_left(lambda u: self.model_other(u)[:, 2], 1.0)
        if self.landing_pitch <= 0.0:
            pitch_rate_end = 0.0  # a flat landing pauses flat (see flat_pause)
        end = np.array([*(self.landing_ankle - self.root_at_strike), self.landing_pitch])
        heel_fixed = lambda p: heel_pinned_ankle(g, self.foothold, p)  # noqa: E731
        ankle_rate_end = (heel_fixed(self.landing_pitch + _H) - heel_fixed(self.landing_pitch - _H)) / (2 * _H)
        root_rate_end = _rate_left(self.root, 1.0)
        end_rate = np.array([*(ankle_rate_end * pitch_rate_end - root_rate_end), pitch_rate_end])
        model = self.model_other
        self._model_pitch_start = model(u0)[0, 2]
        self._pitch_rate_start = start_rate[2] * span  # per unit of swing progress s
        self._pitch_rate_end = pitch_rate_end * span
        self._d0 = start - model(u0)[0]
        self._d0_rate = (start_rate - _rate_right(model, u0)) * span
        self._d1 = end - model(1.0)[0]
        self._d1_rate = (end_rate - _rate_left(model, 1.0)) * span
        ends = (float(np.hypot(*start[:2])), float(np.hypot(*end[:2])))
        self._saturate_from = max(ends) + 1e-9 * g.leg_length
        self._saturate_to = min(max(self._reach_limit, self._saturate_from + 1e-3 * g.leg_length),
                                g.leg_length * (1.0 - 1e-6))
        self.lift = 0.0
        s = np.linspace(0.0, 1.0, 201)
        u = u0 + s * span
        root = self.root(u)
        inside = (s >= CLEARANCE_WINDOW[0]) & (s <= CLEARANCE_WINDOW[1])
        # aim a little above the configured clearance so the sampled frames hold it with margin
        aim = np.where(inside, self.ctx.clearance * 1.02 + 1e-6 * g.leg_length, 1e-7 * g.leg_length)
        shape = plateau(s, CLEARANCE_WINDOW[0])
        usable = shape > 1e-6
        for _ in range(60):  # the reach saturation absorbs part of each lift increment: iterate to the end
            target = self.swing_relative(u)
            deficit = aim - lowest_sole_y(g, target[:, :2] + root, target[:, 2])
            extra = float((deficit[usable] / shape[usable]).max())
            if extra <= 1e-9 * g.leg_length:
                break
            self.lift += 1.5 * extra  # over-relaxed: near full reach only about 2/3 of a lift turns into height
        else:
            raise GaitGenerationError(f"{self.what}: the swing foot cannot clear the ground by "
                                      f"{self.ctx.clearance:g} within the leg's reach")

    LEVEL_FROM_S, LEVEL_UNTIL_S = 0.3, 0.7  # the swing sole is level over this share of the swing

    def _swing_pitch(self, s):
        """Sole pitch over the swing: from the toe-off pitch to level, level, then to the landing pitch.

        The model's own swing pitch stays toe-down (knee flexion tips the foot), which on a long
        robot foot drags the toe or needs a tall lift; a level sole mid-swing clears the ground
        with the least lift. Pitch and its rate match the pinned foot at toe-off and the landing."""
        a, b = self.LEVEL_FROM_S, self.LEVEL_UNTIL_S
        p0, r0 = self._d0[2] + self._model_pitch_start, self._pitch_rate_start
        p1, r1 = self.landing_pitch, self._pitch_rate_end
        rise = hermite_segment(np.clip(s / a, 0, 1), np.array([p0]), np.array([r0 * a]), np.zeros(1), np.zeros(1))[:, 0]
        fall = hermite_segment(np.clip((s - b) / (1 - b), 0, 1), np.zeros(1), np.zeros(1), np.array([p1]),
                               np.array([r1 * (1 - b)]))[:, 0]
        return np.where(s < a, rise, np.where(s > b, fall, 0.0))

    def swing_relative(self, u):
        """Swing foot (ankle x, y relative to the hip; pitch) for u in [toe-off, 1]."""
        u = np.atleast_1d(np.asarray(u, dtype=float))
        s = (u - self.u_toe_off) / (1.0 - self.u_toe_off)
        target = self.model_other(u) + hermite_segment(s, self._d0, self._d0_rate, self._d1, self._d1_rate)
        target[:, 2] = self._swing_pitch(s)
        target[:, 1] += self.lift * plateau(s, CLEARANCE_WINDOW[0])
        target[:, :2] = _saturate_reach(target[:, :2], self._saturate_from, self._saturate_to)
        return target

    def other_foot(self, u, root=None):
        """Rear/swing foot relative to the hip (n, 3): pinned until toe-off, then the swing target."""
        u = np.atleast_1d(np.asarray(u, dtype=float))
        root = self.root(u) if root is None else root
        pinned = u <= self.u_toe_off
        target = np.empty((len(u), 3))
        if pinned.any():
            target[pinned] = self._pinned_target(u[pinned])
            target[pinned, :2] -= root[pinned]
        if (~pinned).any():
            target[~pinned] = self.swing_relative(u[~pinned])
        return target

    def evaluate(self, u):
        u = np.atleast_1d(np.asarray(u, dtype=float))
        g = self.ctx.geometry
        stance = self.stance_foot(u)
        root = root_of(g, self.state.anchor_stance, stance)
        other = self.other_foot(u, root)
        return _assemble(self.state.stance_left, angles_of(g, stance, self.what), angles_of(g, other, self.what), root)

    def end_state(self) -> WalkState:
        duration = self.n_frames / self.ctx.rate_hz
        stance_pitch = lambda u: self.stance_foot(u)[:, 2]  # noqa: E731
        return WalkState(
            stance_left=not self.state.stance_left,
            anchor_stance=self.foothold,
            anchor_rear=self.state.anchor_stance,
            foot_stance=self.other_foot(1.0)[0],
            foot_rate_stance=_rate_left(self.other_foot, 1.0) / duration,
            pitch_rear=float(stance_pitch(1.0)[0]),
            pitch_rate_rear=float(_rate_left(stance_pitch, 1.0)) / duration,
            step_length=self.step_length,
        )
