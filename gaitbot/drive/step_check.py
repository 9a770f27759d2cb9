"""The drive's check of every planned step before the walker gets it (before its first frame is sent).

Preflight cannot see a live walk's future, so each step the footstep planner proposes is checked here, from
the step's own plan (the walker's ``preview_step``: its frames' ankles, feet yaws, root height and ZMP
reference, computed on copies), before it is appended:

* the feet's clearance: the stance sole and the swing sole along the swing's whole path keep the robot's
  ``[steer] min_gap_m`` (the planner measures it for every step, its last resort included: Footstep.gap_m);
* balance: at every frame of the step the planned ZMP lies inside the support polygon (the soles on the
  floor) by at least ZMP_MARGIN_SHARE of the sole's width;
* limits: the legs' angles at every frame of the step, from the IK of the planned ankles with the pelvis
  over the CoM of the linear inverted pendulum whose ZMP follows the step's reference (``lipm_com``; after
  the step, the close the walker previews), inside the joints' limits (within ANGLE_SLACK_DEG) and within
  reach, and their velocities and accelerations (finite differences over the frames) within
  PREDICTION_SLACK times the limits.

The limits are a prediction (the walker places the body by its two preview stages), so the slack lets
through what the frame guard (gaitbot.drive.guard) judges exactly, frame by frame; a step refused here is
never appended: the drive plans a stop instead. The work is split in STAGES stages, one a frame
(python tools/step_check_accuracy.py measures the prediction's error and each stage's cost).
"""

from __future__ import annotations

import math

import numpy as np

from gaitbot.gait.balance.placement import torso_yaw
from gaitbot.gait.balance.zmp_reference import FootPlacement, smootherstep, zmp_point
from gaitbot.gait.convex_hull import convex_hull
from gaitbot.gait.joints import LEG_JOINTS, SIDES
from gaitbot.gait.kinematics6 import ReachError, leg_ik, rot_z
from gaitbot.gait.mass import GRAVITY_M_S2
from gaitbot.gait.steer.soles import sole_box

GAP_TOLERANCE_M = 1e-4
STAGES = 3
"""Frames a live drive spends on one step's check (the plan's preview, balance, limits)."""
ZMP_MARGIN_SHARE = 0.1
"""The planned ZMP keeps this share of the sole's width from the support polygon's edge."""
ANGLE_SLACK_DEG = 10.0
"""A predicted angle may pass its limit by this much (the estimate's error): the frame guard is exact."""
PREDICTION_SLACK = 1.25
"""A predicted velocity or acceleration may reach this multiple of its limit (the estimate's error:
python tools/step_check_accuracy.py measures it: docs/driving.md)."""
GROUNDED_M = 1e-6


KERNEL_SPAN = 4.0
"""The LIPM CoM kernel exp(-w |t|) is cut at this many time constants (exp(-4): 2% of its peak)."""


