"""The balanced walker: footholds -> ZMP reference -> preview-controlled CoM -> pelvis -> leg IK.

For a robot whose legs roll (docs/balance.md):
- footholds and timing (gaitbot.gait.balance.step_plan): exact step lengths, whole frames;
- the CoM in x and y by Kajita's preview control (gaitbot.gait.balance.preview) on the cart-table model
  at the robot's own CoM height (the whole robot's, from its mass model, in the walking crouch);
- a second preview stage (Kajita et al. 2003, section IV): the ZMP of the whole multibody motion
  (every link a point mass) differs from the cart-table's by up to ~2 cm, mostly from the swing leg;
  previewing that error as a CoM correction brings the multibody ZMP back onto the reference;
- the pelvis (root) placed every frame so that the whole robot's CoM is the planned one
  (gaitbot.gait.balance.placement); the root stays upright at a constant walking height;
- stance soles flat and still, the swing foot on the planar Boulic swing's shape (swing.py);
- legs by the analytic 6-joint IK (gaitbot.gait.kinematics6);
- optional servo-sag feedforward: goal = planned angle + gravity torque / servo stiffness.

Online and offline compute the same frames. ``BalancedWalker.next_frame`` runs both preview stages one
frame at a time (the first one horizon + 1 frame ahead of the output, since the second needs the
multibody ZMP error over its horizon), placing the body with flat_foot_body.py's float code;
``generate_balanced_walk`` runs the same recursions over a closed walk, vectorised. Steps appended while
walking enter the horizon at once: until the walk is closed, the frames beyond the queued steps are the
close-and-stand that ``finish`` would add (so a walker whose queue runs dry stops safely), and
appending a step reruns the first stage from the next output frame with the new reference: its body
placements at once, or with ``spread=True`` a few a frame in ``work`` (gaitbot.gait.balance.lookahead,
which also drops the plan behind the output: bounded memory on a walk of any length).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from gaitbot.gait.balance.lookahead import Lookahead, extrapolated
from gaitbot.gait.balance.placement import (MAX_PLACEMENT_ITERATIONS, PLACEMENT_TOLERANCE_M, WholeBody, multibody_zmp,
                                            to_world, torso_yaw)
from gaitbot.gait.balance.preview import preview_gains, preview_offline
from gaitbot.gait.balance.settings import BalanceSettings
from gaitbot.gait.balance.step_plan import (RISE_S, START_PAUSE_S, Landing, PlanBlocks, StepPlanner,
                                           feedforward_weight)
from gaitbot.gait.balance.swing import swing_shapes
from gaitbot.gait.balance.zmp_reference import FootPlacement, Timing, smootherstep
from gaitbot.gait.body import SIDE_SIGN, BodyModel
from gaitbot.gait.geometry import LegGeometry
from gaitbot.gait.joints import LEG_JOINTS
from gaitbot.gait.planning import PlannedStep
from gaitbot.gait.walk_segments import GaitGenerationError
from gaitbot.gait.trajectory import HeelStrike, Trajectory

STEP_LENGTH_TOLERANCE_M = 1e-12
FEEDFORWARD_SMOOTHING_S = 0.1
"""The sag feedforward splits the weight between the feet by the planned load share averaged over +- this:
a short double support (2 frames at 0.2 m/s) would otherwise swing the stance joints' offsets across in
two frames, asking the servos for more speed than the motion itself."""


def smoothed_share(share, rate_hz: float, index=None):
    """The load share averaged over +- FEEDFORWARD_SMOOTHING_S (edges held), at every frame or at ``index``."""
    half = max(0, round(FEEDFORWARD_SMOOTHING_S * rate_hz))
    share = np.asarray(share, dtype=float)
    if index is not None:
        window = np.clip(np.arange(index - half, index + half + 1), 0, len(share) - 1)
        return float(share[window].mean())
    padded = np.concatenate([np.repeat(share[:1], half), share, np.repeat(share[-1:], half)])
    return np.convolve(padded, np.ones(2 * half + 1) / (2 * half + 1), mode="valid")


class BalancedWalkError(GaitGenerationError):
    """A balanced walk the robot cannot make (a step too long, a joint past its limit): one line."""


@dataclass(frozen=True)
class BalancedGaitSettings:
    """The walk's timing and reach: cycle (s, two steps; rounded to whole frames per step), frame rate
    (Hz), longest step (m) and the swing sole's least height over the middle of each swing (m).
    ``clearance_asked``: the clearance is the user's (``--clearance``), which the speed fit keeps rather than
    lowers (gaitbot.gait.balance.speed_fit)."""

    cycle_s: float
    rate_hz: float
    max_step_m: float
    clearance_m: float
    clearance_asked: bool = False


@dataclass(frozen=True)
class BalancedWalk:
    """A walk as arrays over frames: planned angles q_rad (n, 12, LEG_JOINTS order), servo goals (planned
    + sag feedforward where on), root (n, 3), planned CoM (n, 3), ZMP reference and planned multibody ZMP
    (n, 2), the ankle points (n, 2, 3), which foot swings (n,), the heel strikes, the steps, and the
    largest CoM placement residual (m)."""

    t_s: np.ndarray
    q_rad: np.ndarray
    goals_rad: np.ndarray
    root_m: np.ndarray
    com_m: np.ndarray
    zmp_ref_m: np.ndarray
    zmp_plan_m: np.ndarray
    ankles_m: np.ndarray
    swinging: np.ndarray
    heel_strikes: tuple[HeelStrike, ...]
    planned_steps: tuple[PlannedStep, ...]
    residual_m: float
    yaw_rad: np.ndarray | None = None  # (n, 2) each foot's yaw where the walk turns; None: straight

    @property
    def feet_yaw_rad(self) -> np.ndarray:
        """Each foot's yaw over frames (n, 2) (zeros for a straight walk)."""
        return np.zeros((len(self.t_s), 2)) if self.yaw_rad is None else self.yaw_rad

    @property
    def torso_yaw_rad(self) -> np.ndarray:
        """The torso's yaw over frames (the mean of the feet's; zeros for a straight walk)."""
        return np.zeros(len(self.t_s)) if self.yaw_rad is None else torso_yaw(self.yaw_rad)

    def trajectory(self, goals: bool = False) -> Trajectory:
        """The planned angles (exact kinematics), or with ``goals`` the angles the servos are sent; a turning
        walk carries the torso's yaw (trajectory format 2's torso_yaw_deg)."""
        rpy = None
        if self.yaw_rad is not None:
            rpy = np.zeros((len(self.t_s), 3))
            rpy[:, 2] = self.torso_yaw_rad
        return Trajectory(self.t_s, self.goals_rad if goals else self.q_rad, self.root_m, self.heel_strikes,
                          LEG_JOINTS, rpy)


