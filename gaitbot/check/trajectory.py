"""Limit checking of a joint trajectory against a robot config.

One function, ``check_trajectory``, is shared by ``gaitbot walk``'s pre-flight and the
``gaitbot check`` command so the two can never disagree about what is safe to send.

Per joint it checks:

* position against the config's min_deg/max_deg (error beyond a limit; with ``margin_deg`` = M,
  samples inside the limits but within M degrees of one are warnings);
* the servo's tick range after calibration (ticks rounded as the streamer rounds them);
  for servos whose encoder wraps (0 and max_tick are neighbours) a tick outside the range, or two
  consecutive ticks whose shortest way round crosses the seam, is a ``wrap_seam`` violation;
* velocity against max_velocity_dps and acceleration against max_acceleration_dps2, as the servos
  see them: gaitbot.robot.joint_motion (the one definition, shared with the recordings' check and the
  planners) on the goal ticks at the frame times.

Consecutive samples beyond the same limit form one Violation (an episode) that reports the worst
value and when it happened, so an hour-long bad file gives a readable list, not a million lines.
Everything is numpy over whole columns: a one-hour 60 Hz trajectory checks in well under a second.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np

from gaitbot.robot.calibration import angle_rad_to_ticks, full_angles_rad, joint_parameters
from gaitbot.robot.config import JointConfig, RobotConfig
from gaitbot.robot.joint_motion import ACCELERATION_METHOD, VELOCITY_METHOD, as_sent_deg, joint_motion

KIND_ORDER = ("position", "tick_range", "wrap_seam", "velocity", "acceleration", "balance", "feet")
_UNITS = {"position": "deg", "tick_range": "ticks", "wrap_seam": "ticks", "velocity": "deg/s",
          "acceleration": "deg/s^2", "balance": "mm", "feet": "mm"}


@dataclass(frozen=True)
class Violation:
    """A limit broken (or, for severity "warning", approached within the margin).

    ``t_s`` and ``value`` are the worst sample of the episode; ``t_start_s``/``t_end_s`` and
    ``n_samples`` say how long the joint stayed beyond the limit. ``limit`` is the bound that was
    crossed (``limit_name`` says which: min_deg, max_deg, max_velocity_dps, ...). Velocities and
    accelerations are reported as magnitudes.
    """

    kind: str  # "position" | "tick_range" | "wrap_seam" | "velocity" | "acceleration" | "balance"
    joint: str
    t_s: float
    value: float
    limit: float
    severity: str  # "error" | "warning"
    limit_name: str
    t_start_s: float
    t_end_s: float
    n_samples: int

    @property
    def unit(self) -> str:
        return _UNITS[self.kind]

    def describe(self) -> str:
        """One line for a person, e.g. 'knee_pitch_left: position 112.3 deg at t=2.417 s exceeds max_deg 110.0'."""
        if self.kind == "wrap_seam":
            what = f"tick {self.value:.0f} at t={self.t_s:.3f} s would cross the encoder seam ({self.limit_name})"
        elif self.kind == "balance" and self.limit_name == "below the floor":
            what = (f"a sole is {self.value:.1f} mm below the floor at t={self.t_s:.3f} s (is the root the robot's "
                    f"root? docs/file-formats.md)")
        elif self.kind == "balance" and self.joint == "support":
            what = f"no sole touches the ground at t={self.t_s:.3f} s (the trajectory lifts both feet)"
        elif self.kind == "feet":
            what = (f"the soles come within {self.value:.1f} mm of each other at t={self.t_s:.3f} s (the least gap "
                    f"allowed: {self.limit:.1f} mm; negative: they overlap)")
        elif self.kind == "balance":
            what = (f"{self.value:.1f} mm outside the support polygon at t={self.t_s:.3f} s: the robot would tip "
                    f"{self.limit_name}")
        else:
            if self.severity == "warning":
                verb = "is within the margin of"
            elif self.limit_name in ("min_deg", "min_tick"):
                verb = "is below"
            else:
                verb = "exceeds"
            fmt = ".0f" if self.kind == "tick_range" else ".1f"
            what = (f"{self.kind} {self.value:{fmt}} {self.unit} at t={self.t_s:.3f} s "
                    f"{verb} {self.limit_name} {self.limit:{fmt}}")
        if self.n_samples > 1:
            what += f" (from t={self.t_start_s:.3f} s to {self.t_end_s:.3f} s, {self.n_samples} samples)"
        return f"{self.joint}: {what}"


@dataclass(frozen=True)
class JointSummary:
    """What one joint did over the whole trajectory and how close it came to its limits."""

    joint: str
    used_min_deg: float
    used_max_deg: float
    min_deg: float
    max_deg: float
    closest_to_limit_deg: float  # smallest distance to min_deg/max_deg; negative = beyond a limit
    closest_t_s: float
    worst_velocity_dps: float
    worst_velocity_t_s: float
    max_velocity_dps: float
    worst_acceleration_dps2: float
    worst_acceleration_t_s: float
    max_acceleration_dps2: float
    verdict: str  # "ok" | "warn" | "fail"


@dataclass(frozen=True)
class BalanceSummary:
    """How close the ZMP came to leaving the support polygon (check/balance.py), or why it was not checked.

    ``closest_margin_mm``: the ZMP's least distance inside the polygon's edge over the whole walk
    (negative: it left the polygon by that much), at ``closest_t_s``; ``com_travel_m``: the centre of
    mass's displacement from the first frame to the last (x, y)."""

    checked: bool
    note: str = ""
    closest_margin_mm: float = 0.0
    closest_t_s: float = 0.0
    frames_outside: int = 0
    com_travel_m: tuple[float, float] = (0.0, 0.0)
    frames_without_support: int = 0
    least_sole_gap_mm: float | None = None  # the soles' least gap over the walk (check/feet.py)
    least_sole_gap_t_s: float = 0.0

    def describe(self) -> str:
        if not self.checked:
            return f"not checked ({self.note})"
        where = "inside" if self.closest_margin_mm >= 0 else "outside"
        if self.frames_without_support:
            return f"no sole on the ground in {self.frames_without_support} frames (docs/checking.md)"
        return (f"ZMP {'inside' if self.frames_outside == 0 else 'outside'} the support polygon"
                f"{'' if self.frames_outside == 0 else f' in {self.frames_outside} frames'}; closest "
                f"{abs(self.closest_margin_mm):.1f} mm {where} an edge at t={self.closest_t_s:.3f} s "
                f"(centre of mass and ZMP of every link's mass, docs/checking.md)" + self._feet())

    def _feet(self) -> str:
        if self.least_sole_gap_mm is None:
            return ""
        return f"; the soles at least {self.least_sole_gap_mm:.1f} mm apart (at t={self.least_sole_gap_t_s:.3f} s)"


