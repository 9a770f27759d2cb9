"""The balanced walk's plan, frame by frame: ZMP reference, feet, load share and the swing paths.

A walk (docs/balance.md) starts standing straight (every joint at 0, the servos' standing pose), bends
its knees slightly (STAND_KNEE_DEG, over RISE_S: both feet flat, the pelvis moved straight to where the
balance plan begins; walker.py adds these frames and their mirror at the end), crouches to the
walking height (SETTLE_S), pauses, shifts its weight onto the first stance foot (a whole step of
double support), walks the queued steps, closes the trailing foot beside the leading one, moves the
ZMP back between the feet, stands still (END_STAND_S) and rises. ``StepPlanner`` appends these blocks
of frames; each block holds per frame: the ZMP reference (2,), both ankle points (2, 3), the root's
height, the share of the weight on the left foot, each foot's planned centre of pressure (2, 2) and
which foot swings (0 none, 1 left, 2 right).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

import numpy as np

from gaitbot.gait.balance.settings import BalanceSettings
from gaitbot.gait.balance.swing import SwingShapes
from gaitbot.gait.balance.zmp_reference import FootPlacement, Timing, shift, smootherstep, standing_zmp, zmp_point
from gaitbot.gait.body import SIDE_SIGN, BodyGeometry
from gaitbot.gait.joints import SIDES

SETTLE_S = 0.5  # stand -> crouch and back, both feet flat
RISE_S = 0.4  # straight legs (all joints 0) <-> standing with STAND_KNEE_DEG, both feet flat
STAND_KNEE_DEG = 10.0  # standing knees: bent this much, so the legs reach wherever the CoM puts the root
START_PAUSE_S = 0.3
END_STAND_S = 1.0
PLAN_KEYS = ("zmp", "ankles", "root_z", "share_left", "cops", "swinging", "yaw")
YAW_WINDOW = (0.05, 0.7)
"""The swing foot turns while its ankle point goes from 5% to 70% of the way to its foothold (the yaw a
smootherstep of that share: zero yaw rate and acceleration at lift-off and touch-down, and none while the
sole leaves or meets the floor). Tying the turn to the position (not to time) makes the swing's path in
the plane one curve, whatever the step's timing: the planner checks the feet's clearance along it."""


def feedforward_weight(frame, last_frame: float, rate_hz: float):
    """The share of the sag feedforward in the goals of the balance plan's frame(s) ``frame``: 0 at its
    first and last frames, 1 from the end of the first crouch (SETTLE_S) to the start of the last rise.
    The walk's first and last goals are then its planned standing poses (all zeros), where the servos
    stand (no ramp before or after the walk: a recording holds exactly the trajectory)."""
    frame = np.asarray(frame, dtype=float)
    n = SETTLE_S * rate_hz
    return np.minimum(smootherstep(frame / n), smootherstep((last_frame - frame) / n))


STEERED_PROGRESSION_END = 0.6
ASIDE_M = 0.015
"""A swing that goes backward, or more than ASIDE_M sideways (in the stance foot's frame), is over its
foothold by 60% of the swing (others: [balance] progression_end): soft servos lag, and a foot still
travelling back or aside when it comes down lands short (on the Menagerie OP3 backward steps land 85% of
their length with 0.85, 89% with 0.6, and sidesteps turn the robot 5 deg per 0.3 m: docs/steering.md)."""


def back_or_aside(stance: FootPlacement, old: FootPlacement, new: FootPlacement) -> bool:
    """Whether the swing from ``old`` to ``new`` goes backward or aside (ASIDE_M), in the stance's frame."""
    c, s = math.cos(stance.yaw_rad), math.sin(stance.yaw_rad)
    dx, dy = new.x_m - old.x_m, new.y_m - old.y_m
    return c * dx + s * dy < 0.0 or abs(-s * dx + c * dy) > ASIDE_M


def swing_yaw_share(position_share):
    """The share of its turn the swing foot has made when its ankle point is ``position_share`` of the way
    to its foothold (0 -> 1 over YAW_WINDOW)."""
    a, b = YAW_WINDOW
    if isinstance(position_share, float):  # one share (the sole sweep's hot path): the same arithmetic in floats
        u = min(max((position_share - a) / (b - a), 0.0), 1.0)
        return u * u * u * (u * (6 * u - 15) + 10)
    return smootherstep((np.asarray(position_share, dtype=float) - a) / (b - a))


def crouch_hip_height_m(geometry: BodyGeometry, knee_deg: float) -> float:
    """Hip-to-ankle distance with the knee bent ``knee_deg`` (the foot under the hip)."""
    a, b = geometry.thigh_m, geometry.shank_m
    return math.sqrt(a * a + b * b + 2 * a * b * math.cos(math.radians(knee_deg)))


@dataclass
class PlanState:
    """Where the plan stands at the end of the frames planned so far (what the next step starts from)."""

    feet: dict
    zmp_now: np.ndarray
    stance_next: str = "left"
    share_left: float = 0.5
    steps: int = 0
    last_length_m: float = 0.0
    paused: bool = False  # both feet stood still since the last step: the next one shifts its weight slowly

    def copy(self) -> "PlanState":
        return replace(self, feet=dict(self.feet), zmp_now=self.zmp_now.copy())


@dataclass
class PlanBlocks:
    """Per-frame plan arrays (PLAN_KEYS), appended block by block."""

    zmp: list = field(default_factory=list)
    ankles: list = field(default_factory=list)
    root_z: list = field(default_factory=list)
    share_left: list = field(default_factory=list)
    cops: list = field(default_factory=list)
    swinging: list = field(default_factory=list)
    yaw: list = field(default_factory=list)
    taken: int = 0  # frames already handed out by take()

    def add(self, zmp, ankles, root_z, share_left, cops, swinging, yaw=(0.0, 0.0)) -> None:
        """One block of n frames; yaw: each foot's yaw (rad), (2,) held or (n, 2)."""
        n = len(zmp)
        self.zmp.append(np.asarray(zmp, dtype=float).reshape(n, 2))
        self.ankles.append(np.asarray(ankles, dtype=float).reshape(n, 2, 3))
        self.root_z.append(np.broadcast_to(np.asarray(root_z, dtype=float), (n,)).copy())
        self.share_left.append(np.broadcast_to(np.asarray(share_left, dtype=float), (n,)).copy())
        self.cops.append(np.asarray(cops, dtype=float).reshape(n, 2, 2))
        self.swinging.append(np.broadcast_to(np.asarray(swinging), (n,)).astype(np.int8))
        self.yaw.append(np.broadcast_to(np.asarray(yaw, dtype=float), (n, 2)).copy())

    @property
    def frames(self) -> int:
        """Frames planned so far (those taken included): the next block's first frame number."""
        return self.taken + int(sum(len(z) for z in self.zmp))

    def arrays(self, start_block: int = 0) -> dict:
        return {name: np.concatenate(getattr(self, name)[start_block:]) for name in PLAN_KEYS}

    def take(self) -> dict:
        """The blocks added since the last take as arrays, dropped from here (frame numbers go on)."""
        out = self.arrays()
        self.taken += len(out["zmp"])
        for name in PLAN_KEYS:
            getattr(self, name).clear()
        return out


@dataclass(frozen=True)
class Landing:
    """A planned heel strike: the frame it lands on, the foot, where its ankle point stands, the step."""

    frame: int
    side: str
    ankle_x_m: float
    ankle_y_m: float
    length_m: float
    start_frame: int
    yaw_rad: float = 0.0


class StepPlanner:
    """Appends the blocks of a balanced walk (see the module docstring)."""

    def __init__(self, geometry: BodyGeometry, balance: BalanceSettings, timing: Timing, swing: SwingShapes,
                 clearance_m: float) -> None:
        self.geometry = geometry
        self.balance = balance
        self.timing = timing
        self.swing = swing
        self.clearance_m = clearance_m
        g = geometry
        self.stand_root_z = crouch_hip_height_m(g, STAND_KNEE_DEG) + g.ankle_height_m + g.hip_below_root_m
        self.walk_root_z = crouch_hip_height_m(g, balance.crouch_knee_deg) + g.ankle_height_m + g.hip_below_root_m

    def start_feet(self) -> dict:
        return self.start_feet_of(self.geometry)

    @staticmethod
    def start_feet_of(g: BodyGeometry) -> dict:
        """Both heels at x = 0 (the planar walker's origin), ankles hip_width apart."""
        return {side: FootPlacement(side, g.heel_back_m, SIDE_SIGN[side] * g.hip_width_m / 2) for side in SIDES}

    def start(self) -> PlanState:
        feet = self.start_feet()
        return PlanState(feet=feet, zmp_now=standing_zmp(self.geometry, feet["left"], feet["right"]))

    def ankles(self, feet: dict) -> np.ndarray:
        h = self.geometry.ankle_height_m
        return np.array([[feet[s].x_m, feet[s].y_m, h] for s in SIDES])

    def cops(self, feet: dict) -> np.ndarray:
        return np.array([zmp_point(self.geometry, self.balance, feet[s]) for s in SIDES])

    def yaws(self, feet: dict) -> np.ndarray:
        return np.array([feet[s].yaw_rad for s in SIDES])

    def _still(self, blocks: PlanBlocks, state: PlanState, n: int, root_z) -> None:
        blocks.add(np.repeat(state.zmp_now[None], n, 0), np.repeat(self.ankles(state.feet)[None], n, 0), root_z,
                   state.share_left, np.repeat(self.cops(state.feet)[None], n, 0), 0, self.yaws(state.feet))

    def settle(self, blocks: PlanBlocks, state: PlanState, bend: bool) -> None:
        """Stand -> walking crouch (bend) or back, in SETTLE_S."""
        n = round(SETTLE_S * self.timing.rate_hz)
        w = smootherstep(np.arange(1, n + 1) / n)
        if not bend:
            w = 1.0 - w
        self._still(blocks, state, n, self.stand_root_z + w * (self.walk_root_z - self.stand_root_z))

    def hold(self, blocks: PlanBlocks, state: PlanState, seconds: float) -> None:
        self._still(blocks, state, round(seconds * self.timing.rate_hz), self.walk_root_z)

    def step(self, blocks: PlanBlocks, state: PlanState, length_m: float) -> Landing:
        """A straight step: the swing foot lands ``length_m`` ahead of the stance foot, hip_width from the
        midline (Jing et al.'s step length, heel strike to heel strike)."""
        stance = state.feet[state.stance_next]
        swing_side = "right" if state.stance_next == "left" else "left"
        new = FootPlacement(swing_side, stance.x_m + length_m, SIDE_SIGN[swing_side] * self.geometry.hip_width_m / 2)
        return self.step_to(blocks, state, new, length_m)

    def step_to(self, blocks: PlanBlocks, state: PlanState, new: FootPlacement, length_m: float) -> Landing:
        """Double support (the ZMP moves to the stance foot), then single support (the other foot swings
        along the planar Boulic swing's shape, scaled to this step, turning to its new yaw inside
        YAW_WINDOW, landing exactly on its foothold ``new``)."""
        g, t, b = self.geometry, self.timing, self.balance
        start_frame = blocks.frames
        stance_side = state.stance_next
        swing_side = "right" if stance_side == "left" else "left"
        if new.side != swing_side:
            raise ValueError(f"the next step is the {swing_side} foot's, not the {new.side} foot's")
        stance, old = state.feet[stance_side], state.feet[swing_side]
        feet_ankles, feet_cops, feet_yaw = self.ankles(state.feet), self.cops(state.feet), self.yaws(state.feet)
        # the first, or the first after a pause: the weight shift
        n_ds = t.step_frames if state.steps == 0 or state.paused else t.ds_frames
        target = zmp_point(g, b, stance)
        zmp, w = shift(state.zmp_now, target, n_ds)
        share_target = 1.0 if stance_side == "left" else 0.0
        blocks.add(zmp, np.repeat(feet_ankles[None], n_ds, 0), self.walk_root_z,
                   state.share_left + w * (share_target - state.share_left), np.repeat(feet_cops[None], n_ds, 0), 0,
                   feet_yaw)
        n_ss = t.ss_frames
        progression, lift = self.swing.at(math.hypot(new.x_m - old.x_m, new.y_m - old.y_m))
        progression_end = min(b.progression_end, STEERED_PROGRESSION_END) if back_or_aside(stance, old, new) \
            else b.progression_end
        peak = self.swing.peak_for_clearance(lift, self.clearance_m)
        tau = np.arange(1, n_ss + 1) / n_ss
        p = np.interp(np.minimum(tau / progression_end, 1.0), self.swing.tau, progression)
        h = peak * np.interp(tau, self.swing.tau, lift)
        ankles = np.repeat(feet_ankles[None], n_ss, 0)
        i = SIDES.index(swing_side)
        ankles[:, i, 0] = old.x_m + p * (new.x_m - old.x_m)
        ankles[:, i, 1] = old.y_m + p * (new.y_m - old.y_m)
        ankles[:, i, 2] = g.ankle_height_m + h
        ankles[-1, i] = [new.x_m, new.y_m, g.ankle_height_m]  # lands exactly on its foothold
        yaw = np.repeat(feet_yaw[None], n_ss, 0)
        yaw[:, i] = old.yaw_rad + swing_yaw_share(p) * (new.yaw_rad - old.yaw_rad)
        yaw[-1, i] = new.yaw_rad
        cops = np.repeat(feet_cops[None], n_ss, 0)
        cops[:, i] += ankles[:, i, :2] - feet_ankles[i, :2]  # the swing foot's point goes with it (it bears no load)
        blocks.add(np.repeat(target[None], n_ss, 0), ankles, self.walk_root_z, share_target, cops, 1 + i, yaw)
        state.feet[swing_side] = new
        state.zmp_now = target
        state.share_left = share_target
        state.stance_next = swing_side
        state.steps += 1
        state.last_length_m = length_m
        state.paused = False
        return Landing(blocks.frames - 1, swing_side, new.x_m, new.y_m, length_m, start_frame, new.yaw_rad)

    def pause(self, blocks: PlanBlocks, state: PlanState, frames: int) -> None:
        """Both feet down for ``frames`` frames: the ZMP moves between the feet (over a whole step's frames,
        or all of them if fewer) and stays; the next step shifts its weight over a whole step, as the first."""
        moving = min(self.timing.step_frames, frames)
        self._weight_to_both_feet(blocks, state, moving)
        state.paused = True
        if frames > moving:
            self._still(blocks, state, frames - moving, self.walk_root_z)

    def _weight_to_both_feet(self, blocks: PlanBlocks, state: PlanState, frames: int) -> None:
        """Both feet still while the ZMP moves between them and the weight to half on each, over ``frames``."""
        middle = standing_zmp(self.geometry, state.feet["left"], state.feet["right"])
        zmp, w = shift(state.zmp_now, middle, frames)
        blocks.add(zmp, np.repeat(self.ankles(state.feet)[None], frames, 0), self.walk_root_z,
                   state.share_left + w * (0.5 - state.share_left), np.repeat(self.cops(state.feet)[None], frames, 0),
                   0, self.yaws(state.feet))
        state.zmp_now, state.share_left = middle, 0.5

    def partner(self, stance: FootPlacement) -> FootPlacement:
        """The other foot side by side with ``stance``: parallel, ankles hip_width apart."""
        side = "right" if stance.side == "left" else "left"
        x, y = stance.to_world(0.0, SIDE_SIGN[side] * self.geometry.hip_width_m)
        return FootPlacement(side, float(x), float(y), stance.yaw_rad)

    def side_by_side(self, state: PlanState) -> bool:
        """Whether the feet stand side by side (the last swing foot where ``partner`` puts it)."""
        last = state.feet["right" if state.stance_next == "left" else "left"]
        other = self.partner(state.feet[state.stance_next])
        return abs(last.x_m - other.x_m) < 1e-12 and abs(last.y_m - other.y_m) < 1e-12 and \
            abs(last.yaw_rad - other.yaw_rad) < 1e-12

    def close(self, blocks: PlanBlocks, state: PlanState) -> list[Landing]:
        """Close the trailing foot beside the leading one (unless it is already), move the ZMP back
        between the feet, stand still for the preview to settle, and stand up."""
        landings = []
        half = self.geometry.hip_width_m / 2
        turned = any(f.yaw_rad != 0.0 or f.y_m != SIDE_SIGN[f.side] * half for f in state.feet.values())
        if not turned and (state.steps == 0 or state.last_length_m != 0.0):
            landings.append(self.step(blocks, state, 0.0))
        elif turned and (state.steps == 0 or not self.side_by_side(state)):
            landings.append(self.step_to(blocks, state, self.partner(state.feet[state.stance_next]), 0.0))
        self._weight_to_both_feet(blocks, state, self.timing.step_frames)
        self.hold(blocks, state, END_STAND_S)
        self.settle(blocks, state, bend=False)
        return landings