def leg_of(body: BodyModel) -> LegGeometry:
    """The planar leg of the same robot (for the swing shapes of the planar Boulic walker)."""
    g = body.geometry
    return LegGeometry(thigh=g.thigh_m, shank=g.shank_m, foot=g.foot_m, hip_width=g.hip_width_m,
                       ankle_height=g.ankle_height_m, heel_back=g.heel_back_m)


class BalancedWalker(Lookahead):
    """Online balanced walker: ``append_step`` plans footholds and the ZMP reference; ``next_frame`` runs
    the preview controllers one frame and places the body: (t_s, q_rad (12,), goal_rad (12,), root_m (3,)),
    or None after the last frame. Like gaitbot.gait.walker.OnlineWalker, a walker whose queue runs dry
    closes its feet and stands.

    limits_rad: (lower, upper) arrays (12,) checked by the offline walk; kp_nm_per_rad: each joint's servo
    stiffness (12,) for the sag feedforward (None: goals are the planned angles)."""

    def __init__(self, body: BodyModel, gait: BalancedGaitSettings, balance: BalanceSettings = BalanceSettings(),
                 *, limits_rad=None, kp_nm_per_rad=None) -> None:
        self.body = body
        self.gait = gait
        self.balance = balance
        self.rate_hz = gait.rate_hz
        self.limits_rad = limits_rad
        self.kp_nm_per_rad = None if kp_nm_per_rad is None else np.asarray(kp_nm_per_rad, dtype=float)
        self._kp = None if kp_nm_per_rad is None else [float(v) for v in self.kp_nm_per_rad]
        self.feedforward = balance.sag_feedforward and self.kp_nm_per_rad is not None
        self.timing = Timing.of(gait.cycle_s, gait.rate_hz, balance.double_support_share)
        shapes = swing_shapes(leg_of(body), gait.max_step_m, self.timing.cycle_s, gait.rate_hz, gait.clearance_m)
        self.planner = StepPlanner(body.geometry, balance, self.timing, shapes, gait.clearance_m)
        self.whole = WholeBody(body)
        self._state = self.planner.start()
        ankles0 = self.planner.ankles(self._state.feet)
        root0 = np.array([[np.mean(ankles0[:, 0]), 0.0, self.planner.walk_root_z]])
        com0 = self.whole.com(root0, ankles0[None])[0]
        self.com_height_m = float(com0[2])
        self.standing_offset = root0[0, :2] - com0[:2]
        self.com_slope = self.whole.com_slope(self.planner.walk_root_z, ankles0 - [root0[0, 0], 0.0, 0.0])
        horizon = round(balance.preview_horizon_s * gait.rate_hz)
        self.gains = preview_gains(round(self.com_height_m, 9), 1.0 / gait.rate_hz, horizon,
                                   balance.preview_jerk_weight)
        self.heel_strikes: list[HeelStrike] = []
        self.planned_steps: list[PlannedStep] = []
        self._last_step: tuple | None = None  # the state before the last appended step (retract_last_step)
        self._blocks = PlanBlocks()
        self.planner.settle(self._blocks, self._state, bend=True)
        self.planner.hold(self._blocks, self._state, START_PAUSE_S)
        self.finished = False
        self._batch = False
        self._base = 0  # the plan's first frame still stored (frames handed out long ago are dropped)
        self._arrays: dict = {}
        self._pending: tuple[int, int] | None = None  # frames first..last left for work()
        self._commit()
        self._k = 0  # the balance plan's next frame
        self._out = 0  # the walk's next frame (rise, balance plan, lower)
        self._primed = False
        # Rising from straight legs to where the balance plan starts (its first CoM is the ZMP reference's)
        self.rise_frames = max(1, round(RISE_S * gait.rate_hz))
        root0, _, _ = self.whole.place(self._arrays["zmp"][:1], ankles0[None], self._arrays["root_z"][:1],
                                       self.standing_offset, self.com_slope)
        self._rise = self.straight_path(root0[0], ankles0, rising=True)
        self._lower = None
        self.com_offset_m = (0.0, 0.0)
        """Added to the next balance frame's CoM (x, y; m) before the body is placed: a correction from outside
        the plan (gaitbot.gait.balance.correction, fed by the IMU in gaitbot.drive.stepping); (0, 0) walks the
        plan."""

    @property
    def period_s(self) -> float:
        return 1.0 / self.rate_hz

    # --- planning ------------------------------------------------------------------------------
    def append_step(self, length_m: float, spread: bool = False) -> None:
        """Queue one step: its foot lands ``length_m`` beyond the previous heel strike. ``spread``: see
        ``work`` (the look-ahead's body placements are redone over the next frames, not at once)."""
        self._check_open()
        if not (math.isfinite(length_m) and 0.0 <= length_m <= self.gait.max_step_m + STEP_LENGTH_TOLERANCE_M):
            raise BalancedWalkError(f"step length {length_m!r} m is outside 0..{self.gait.max_step_m:g} m")
        self._record(self.planner.step(self._blocks, self._state, float(length_m)), closing=False)
        self._appended(spread)
        self._last_step = None  # only a step appended by append_footstep is taken back

    def append_footstep(self, foothold: FootPlacement, length_m: float = 0.0, spread: bool = False) -> None:
        """Queue one steered step: the next swing foot (``next_swing_side``) lands at ``foothold`` (its
        ankle point and yaw, world); ``length_m`` is recorded as the step's length (its forward part).
        The planner (gaitbot.gait.steer.planner) has bounded it and checked the feet's clearance.
        ``spread``: as append_step's."""
        self._check_open()
        if not all(math.isfinite(v) for v in (foothold.x_m, foothold.y_m, foothold.yaw_rad, length_m)):
            raise BalancedWalkError(f"foothold {foothold!r} is not finite")
        before = (self._state.copy(), self._committed, len(self.heel_strikes), len(self.planned_steps))
        self._record(self.planner.step_to(self._blocks, self._state, foothold, float(length_m)), closing=False)
        self._appended(spread)
        self._last_step = before if not self._batch else None

    @property
    def last_step_unstarted(self) -> bool:
        """Whether the last step appended (by ``append_footstep``) may still be taken back: none of its frames
        has been handed out, and the walk is open."""
        return self._last_step is not None and not self.finished and self._last_step[1] > self._k

    def retract_last_step(self) -> None:
        """Take back the last step appended, which has not started (``last_step_unstarted``): the plan and
        the walker's state are as before it, so that a step to another foothold can be appended instead
        (a push felt after the step was queued: gaitbot.drive.stepping). Its frames' previews are redone by
        that append's replan, which reruns the first stage from the next output frame."""
        if not self.last_step_unstarted:
            raise RuntimeError("the last step has started (or there is none to take back)")
        state, committed, strikes, steps = self._last_step
        self._last_step = None
        self._arrays = {key: a[:committed - self._base].copy() for key, a in self._arrays.items()}
        self._blocks.taken = committed
        self._state = state
        del self.heel_strikes[strikes:]
        del self.planned_steps[steps:]
        self._commit()

    def append_pause(self, frames: int, spread: bool = False) -> None:
        """Queue ``frames`` frames of standing on both feet (StepPlanner.pause): a push that lifting the next
        foot would make worse is waited out (gaitbot.drive.stepping). ``spread``: as append_step's."""
        self._check_open()
        self.planner.pause(self._blocks, self._state, int(frames))
        self._appended(spread)
        self._last_step = None

    def _check_open(self) -> None:
        if self.finished:
            raise RuntimeError("the walk has already been closed; start a new walker")

    def _appended(self, spread: bool) -> None:
        if not self._batch:
            self._commit()
            if self._primed:
                self._replan_lookahead(spread)

    @property
    def planned_frames(self) -> int:
        """Frames of the balance plan so far (the walk's, without the rise and the lowering)."""
        return self._committed

    def preview_step(self, foothold: FootPlacement, length_m: float = 0.0,
                     before_frames: int = 0, replacing_last: bool = False) -> tuple[dict, int, int]:
        """The plan arrays (PLAN_KEYS) of the last ``before_frames`` frames planned, one more step to
        ``foothold`` and the provisional close-and-stand after it (what the walker previews when no other
        step follows), computed on copies: the walker does not change (a live drive checks a step this way
        before it appends it). ``replacing_last``: the step in place of the last one appended, which has not
        started (``last_step_unstarted``: the plan as ``retract_last_step`` would leave it; a moved step is
        checked this way while the planned one stays queued). Returns (arrays, first, end): the step's own
        frames are ``arrays[key][first:end]``."""
        state, planned = self._state, self._arrays
        if replacing_last:
            if not self.last_step_unstarted:
                raise RuntimeError("the last step has started (or there is none to take back)")
            state, committed = self._last_step[:2]
            planned = {key: a[:committed - self._base] for key, a in planned.items()}
        blocks, state = PlanBlocks(), state.copy()
        self.planner.step_to(blocks, state, foothold, float(length_m))
        n = blocks.frames
        new = blocks.arrays()
        before = min(int(before_frames), len(planned["zmp"]))
        arrays = {k: np.concatenate([planned[k][len(planned[k]) - before:], new[k]]) for k in new}
        return arrays, before, before + n

    def lead_with(self, side: str) -> None:
        """Make ``side`` the first foot to swing (a sidestep or a turn leads with the foot on its side)."""
        if self.planned_steps:
            raise RuntimeError("the first step is already planned")
        self._state.stance_next = "right" if side == "left" else "left"
        if not self._batch:
            self._commit()

    @property
    def next_swing_side(self) -> str:
        """The foot the next queued step swings."""
        return "right" if self._state.stance_next == "left" else "left"

    @property
    def feet(self) -> dict:
        """Where each foot stands after the steps queued so far (side -> FootPlacement)."""
        return dict(self._state.feet)

    def finish(self) -> None:
        """Close the trailing foot beside the leading one, move the weight between the feet and stand."""
        if self.finished:
            return
        for landing in self.planner.close(self._blocks, self._state):
            self._record(landing, closing=True)
        self.finished = True
        self._commit()

    @property
    def rise_path(self) -> tuple[np.ndarray, np.ndarray]:
        """(roots, angles) of the rise from straight legs that comes before the balance plan."""
        return self._rise

    def straight_path(self, root_m, ankles, rising: bool, yaw=None) -> tuple[np.ndarray, np.ndarray]:
        """(roots (n, 3), angles (n, 12)) between straight legs over ``ankles`` (both feet flat, every joint
        0) and the pose whose root is ``root_m``: rising, from straight up to just before that pose;
        else from just after it down to straight. The pelvis moves on a straight line (smootherstep in
        time), the legs by the IK: the feet stay exactly where they are."""
        g = self.body.geometry
        straight = np.array([ankles[:, 0].mean(), ankles[:, 1].mean(), g.standing_root_height_m])
        n = self.rise_frames
        tau = np.arange(n) / n if rising else np.arange(1, n + 1) / n
        w = smootherstep(tau)[:, None]
        roots = (straight + w * (root_m - straight)) if rising else (root_m + w * (straight - root_m))
        yaws = None if yaw is None or not np.any(yaw) else np.repeat(np.asarray(yaw, dtype=float)[None], n, 0)
        q = self.whole.legs(roots, np.repeat(np.asarray(ankles)[None], n, 0), yaws)
        q[0 if rising else -1] = 0.0  # exactly the servos' standing pose
        return roots, q

    def _record(self, landing: Landing, closing: bool) -> None:
        g = self.body.geometry
        t = (landing.frame + self.rise_frames) / self.rate_hz
        foot = FootPlacement(landing.side, landing.ankle_x_m, landing.ankle_y_m, landing.yaw_rad)
        if landing.yaw_rad != 0.0:
            heel_x = float(foot.to_world(-g.heel_back_m, 0.0)[0])
            sole_y = float(foot.to_world(0.0, SIDE_SIGN[landing.side] * g.sole_outward_m)[1])
        else:
            heel_x = landing.ankle_x_m - g.heel_back_m
            sole_y = landing.ankle_y_m + SIDE_SIGN[landing.side] * g.sole_outward_m
        self.heel_strikes.append(HeelStrike(t, landing.side, heel_x, sole_y))
        self.planned_steps.append(PlannedStep(len(self.planned_steps) + 1, landing.side, landing.length_m, None,
                                              (landing.start_frame + self.rise_frames) / self.rate_hz, t, heel_x,
                                              closing))

    def _commit(self) -> None:
        """Refresh the plan arrays: the planned frames, then (until the walk is closed) the provisional
        close-and-stand; frames past the end repeat the last one (standing)."""
        if self._blocks.zmp:  # the blocks added since the last commit
            new = self._blocks.take()
            self._arrays = new if not self._arrays else {k: np.concatenate([self._arrays[k], new[k]])
                                                         for k in self._arrays}
        self._committed = self._base + len(self._arrays["zmp"])
        if self.finished:
            self._ext = self._arrays
        else:
            tail = PlanBlocks()
            self.planner.close(tail, self._state.copy())
            t = tail.arrays()
            self._ext = {k: np.concatenate([self._arrays[k], t[k]]) for k in self._arrays}
        zmp = self._ext["zmp"]
        self._zmp_padded = np.concatenate([zmp, np.repeat(zmp[-1:], self.gains.horizon_frames + 2, 0)])  # from _base

    def plan_arrays(self) -> dict:
        """The plan's per-frame arrays so far (gaitbot.gait.balance.step_plan.PLAN_KEYS), from frame
        ``plan_start_frame`` on (0 until the walker has walked lookahead.STORED_FRAMES frames: then the frames
        handed out are dropped, bounding the memory of a long walk)."""
        return self._arrays

    @property
    def plan_start_frame(self) -> int:
        return self._base

    @property
    def stored_frames(self) -> int:
        """The most frames any of the walker's per-frame stores holds (the plan's arrays, the preview
        stages' errors, points and snapshots): bounded on a walk of any length."""
        stores = [len(self._ext["zmp"]), len(self._zmp_padded)]
        if self._primed:
            stores += [len(self._err), len(self._pts), len(self._s1_com), len(self._s1_snapshot)]
        return max(stores)

    def last_torso_yaw_rad(self) -> float:
        """The torso's yaw (rad, the walker's world) in the frame ``next_frame`` gave last: the mean of the
        feet's yaws at that plan frame (while rising: the first; while lowering: the last). For the view."""
        return float(torso_yaw(self._ext_at("yaw", max(self._k - 1, 0))))

    def _ext_at(self, name: str, j: int):
        a = self._ext[name]
        return a[min(j - self._base, len(a) - 1)]

    def _last_frame(self) -> int:
        """Index of the walk's last frame once closed; unbounded while it is open."""
        return self._committed - 1 if self.finished else 1 << 60

    # --- online (the preview stages: gaitbot.gait.balance.lookahead) -----------------------------
    @property
    def pending_frames(self) -> int:
        """Body placements a spread append has left for ``work``."""
        return 0 if self._pending is None else self._pending[1] - max(self._pending[0], self._k) + 1

    def next_frame(self):
        """(t_s, q_rad (12,), goal_rad (12,), root_m (3,)) of the next frame, or None after the last."""
        j = self._out
        if j < self.rise_frames:
            roots, q = self._rise
            frame = (q[j].copy(), q[j].copy(), roots[j].copy())
            self._warm_up(j)
        else:
            frame = self._balance_frame()
            if frame is None:
                if self._lower is None:
                    last = self._committed - 1 - self._base
                    self._lower = self.straight_path(self._last_root, self._ext["ankles"][last], rising=False,
                                                     yaw=self._ext["yaw"][last])
                i = j - self.rise_frames - self._committed
                if i >= self.rise_frames:
                    return None
                roots, q = self._lower
                frame = (q[i].copy(), q[i].copy(), roots[i].copy())
        self._out += 1
        return (j / self.rate_hz, *frame)

    def _warm_up(self, j: int) -> None:
        """While rising (frames that cost nothing), run the first preview stage a share of the horizon
        ahead each frame, so that the balance plan's first frame does not pay for a whole horizon."""
        if not self._primed:
            self._prime()
        ahead = self.gains.horizon_frames + 2
        until = math.ceil((j + 1) * ahead / self.rise_frames) - 1
        self._stage1_until(until)
        self._zmp_errors_until(min(until - 1, self.gains.horizon_frames))

    def _balance_frame(self):
        """The balance plan's next frame: (q, goal, root), or None after its last."""
        if not self._primed:
            self._prime()
        k = self._k
        if k >= self._committed and not self.finished:
            self.finish()  # the queue ran dry: close the feet and stand
        if k >= self._committed:
            return None
        horizon = self.gains.horizon_frames
        self._stage1_until(k + horizon + 1)
        self._zmp_errors_until(k + horizon)
        stage2 = self._stage2
        correction = stage2.com
        e = self._err[k - self._base:k - self._base + horizon + 2]
        (px, py), = stage2.preview_sums(e, 0, 1).tolist()
        stage2.step(-e[0, 0], -e[0, 1], -px, -py)
        s1 = self._s1_com[k]
        extra = self.com_offset_m
        com = (s1[0] + correction[0] + extra[0], s1[1] + correction[1] + extra[1])
        flat = self._flat
        guess = extrapolated(self._offset, self._previous_offset)
        yaws = self._yaws_at(k)
        root, q, _ = flat.place(com[0], com[1], self._ext_at("ankles", k), float(self._ext_at("root_z", k)),
                                guess[0], guess[1], self.com_slope, PLACEMENT_TOLERANCE_M, MAX_PLACEMENT_ITERATIONS,
                                yaws)
        self._previous_offset = self._offset
        self._offset = (root[0] - com[0], root[1] - com[1])
        for cache in (self._s1_com, self._s1_snapshot, self._s1_offsets):  # drop the past
            cache.pop(k - 2, None)
        goal = q
        if self.feedforward:
            torque = self._gravity_torques(q, root, k, yaws)
            last = self._committed - 1 if self.finished else math.inf
            w = float(feedforward_weight(k, last, self.rate_hz))
            goal = [a + w * t / kp for a, t, kp in zip(q, torque, self._kp)]
        self._k += 1
        self._last_root = np.array(root)
        self._trim()
        return np.array(q), np.array(goal), np.array(root)

    def _yaws_at(self, i: int):
        """The feet's yaws at plan frame i as floats, or None where both are 0 (the straight walk's code)."""
        yaw = self._ext_at("yaw", i)
        return None if yaw[0] == 0.0 and yaw[1] == 0.0 else (float(yaw[0]), float(yaw[1]))

    def _gravity_torques(self, q, root, k: int, yaws):
        """The sag feedforward's joint torques at plan frame k (the float code; turned feet: the feet's
        centres of pressure in the turned torso's frame)."""
        cops = self._arrays["cops"][k - self._base]
        share = smoothed_share(self._ext["share_left"], self.rate_hz, k - self._base)
        if yaws is None:
            return self._flat.gravity_torques(q, share, ((cops[0, 0] - root[0], cops[0, 1] - root[1]),
                                                         (cops[1, 0] - root[0], cops[1, 1] - root[1])))
        psi = 0.5 * (yaws[0] + yaws[1])
        c, sn = math.cos(psi), math.sin(psi)
        local = [(c * (x - root[0]) + sn * (y - root[1]), -sn * (x - root[0]) + c * (y - root[1]))
                 for x, y in cops.tolist()]
        return self._flat.gravity_torques(q, share, local)


