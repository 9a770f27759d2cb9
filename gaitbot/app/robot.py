"""``gaitbot robot new``, ``export`` and ``import``: a new robot's config from a template, a robot config to
and from URDF and MJCF.

The parser lives here (``add_parser``: the command line registers it in one line); the work is the robot
room's (gaitbot.robot.description: the URDF writer, the chain finder, the importer, the draft) and the sim
room's (gaitbot.sim.model3d writes the MJCF, gaitbot.sim.description reads one through MuJoCo).
docs/robot-description.md says what the files hold.
"""

from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path

from gaitbot.app.arguments import add_command


def add_parser(sub) -> argparse.ArgumentParser:
    """The ``robot`` command and its two sub-commands on ``sub`` (argparse subparsers); ``p.commands`` holds the
    sub-commands' parsers by name (their errors print their own usage)."""
    command = add_command
    p = command(sub, "robot")
    robot = p.add_subparsers(dest="robot_command", required=True, metavar="{new,export,import}",
                             help="start a new robot's config, export a config to URDF/MJCF, or import a URDF/MJCF "
                                  "as a config draft")
    n = command(robot, "robot new")
    n.add_argument("name", help="the robot's name ([robot] name), e.g. mybot")
    n.add_argument("--legs", type=int, required=True, choices=(6, 12), metavar="{6,12}",
                   help="joints in both legs: 6 (hip, knee, ankle pitch; walks on a boom) or 12 (also hip yaw and "
                        "roll, ankle roll; balances)")
    n.add_argument("-o", "--output", required=True, metavar="FILE", help="the config to write (.toml)")
    e = command(robot, "robot export")
    e.add_argument("robot", help="robot config: a .toml path or a shipped name (e.g. op3)")
    e.add_argument("--urdf", metavar="FILE", help="write the robot as URDF to FILE")
    e.add_argument("--mjcf", metavar="FILE", help="write the robot as MuJoCo MJCF to FILE (the simulated robot)")
    i = command(robot, "robot import")
    i.add_argument("description", help="the robot's URDF (.urdf) or MJCF (.xml) file")
    i.add_argument("-o", "--output", required=True, metavar="FILE", help="config draft to write (.toml)")
    i.add_argument("--like", metavar="CONFIG", help="take the bus, servo models, ids, zero ticks, directions and "
                   "gait settings from this config, by joint name (default: placeholders, marked as a draft)")
    i.add_argument("--map", metavar="FILE", help="which description joint is which gaitbot joint, when the names do "
                   "not say: a [joints] table, gaitbot joint = \"description joint\" (a leading - flips the sign)")
    p.commands = {"robot new": n, "robot export": e, "robot import": i}
    return p


def run(args) -> int:
    return {"new": new, "export": export, "import": import_description}[args.robot_command](args)


def new(args) -> int:
    from gaitbot.app.options import UsageError, file_option
    from gaitbot.app.outputs import output_path, write_output
    from gaitbot.robot.config import ConfigError, load_robot_config
    from gaitbot.robot.template import template_text

    out = Path(file_option(args.output, "-o"))
    if out.suffix != ".toml":
        raise UsageError(f"-o {out}: a robot config's name ends in .toml")
    name = args.name.strip()
    if not name or len(name) > 64 or not all(c.isalnum() or c in "-_." for c in name):
        raise UsageError(f"name {args.name!r}: 1..64 letters, digits, '-', '_' or '.'")
    output_path(out, "-o", args)
    write_output(out, lambda path: path.write_text(template_text(name, args.legs, str(out))))
    try:
        config = load_robot_config(out)  # the template loads as written, or nothing is left behind
    except ConfigError as exc:
        out.unlink(missing_ok=True)
        raise UsageError(f"the template would not load ({exc}); nothing written") from None
    print(f"wrote {out}: {config.name}, {len(config.joints)} joints, a draft: fill in what is marked FILL IN, "
          f"then delete the [robot] draft line (docs/robot-config.md)")
    return 0