class StepCheck:
    """``stages(walker, step)``: why the step would fail, or None, a stage a frame."""

    def __init__(self, config, period_s: float) -> None:
        joints = {j.name: j for j in config.joints}
        chosen = [joints[name] for name in LEG_JOINTS]
        slack = math.radians(ANGLE_SLACK_DEG)
        self.lower = np.radians([j.hold_deg if j.hold_deg is not None else j.min_deg for j in chosen]) - slack
        self.upper = np.radians([j.hold_deg if j.hold_deg is not None else j.max_deg for j in chosen]) + slack
        self.max_velocity = np.radians([j.max_velocity_dps for j in chosen]) * PREDICTION_SLACK
        self.max_accel = np.radians([j.max_acceleration_dps2 for j in chosen]) * PREDICTION_SLACK
        self.period_s = period_s
        self.geometry = config.body.geometry
        self.min_gap_m = config.steer.min_gap_m if config.steer is not None else 0.0
        self.margin_m = ZMP_MARGIN_SHARE * self.geometry.foot_width_m

    def stages(self, walker, step, replacing_last: bool = False):
        """Why ``step`` (a gaitbot.gait.steer.planner.Footstep for the walker's next swing foot) would fail,
        as a generator of STAGES stages (one a frame: each well under a millisecond) whose return value is the
        reason or None; the walker does not change. Valid while the walker gets no other step.
        ``replacing_last``: ``step`` in place of the walker's last step, not started (BalancedWalker.preview_step)."""
        gap = step.gap_m  # measured by the planner over the swing's path, its last resort included
        if gap < self.min_gap_m - GAP_TOLERANCE_M:
            return f"would bring the soles {gap * 1e3:.1f} mm apart (the least is {self.min_gap_m * 1e3:.0f} mm)"
        arrays, first, end = walker.preview_step(step.foothold, max(0.0, step.length_m),
                                                 before_frames=round(KERNEL_SPAN / self.omega(walker) / self.period_s),
                                                 replacing_last=replacing_last)
        yield
        reason = self._balance(arrays, first, end)
        if reason is not None:
            return reason
        yield
        reason = self._limits(walker, arrays, first, end, step.foothold)
        yield
        return reason

    def _with_close(self, zmp, arrays, walker, foothold: FootPlacement) -> np.ndarray:
        """The ZMP reference followed by the close the walker previews when no step follows, without planning
        it: to the new foot's ZMP point in a double support, held while the other foot closes beside it,
        then back between the soles' centres over one step (smootherstep), then held."""
        g, t = self.geometry, walker.timing
        centres = []
        for i in range(2):
            x, y, _ = arrays["ankles"][-1, i]
            yaw = float(arrays["yaw"][-1, i])
            u, v = g.foot_m / 2 - g.heel_back_m, (1 if i == 0 else -1) * g.sole_outward_m
            centres.append((x + math.cos(yaw) * u - math.sin(yaw) * v, y + math.sin(yaw) * u + math.cos(yaw) * v))
        middle = np.mean(centres, axis=0)
        landed = zmp_point(g, walker.balance, foothold)
        w_ds = smootherstep(np.arange(1, t.ds_frames + 1) / t.ds_frames)[:, None]
        w = smootherstep(np.arange(1, t.step_frames + 1) / t.step_frames)[:, None]
        return np.concatenate([zmp, zmp[-1] + w_ds * (landed - zmp[-1]), np.repeat(landed[None], t.ss_frames, 0),
                               landed + w * (middle - landed)])

    @staticmethod
    def omega(walker) -> float:
        return math.sqrt(GRAVITY_M_S2 / walker.com_height_m)

    def _balance(self, arrays, first: int, end: int) -> str | None:
        g, h = self.geometry, self.geometry.ankle_height_m
        ankles, yaws, zmp = arrays["ankles"], arrays["yaw"], arrays["zmp"]
        worst, where, hulls = math.inf, None, {}
        for k in range(first, end):
            grounded = tuple(bool(ankles[k, i, 2] <= h + GROUNDED_M) for i in range(2))
            key = (grounded, *(tuple(ankles[k, i, :2]) + (yaws[k, i],) for i in range(2) if grounded[i]))
            hull = hulls.get(key)
            if hull is None:
                corners = [c for i, side in enumerate(SIDES) if grounded[i] for c in
                           sole_box(g, FootPlacement(side, float(ankles[k, i, 0]), float(ankles[k, i, 1]),
                                                     float(yaws[k, i])))]
                hull = hulls[key] = convex_hull(corners) if len(corners) >= 3 else []
            depth = _depth_in_hull(zmp[k], hull)
            if depth < worst:
                worst, where = depth, k - first
        if worst < self.margin_m:
            return (f"would put its planned ZMP {worst * 1e3:.1f} mm inside the support polygon at frame {where} "
                    f"(the least is {self.margin_m * 1e3:.1f} mm)")
        return None

    def predicted_angles(self, walker, arrays, first: int, end: int,
                         foothold: FootPlacement) -> tuple[np.ndarray, int]:
        """The legs' angles (n, 12; LEG_JOINTS) predicted for the step's frames and up to two frames before
        them (for the differences), and how many frames come before; ReachError if a foot is out of reach."""
        lo, hi = max(0, first - 2), end
        com = lipm_com(self._with_close(arrays["zmp"], arrays, walker, foothold), walker.com_height_m,
                       self.period_s)[lo:hi]
        idx = np.arange(lo, hi)
        yaw = arrays["yaw"][idx]
        psi = torso_yaw(yaw)
        off = np.asarray(walker.standing_offset, dtype=float)
        c, s = np.cos(psi), np.sin(psi)
        root = np.stack([com[:, 0] + c * off[0] - s * off[1], com[:, 1] + s * off[0] + c * off[1],
                         arrays["root_z"][idx]], -1)
        ankles = arrays["ankles"][idx]
        back = rot_z(-psi)
        q = np.concatenate([leg_ik(self.geometry, side, np.einsum("nij,nj->ni", back, ankles[:, i] - root),
                                   rot_z(yaw[:, i] - psi)) for i, side in enumerate(SIDES)], axis=-1)
        return q, first - lo

    def _limits(self, walker, arrays, first: int, end: int, foothold: FootPlacement) -> str | None:
        try:
            q, skip = self.predicted_angles(walker, arrays, first, end, foothold)  # skip: frames before the step
        except ReachError as exc:
            return f"is out of the legs' reach ({exc})"
        bad = (q[skip:] < self.lower) | (q[skip:] > self.upper)
        if bad.any():
            k, j = np.argwhere(bad)[0]
            return (f"would take {LEG_JOINTS[j]} to {math.degrees(q[skip + k, j]):.1f} deg at frame {k}, outside "
                    f"its limits")
        dt = self.period_s
        velocity = np.diff(q, axis=0) / dt
        v0, a0 = max(0, skip - 1), max(0, skip - 2)
        fast = np.abs(velocity[v0:]) > self.max_velocity
        if fast.any():
            k, j = np.argwhere(fast)[0]
            return (f"would move {LEG_JOINTS[j]} at {math.degrees(abs(velocity[v0 + k, j])):.0f} deg/s, "
                    f"beyond its limit")
        accel = np.diff(velocity, axis=0) / dt
        sharp = np.abs(accel[a0:]) > self.max_accel
        if sharp.any():
            k, j = np.argwhere(sharp)[0]
            return (f"would accelerate {LEG_JOINTS[j]} at {math.degrees(abs(accel[a0 + k, j])):.0f} "
                    f"deg/s^2, beyond its limit")
        return None


