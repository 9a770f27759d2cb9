"""Capture-point stepping: the measured divergent component of motion (DCM) and the next foothold moved to it.

The DCM is xi = c + c_dot / omega, omega = sqrt(g / z_c) (Pratt et al., "Capture point: a step toward humanoid
push recovery"; Englsberger et al., "Three-dimensional bipedal walking control based on divergent component
of motion"). The plan keeps the torso upright, so the plan's xi is the planned CoM's, and what the IMU felt
is the difference: with the legs as stiff as their servos hold them, a push tips the whole robot about its
support, and the CoM, z_c above it, moves by z_c x tilt (small angles) at z_c x tilt rate. Hence

    xi_error = z_c (tilt + tilt_rate / omega)     (x: pitch forward; y: -roll, roll positive leaning right)

from the tilt estimate (gaitbot.feel.estimate: gyro and accelerometer only, the same on a robot and in the
simulation). While |xi_error| is inside what the ankles can hold (HOLD_SHARE of the sole's half length and
half width: the ZMP can move that far from its planned point), nothing changes. Beyond it, the next foothold
(a step not yet started) moves by STEP_GAIN x xi_error (xi keeps diverging until that foot lands), the move
clipped per axis to the robot's ``[steer]`` per-step limits (forward, backward, sideways), the foot never
further behind the stance foot than max_backward_m, and never inward: toward the stance foot there is only
the soles' gap's slack (7 mm on the op3: the soles stand 17 mm apart, min_gap_m is 10), and those small
inward moves were measured to make more pushes fall, not fewer (the lateral sway they add grows from step to
step); a push toward the stance foot is caught by the next step, the other foot's, outward. The soles' gap
over the whole swing (gaitbot.gait.steer.soles) is measured and kept at least min_gap_m. The caller then
checks the moved step as the drive checks every step (gaitbot.drive.step_check: reach, joint limits, ZMP).
A robot without ``[steer]`` does not step.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from gaitbot.gait.balance.zmp_reference import FootPlacement
from gaitbot.gait.body import BodyGeometry
from gaitbot.gait.mass import GRAVITY_M_S2
from gaitbot.gait.steer.limits import SteerLimits
from gaitbot.gait.steer.soles import swept_gap_m

HOLD_SHARE = 0.8
"""The share of the sole's half length (forward, back) and half width (sideways) the ankles are trusted to
hold the DCM's error in: the ZMP planned near the sole's middle can move that far before the foot tips
(0.5 moved steps more often and caught no more pushes; an unpushed walk's error stays under 1.5 cm)."""
STEP_GAIN = 1.0
"""The foothold moves by this multiple of the DCM's error when it was felt (0.6, 1.0 and 1.5 measured alike
on the pushes that fell: python tools/push_survival.py --modes step; docs/feedback.md)."""


@dataclass(frozen=True)
class CaptureStep:
    """A decision: the DCM's error (m, x forward, y left, the walk's world), whether it left what the ankles
    hold, and the foothold (moved, or the planned one)."""

    error_m: tuple[float, float]
    beyond: bool
    foothold: FootPlacement
    moved_m: tuple[float, float]
    gap_m: float = math.inf  # the soles' least gap over the swing to the foothold (m; measured when moved)


def dcm_error_m(roll_deg: float, pitch_deg: float, roll_rate_dps: float, pitch_rate_dps: float,
                com_height_m: float) -> tuple[float, float]:
    """The measured DCM minus the plan's (x forward, y left; m), from the torso's tilt and tilt rates."""
    omega = math.sqrt(GRAVITY_M_S2 / com_height_m)
    x = com_height_m * (math.radians(pitch_deg) + math.radians(pitch_rate_dps) / omega)
    y = -com_height_m * (math.radians(roll_deg) + math.radians(roll_rate_dps) / omega)
    return x, y


class CapturePoint:
    """``decide(error, stance, swing_from, planned)``: the next foothold for the DCM's error (module docstring)."""

    def __init__(self, geometry: BodyGeometry, limits: SteerLimits, *, hold_share: float = HOLD_SHARE,
                 gain: float = STEP_GAIN) -> None:
        self.geometry, self.limits, self.gain = geometry, limits, gain
        self.hold_x_m = hold_share * geometry.foot_m / 2
        self.hold_y_m = hold_share * geometry.foot_width_m / 2

    def beyond(self, error_m: tuple[float, float]) -> bool:
        """Whether the error left the ellipse the ankles hold."""
        return math.hypot(error_m[0] / self.hold_x_m, error_m[1] / self.hold_y_m) > 1.0

    def decide(self, error_m: tuple[float, float], stance: FootPlacement, swing_from: FootPlacement,
               planned: FootPlacement) -> CaptureStep:
        """The next foothold of the swing foot (now at ``swing_from``, planned to land at ``planned``; the other
        foot stands at ``stance``), moved toward the DCM when its error left what the ankles hold."""
        if not self.beyond(error_m):
            return CaptureStep(error_m, False, planned, (0.0, 0.0))
        lim = self.limits
        c, s = math.cos(stance.yaw_rad), math.sin(stance.yaw_rad)
        # the move in the stance foot's frame (forward, left), clipped to the per-step limits
        fx = c * error_m[0] + s * error_m[1]
        fy = -s * error_m[0] + c * error_m[1]
        fx = min(max(self.gain * fx, -lim.max_backward_m), lim.max_forward_m)
        fy = min(max(self.gain * fy, -lim.max_side_m), lim.max_side_m)
        # never further back from the stance foot than a backward step may go
        px, py = planned.x_m - stance.x_m, planned.y_m - stance.y_m
        ahead = c * px + s * py
        fx = max(ahead + fx, min(-lim.max_backward_m, ahead)) - ahead
        outward = 1.0 if planned.side == "left" else -1.0
        if fy * outward < 0:  # inward, toward the stance foot: not at all (INWARD, module docstring)
            fy = 0.0
        moved = FootPlacement(planned.side, planned.x_m + c * fx - s * fy, planned.y_m + s * fx + c * fy,
                              planned.yaw_rad)
        gap = swept_gap_m(self.geometry, stance, swing_from, moved)
        if gap < lim.min_gap_m:
            return CaptureStep(error_m, True, planned, (0.0, 0.0))  # even the forward move alone would not keep it
        return CaptureStep(error_m, True, moved, (moved.x_m - planned.x_m, moved.y_m - planned.y_m), gap)

    def halved(self, step: CaptureStep, stance: FootPlacement, swing_from: FootPlacement,
               planned: FootPlacement) -> CaptureStep:
        """The same decision with half the move (a move the step check refused may pass halved)."""
        dx, dy = 0.5 * step.moved_m[0], 0.5 * step.moved_m[1]
        moved = FootPlacement(planned.side, planned.x_m + dx, planned.y_m + dy, planned.yaw_rad)
        gap = swept_gap_m(self.geometry, stance, swing_from, moved)
        if gap < self.limits.min_gap_m:
            return CaptureStep(step.error_m, True, planned, (0.0, 0.0))
        return CaptureStep(step.error_m, True, moved, (dx, dy), gap)