@dataclass(frozen=True)
class CheckReport:
    """Result of ``check_trajectory``: per-joint summaries and the violations in time order."""

    config_path: str
    n_frames: int
    duration_s: float
    margin_deg: float
    joints: tuple[JointSummary, ...]
    violations: tuple[Violation, ...]
    velocity_method: str = VELOCITY_METHOD
    acceleration_method: str = ACCELERATION_METHOD
    balance: "BalanceSummary | None" = None
    robot: str = ""  # the robot's name (people read it; the config's path may be deep in site-packages)

    @property
    def errors(self) -> tuple[Violation, ...]:
        return tuple(v for v in self.violations if v.severity == "error")

    @property
    def warnings(self) -> tuple[Violation, ...]:
        return tuple(v for v in self.violations if v.severity == "warning")

    @property
    def ok(self) -> bool:
        """True when nothing is beyond a limit (warnings allowed)."""
        return not any(v.severity == "error" for v in self.violations)

    @property
    def first_error(self) -> str | None:
        """The earliest error as one line (for the walk's refusal), or None."""
        for v in self.violations:
            if v.severity == "error":
                return v.describe()
        return None

    def to_dict(self) -> dict:
        """Plain data for JSON."""
        return {
            "ok": self.ok,
            "robot": self.robot,
            "config": self.config_path,
            "n_frames": self.n_frames,
            "duration_s": self.duration_s,
            "margin_deg": self.margin_deg,
            "velocity_method": self.velocity_method,
            "acceleration_method": self.acceleration_method,
            "first_error": self.first_error,
            "joints": [asdict(j) for j in self.joints],
            "violations": [{**asdict(v), "unit": v.unit, "message": v.describe()} for v in self.violations],
            "balance": None if self.balance is None else asdict(self.balance),
        }

    def format_text(self, max_per_kind: int = 5) -> str:
        """A short table per joint, then the first ``max_per_kind`` violations of each kind and a count of the rest."""
        lines = [f"{self.robot or self.config_path}: {self.n_frames} frames over {self.duration_s:.3f} s, "
                 f"margin {self.margin_deg:g} deg: {'OK' if self.ok else 'FAIL'}"
                 f" ({len(self.errors)} errors, {len(self.warnings)} warnings)",
                 "",
                 f"{'joint':<20} {'used deg':>16} {'limits deg':>14} {'closest deg':>11} "
                 f"{'|vel| / limit deg/s':>21} {'|acc| / limit deg/s^2':>23}  verdict"]
        for j in self.joints:
            used = f"{j.used_min_deg:.1f}..{j.used_max_deg:.1f}"
            limits = f"{j.min_deg:.1f}..{j.max_deg:.1f}"
            vel = f"{j.worst_velocity_dps:.1f} / {j.max_velocity_dps:.0f}"
            acc = f"{j.worst_acceleration_dps2:.0f} / {j.max_acceleration_dps2:.0f}"
            lines.append(f"{j.joint:<20} {used:>16} {limits:>14} {j.closest_to_limit_deg:>11.1f} "
                         f"{vel:>21} {acc:>23}  {j.verdict}")
        lines += ["", f"velocity: {self.velocity_method}", f"acceleration: {self.acceleration_method}"]
        if self.balance is not None:
            lines.append(f"balance: {self.balance.describe()}")
        for kind in KIND_ORDER:
            found = [v for v in self.violations if v.kind == kind]
            if not found:
                continue
            lines += ["", f"{kind} ({len(found)}):"]
            lines += [f"  {v.severity}: {v.describe()}" for v in found[:max_per_kind]]
            if len(found) > max_per_kind:
                lines.append(f"  ... and {len(found) - max_per_kind} more")
        return "\n".join(lines)