def export(args) -> int:
    from gaitbot.app.options import UsageError, file_option, load_robot
    from gaitbot.app.outputs import output_path, write_output
    from gaitbot.robot.description.urdf_writer import urdf_text
    from gaitbot.sim.model3d import exported_mjcf

    if not args.urdf and not args.mjcf:
        raise UsageError("give --urdf FILE and/or --mjcf FILE")
    outputs = [(flag, Path(file_option(value, flag)), make) for flag, value, make in
               (("--urdf", args.urdf, urdf_text), ("--mjcf", args.mjcf, exported_mjcf)) if value]
    for flag, out, _ in outputs:
        output_path(out, flag, args)
    config = load_robot(args.robot)
    for flag, out, make in outputs:
        text = make(config)
        write_output(out, lambda path: path.write_text(text), flag)
        print(f"wrote {out}: {config.name}, {len(config.walking_joints)} joints that walk"
              + (f", {len(config.held_joints)} held (fixed)" if config.held_joints else "")
              + f", {config.body.total_kg:.6g} kg")
    return 0


def import_description(args) -> int:
    from gaitbot.app.options import UsageError, file_option, load_robot
    from gaitbot.app.outputs import output_path, write_output
    from gaitbot.robot.config import ConfigError, load_robot_config
    from gaitbot.robot.description.chains import leg_joints, mapping_text, read_map
    from gaitbot.robot.description.draft import draft_text
    from gaitbot.robot.description.importer import FK_REFUSE_SHARE_OF_LEG, SOLE_KEYS, fk_deviation_m, import_tree
    from gaitbot.robot.description.tree import DescriptionError
    from gaitbot.sim.description import read_description

    out = Path(file_option(args.output, "-o"))
    output_path(out, "-o", args)
    source = Path(file_option(args.description, "description"))
    like = load_robot(args.like) if args.like is not None else None
    mapping = read_map(file_option(args.map, "--map")) if args.map is not None else None
    tree = read_description(source)
    legs = leg_joints(tree, mapping)
    sole = {key: getattr(like.body.geometry, key) for key in SOLE_KEYS} if like is not None else None
    imported = import_tree(tree, legs, sole)
    text = draft_text(out.stem, source.name, imported, like)
    write_output(out, lambda path: path.write_text(text))
    try:
        config = load_robot_config(out)
    except ConfigError as exc:
        out.unlink(missing_ok=True)
        raise UsageError(f"the imported config would not load ({exc.field}: {exc.reason}); nothing written") from None
    limits = {j.name: (math.radians(j.min_deg), math.radians(j.max_deg)) for j in config.walking_joints}
    deviation = fk_deviation_m(tree, legs, imported.origin_m, config.body.geometry, limits)
    leg_m = config.body.geometry.leg_length_m
    if deviation > FK_REFUSE_SHARE_OF_LEG * leg_m:
        out.unlink(missing_ok=True)
        raise DescriptionError(source, "joints", f"gaitbot's leg model with this mapping misses the description's "
                                                 f"knees, ankles or feet by {deviation * 1000:.1f} mm at random poses "
                                                 f"(leg {leg_m * 1000:.0f} mm): wrong joints? give a --map file")
    print(f"# joints found in {source.name} (gaitbot joint = description joint; '-': opposite sense). "
          f"Check them; save this as a --map file to change them:")
    print(mapping_text(legs), end="")
    for note in imported.notes:
        print(f"note: {note}", file=sys.stderr)
    print(f"wrote {out}: {config.name}, {len(legs['left'])} joints a leg, {config.body.total_kg:.6g} kg; forward "
          f"kinematics agree with {source.name}'s within {deviation * 1000:.3f} mm at random poses"
          + ("" if like is not None else "; a draft (bus, servos, ids, gait: placeholders; see [robot] draft)"))
    return 0