def plan_balanced_walk(body: BodyModel, step_lengths, gait: BalancedGaitSettings,
                       balance: BalanceSettings = BalanceSettings(), **options) -> BalancedWalker:
    """A closed walker with every step queued (nothing computed past the plan yet)."""
    walker = BalancedWalker(body, gait, balance, **options)
    walker._batch = True
    for step in step_lengths:  # a length (m), or a steered step (gaitbot.gait.steer.planner.Footstep)
        if hasattr(step, "foothold"):
            if not walker.planned_steps and step.foothold.side != walker.next_swing_side:
                walker.lead_with(step.foothold.side)
            walker.append_footstep(step.foothold, step.length_m)
        else:
            walker.append_step(step)
    walker._batch = False
    walker.finish()
    return walker


def generate_balanced_walk(body: BodyModel, step_lengths, gait: BalancedGaitSettings,
                           balance: BalanceSettings = BalanceSettings(), **options) -> BalancedWalk:
    """A whole walk as arrays (offline, vectorised): the same frames as BalancedWalker.next_frame."""
    walker = plan_balanced_walk(body, step_lengths, gait, balance, **options)
    return walk_of(walker)


def walk_of(walker: BalancedWalker) -> BalancedWalk:
    """Every frame of a closed walker that has handed out none, computed offline."""
    if not walker.finished or walker._out:
        raise RuntimeError("walk_of needs a closed walker that has not walked")
    a = walker.plan_arrays()
    whole, gains = walker.whole, walker.gains
    n = len(a["zmp"])
    dt = 1.0 / walker.rate_hz
    yaw = a["yaw"] if a["yaw"].any() else None
    com1 = preview_offline(gains, a["zmp"])  # first stage: the cart-table's CoM for the ZMP reference
    root1, q1, _ = whole.place(com1, a["ankles"], a["root_z"], walker.standing_offset, walker.com_slope, yaw)
    points = whole.link_points(root1, q1, yaw)  # second stage: preview the multibody ZMP's error
    error = multibody_zmp(np.concatenate([points[:1], points, points[-1:]]), whole.point_masses_kg, dt) - a["zmp"]
    com_xy = com1 + preview_offline(gains, -error, com_xy0=np.zeros(2))
    root, q, residual = whole.place(com_xy, a["ankles"], a["root_z"], walker.standing_offset, walker.com_slope, yaw)
    goals = q
    if walker.feedforward:
        w = feedforward_weight(np.arange(n), n - 1, walker.rate_hz)[:, None]
        share = smoothed_share(a["share_left"], walker.rate_hz)
        goals = q + w * (whole.sag_goals(q, share, a["cops"], root, walker.kp_nm_per_rad, yaw) - q)
    # the rise from straight legs before the balance plan, and the way back down after it
    rise_root, rise_q = walker.rise_path
    lower_root, lower_q = walker.straight_path(root[-1], a["ankles"][-1], rising=False, yaw=a["yaw"][-1])
    m = walker.rise_frames

    def framed(before, middle, after):
        return np.concatenate([before, middle, after])

    root = framed(rise_root, root, lower_root)
    q = framed(rise_q, q, lower_q)
    goals = framed(rise_q, goals, lower_q)
    _check_limits(walker, q)
    _check_limits(walker, goals)
    ankles = framed(np.repeat(a["ankles"][:1], m, 0), a["ankles"], np.repeat(a["ankles"][-1:], m, 0))
    zmp_ref = framed(np.repeat(a["zmp"][:1], m, 0), a["zmp"], np.repeat(a["zmp"][-1:], m, 0))
    swinging = framed(np.zeros(m, np.int8), a["swinging"], np.zeros(m, np.int8))
    if yaw is not None:
        yaw = framed(np.repeat(yaw[:1], m, 0), yaw, np.repeat(yaw[-1:], m, 0))
    com = root + to_world(whole.mass.com_in_root(q), yaw)
    points = whole.link_points(root, q, yaw)
    zmp_plan = multibody_zmp(np.concatenate([points[:1], points, points[-1:]]), whole.point_masses_kg, dt)
    return BalancedWalk(np.arange(len(q)) / walker.rate_hz, q, goals, root, com, zmp_ref, zmp_plan, ankles,
                        swinging, tuple(walker.heel_strikes), tuple(walker.planned_steps), residual, yaw)


def _check_limits(walker: BalancedWalker, q) -> None:
    if walker.limits_rad is None:
        return
    lower, upper = walker.limits_rad
    bad = (q < np.asarray(lower) - 1e-9) | (q > np.asarray(upper) + 1e-9)
    if bad.any():
        frame, joint = np.argwhere(bad)[0]
        raise BalancedWalkError(f"frame {frame} ({frame / walker.rate_hz:.2f} s): {LEG_JOINTS[joint]} would go to "
                                f"{math.degrees(q[frame, joint]):.1f} deg, outside its limits "
                                f"{math.degrees(lower[joint]):.1f}..{math.degrees(upper[joint]):.1f} deg")
