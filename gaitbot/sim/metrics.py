"""Did the simulated walk really walk? Measurements taken at the end of every frame of a sim run.

What the plan promised (distance, when each foot swings) is handed in by the command layer as a
:class:`WalkPlan`; this module never looks at the gait. Times are simulated seconds from the
first goal (the walk's first frame: the robot starts in it, standing).

Definitions (docs/simulation.md repeats them):

distance_planned_m / distance_travelled_m
    Forward displacement of the root (the hip point of a planar robot; the torso on its boom or
    floating free): planned by the gait, and measured from the start (standing, before the first
    goal) to the last sample of the run.
fell, fell_at_s, fall_reason
    The first sample at which a part other than a sole touches the floor, the hip is below
    FALL_HEIGHT_SHARE of its standing height, or the torso tilts more than FALL_PITCH_DEG (free
    pitch or free-floating); a robot without a boom would be on the floor. A fall is a failure:
    ``gaitbot walk --sim`` says so and exits with status 1.
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
    Per modelled joint (the walking joints in the config's order, then held ones), the stiffness its
    simulated servo walked with: the position error at which it gave full torque, as read from its gain
    register (the value the session wrote, or the factory one) at the last sample of the walk.
lateral_drift_m, yaw_deg, max_abs_yaw_deg
    The root's sideways displacement (left positive) from the start to the last sample, less the
    plan's; the torso's heading at the last sample and its largest magnitude over the run (deg).
torso_roll_rms_deg, torso_roll_max_deg, torso_pitch_rms_deg, torso_pitch_max_deg
    The torso's roll and pitch (forward lean positive) over the samples: root mean square and largest
    magnitude (0 on the boom, but the pitch with --free-pitch).
fall_direction
    Which way the robot went down: the direction its torso leans at the fall (in its own heading),
    or, for a fall with little lean, where its centre of mass left the feet: forwards, backwards,
    sideways (left) or sideways (right).
heel_strikes, max_foothold_error_m
    For each planned heel strike (docs/balance.md: the heel's x and the sole centre's y), where that
    foot's heel and sole centre are at the end of the frame it lands on, and the distance between the
    two (horizontal; x only for a planar walk); the largest such error.
push
    With ``--push``: the impulse (N s, positive to the left), when it began and ended, and the step
    whose single support it fell in.
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
class PlannedStrike:
    """A planned heel strike in the plan's world: when (s from the walk's first frame), which leg, the
    heel's x and the sole centre's y (None for a planar walk), metres."""

    t_s: float
    leg: str
    x_m: float
    y_m: float | None = None


@dataclass(frozen=True)
class WalkPlan:
    """What the gait planned, in the terms the measurements need (metres, simulated seconds).

    footholds: (leg, heel x) for the video, in the plan's world; heel_strikes: the same with times
    and y; lateral_m: the root's planned sideways displacement; start_angles_rad / start_root_m: the
    walk's first pose (joint name -> angle, root x, y, z), in which a 3D model is placed before the
    walk; x_origin_m: the plan's x at the simulated world's x = 0 (0 when the robot was placed; the
    root's first x for the planar model, which starts standing straight at the origin)."""

    distance_m: float
    swings: tuple[SwingWindow, ...] = ()
    footholds: tuple[tuple[str, float], ...] = ()
    heel_strikes: tuple[PlannedStrike, ...] = ()
    lateral_m: float = 0.0
    start_angles_rad: dict | None = None
    start_root_m: tuple[float, float, float] | None = None
    x_origin_m: float = 0.0


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
    support: str = "boom"
    fall_direction: str | None = None
    lateral_drift_m: float = 0.0
    yaw_deg: float = 0.0
    max_abs_yaw_deg: float = 0.0
    torso_roll_rms_deg: float = 0.0
    torso_roll_max_deg: float = 0.0
    torso_pitch_rms_deg: float = 0.0
    torso_pitch_max_deg: float = 0.0
    heel_strikes: tuple[dict, ...] = ()
    max_foothold_error_m: float | None = None
    push: dict | None = None
    heading_deg: float = 0.0  # the torso's yaw change over the run, unwrapped (a steered walk's full turn: 360)
    self_contacts: tuple[dict, ...] = ()  # the robot's own bodies that touched: names, first time (s), frames

    def to_dict(self) -> dict:
        return asdict(self)

    @property
    def travel_share(self) -> float:
        return self.distance_travelled_m / self.distance_planned_m if self.distance_planned_m else float("nan")

    def summary(self) -> str:
        planned = self.distance_planned_m
        share = f" ({100 * self.distance_travelled_m / planned:.1f}% of plan)" if planned else ""
        fall = (f"FELL {self.fall_direction} at {self.fell_at_s:.2f} s ({self.fall_reason})" if self.fell
                else "did not fall")
        support = {"free": "free-floating", "boom": "pitch held by the boom",
                   "boom-pitch": "free pitch"}.get(self.support, self.support)
        text = (f"Simulated {self.simulated_s:.2f} s ({support}): travelled {self.distance_travelled_m:.3f} m of "
                f"{planned:.3f} m planned{share}; {fall}; max slip {self.max_slip_m * 1e3:.2f} mm; "
                f"scuff {100 * self.scuff_fraction:.1f}% of swing time; max torque "
                f"{100 * self.max_torque_fraction:.0f}% of stall; max tracking error "
                f"{self.max_tracking_error_deg:.2f} deg{self._stiffness()}.")
        if self.support != "boom" or self.max_foothold_error_m is not None:
            text += (f"\nLateral drift {100 * self.lateral_drift_m:+.1f} cm, yaw {self.yaw_deg:+.1f} deg (at most "
                     f"{self.max_abs_yaw_deg:.1f}); torso roll RMS {self.torso_roll_rms_deg:.2f} deg (max "
                     f"{self.torso_roll_max_deg:.1f}), pitch RMS {self.torso_pitch_rms_deg:.2f} deg (max "
                     f"{self.torso_pitch_max_deg:.1f})")
            if self.max_foothold_error_m is not None:
                text += (f"; heel strikes within {1e3 * self.max_foothold_error_m:.1f} mm of their footholds "
                         f"({len(self.heel_strikes)} measured)")
            text += "."
        if self.push is not None:
            direction = self.push.get("direction_deg", 90.0)
            way = "sideways" if direction == 90.0 else f"towards {direction:g} deg from forward"
            phase, step, leg = self.push.get("phase"), self.push["step"], self.push["leg"]
            where = (f"mid-swing of step {step} ({leg} foot swinging)" if phase is None else
                     f"{phase:g} of the way through step {step} (0: the {leg} foot lifts; 1: the next foot lifts)")
            text += f"\nPushed {self.push['impulse_n_s']:+.2f} N s {way} at {self.push['start_s']:.2f} s, {where}."
        if self.self_contacts:
            pairs = "; ".join(f"{' and '.join(c['bodies'])} ({c['frames']} frames from {c['first_s']:.2f} s)"
                              for c in self.self_contacts)
            text += f"\nThe robot's own bodies touched: {pairs}."
        return text

    def _stiffness(self) -> str:
        if not self.full_torque_error_deg:
            return ""
        low, high = min(self.full_torque_error_deg), max(self.full_torque_error_deg)
        spread = f"{low:.2f}" if high - low < 5e-3 else f"{low:.2f} to {high:.2f}"
        return f"; servos at full torque from {spread} deg of error"


def _rms_max(values_deg: np.ndarray) -> tuple[float, float]:
    if values_deg.size == 0:
        return 0.0, 0.0
    return float(np.sqrt(np.mean(values_deg ** 2))), float(np.abs(values_deg).max())


class WalkMeter:
    """An observer of a SimRobot (``robot.observers.append(meter)``): samples every frame end.

    Samples only while every walking servo has torque on (the walk, its ramps and its stop); what
    a limp robot does after torque off is not part of the walk. ``plan`` (optional here, needed by
    the foothold measure) says where the heel strikes are planned."""

    def __init__(self, robot: SimRobot, plan: WalkPlan | None = None) -> None:
        self.robot = robot
        self.plan = plan
        self.start_xyz_m = robot.torso_xyz_m()
        self.start_x_m, self.standing_hip_m = (float(v) for v in robot.torso_position_m())
        self.times_s: list[float] = []
        self.torso_x_m: list[float] = []
        self.torso_y_m: list[float] = []
        self.rpy_deg: list[np.ndarray] = []
        self.tilt_deg: list[float] = []  # the torso's true tilt from upright, each frame (_tilt_deg)
        self.touch_share: list[np.ndarray] = []
        self.effort: list[float] = []
        self.tracking_deg: list[float] = []
        self.stiffness_deg: tuple[float, ...] = ()
        self.fell_at_s: float | None = None
        self.fall_reason: str | None = None
        self.fall_direction: str | None = None
        self.max_slip_m = 0.0
        self.strikes: list[dict] = []
        self._pending = sorted(plan.heel_strikes, key=lambda h: h.t_s) if plan is not None else []
        self._slip_run = np.zeros(len(SIDES))
        self._last_pose: list[tuple[np.ndarray, np.ndarray] | None] = [None] * len(SIDES)
        self._self_touch: dict[tuple[int, int], list] = {}  # body pair -> [first time s, frames]

    def __call__(self, robot: SimRobot) -> None:
        effort, touched = robot.effort_peak.copy(), robot.touch_steps.copy()
        robot.effort_peak[:] = 0.0
        robot.touch_steps[:] = 0
        if not robot.torque_on.all():
            self._last_pose = [None] * len(SIDES)
            return
        t = robot.time_s
        torso = robot.torso_position_m()
        xyz = robot.torso_xyz_m()
        self.times_s.append(t)
        self.torso_x_m.append(float(torso[0]))
        self.torso_y_m.append(float(xyz[1]))
        self.rpy_deg.append(np.degrees(robot.torso_rpy_rad()))
        self.tilt_deg.append(self._tilt_deg(robot))
        self.touch_share.append(touched / robot.substeps)
        self.effort.append(float(effort.max()))
        error = np.abs(robot.goals_rad() - robot.joint_angles_rad())
        self.tracking_deg.append(math.degrees(float(error.max())))
        self.stiffness_deg = tuple(float(e) for e in robot.full_torque_error_deg)
        contacts = robot.floor_contacts()
        for pair in robot.self_contacts():
            self._self_touch.setdefault(pair, [t, 0])[1] += 1
        self._check_fall(robot, t, torso, contacts)
        self._measure_slip(robot, contacts)
        self._measure_strikes(robot, t)

    def _check_fall(self, robot: SimRobot, t: float, torso: np.ndarray, contacts) -> None:
        if self.fell_at_s is not None:
            return
        others = sorted({robot.model.geom(g).name or f"geom {g}" for g, _ in contacts if g not in robot.sole_side_of})
        tilt = self.tilt_deg[-1]
        reason = None
        if others:
            reason = f"{', '.join(others)} touched the floor"
        elif torso[1] < FALL_HEIGHT_SHARE * self.standing_hip_m:
            reason = f"hip down to {torso[1] * 1e3:.0f} mm"
        elif tilt > FALL_PITCH_DEG:
            reason = f"torso tilted {tilt:.0f} deg"
        if reason is not None:
            self.fell_at_s, self.fall_reason = t, reason
            self.fall_direction = fall_direction(robot)

    @staticmethod
    def _tilt_deg(robot: SimRobot) -> float:
        """The torso's tilt from upright (any direction), degrees."""
        if robot.support == "free":
            up_z = float(robot.data.xmat[robot.torso_body][8])
            return math.degrees(math.acos(max(-1.0, min(1.0, up_z))))
        return abs(math.degrees(robot.torso_pitch_rad()))

    def _measure_strikes(self, robot: SimRobot, t: float) -> None:
        """Each planned heel strike at the end of the frame the foot lands on (plan time + one frame)."""
        plan = self.plan
        while self._pending and t + 1e-9 >= self._pending[0].t_s + robot.frame_s:
            strike = self._pending.pop(0)
            g = robot.config.body.geometry
            side = SIDES.index(strike.leg)
            body = robot.foot_bodies[side]
            pos, rot = robot.data.xpos[body], robot.data.xmat[body].reshape(3, 3)
            sign = 1.0 if strike.leg == "left" else -1.0
            heel = robot.foot_axes[side] @ np.array([-g.heel_back_m, sign * g.sole_outward_m, 0.0])
            point = pos + rot @ (robot.ankle_in_foot_m[side] + heel)
            x, y = float(point[0]) + plan.x_origin_m, float(point[1])
            if strike.y_m is None:
                error = abs(x - strike.x_m)
            else:
                error = math.hypot(x - strike.x_m, y - strike.y_m)
            self.strikes.append({"t_s": strike.t_s, "leg": strike.leg, "planned_x_m": strike.x_m,
                                 "planned_y_m": strike.y_m, "x_m": x, "y_m": y, "error_m": error})

    def _measure_slip(self, robot: SimRobot, contacts) -> None:
        data = robot.data
        for side, body in enumerate(robot.foot_bodies):
            points = [p for g, p in contacts if robot.sole_side_of.get(g) == side]
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

    def report(self, plan: WalkPlan, free_pitch: bool, push: dict | None = None) -> SimReport:
        times = np.array(self.times_s)
        travelled = self.torso_x_m[-1] - self.start_x_m if self.torso_x_m else 0.0
        lateral = self.torso_y_m[-1] - float(self.start_xyz_m[1]) - plan.lateral_m if self.torso_y_m else 0.0
        rpy = np.array(self.rpy_deg).reshape(-1, 3)
        roll, pitch = _rms_max(rpy[:, 0]), _rms_max(rpy[:, 1])
        errors = [s["error_m"] for s in self.strikes]
        return SimReport(
            distance_planned_m=float(plan.distance_m), distance_travelled_m=float(travelled),
            fell=self.fell_at_s is not None, fell_at_s=self.fell_at_s, fall_reason=self.fall_reason,
            max_slip_m=float(self.max_slip_m), scuff_fraction=self._scuff_fraction(times, plan),
            max_torque_fraction=float(max(self.effort, default=0.0)),
            max_tracking_error_deg=float(max(self.tracking_deg, default=0.0)),
            simulated_s=float(times[-1]) if times.size else 0.0, free_pitch=free_pitch,
            full_torque_error_deg=self.stiffness_deg, support=self.robot.support,
            fall_direction=self.fall_direction, lateral_drift_m=float(lateral),
            yaw_deg=float(rpy[-1, 2]) if len(rpy) else 0.0,
            max_abs_yaw_deg=float(np.abs(rpy[:, 2]).max()) if len(rpy) else 0.0,
            torso_roll_rms_deg=roll[0], torso_roll_max_deg=roll[1], torso_pitch_rms_deg=pitch[0],
            torso_pitch_max_deg=pitch[1], heel_strikes=tuple(self.strikes),
            max_foothold_error_m=max(errors) if errors else None, push=push,
            heading_deg=float(np.degrees(np.unwrap(np.radians(rpy[:, 2])))[-1]) if len(rpy) else 0.0,
            self_contacts=tuple({"bodies": [self.robot.model.body(b).name or f"body {b}" for b in pair],
                                 "first_s": round(first_s, 4), "frames": frames}
                                for pair, (first_s, frames) in sorted(self._self_touch.items())))

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


def fall_direction(robot: SimRobot) -> str:
    """Which way the robot is going down, in its own heading: the direction its torso leans, or, when it
    hardly leans (a fall by the hip sinking or a knee touching), where its CoM is from between its feet."""
    r = robot.data.xmat[robot.torso_body].reshape(3, 3)
    yaw = math.atan2(r[1, 0], r[0, 0])
    lean = r[:2, 2].copy()  # the torso's up axis, its horizontal part
    if math.hypot(*lean) < math.sin(math.radians(15)):
        feet = robot.data.xpos[robot.foot_bodies][:, :2].mean(axis=0)
        lean = robot.data.subtree_com[robot.torso_body][:2] - feet
    forward = math.cos(yaw) * lean[0] + math.sin(yaw) * lean[1]
    left = -math.sin(yaw) * lean[0] + math.cos(yaw) * lean[1]
    if abs(forward) >= abs(left):
        return "forwards" if forward > 0 else "backwards"
    return "sideways (left)" if left > 0 else "sideways (right)"