# ---------------------------------------------------------------------------------------------


def check_trajectory(config: RobotConfig, t_s, angles_deg, margin_deg: float = 0.0) -> CheckReport:
    """Check sampled joint angles against the config's limits.

    t_s: (N,) strictly increasing sample times in seconds.
    angles_deg: (N, n_joints) angles in degrees for the config's joints (walking joints then held
        joints), or (N, 6) walking joints only, in which case held joints are taken at hold_deg.
    margin_deg: samples inside the position limits but closer than this to one are warnings.
    Raises ValueError for malformed input (shapes, non-finite values, times not increasing).
    """
    t = np.asarray(t_s, dtype=float)
    if t.ndim != 1 or len(t) < 1:
        raise ValueError(f"t_s must be a 1-D array of sample times, got shape {t.shape}")
    if margin_deg < 0 or not np.isfinite(margin_deg):
        raise ValueError(f"margin_deg must be a finite number >= 0, got {margin_deg}")
    raw = np.asarray(angles_deg, dtype=float)
    if raw.ndim != 2 or raw.shape[0] != len(t):
        raise ValueError(f"angles_deg must have shape ({len(t)}, n_joints), got {raw.shape}")
    angles = np.degrees(full_angles_rad(config, np.radians(raw))) if raw.shape[1] != len(config.joints) else raw
    if not (np.all(np.isfinite(t)) and np.all(np.isfinite(angles))):
        raise ValueError("t_s and angles_deg must hold finite numbers only")
    dt = np.diff(t)
    if np.any(dt <= 0):
        i = int(np.argmax(dt <= 0)) + 1
        raise ValueError(f"t_s must increase, but sample {i} has t={t[i]!r} after {t[i - 1]!r}")

    joints = config.joints
    lo = np.array([j.min_deg for j in joints])
    hi = np.array([j.max_deg for j in joints])
    v_lim = np.array([j.max_velocity_dps for j in joints])
    a_lim = np.array([j.max_acceleration_dps2 for j in joints])

    # The one definition (gaitbot.robot.joint_motion): the goal ticks as sent, at the frame times.
    velocity, acceleration = joint_motion(t, as_sent_deg(config, angles))  # at t[1:] and t[1:-1]
    t_vel = t[1:]
    t_acc = t[1:-1]

    zero, direction, tpr = joint_parameters(config)
    ticks = angle_rad_to_ticks(np.radians(angles), zero, direction, tpr)

    found: list[Violation] = []
    for col, joint in enumerate(joints):
        found += _joint_violations(joint, t, angles[:, col], ticks[:, col], t_vel, velocity[:, col],
                                   t_acc, acceleration[:, col], margin_deg)
    kind_rank = {k: i for i, k in enumerate(KIND_ORDER)}
    found.sort(key=lambda v: (v.t_start_s, kind_rank[v.kind], v.joint))

    summaries = tuple(
        _summary(joint, t, angles[:, c], t_vel, velocity[:, c], t_acc, acceleration[:, c],
                 [v for v in found if v.joint == joint.name], lo[c], hi[c], v_lim[c], a_lim[c])
        for c, joint in enumerate(joints))
    return CheckReport(config_path=str(config.path), n_frames=len(t), duration_s=float(t[-1] - t[0]),
                       margin_deg=float(margin_deg), joints=summaries, violations=tuple(found), robot=config.name)


