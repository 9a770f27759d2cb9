"""The measured CoM error fed to the preview controller's state: a CoM correction whose ZMP stays in the soles.

The first preview stage (gaitbot.gait.balance.preview, FloatPreview.step) is linear in its state z = [s, x, x',
x''] per axis (s: the summed ZMP error). Two runs on the same reference that start from states differing by dz0
differ ever after by dz_k = M^k dz0, M the closed loop (``closed_loop``):

    s+ = s + C X,   u = -k_sum s+ - K X,   X+ = A X + B u      (the reference's part cancels)

so the controller's answer to a state error is the plan plus that decaying response, superposed. What the
IMU measures is not the CoM but the torso's tilt; the plan keeps the torso upright, so (as the capture
point's estimate, gaitbot.feel.capture) the CoM's unplanned error is e = z_c tilt, at e' = z_c tilt rate,
and where the walker places the pelvis does not change it. The correction dz (added to the plan's CoM, the
legs placed for it by the walker's own IK, gaitbot.gait.balance.walker's ``com_offset_m``) is kept as the
controller would run from the plan plus the correction plus g e, less what will still be there of the
error one frame on (it moves on at its rate), since the walker commands only the joints:

    dz <- M (dz + g e4) - g e4',    e4 = [0, e, e', 0],  e4' = [0, e + e' dt, e', 0]      (``step``)

With no error dz decays to zero along the controller's own response; a steady error e leads to dz = -g e.
``gain`` g (|g| <= 1) sets the sign: g > 0 brings the CoM back over its plan's point, against the lean (the
ZMP moves toward the error first); g < 0 yields, the commanded CoM following a share of the measured error
before the closed loop brings it back (the robot gives way to a push in its joints rather than tipping on a
sole's edge). Measured in gaitbot's own simulation (docs/feedback.md): g > 0 loses pushes the open walk
survives, g < 0 survives about as many as ``full``; so GAIN is -0.3.

The closed loop comes from preview gains of the same model with the jerk weight JERK_WEIGHT (the walker's own,
1e-6, answers within a few frames: its accelerations put the correction's ZMP at the sole's edge for a 1 cm
error, and it lost more pushes). The correction's own ZMP shift C dz = dx - (z_c / g) dx'' is kept inside
the support polygon (the grounded soles' convex hull, each sole shrunk about its centre to SOLE_SHARE): if
the plan's ZMP reference plus the shift would leave it, the shift is cut back along itself to the polygon's
edge by changing dz's acceleration only (the position stays continuous). A dead band (DEAD_BAND_M of the
capture point's error, soft: only the part beyond it is fed) keeps an unpushed walk on its plan. Each
``step`` is a few dozen float operations and a hull of at most 8 corners: microseconds a frame.
"""

from __future__ import annotations

import math

import numpy as np

from gaitbot.gait.balance.preview import GRAVITY_M_S2, PreviewGains, preview_gains
from gaitbot.gait.balance.zmp_reference import FootPlacement
from gaitbot.gait.body import SIDE_SIGN, BodyGeometry
from gaitbot.gait.convex_hull import convex_hull

GAIN = -0.3
"""The share of the measured error fed to the controller's state, signed (module docstring; docs/feedback.md:
+0.3 lost pushes; -0.3, -0.6 and -1 survived as many as feedback full)."""
DEAD_BAND_M = 0.03
"""The capture point's error (m) below which nothing is fed: at 1.5 cm (the unpushed error's size) the walk's own sway
was fed, up to 10 ticks from the plan; at 3 cm the unpushed 0.15 m/s walk stays within 3 ticks of it."""
JERK_WEIGHT = 1e-2
"""The correction's closed loop: preview gains of the walker's model with this jerk weight (None: the walker's
own; 1e-3 measured alike, the walker's 1e-6 lost more pushes). Its slowest mode decays by 0.957 a frame at the
op3's 60 Hz (5% left after about 70 frames)."""
SOLE_SHARE = 0.8
"""The correction's ZMP stays inside the soles shrunk to this share of their length and width."""
GROUNDED_M = 1e-6
SIDES = ("left", "right")


def closed_loop(gains: PreviewGains) -> np.ndarray:
    """The first preview stage's closed loop (4, 4) on z = [s, x, x', x''] with the reference removed."""
    a, b, c = gains.a, gains.b, gains.c
    k = np.concatenate([[gains.k_sum], gains.k_state])
    # z' = [s + C X; A X + B u], u = -k [s'; X]
    pre = np.zeros((4, 4))
    pre[0, 0], pre[0, 1:] = 1.0, c
    pre[1:, 1:] = np.eye(3)
    after = np.zeros((4, 4))
    after[0, 0] = 1.0
    after[1:, 1:] = a
    u = -k @ pre  # the input as a function of z (through s')
    return after @ pre + np.concatenate([[0.0], b])[:, None] @ u[None, :]


def sole_corners(geometry: BodyGeometry, foot: FootPlacement, share: float) -> list[tuple[float, float]]:
    """The sole's four corners on the floor, shrunk about its centre to ``share`` of its length and width."""
    fwd = geometry.foot_m / 2 - geometry.heel_back_m
    left = SIDE_SIGN[foot.side] * geometry.sole_outward_m
    half_l, half_w = share * geometry.foot_m / 2, share * geometry.foot_width_m / 2
    c, s = math.cos(foot.yaw_rad), math.sin(foot.yaw_rad)
    return [(foot.x_m + c * (fwd + a * half_l) - s * (left + b * half_w),
             foot.y_m + s * (fwd + a * half_l) + c * (left + b * half_w))
            for a, b in ((1, 1), (-1, 1), (-1, -1), (1, -1))]


