"""The check ``gaitbot walk`` runs before anything moves: the same code as ``gaitbot check``."""

from __future__ import annotations

from gaitbot.check.trajectory import CheckReport, check_trajectory, trajectory_angles_deg
from gaitbot.errors import UserError
from gaitbot.gait.trajectory import Trajectory
from gaitbot.robot.config import RobotConfig


class TrajectoryMismatch(UserError, ValueError):
    """A trajectory moves a joint the robot does not have, or one it holds: one line, exit 2."""


def robot_angles_deg(config: RobotConfig, trajectory: Trajectory):
    """(N, n_joints) degrees of every joint of ``config`` for ``trajectory``, its joints placed by name:
    moving joints the trajectory lacks stay at 0 (a planar walk keeps roll and yaw straight)."""
    try:
        return trajectory_angles_deg(config, trajectory.angles_rad, trajectory.joints)
    except ValueError as exc:
        raise TrajectoryMismatch(f"the trajectory does not fit robot {config.name}: {exc}") from None


def preflight(config: RobotConfig, trajectory: Trajectory, margin_deg: float = 0.0) -> CheckReport:
    """Every frame of ``trajectory`` against ``config``'s limits, held joints at their hold angles."""
    return check_trajectory(config, trajectory.t_s, robot_angles_deg(config, trajectory), margin_deg)