def _joint_violations(joint: JointConfig, t, angle_deg, ticks, t_vel, vel, t_acc, acc, margin_deg) -> list[Violation]:
    """All violation episodes of one joint."""
    out: list[Violation] = []
    name = joint.name
    # Position: beyond a limit is an error; inside but within the margin, a warning.
    out += _episodes("position", name, "max_deg", joint.max_deg, "error", t, angle_deg,
                     angle_deg > joint.max_deg, angle_deg - joint.max_deg)
    out += _episodes("position", name, "min_deg", joint.min_deg, "error", t, angle_deg,
                     angle_deg < joint.min_deg, joint.min_deg - angle_deg)
    if margin_deg > 0:
        near_hi = (angle_deg <= joint.max_deg) & (angle_deg > joint.max_deg - margin_deg)
        near_lo = (angle_deg >= joint.min_deg) & (angle_deg < joint.min_deg + margin_deg)
        out += _episodes("position", name, "max_deg", joint.max_deg, "warning", t, angle_deg,
                         near_hi, angle_deg - joint.max_deg)
        out += _episodes("position", name, "min_deg", joint.min_deg, "warning", t, angle_deg,
                         near_lo, joint.min_deg - angle_deg)
    # Tick range (a wrapping servo would jump across its seam instead).
    model = joint.model
    kind = "wrap_seam" if model.wraps else "tick_range"
    out += _episodes(kind, name, "max_tick", model.max_tick, "error", t, ticks,
                     ticks > model.max_tick, ticks - model.max_tick)
    out += _episodes(kind, name, "min_tick", model.min_tick, "error", t, ticks,
                     ticks < model.min_tick, model.min_tick - ticks)
    if model.wraps and len(ticks) > 1:
        # Two consecutive goals more than half a turn apart: the short way between them crosses the seam
        # (typically an angle file that wrapped at +-180 deg).
        jump = np.abs(np.diff(ticks))
        half_turn = model.resolution_ticks / 2
        out += _episodes("wrap_seam", name, "jump of more than half a turn", half_turn, "error", t[1:],
                         ticks[1:], jump > half_turn, jump - half_turn)
    # Velocity and acceleration magnitudes.
    speed = np.abs(vel)
    out += _episodes("velocity", name, "max_velocity_dps", joint.max_velocity_dps, "error", t_vel, speed,
                     speed > joint.max_velocity_dps, speed)
    accel = np.abs(acc)
    out += _episodes("acceleration", name, "max_acceleration_dps2", joint.max_acceleration_dps2, "error", t_acc,
                     accel, accel > joint.max_acceleration_dps2, accel)
    return out