def support_polygon(geometry: BodyGeometry, ankles, yaws, share: float = SOLE_SHARE) -> list[tuple[float, float]]:
    """The grounded soles' hull (counter-clockwise) for one frame's ankle points (2, 3: left, right) and
    yaws (2,): a sole is grounded when its ankle is at the standing ankle height."""
    corners = []
    for i, side in enumerate(SIDES):
        if float(ankles[i][2]) <= geometry.ankle_height_m + GROUNDED_M:
            corners += sole_corners(geometry, FootPlacement(side, float(ankles[i][0]), float(ankles[i][1]),
                                                            float(yaws[i])), share)
    return convex_hull(corners)


def fraction_inside(start, shift, hull) -> float:
    """The largest t in [0, 1] with start + t shift inside the counter-clockwise convex ``hull`` (0 if start
    itself is outside, or there is no polygon)."""
    if len(hull) < 3:
        return 0.0
    px, py = float(start[0]), float(start[1])
    dx, dy = float(shift[0]), float(shift[1])
    t = 1.0
    for k in range(len(hull)):
        ax, ay = hull[k]
        bx, by = hull[(k + 1) % len(hull)]
        ex, ey = bx - ax, by - ay
        inside = ex * (py - ay) - ey * (px - ax)  # >= 0 inside this edge
        if inside < 0:
            return 0.0
        toward = ex * dy - ey * dx  # d(inside)/dt
        if toward < 0:
            t = min(t, inside / -toward)
    return max(0.0, t)


class ComCorrection:
    """The CoM correction (x, y; m) of the walker's next frame from the measured CoM error (module docstring).

    ``step(error_m, rate_m_s, zmp_ref, hull)`` once a frame: the measured error (x, y) and its rate, the
    plan's ZMP reference at the frame and its support polygon; returns the correction to add to the frame's
    planned CoM. ``zmp_shift_m`` is the correction's ZMP shift (x, y) after the clip."""

    def __init__(self, gains: PreviewGains, *, gain: float | None = None, dead_band_m: float | None = None,
                 sole_share: float | None = None, jerk_weight: float | None = None) -> None:
        gain = GAIN if gain is None else gain
        jerk_weight = JERK_WEIGHT if jerk_weight is None else jerk_weight
        if jerk_weight is not None:
            gains = preview_gains(gains.com_height_m, gains.dt_s, gains.horizon_frames, jerk_weight)
        dead_band_m = DEAD_BAND_M if dead_band_m is None else dead_band_m
        self.sole_share = SOLE_SHARE if sole_share is None else sole_share
        if not -1.0 <= gain <= 1.0:
            raise ValueError(f"the correction's gain must be within -1..1, got {gain}")
        self.m = closed_loop(gains)
        self.rows = [tuple(float(v) for v in row) for row in self.m]
        self.dt = gains.dt_s
        self.z_over_g = gains.com_height_m / GRAVITY_M_S2
        self.omega = math.sqrt(GRAVITY_M_S2 / gains.com_height_m)
        self.gain, self.dead_band_m = float(gain), float(dead_band_m)
        self.state = [[0.0, 0.0, 0.0, 0.0], [0.0, 0.0, 0.0, 0.0]]  # per axis: s, x, x', x''
        self.zmp_shift_m = (0.0, 0.0)
        self.clipped = 0  # frames whose ZMP shift was cut back

    @property
    def offset_m(self) -> tuple[float, float]:
        return self.state[0][1], self.state[1][1]

    def fed_share(self, error_m, rate_m_s) -> float:
        """The share of the error fed: gain x the part of the capture point's error beyond the dead band."""
        dcm = math.hypot(error_m[0] + rate_m_s[0] / self.omega, error_m[1] + rate_m_s[1] / self.omega)
        if dcm <= self.dead_band_m:
            return 0.0
        return self.gain * (1.0 - self.dead_band_m / dcm)

    def step(self, error_m, rate_m_s, zmp_ref=None, hull=None) -> tuple[float, float]:
        g = self.fed_share(error_m, rate_m_s)
        rows, dt = self.rows, self.dt
        for axis in range(2):
            s, x, v, a = self.state[axis]
            e, r = g * float(error_m[axis]), g * float(rate_m_s[axis])
            z = (s, x + e, v + r, a)
            s, x, v, a = (sum(m * w for m, w in zip(row, z)) for row in rows)
            self.state[axis] = [s, x - e - r * dt, v - r, a]
        shift = [st[1] - self.z_over_g * st[3] for st in self.state]
        if hull is not None and zmp_ref is not None and (shift[0] or shift[1]):
            t = fraction_inside(zmp_ref, shift, hull)
            if t < 1.0:
                self.clipped += 1
                for axis in range(2):
                    st = self.state[axis]
                    shift[axis] *= t
                    st[3] = (st[1] - shift[axis]) / self.z_over_g
        self.zmp_shift_m = (shift[0], shift[1])
        return self.offset_m
