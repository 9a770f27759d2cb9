"""From a robot config to the gait room's inputs: leg geometry and walk settings."""

from __future__ import annotations

from gaitbot.gait.geometry import LegGeometry
from gaitbot.gait.walker import WalkSettings
from gaitbot.robot.config import RobotConfig


def leg_geometry(config: RobotConfig) -> LegGeometry:
    """The robot's leg in metres (the heel heel_back_m behind the ankle, projected on the sole)."""
    g = config.geometry
    return LegGeometry(thigh=g.thigh_m, shank=g.shank_m, foot=g.foot_m, hip_width=g.hip_width_m,
                       ankle_height=g.ankle_height_m, heel_back=g.heel_back_m)


def walk_settings(config: RobotConfig, rate_hz: float | None = None) -> WalkSettings:
    """Walk settings from ``[gait]``; ``rate_hz`` overrides the configured frame rate."""
    gait = config.gait
    return WalkSettings(cycle_s=gait.cycle_s, rate_hz=rate_hz or gait.rate_hz, clearance=gait.clearance_m)