def _episodes(kind, joint, limit_name, limit, severity, t, value, mask, excess) -> list[Violation]:
    """One Violation per run of consecutive True samples in ``mask``, reporting the sample of the run
    with the largest ``excess`` (ties: the earliest)."""
    if not mask.any():
        return []
    idx = np.flatnonzero(mask)
    new_run = np.empty(len(idx), dtype=bool)
    new_run[0] = True
    new_run[1:] = np.diff(idx) > 1
    starts = np.flatnonzero(new_run)  # positions in idx where a run begins
    ends = np.append(starts[1:], len(idx)) - 1
    run_of = np.cumsum(new_run) - 1
    e = np.asarray(excess, dtype=float)[idx]
    run_max = np.maximum.reduceat(e, starts)
    is_worst = e == run_max[run_of]
    _, first_worst = np.unique(run_of[is_worst], return_index=True)
    worst = idx[np.flatnonzero(is_worst)[first_worst]]
    t_start, t_end, n = t[idx[starts]], t[idx[ends]], ends - starts + 1
    return [Violation(kind=kind, joint=joint, t_s=float(t[w]), value=float(value[w]), limit=float(limit),
                      severity=severity, limit_name=limit_name, t_start_s=float(a), t_end_s=float(b),
                      n_samples=int(c))
            for w, a, b, c in zip(worst, t_start, t_end, n)]


def _summary(joint, t, angle_deg, t_vel, vel, t_acc, acc, violations, lo, hi, v_lim, a_lim) -> JointSummary:
    distance = np.minimum(angle_deg - lo, hi - angle_deg)
    closest = int(np.argmin(distance))
    worst_v = int(np.argmax(np.abs(vel))) if len(vel) else None
    worst_a = int(np.argmax(np.abs(acc))) if len(acc) else None
    if any(v.severity == "error" for v in violations):
        verdict = "fail"
    elif violations:
        verdict = "warn"
    else:
        verdict = "ok"
    return JointSummary(
        joint=joint.name, used_min_deg=float(angle_deg.min()), used_max_deg=float(angle_deg.max()),
        min_deg=float(lo), max_deg=float(hi),
        closest_to_limit_deg=float(distance[closest]), closest_t_s=float(t[closest]),
        worst_velocity_dps=float(abs(vel[worst_v])) if worst_v is not None else 0.0,
        worst_velocity_t_s=float(t_vel[worst_v]) if worst_v is not None else float(t[0]),
        max_velocity_dps=float(v_lim),
        worst_acceleration_dps2=float(abs(acc[worst_a])) if worst_a is not None else 0.0,
        worst_acceleration_t_s=float(t_acc[worst_a]) if worst_a is not None else float(t[0]),
        max_acceleration_dps2=float(a_lim), verdict=verdict)


def trajectory_angles_deg(config: RobotConfig, angles_rad, names=None) -> np.ndarray:
    """(N, n_joints) degrees for every joint of the config from (N, J) angles in radians of the
    ``names`` joints (default: the moving joints; e.g. ``Trajectory.angles_rad`` and ``.joints``); held
    joints at their hold_deg. Feed this to check_trajectory."""
    return np.degrees(full_angles_rad(config, angles_rad, names))
