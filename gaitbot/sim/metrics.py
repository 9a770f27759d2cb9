"""Did the simulated walk really walk? Measurements taken at the end of every frame of a sim run.

What the plan promised (distance, when each foot swings) is handed in by the command layer as a
:class:`WalkPlan`; this module never looks at the gait. Times are simulated seconds from the
first goal (the walk's first frame: the robot starts in it, standing).

Definitions (docs/simulation.md repeats them):

distance_planned_m / distance_travelled_m
    Forward displacement of the hip point (the torso on its boom): planned by the gait, and
    measured from the start (standing, before the first goal) to the last sample of the run.
fell, fell_at_s, fall_reason
    The first sample at which a part other than a sole touches the floor, the hip is below
    FALL_HEIGHT_SHARE of its standing height, or the torso leans more than FALL_PITCH_DEG (free
    pitch only); a robot without a boom would be on the floor.
max_slip_m
    For each sole and each spell of floor contact (consecutive samples in contact): the running
    horizontal displacement of the material point of the sole under its contact (the mean of its
    contact points), summed frame by frame; the largest absolute value over all spells. A sole
    that rolls over its heel or toe without sliding adds nothing; a sliding or creeping one does.
scuff_fraction
    Over the planned swings' clearance windows (the part of each swing where the gait promises the
    configured clearance), the share of time the swinging sole touches the floor: contact is timed
    per physics step within each frame, and a frame that only partly overlaps a window counts in
    proportion to the overlap.
max_torque_fraction
    The largest |torque asked of a servo| / its stall torque over the run, per physics step
    (1.0: the servo is saturated at least once).
max_tracking_error_deg
    The largest |goal - joint angle| over the walking joints at the end of each frame, i.e. just
    before the next goal replaces the present one.
full_torque_error_deg
    Per walking joint (hip, knee, ankle left, then right), the stiffness its simulated servo walked
    with: the position error at which it gave full torque, as read from its gain register (the value
    the session wrote, or the factory one) at the last sample of the walk.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass

import numpy as np

from gaitbot.sim.model import SIDES
from gaitbot.sim.physics import SimRobot

FALL_HEIGHT_SHARE = 0.5
FALL_PITCH_DEG = 45.0


@dataclass(frozen=True)
class SwingWindow:
    """Where a planned swing must clear the floor: leg ("left"/"right"), from start_s to end_s."""

    leg: str
    start_s: float
    end_s: float


@dataclass(frozen=True)
class WalkPlan:
    """What the gait planned, in the terms the measurements need (metres, simulated seconds)."""

    distance_m: float
    swings: tuple[SwingWindow, ...] = ()
    footholds: tuple[tuple[str, float], ...] = ()  # (leg, heel x in the simulated world)


@dataclass(frozen=True)
class SimReport:
    """The measurements of one simulated run (see the module docstring for each definition)."""

    distance_planned_m: float
    distance_travelled_m: float
    fell: bool
    fell_at_s: float | None
    fall_reason: str | None
    max_slip_m: float
    scuff_fraction: float
    max_torque_fraction: float
    max_tracking_error_deg: float
    simulated_s: float
    free_pitch: bool
    full_torque_error_deg: tuple[float, ...] = ()

    def to_dict(self) -> dict:
        return asdict(self)

    def summary(self) -> str:
        planned = self.distance_planned_m
        share = f" ({100 * self.distance_travelled_m / planned:.1f}% of plan)" if planned else ""
        fall = f"fell at {self.fell_at_s:.2f} s ({self.fall_reason})" if self.fell else "did not fall"
        boom = "free pitch" if self.free_pitch else "pitch held by the boom"
        return (f"Simulated {self.simulated_s:.2f} s ({boom}): travelled {self.distance_travelled_m:.3f} m of "
                f"{planned:.3f} m planned{share}; {fall}; max slip {self.max_slip_m * 1e3:.2f} mm; "
                f"scuff {100 * self.scuff_fraction:.1f}% of swing time; max torque "
                f"{100 * self.max_torque_fraction:.0f}% of stall; max tracking error "
                f"{self.max_tracking_error_deg:.2f} deg{self._stiffness()}.")

    def _stiffness(self) -> str:
        if not self.full_torque_error_deg:
            return ""
        low, high = min(self.full_torque_error_deg), max(self.full_torque_error_deg)
        spread = f"{low:.2f}" if high - low < 5e-3 else f"{low:.2f} to {high:.2f}"
        return f"; servos at full torque from {spread} deg of error"


class WalkMeter:
    """An observer of a SimRobot (``robot.observers.append(meter)``): samples every frame end.

    Samples only while every walking servo has torque on (the walk, its ramps and its stop); what
    a limp robot does after torque off is not part of the walk."""

    def __init__(self, robot: SimRobot) -> None:
        self.robot = robot
        self.start_x_m, self.standing_hip_m = (float(v) for v in robot.torso_position_m())
        self.times_s: list[float] = []
        self.torso_x_m: list[float] = []
        self.touch_share: list[np.ndarray] = []
        self.effort: list[float] = []
        self.tracking_deg: list[float] = []
        self.stiffness_deg: tuple[float, ...] = ()
        self.fell_at_s: float | None = None
        self.fall_reason: str | None = None
        self.max_slip_m = 0.0
        self._slip_run = np.zeros(len(SIDES))
        self._last_pose: list[tuple[np.ndarray, np.ndarray] | None] = [None] * len(SIDES)

    def __call__(self, robot: SimRobot) -> None:
        effort, touched = robot.effort_peak.copy(), robot.touch_steps.copy()
        robot.effort_peak[:] = 0.0
        robot.touch_steps[:] = 0
        if not robot.torque_on.all():
            self._last_pose = [None] * len(SIDES)
            return
        t = robot.time_s
        torso = robot.torso_position_m()
        self.times_s.append(t)
        self.torso_x_m.append(float(torso[0]))
        self.touch_share.append(touched / robot.substeps)
        self.effort.append(float(effort.max()))
        error = np.abs(robot.goals_rad() - robot.joint_angles_rad())
        self.tracking_deg.append(math.degrees(float(error.max())))
        self.stiffness_deg = tuple(float(e) for e in robot.full_torque_error_deg)
        contacts = robot.floor_contacts()
        self._check_fall(robot, t, torso, contacts)
        self._measure_slip(robot, contacts)

    def _check_fall(self, robot: SimRobot, t: float, torso: np.ndarray, contacts) -> None:
        if self.fell_at_s is not None:
            return
        soles = set(robot.sole_geoms.tolist())
        others = sorted({robot.model.geom(g).name for g, _ in contacts if g not in soles})
        reason = None
        if others:
            reason = f"{', '.join(others)} touched the floor"
        elif torso[1] < FALL_HEIGHT_SHARE * self.standing_hip_m:
            reason = f"hip down to {torso[1] * 1e3:.0f} mm"
        elif abs(math.degrees(robot.torso_pitch_rad())) > FALL_PITCH_DEG:
            reason = f"torso leaning {math.degrees(robot.torso_pitch_rad()):.0f} deg"
        if reason is not None:
            self.fell_at_s, self.fall_reason = t, reason

    def _measure_slip(self, robot: SimRobot, contacts) -> None:
        data = robot.data
        for side, (geom, body) in enumerate(zip(robot.sole_geoms, robot.foot_bodies)):
            points = [p for g, p in contacts if g == geom]
            pose = (data.xpos[body].copy(), data.xmat[body].reshape(3, 3).copy())
            if not points:
                self._last_pose[side] = None
                continue
            where = np.mean(points, axis=0)
            last = self._last_pose[side]
            if last is None:
                self._slip_run[side] = 0.0
            else:
                local = pose[1].T @ (where - pose[0])  # the sole's material point under the contact
                before = last[1] @ local + last[0]
                self._slip_run[side] += where[0] - before[0]
                self.max_slip_m = max(self.max_slip_m, abs(float(self._slip_run[side])))
            self._last_pose[side] = pose

    def report(self, plan: WalkPlan, free_pitch: bool) -> SimReport:
        times = np.array(self.times_s)
        travelled = self.torso_x_m[-1] - self.start_x_m if self.torso_x_m else 0.0
        return SimReport(
            distance_planned_m=float(plan.distance_m), distance_travelled_m=float(travelled),
            fell=self.fell_at_s is not None, fell_at_s=self.fell_at_s, fall_reason=self.fall_reason,
            max_slip_m=float(self.max_slip_m), scuff_fraction=self._scuff_fraction(times, plan),
            max_torque_fraction=float(max(self.effort, default=0.0)),
            max_tracking_error_deg=float(max(self.tracking_deg, default=0.0)),
            simulated_s=float(times[-1]) if times.size else 0.0, free_pitch=free_pitch,
            full_torque_error_deg=self.stiffness_deg)

    def _scuff_fraction(self, times: np.ndarray, plan: WalkPlan) -> float:
        """Touching time over window time; a sample at t covers the frame (t - frame, t]."""
        if not plan.swings or times.size == 0:
            return 0.0
        frame = self.robot.frame_s
        share = np.array(self.touch_share)
        touching = window = 0.0
        for swing in plan.swings:
            side = SIDES.index(swing.leg)
            overlap = np.clip(np.minimum(times, swing.end_s) - np.maximum(times - frame, swing.start_s), 0.0, frame)
            touching += float(np.sum(overlap * share[:, side]))
            window += swing.end_s - swing.start_s
        return touching / window if window > 0 else 0.0
