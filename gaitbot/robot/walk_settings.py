"""From a robot config to the gait room's inputs: leg geometry, walk settings, terrain settings and
the limits the session's ramps keep to."""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

from gaitbot.gait.geometry import LegGeometry
from gaitbot.gait.terrain.course_file import Course, TerrainFileError
from gaitbot.gait.terrain.envelope import StepEnvelope
from gaitbot.gait.terrain.walk import TerrainSettings, default_weights
from gaitbot.gait.walker import WalkSettings
from gaitbot.robot.config import RobotConfig
from gaitbot.robot.motion_margin import PLANNED_SHARE


def leg_geometry(config: RobotConfig) -> LegGeometry:
    """The robot's leg in metres (the heel heel_back_m behind the ankle, projected on the sole)."""
    g = config.geometry
    return LegGeometry(thigh=g.thigh_m, shank=g.shank_m, foot=g.foot_m, hip_width=g.hip_width_m,
                       ankle_height=g.ankle_height_m, heel_back=g.heel_back_m)


def walk_settings(config: RobotConfig, rate_hz: float | None = None) -> WalkSettings:
    """Walk settings from ``[gait]``; ``rate_hz`` overrides the configured frame rate."""
    gait = config.gait
    return WalkSettings(cycle_s=gait.cycle_s, rate_hz=rate_hz or gait.rate_hz, clearance=gait.clearance_m)


@dataclass(frozen=True)
class GaitSource:
    """Where a walk's geometry and settings come from, and the longest step allowed (metres).

    ``robot`` is None when the leg is not the configured robot's (a leg given on the command line),
    whose joint limits then do not apply. ``default_step_m``: the longest step of ``--distance`` when
    ``--max-step`` is not given, if not ``max_step_m`` (a balanced robot's ``[gait] max_step_m`` is its
    default, and its reach the limit). ``clearance_asked``: the settings' clearance is ``--clearance``'s, which a
    balanced walk keeps (its speed fit lowers only the robot's own)."""

    geometry: LegGeometry
    settings: WalkSettings
    max_step_m: float
    robot: RobotConfig | None
    default_step_m: float | None = None
    clearance_asked: bool = False

    @property
    def balanced(self) -> bool:
        """The robot's legs roll: it walks with the balanced walker (gaitbot.robot.balanced_walk)."""
        return self.robot is not None and self.robot.is_3d


def joint_limits_ticks(config: RobotConfig) -> tuple[float, float]:
    """What ramps are planned at, in ticks/s and ticks/s^2: the slowest joint's velocity and acceleration
    limits times PLANNED_SHARE (gaitbot.robot.motion_margin)."""
    vel = min(math.radians(j.max_velocity_dps) * j.model.ticks_per_rad for j in config.joints)
    acc = min(math.radians(j.max_acceleration_dps2) * j.model.ticks_per_rad for j in config.joints)
    return PLANNED_SHARE * vel, PLANNED_SHARE * acc


def terrain_envelope(source: GaitSource, course: Course) -> StepEnvelope:
    """The robot's step envelope (its config's [terrain], else the unmeasured default), tightened by the
    course's own max_rise_m / max_step_m; a course asking for more than the robot can do is refused."""
    g = source.geometry
    reach = source.robot.terrain if source.robot is not None else None
    who = source.robot.name if source.robot is not None else "this leg"
    if reach is not None:
        env = StepEnvelope.for_foot(g.foot, reach.max_rise_m, reach.max_drop_m, reach.max_gap_m, who)
    else:
        env = StepEnvelope.default(g.foot, g.leg_length, f"{who}, not measured")
    if course.max_rise_m is not None:
        if course.max_rise_m > max(env.max_rise, env.max_drop) + 1e-12:
            raise TerrainFileError(course.path, "course.max_rise_m", f"{course.max_rise_m:g} m is more than {who} "
                                   f"can step (max rise {env.max_rise:.3f} m, drop {env.max_drop:.3f} m)")
        env = replace(env, max_rise=min(env.max_rise, course.max_rise_m), max_drop=min(env.max_drop, course.max_rise_m))
    if course.max_step_m is not None:
        if course.max_step_m > env.longest + 1e-12:
            raise TerrainFileError(course.path, "course.max_step_m", f"{course.max_step_m:g} m is longer than {who} "
                                   f"can step between surfaces (max {env.longest:.3f} m)")
        env = replace(env, max_gap=max(0.0, course.max_step_m - env.reference_step))
    return env


def terrain_settings(source: GaitSource, course: Course, clearance_override: float | None = None) -> TerrainSettings:
    """How to walk a course: the file's values, else the robot's (clearance, joint ranges and limits, step
    envelope)."""
    lo = hi = speed = accel = None
    if source.robot is not None:
        pairs = list(zip(source.robot.joints[:3], source.robot.joints[3:6]))  # (left, right) hip, knee, ankle
        lo = tuple(math.radians(max(a.min_deg, b.min_deg)) for a, b in pairs)
        hi = tuple(math.radians(min(a.max_deg, b.max_deg)) for a, b in pairs)
        speed = tuple(math.radians(min(a.max_velocity_dps, b.max_velocity_dps)) for a, b in pairs)
        accel = tuple(math.radians(min(a.max_acceleration_dps2, b.max_acceleration_dps2)) for a, b in pairs)
    clearance = course.clearance_m if course.clearance_m is not None else source.settings.clearance
    if clearance_override is not None:
        clearance = clearance_override
    return TerrainSettings(envelope=terrain_envelope(source, course), margin=course.margin_m, clearance=clearance,
                           weights=course.weights or default_weights(lo, hi), joint_lo=lo, joint_hi=hi,
                           joint_speed=speed, joint_accel=accel)
