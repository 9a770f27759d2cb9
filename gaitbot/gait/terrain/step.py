"""One terrain step (Zhang 2008): both feet in the world, the legs by IK from a pelvis path.

A step runs from one heel strike to the next, in two parts of its progress u:

- double support, u in [0, DOUBLE_SUPPORT_U]: the stance foot settles from its landing pitch to
  flat (through ``flat_pause``, so its pivot changes from heel to toe only at zero pitch rate)
  and then stays parallel to its tread; the rear foot stays pinned on its tread and rolls onto
  its toe by as much as it lies behind (``toe_off_pitch``), coming to rest at lift-off;
- swing, u in [DOUBLE_SUPPORT_U, 1]: the rear foot follows ``SwingPath`` from rest to rest and
  lands flat on its foothold;
- heel-off, u in HEEL_OFF_U: where the landing needs it, the stance foot rises onto its toe
  (``_heel_off_pitch``), as a person's trailing foot does before the leading one lands on a stair:
  it lifts the ankle, and so the hip, by up to a foot length times the sine of the pitch, which
  lets the leading leg land on a higher or farther tread without bending its hip past its range.
  The foot comes to rest on its toe at the heel strike and goes on rolling in the next step.

The pelvis is not this module's: ``run_pelvis.py`` builds one path for a run of consecutive terrain
steps and hands it over (``pelvis``); then ``evaluate`` gives every leg angle by 2-link IK.
"""

from __future__ import annotations

import numpy as np

from ..contact import grounded_ankle, heel_pinned_ankle
from ..geometry import leg_ik
from ..walk_segments import GaitContext, GaitGenerationError, WalkState, flat_pause, flat_pause_inverse, flat_pause_slope
from ..smooth import hermite_segment, smootherstep
from .footholds import Foothold
from .legs import LegRange
from .model import Terrain
from .swing import WARPS, SwingPath, warp, warp_table

DOUBLE_SUPPORT_U = 0.25  # share of a terrain step in double support (the rear foot lifts off here)
TERRAIN_STEP_TIME = 1.5  # a terrain step takes this many flat steps' time: higher lifts at the same joint speeds
TOE_OFF_RAD = np.radians(20.0)  # a rear foot a whole foot length (or more) behind rolls this far onto its toe
HEEL_OFF_U = (0.65, 0.95)  # the stance heel may rise over this part of the step (and rest on its toe till the strike)
HEEL_OFF_CHOICES_RAD = np.radians([0.0, -4.0, -8.0, -12.0, -16.0, -20.0, -25.0, -30.0])
HEEL_OFF_ROOM = 0.5  # the least heel-off leaving the pelvis this share of the most room any heel-off leaves
LANDING_SPARE_RAD = np.radians(3.0)  # the landing test keeps this far inside the joint ranges
LANDING_MIN_KNEE_RAD = np.radians(8.0)
TIP_LIFT_SHARE = 1.0  # a timing whose tipped sole needs more extra lift than this share of the clearance is out:
# the tip grows with the lift (a higher foot bends the knee more), so large extra lifts are fragile
FREE_ANKLE_RAD = (-np.radians(60.0), np.radians(60.0))  # the swing ankle's range when no joint ranges are given


def toe_off_pitch(pitch0: float, rate_u: float, behind: float, above: float, g, limit: float) -> float:
    """Pitch (negative: toe down) at which a pinned rear foot comes to rest before it lifts.

    A foot beside the stance foot lifts flat; one a foot length or more behind rolls onto its toe
    by TOE_OFF_RAD, which raises its ankle towards the hip (what lets a short leg reach a long or
    rising step). A rear foot higher than the stance foot (a step down) rolls less, none from a
    tenth of a leg length up: raising it further would only bend the knee more. A foot already
    rolling keeps rolling where its rate takes it, but never past the pitch limit (a foot that a
    deep heel-off left rolled further comes back to it)."""
    higher = float(np.clip(1.0 - above / (0.1 * g.leg_length), 0.0, 1.0))
    target = -TOE_OFF_RAD * float(np.clip(behind / g.foot, 0.0, 1.0)) * higher
    coasting = pitch0 + rate_u / 3.0
    return float(max(min(target, coasting) if pitch0 < 0 else target, -max(limit, TOE_OFF_RAD)))