def lipm_com(zmp, com_height_m: float, period_s: float) -> np.ndarray:
    """The CoM (n, 2) of the linear inverted pendulum whose ZMP follows ``zmp`` (n, 2), bounded both ways:
    x - x''/w^2 = p has the bounded solution x = p convolved with (w/2) exp(-w |t|), w = sqrt(g/z). The
    ends are held (the plan starts and ends still), the kernel cut at KERNEL_SPAN / w and renormalised."""
    w = math.sqrt(GRAVITY_M_S2 / com_height_m)
    half = max(1, round(KERNEL_SPAN / w / period_s))
    t = np.arange(-half, half + 1) * period_s
    kernel = np.exp(-w * np.abs(t))
    kernel /= kernel.sum()
    padded = np.concatenate([np.repeat(zmp[:1], half, 0), zmp, np.repeat(zmp[-1:], half, 0)])
    return np.stack([np.convolve(padded[:, j], kernel, mode="valid") for j in range(2)], -1)


def _depth_in_hull(point, hull) -> float:
    """How far ``point`` lies inside a counter-clockwise convex ``hull`` (negative: outside; -inf: none)."""
    if len(hull) < 3:
        return -math.inf
    px, py = float(point[0]), float(point[1])
    depth = math.inf
    for k in range(len(hull)):
        ax, ay = hull[k]
        bx, by = hull[(k + 1) % len(hull)]
        ex, ey = bx - ax, by - ay
        depth = min(depth, (ex * (py - ay) - ey * (px - ax)) / math.hypot(ex, ey))
    return depth
