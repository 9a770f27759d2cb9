"""A planned balanced walk walked online, its next foothold moved when the IMU says a push needs a step.

``--feedback step`` (gaitbot.app.walk): the planned walk's steps are fed one at a time to an online
BalancedWalker (the drive's walker, with the plan's own speed-fitted settings, so that unpushed it walks the
plan's frames), each appended DECIDE_FRAMES frames before its double support starts: about when the step before it starts,
as the live drive queues its steps, early enough for the walker's preview to see the step coming. At that moment gaitbot.feel.capture compares the measured
DCM with the plan's; if it left what the ankles hold, the step's foothold moves toward it (within ``[steer]``
limits and the soles' gap). The moved step is checked (gaitbot.drive.step_check) in place of the planned one,
which is queued at once: a stage a frame, as the live drive checks its steps, so that no frame carries more
than one piece of planning; once it passes, the walker takes the planned step back and it is queued to the
moved foothold (``_advance_check``). Until that step starts, a push felt later moves it again
(``_redecide``: checked the same way). When the error leans toward the foot that step would
lift, so that standing on the other foot would leave the DCM further outside it, the step waits instead
(``_pause``): it is taken back, both feet stay down for PAUSE_FRAMES with the ZMP between them, and it is
queued again before the pause ends, its weight shifted over a whole step as a walk's first step's is. The
steps after a moved one keep their planned length
from the foot they follow and their side's distance from it. Every goal then goes through the session's
Feedback, which keeps it inside every joint's position, velocity and acceleration limits (``gaitbot check``
holds it).

``--feedback zmp`` walks the same way without moving footholds (``stepping=False``): instead, before each frame,
the CoM error the IMU measured (z_c x tilt, at z_c x tilt rate, turned into the walk's world) feeds the preview
controller's state through gaitbot.gait.balance.correction, and the walker places the body for its planned CoM
plus the correction (``BalancedWalker.com_offset_m``), the correction's ZMP kept inside the grounded soles.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from gaitbot.drive.step_check import StepCheck
from gaitbot.feel.capture import CapturePoint, CaptureStep, dcm_error_m
from gaitbot.gait.balance.correction import ComCorrection, support_polygon
from gaitbot.gait.balance.walker import BalancedWalker
from gaitbot.gait.balance.zmp_reference import FootPlacement
from gaitbot.gait.body import SIDE_SIGN
from gaitbot.gait.joints import LEG_JOINTS
from gaitbot.robot.balanced_walk import leg_limits_rad, servo_stiffness_nm_per_rad

DECIDE_FRAMES = 24
"""A step is appended (and its foothold decided) this many frames before its double support starts: 0.4 s at
60 Hz, one step of the op3's 0.8 s cycle, as the live drive keeps one step queued. Later (12 or 2 frames)
answers a push sooner, but the walker's preview then sees the step late: unpushed, the frames leave the
plan's by up to 20 ticks (3 at 24), and pushes that the planned walk survives fell (measured with
python tools/push_survival.py --modes step; docs/feedback.md)."""
REDECIDE_M = 0.01
"""A step queued but not started is moved again when the DCM's error asks for a foothold this far (m) from the
one it was given: a push felt after the step was queued is answered by it, not by the step after it."""
PAUSE_FRAMES = 48
"""Frames both feet stay down when a push leans the robot over the foot about to lift (0.8 s at 60 Hz)."""
PAUSE_HOLD = 0.7
"""A pause is taken when the DCM's error toward the foot about to lift passes this multiple of the sideways hold
(HOLD_SHARE's ellipse, sideways: 2.2 cm on the op3). On python tools/push_survival.py's pushes, seeds 23, 24
and 25, ``step`` survived 163 of 300 without pauses, 173 with 1.0 and 175 with 0.7 (before the tilt estimate's
spin gating; 181 with it: docs/push-stepping.md)."""
MAX_PAUSES = 2
"""Pauses in a row before the step is taken whatever the error."""
CHECK_TRIES = 3
"""A moved step refused by the step check is tried at half the move, then at a quarter; then the plan's."""


@dataclass(frozen=True)
class MovedStep:
    """A moved step in the terms the step check reads (gaitbot.drive.step_check)."""

    foothold: FootPlacement
    length_m: float
    gap_m: float


@dataclass
class QueuedStep:
    """The step appended last: where the feet stood for it (the stance foot, the swing foot's start), its
    planned foothold and length, the foothold it was given, and whether it was moved again since."""

    stance: FootPlacement
    swing_from: FootPlacement
    planned: FootPlacement
    length_m: float
    foothold: FootPlacement
    redecided: bool = False


@dataclass
class SteppingLog:
    """The decisions taken: one CaptureStep per move of a step (with when the moved step was queued, its check
    passed: s from the walk's start; and whether the step had been queued and was moved again), and how many
    times the error left the hold but nothing moved (inward only, or refused by the step check: the plan's
    foothold kept)."""

    moved: list[tuple[float, CaptureStep, bool]] = field(default_factory=list)
    steps: int = 0
    refused: int = 0
    paused_s: list[float] = field(default_factory=list)

    def summary(self) -> list[dict]:
        """The moved steps for ``--json``: when queued (``decided_s``, s of the walk), the DCM's error and the
        move (m)."""
        return [{"decided_s": round(t_s, 4), "side": c.foothold.side, "requeued": requeued,
                 "dcm_error_m": [round(v, 4) for v in c.error_m], "moved_m": [round(v, 4) for v in c.moved_m]}
                for t_s, c, requeued in self.moved]


@dataclass
class CorrectionLog:
    """What the CoM correction did (gaitbot.gait.balance.correction): the largest correction and ZMP shift
    (m), and the frames whose ZMP shift was cut back to the support polygon."""

    frames: int = 0
    max_offset_m: float = 0.0
    max_zmp_shift_m: float = 0.0
    clipped: int = 0

    def summary(self) -> dict:
        return {"frames": self.frames, "max_offset_m": round(self.max_offset_m, 4),
                "max_zmp_shift_m": round(self.max_zmp_shift_m, 4), "clipped_frames": self.clipped}


class SteppingFrames:
    """An iterator of tick frames: the plan's steps walked online with capture steps (module docstring).
    ``plan``: a gaitbot.robot.balanced_walk.BalancedPlan; ``estimate``: anything with roll_deg, pitch_deg,
    rates_dps and started (gaitbot.feel.estimate.TiltEstimate, the session's Feedback's); ``active``: a
    callable saying whether the IMU may be trusted (a faulty IMU walks the plan's footholds).
    ``stepping``: move footholds (``--feedback step``); ``correction``: feed the measured CoM error to the
    preview controller's state (gaitbot.gait.balance.correction; ``--feedback zmp``), a ComCorrection's
    keyword arguments (a dict) or True for its defaults."""

    def __init__(self, config, plan, estimate, active=lambda: True, *, stepping: bool = True,
                 correction=None) -> None:
        if stepping and config.steer is None:
            raise ValueError(f"robot {config.name} has no [steer] limits: it cannot step to catch a push")
        self.config, self.estimate, self.active, self.stepping = config, estimate, active, stepping
        fit = plan.fit
        self.walker = BalancedWalker(config.body, fit.gait, fit.balance, limits_rad=leg_limits_rad(config),
                                     kp_nm_per_rad=servo_stiffness_nm_per_rad(config))
        self.correction = None
        if correction:
            self.correction = ComCorrection(self.walker.gains, **(correction if isinstance(correction, dict) else {}))
        self.correction_log = CorrectionLog()
        self.steps = [s for s in plan.planned_steps if not s.closing]
        if self.steps and self.steps[0].leg != self.walker.next_swing_side:
            self.walker.lead_with(self.steps[0].leg)
        self.capture = CapturePoint(config.body.geometry, config.steer) if stepping else None
        self.step_check = StepCheck(config, 1.0 / self.walker.rate_hz) if stepping else None
        self.rate_hz = self.walker.rate_hz
        self.log = SteppingLog()
        self._queued: QueuedStep | None = None  # the step appended last (moved again by _redecide)
        self._checking = None  # the check of a move of the queued step, a stage a frame (_moving)
        self._moved: tuple[CaptureStep, bool] | None = None  # a move that passed it (and requeued), queued next
        self._pauses = 0  # pauses in a row before the queued step
        self._resume_frame = 0  # the walk frame where the last pause ends
        self._next = 0
        self._frames = len(plan.walk.t_s)
        self._append_due()  # the first step: before the walk starts, as the plan has it

    def __len__(self) -> int:
        return self._frames

    def __iter__(self):
        return self

    def __next__(self) -> np.ndarray:
        # at most one piece of planning a frame (an append, a pause, a stage of a check), as the drive does
        if not self._append_due() and not self._pause() and not self._advance_check() and not self._redecide():
            self.walker.work()  # a share of the last append's replan, as the drive does (BalancedWalker.work)
        if self.correction is not None:
            self._correct()
        frame = self.walker.next_frame()
        if frame is None:
            raise StopIteration
        return self.config.calibration.angles_to_ticks(frame[2], LEG_JOINTS)

    def _append_due(self) -> bool:
        """Append the next step when its double support is DECIDE_FRAMES away (or close the walk); whether it did."""
        walker = self.walker
        if walker.finished:
            return False
        if self._next >= len(self.steps):
            if walker._out + DECIDE_FRAMES >= self._start_frame():
                walker.finish()
                return True
            return False
        if self.log.steps and walker._out + DECIDE_FRAMES < self._start_frame():
            return False
        step = self.steps[self._next]
        self._next += 1
        self.log.steps += 1
        stance_side = "left" if step.leg == "right" else "right"
        feet = walker.feet
        stance, swing_from = feet[stance_side], feet[step.leg]
        planned = FootPlacement(step.leg, stance.x_m + step.length_m,
                                stance.y_m + SIDE_SIGN[step.leg] * self.config.body.geometry.hip_width_m, 0.0)
        queued = QueuedStep(stance, swing_from, planned, step.length_m, planned)
        walker.append_footstep(planned, step.length_m, spread=True)
        self._queued = queued if self.stepping else None
        self._checking = self._moved = None  # (the step before is no longer the last: not taken back)
        decision = self._decide(stance, swing_from, planned)
        if decision is not None and decision.beyond:
            self._checking = self._moving(decision, queued)
        return True

    def _advance_check(self) -> bool:
        """A frame's piece of a move's check (``_moving``): the next stage, or the queued step taken back and
        queued again to the moved foothold that passed. Dropped if that step has started meanwhile. Whether
        it did a piece."""
        queued, walker = self._queued, self.walker
        if self._checking is None and self._moved is None:
            return False
        if queued is None or not walker.last_step_unstarted:
            self._checking = self._moved = None
            return False
        if self._moved is not None:
            (decision, requeued), self._moved = self._moved, None
            walker.retract_last_step()
            walker.append_footstep(decision.foothold, queued.length_m, spread=True)
            queued.foothold = decision.foothold
            self.log.moved.append((walker._out / self.rate_hz, decision, requeued))
            return True
        try:
            next(self._checking)
        except StopIteration as done:
            self._checking, self._moved = None, done.value
        return True

    def _moving(self, decision: CaptureStep, queued: QueuedStep, requeued: bool = False):
        """A generator, one check stage a frame: a decision beyond the hold as the step check lets it through
        in place of the queued step, and ``requeued`` (moved again; both logged once it is queued), or None
        (refused: the queued foothold stays)."""
        decision = yield from self._checked(decision, queued.stance, queued.swing_from, queued.planned,
                                            queued.length_m)
        if decision.moved_m == (0.0, 0.0):
            self.log.refused += 1
            return None
        return decision, requeued

    def _pause(self) -> bool:
        """The step queued last, not started yet, taken back and a pause of PAUSE_FRAMES queued instead when the
        DCM's error leans toward the foot it would lift (beyond PAUSE_HOLD x the sideways hold): standing on
        the other foot would leave the DCM further outside it. The step is queued again before the pause
        ends. Whether it did."""
        queued, walker = self._queued, self.walker
        if queued is None:
            return False
        if not walker.last_step_unstarted:
            self._pauses = 0  # the step after the pauses has started
            return False
        error = self._dcm_error_m() if self._pauses < MAX_PAUSES else None
        if error is None or error[1] * SIDE_SIGN[queued.planned.side] < PAUSE_HOLD * self.capture.hold_y_m:
            return False
        walker.retract_last_step()
        walker.append_pause(PAUSE_FRAMES, spread=True)
        self._queued, self._checking, self._moved = None, None, None
        self._next -= 1
        self.log.steps -= 1
        self._pauses += 1
        self.log.paused_s.append(walker._out / self.rate_hz)
        self._resume_frame = walker.rise_frames + walker.planned_frames
        self._frames += PAUSE_FRAMES  # (a progress bar's total: the slower weight shift after it is not counted)
        return True

    def _redecide(self) -> bool:
        """The step queued last, not started yet, moved again when the DCM's error now asks for a foothold
        REDECIDE_M or more from the one it was given (a push felt after the step was queued): its check
        started (``_moving``; taken back and queued to the new foothold once it passes), once a step. Whether
        it did."""
        queued, walker = self._queued, self.walker
        if queued is None or queued.redecided or not walker.last_step_unstarted:
            return False
        decision = self._decide(queued.stance, queued.swing_from, queued.planned)
        if decision is None or not decision.beyond:
            return False
        moved = decision.foothold
        if math.hypot(moved.x_m - queued.foothold.x_m, moved.y_m - queued.foothold.y_m) < REDECIDE_M:
            return False
        queued.redecided = True
        self._checking = self._moving(decision, queued, requeued=True)
        return self._advance_check()

    def _correct(self) -> None:
        """The next frame's CoM correction from the measured error (none before the balance plan starts)."""
        walker, e = self.walker, self.estimate
        if walker._out < walker.rise_frames or walker.finished and walker._k >= walker.planned_frames:
            return
        error, rate = (0.0, 0.0), (0.0, 0.0)
        if self.active() and e.started:
            z = walker.com_height_m
            yaw = walker.last_torso_yaw_rad()
            c, s = math.cos(yaw), math.sin(yaw)
            fx, fy = z * math.radians(e.pitch_deg), -z * math.radians(e.roll_deg)  # the torso's frame
            vx, vy = z * math.radians(float(e.rates_dps[1])), -z * math.radians(float(e.rates_dps[0]))
            error, rate = (c * fx - s * fy, s * fx + c * fy), (c * vx - s * vy, s * vx + c * vy)
        k = walker._k
        hull = support_polygon(self.config.body.geometry, walker._ext_at("ankles", k), walker._ext_at("yaw", k),
                               self.correction.sole_share)
        walker.com_offset_m = self.correction.step(error, rate, walker._ext_at("zmp", k), hull)
        log, corr = self.correction_log, self.correction
        log.frames += 1
        log.max_offset_m = max(log.max_offset_m, math.hypot(*walker.com_offset_m))
        log.max_zmp_shift_m = max(log.max_zmp_shift_m, math.hypot(*corr.zmp_shift_m))
        log.clipped = corr.clipped

    def _checked(self, decision: CaptureStep, stance, swing_from, planned, length_m: float):
        """A generator of the check's stages: the move, or its half, that passes the drive's step check (reach,
        limits, ZMP, gap) in place of the queued step; else none."""
        for _ in range(CHECK_TRIES):
            if decision.moved_m == (0.0, 0.0):
                return decision
            step = MovedStep(decision.foothold, length_m, decision.gap_m)
            try:
                reason = yield from self.step_check.stages(self.walker, step, replacing_last=True)
            except (ValueError, ArithmeticError) as exc:  # beyond the swing's shapes or the leg's reach
                reason = str(exc)
            if reason is None:
                return decision
            decision = self.capture.halved(decision, stance, swing_from, planned)
        return CaptureStep(decision.error_m, True, planned, (0.0, 0.0))

    def _start_frame(self) -> int:
        """The walk frame where the next step's double support starts: the last planned step's landing."""
        walker = self.walker
        if not walker.planned_steps:
            return 0
        return max(round(walker.planned_steps[-1].end_s * self.rate_hz), self._resume_frame)

    def _decide(self, stance, swing_from, planned) -> CaptureStep | None:
        error = self._dcm_error_m()
        return None if error is None else self.capture.decide(error, stance, swing_from, planned)

    def _dcm_error_m(self) -> tuple[float, float] | None:
        """The DCM's error the IMU measures (gaitbot.feel.capture.dcm_error_m), or None when not stepping or
        the IMU is not to be trusted."""
        e = self.estimate
        if not (self.stepping and self.active() and e.started):
            return None
        return dcm_error_m(e.roll_deg, e.pitch_deg, float(e.rates_dps[0]), float(e.rates_dps[1]),
                           self.walker.com_height_m)