class TerrainStepSegment:
    """One step off the flat: from a heel strike (or the crouch) to the heel strike on ``target``.

    ``stance`` and ``rear`` are the footholds under the supporting and the rear foot at the start."""

    def __init__(self, ctx: GaitContext, state: WalkState, stance: Foothold, rear: Foothold, target: Foothold,
                 terrain: Terrain, clearance: float, legs: LegRange, t0: float, closing: bool = False) -> None:
        self.ctx, self.state, self.terrain = ctx, state, terrain
        self.stance_hold, self.rear_hold, self.target = stance, rear, target
        self.t0, self.closing = t0, closing
        self.n_frames = int(round(ctx.step_frames * TERRAIN_STEP_TIME))
        self.duration = self.n_frames / ctx.rate_hz
        self.u_ds = DOUBLE_SUPPORT_U
        self.foothold = target.heel_x
        self.step_length = target.heel_x - state.anchor_stance
        self.what = f"step to x = {target.heel_x:.3f} m (height {target.height:.3f} m)"
        g = ctx.geometry
        ds_time = self.duration * self.u_ds
        raw = flat_pause_inverse(state.foot_stance[2])
        slope = float(flat_pause_slope(raw))
        self._stance_raw0 = raw
        self._stance_raw_rate0 = (state.foot_rate_stance[2] / slope if slope > 1e-9 else 0.0) * ds_time
        self._rear0, self._rear_rate0 = state.pitch_rear, state.pitch_rate_rear * ds_time
        self._rear_off = toe_off_pitch(state.pitch_rear, self._rear_rate0, state.anchor_stance - state.anchor_rear,
                                       rear.height - stance.height, g, ctx.pitch_limit_rad)
        self.landing = np.array([*heel_pinned_ankle(g, self.foothold, 0.0, target.height), 0.0])
        ankle = (legs.joint_lo[2], legs.joint_hi[2]) if legs.joint_lo is not None else FREE_ANKLE_RAD
        self.swing = SwingPath(g, terrain, self.rear_world(np.array([self.u_ds]))[0], self.landing, clearance,
                               ankle, self.what)
        self.heel_off = self._heel_off_pitch(legs.with_spare(LANDING_SPARE_RAD, LANDING_MIN_KNEE_RAD))
        self.pelvis = None  # set by the run

    def _heel_off_pitch(self, legs: LegRange) -> float:
        """The heel-off (toe-down pitch of the stance foot at the heel strike): the least that leaves the pelvis
        at least HEEL_OFF_ROOM of the most room any choice leaves, room being the pelvis points (on a grid)
        from which both legs reach their feet with ``legs``' margins all through the swing's last part
        (the approach and the landing, where the pelvis moves little). Rising steps need it for the
        leading hip, falling ones for the stance ankle; a step that has room enough flat takes none."""
        g = self.ctx.geometry
        ground = self.stance_hold.height
        s = np.linspace(0.7, 1.0, 4)
        u = self.u_ds + s * (1.0 - self.u_ds)
        swing = self.swing.path(s, lift=True)
        top = max(ground, self.target.height) + g.leg_length + g.ankle_height
        xs = np.linspace(min(self.landing[0], self.state.anchor_stance) - 0.5 * g.leg_length,
                         max(self.landing[0], self.state.anchor_stance) + 0.5 * g.leg_length, 51)
        ys = np.linspace(top - 0.6 * g.leg_length, top, 41)
        gx, gy = np.meshgrid(xs, ys, indexing="ij")
        roots = np.column_stack([gx.ravel(), gy.ravel()])
        n = len(roots)
        swing_fits = np.ones(n, bool)
        for i, pose in enumerate(swing):
            swing_fits &= legs.fits(np.repeat(pose[None], n, axis=0), roots, i == len(s) - 1)
        room = []
        for pitch in HEEL_OFF_CHOICES_RAD:
            fits = swing_fits.copy()
            for pose in self._stance_pose(u, pitch):
                fits &= legs.fits(np.repeat(pose[None], n, axis=0), roots)
            room.append(int(fits.sum()))
        room = np.array(room)
        return float(HEEL_OFF_CHOICES_RAD[int(np.argmax(room >= HEEL_OFF_ROOM * room.max()))])

    @property
    def lift(self) -> float:
        return self.swing.total_lift

    # --- feet in the world ---------------------------------------------------------------------
    def stance_world(self, u):
        """The supporting foot: settling flat over the double support, flat on its tread, then rising
        onto its toe by ``heel_off`` towards the heel strike."""
        return self._stance_pose(u, self.heel_off)

    def _stance_pose(self, u, heel_off: float):
        u = np.atleast_1d(np.asarray(u, dtype=float))
        x = np.clip(u / self.u_ds, 0.0, 1.0)
        raw = hermite_segment(x, np.array([self._stance_raw0]), np.array([self._stance_raw_rate0]),
                              np.zeros(1), np.zeros(1))[:, 0]
        pitch = flat_pause(raw) + heel_off * smootherstep((u - HEEL_OFF_U[0]) / (HEEL_OFF_U[1] - HEEL_OFF_U[0]))
        ankle = grounded_ankle(self.ctx.geometry, self.state.anchor_stance, pitch, self.stance_hold.height)
        return np.column_stack([ankle, pitch])

    def rear_world(self, u):
        """The rear foot while pinned (u <= u_ds): rolling about its lower point to its toe-off pitch."""
        u = np.atleast_1d(np.asarray(u, dtype=float))
        x = np.clip(u / self.u_ds, 0.0, 1.0)
        pitch = hermite_segment(x, np.array([self._rear0]), np.array([self._rear_rate0]), np.array([self._rear_off]),
                                np.zeros(1))[:, 0]
        ankle = grounded_ankle(self.ctx.geometry, self.state.anchor_rear, pitch, self.rear_hold.height)
        return np.column_stack([ankle, pitch])

    def swing_time(self, s):
        """Time at swing progress s in [0, 1] (lift-off to heel strike)."""
        return self.time(self.u_ds + np.asarray(s, dtype=float) * (1.0 - self.u_ds))

    def swing_frames(self) -> int:
        """Frames from lift-off to the heel strike (a dense check of the swing samples every one)."""
        return int(np.ceil(self.n_frames * (1.0 - self.u_ds))) + 1

    def feasible_warp(self, pelvis, legs: LegRange, s_to: float = 1.0, samples: int = 31, warps=WARPS):
        """The swing timing (of ``warps``, nearest the identity first) that keeps the swing leg in its
        ranges, and its speed and acceleration limits (``LegRange.motion_excess``), from lift-off to swing
        progress ``s_to`` for the pelvis path ``pelvis(t)``, and 0; or, if none does, the one that comes
        nearest and by how much (``LegRange.excess`` summed over the samples). The foot is the fitted
        one (its sole tipped for the ankle and lifted to stay clear), so the ankle keeps its range by
        construction and is not checked; a timing whose tipped sole needs more extra lift than
        TIP_LIFT_SHARE of the clearance counts as that much beyond too."""
        return self.feasible_warps(pelvis(self.swing_times(s_to, samples))[None], legs, s_to, warps)[0]

    def swing_times(self, s_to: float = 1.0, samples: int = 31):
        """The times (s) at which ``feasible_warp`` samples the swing: lift-off to swing progress ``s_to``."""
        return self.swing_time(np.linspace(0.0, s_to, samples))

    def feasible_warps(self, roots, legs: LegRange, s_to: float = 1.0, warps=WARPS) -> list:
        """``feasible_warp`` for many pelvis paths at once (the grid search scores a level's cells together):
        ``roots`` (p, samples, 2), each path's hip at ``swing_times(s_to, samples)``; p (timing, excess)."""
        paths, samples = roots.shape[:2]
        s = np.linspace(0.0, s_to, samples)
        sigma = warp_table(s_to, samples) if warps is WARPS else np.stack([warp(s, *w) for w in warps])
        rows = len(warps) * paths
        hips = np.broadcast_to(roots[:, None], (paths, len(warps), samples, 2))
        poses, extra = self.swing.fitted(s, sigma, hips, paths=paths)
        excess, q = legs.check(poses.reshape(-1, 3), hips.reshape(-1, 2), False)
        excess = excess.reshape(rows, samples).sum(axis=1)
        excess += np.maximum(extra - TIP_LIFT_SHARE * self.swing.clearance, 0.0) / self.ctx.geometry.leg_length
        excess += legs.motion_excess(q.reshape(rows, samples, 3),
                                     s_to * self.duration * (1.0 - self.u_ds) / (samples - 1))
        out = []
        for row in excess.reshape(paths, len(warps)):
            best = int(np.argmax(row <= 0.0)) if (row <= 0.0).any() else int(np.argmin(row))
            out.append((warps[best], float(row[best])))
        return out

    def swing_progress(self, u):
        return np.clip((np.asarray(u, dtype=float) - self.u_ds) / (1.0 - self.u_ds), 0.0, 1.0)

    def other_world(self, u):
        """The rear foot, pinned then swinging."""
        u = np.atleast_1d(np.asarray(u, dtype=float))
        return np.where((u <= self.u_ds)[:, None], self.rear_world(u), self.swing(self.swing_progress(u)))

    def feet_world(self, u):
        """(stance pose, other pose, other supporting?) in the world for progress u."""
        u = np.atleast_1d(np.asarray(u, dtype=float))
        return self.stance_world(u), self.other_world(u), u <= self.u_ds

    def time(self, u):
        return self.t0 + np.asarray(u, dtype=float) * self.duration

    def finalize_swing(self, warp_coeffs) -> None:
        """Once the pelvis is known: fix the swing's timing and fit its sole to the ankle's range."""
        self.swing.finalize(warp_coeffs, lambda s: self.pelvis(self.swing_time(s)))

    # --- the segment ---------------------------------------------------------------------------
    def evaluate(self, u):
        u = np.atleast_1d(np.asarray(u, dtype=float))
        root = self.pelvis(self.time(u))
        stance, other, _ = self.feet_world(u)
        qs, qo = self._ik(stance, root), self._ik(other, root)
        left, right = (qs, qo) if self.state.stance_left else (qo, qs)
        return np.concatenate([left, right], axis=-1), root

    def _ik(self, pose, root):
        try:
            return leg_ik(self.ctx.geometry, pose[:, :2] - root, pose[:, 2])
        except ValueError:
            raise GaitGenerationError(f"{self.what}: a foot is out of the leg's reach") from None

    def end_state(self) -> WalkState:
        t1 = self.time(1.0)
        root, vel = self.pelvis(t1)[0], self.pelvis.velocity(t1)[0]
        return WalkState(
            stance_left=not self.state.stance_left,
            anchor_stance=self.foothold,
            anchor_rear=self.state.anchor_stance,
            foot_stance=np.array([*(self.landing[:2] - root), 0.0]),
            foot_rate_stance=np.array([*(-vel), 0.0]),
            pitch_rear=self.heel_off,
            pitch_rate_rear=0.0,
            step_length=self.step_length,
        )

    def provisional_end_state(self) -> WalkState:
        """The state after this step as far as the next terrain step needs it before the pelvis exists."""
        return WalkState(not self.state.stance_left, self.foothold, self.state.anchor_stance, np.zeros(3), np.zeros(3),
                         self.heel_off, 0.0, self.step_length)
