"""The check ``gaitbot walk`` runs before anything moves: the same code as ``gaitbot check``."""

from __future__ import annotations

from gaitbot.check.trajectory import CheckReport, check_trajectory, trajectory_angles_deg
from gaitbot.gait.trajectory import Trajectory
from gaitbot.robot.config import RobotConfig


def preflight(config: RobotConfig, trajectory: Trajectory, margin_deg: float = 0.0) -> CheckReport:
    """Every frame of ``trajectory`` against ``config``'s limits, held joints at their hold angles."""
    return check_trajectory(config, trajectory.t_s, trajectory_angles_deg(config, trajectory.angles_rad), margin_deg)
