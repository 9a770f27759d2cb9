"""``gaitbot drive``'s command line: its options (light: the parser imports this module) and ``run``, which
hands the drive to gaitbot.app.drive_run (numpy, the walker, the bus). docs/driving.md."""

from __future__ import annotations

from gaitbot.app.arguments import add_command
from gaitbot.app.feel_options import add_feedback_option
from gaitbot.app.sim_options import DEFAULT_PUSH_AT_S, add_sim_model_options
from gaitbot.app.view_options import add_view_options


def add_parser(subparsers):
    """``drive``'s options on the command line's parser (gaitbot.app.cli)."""
    p = add_command(subparsers, "drive")
    p.add_argument("--robot", help="robot config: a name in config/ or a .toml file (default xl430-biped)")
    p.add_argument("--calibration", metavar="FILE", help="calibration file applied on top of the robot config")
    p.add_argument("--input", metavar="SOURCE",
                   help="keyboard (default), gamepad[:DEVICE], udp:[HOST:]PORT, commands:FILE or foxglove (the Teleop "
                   "panel's Twists on /cmd_vel; the default with --foxglove)")
    p.add_argument("--port", help="serial port of the robot (default: the config's)")
    p.add_argument("--dry-run", action="store_true", help="drive the mock bus under the real SDK: no hardware")
    p.add_argument("--sim", action="store_true", help="drive the simulated robot (MuJoCo, free-floating)")
    p.add_argument("--realtime", action="store_true", help="--dry-run: pace it at the real frame rate")
    add_sim_model_options(p, "at --push-at")  # --push, --imu-fault, --imu-seed, --sim-model, --sim-map (gaitbot.app.sim_options)
    p.add_argument("--push-at", type=float, metavar="S", help=f"--sim --push: when the push starts, in seconds "
                   f"from the start of the drive (default {DEFAULT_PUSH_AT_S:g})")
    add_feedback_option(p)  # --feedback (gaitbot.app.feel_options)
    p.add_argument("--record", metavar="FILE", help="write every bus packet to this .jsonl file (gaitbot check reads it)")
    p.add_argument("--record-commands", metavar="FILE", help="write the commands received (JSON Lines, as "
                   "--input commands:FILE and --commands read them)")
    p.add_argument("--max-time", type=float, metavar="S", help="stop (to standing) after this many seconds")
    p.add_argument("--json", action="store_true", help="print the final report as one JSON object")
    p.add_argument("--reply-timeout-ms", type=float, metavar="MS", help="status packet timeout")
    add_view_options(p)  # --mcap, --foxglove (gaitbot.app.view_options)
    return p


def run(args) -> int:
    from gaitbot.app.drive_run import run as drive

    return drive(args)
