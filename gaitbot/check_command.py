"""``gaitbot check``: a trajectory or a recording against a robot's limits (exit 0 ok, 1 broken, 2 unreadable)."""

from __future__ import annotations

import json

from gaitbot.check import check_trajectory, trajectory_angles_deg
from gaitbot.gait.trajectory import Trajectory
from gaitbot.session import UsageError, load_robot


def run_check(args) -> int:
    config = load_robot(args.robot)
    if str(args.file).endswith(".jsonl"):
        raise UsageError(f"{args.file}: checking recordings is not implemented yet")
    trajectory = Trajectory.load(args.file)
    report = check_trajectory(config, trajectory.t_s, trajectory_angles_deg(config, trajectory.angles_rad),
                              args.margin_deg)
    print(json.dumps(report.to_dict(), indent=2) if args.json else report.format_text())
    return 0 if report.ok else 1
