"""Steering options of ``plan``, ``generate`` and ``walk``: ``--velocity VX,VY,WZ`` with ``--duration S``
(or ``--distance M`` for a straight walk), and ``--commands FILE`` (JSON Lines, docs/file-formats.md).

Kept apart from the parser and the straight walk's options so that the command line's layout can change
around them: ``add_steer_options`` defines them and ``steer_requested`` says whether a walk is steered
(light: the parser imports this module); gaitbot.app.steer_walk is the gait source of a steered walk.
"""

from __future__ import annotations


def add_steer_options(p) -> None:
    """--velocity, --duration and --commands on a walk command's parser."""
    p.add_argument("--velocity", metavar="VX,VY,WZ", help="walk at this velocity: forward and left in m/s, turning "
                   "counter-clockwise in deg/s (robot frame), for --duration S (or --distance M if straight)")
    p.add_argument("--duration", type=float, metavar="S", help="how long --velocity holds, seconds (then the walk stops)")
    p.add_argument("--commands", metavar="FILE", help="walk the timed velocity commands of a JSON Lines file "
                   "({\"t\": 0, \"vx\": 0.05, \"vy\": 0, \"wz\": 0} per line, ending with {\"t\": S, \"stop\": true})")


def steer_sources(args) -> list[str]:
    """The steering sources given (for the one-source check of plan, generate and walk)."""
    return [name for name in ("velocity", "commands") if getattr(args, name, None) is not None]


def steer_requested(args) -> bool:
    return bool(steer_sources(args))
