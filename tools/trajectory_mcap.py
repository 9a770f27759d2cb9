"""A planned walk as an MCAP log, to look at in Foxglove (or ``ros2 bag``) before it runs.

    python tools/trajectory_mcap.py walk.npz --robot op3 -o walk.mcap

Writes gaitbot.stream.mcap_log's channels for a trajectory file (``gaitbot generate``): the goals
(/joint_goals), the robot's pose (/tf, /tf_static, the URDF on /robot_description) and its planned centre of
mass (/com/planned), one message a frame. Needs the ecosystem extra (mcap, mcap-ros2-support). The live
walk's ``--mcap`` writes the same channels and more (docs/robot-description.md, "Logs in MCAP").
"""

from __future__ import annotations

import argparse
import sys

from gaitbot.app.options import load_robot
from gaitbot.errors import UserError
from gaitbot.gait.trajectory import Trajectory
from gaitbot.stream.mcap_log import write_trajectory


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description="a trajectory file as an MCAP log (ROS 2 messages)")
    parser.add_argument("trajectory", help="trajectory file (.csv or .npz, gaitbot generate)")
    parser.add_argument("--robot", help="robot config the trajectory is for (default xl430-biped)")
    parser.add_argument("-o", "--output", required=True, help="MCAP file to write")
    args = parser.parse_args(argv)
    try:
        config = load_robot(args.robot)
        frames = write_trajectory(args.output, config, Trajectory.load(args.trajectory))
    except (UserError, OSError) as exc:
        print(f"trajectory_mcap: error: {' '.join(str(exc).split())}", file=sys.stderr)
        return 2
    print(f"wrote {args.output}: {frames} frames of {config.name}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
