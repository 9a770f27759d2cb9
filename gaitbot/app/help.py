"""What ``gaitbot COMMAND --help`` says beyond the options: what the command is for, and examples.

Written here, apart from the parser, so that the texts read as one piece. The examples are run by the
tests (tests/docs/test_examples.py runs every ``$ `` line of every epilog in a temporary folder, in
order, as the docs' commands are run), so they cannot go stale.
"""

from __future__ import annotations

import argparse
from dataclasses import dataclass


class HelpFormatter(argparse.RawDescriptionHelpFormatter):
    """Descriptions and examples keep their line breaks; option help is wrapped as usual."""


@dataclass(frozen=True)
class CommandHelp:
    summary: str  # one line, in the list of commands
    description: str  # what it does and why, a few lines
    examples: tuple[str, ...]  # command lines (without the leading "gaitbot"-less prompt), run by the tests
    robot_examples: tuple[str, ...] = ()  # command lines that need servos at hand (not run by the tests)

    @property
    def epilog(self) -> str:
        lines = ["examples:"] + [f"  $ {line}" for line in self.examples]
        if self.robot_examples:
            lines += ["examples with the servos connected (docs/bring-up.md):"]
            lines += [f"  {line}" for line in self.robot_examples]
        return "\n".join(lines)


EXIT_STATUSES = """exit status:
  0    success
  1    the robot or the check failed: a limit broken, a bus fault, a fall in the simulation
  2    bad input: one line naming the argument, file or field; nothing was sent to a servo
  130  stopped by Ctrl-C (a walk brakes and ramps to standing first)
  141  the output was closed early (e.g. piped into head)
  143  stopped by SIGTERM (as Ctrl-C)"""

DESCRIPTION = """Walking gaits for small servo bipeds: plan and generate walks (Boulic's model with exact step
lengths, terrain, eigen-gaits), check them against the robot's limits, and stream them at the robot's
frame rate to Dynamixel or Feetech servos, a mock bus or a simulated robot."""

EPILOG = f"""{EXIT_STATUSES}

examples:
  $ gaitbot walk --dry-run --record run.jsonl
  $ gaitbot plan --distance 1.0

Each command's own --help explains it, with examples; the manual is docs/ in the source
(docs/command-line.md lists every command)."""

COMMAND_HELP = {
    "plan": CommandHelp(
        "print the step plan: lengths, speeds, timing, footholds",
        "Plan a walk without moving anything: each step's length, its relative velocity RV (walking speed\n"
        "over leg length, which sets the joint motion of Boulic's model), start and end time, and where\n"
        "each heel lands. With --terrain: the footholds on the treads, which steps use the terrain walker,\n"
        "how high each swing foot lifts, and the pelvis search (docs/terrain.md).",
        ("gaitbot plan --distance 1.0",
         "gaitbot plan --steps 0.05,0.08,0.10 --json",
         "gaitbot plan --terrain config/terrain/kerb.toml")),
    "generate": CommandHelp(
        "write the trajectory (joint angles over time) to CSV or NPZ",
        "Generate every frame of a walk (hip, knee and ankle of both legs, and the hip's path) and write\n"
        "it to a file that plot, check, walk --trajectory and eigen fit read (docs/file-formats.md).",
        ("gaitbot generate --distance 1.0 -o walk.csv",
         "gaitbot generate --terrain config/terrain/kerb.toml -o kerb.csv")),
    "plot": CommandHelp(
        "draw a trajectory (or an eigen-gait model) to a picture",
        "Draw joint angles, foot heights against the clearance line, stick figures and footholds of a\n"
        "trajectory file; or, for a model from eigen fit, its mean cycle and eigen-motions.",
        ("gaitbot generate --distance 1.0 -o walk.csv",
         "gaitbot plot walk.csv -o walk.png")),
    "walk": CommandHelp(
        "walk the robot, the mock bus (--dry-run) or the simulated robot (--sim)",
        "Check every frame against the robot's limits, then stream the walk at the robot's frame rate.\n"
        "Nothing moves if any frame breaks a limit. On hardware, Ctrl-C or SIGTERM brake the motion and\n"
        "ramp the robot to standing. --dry-run sends every packet through the vendor SDK to a mock bus\n"
        "(no hardware); --sim walks a MuJoCo model of the robot and says whether it really walks.",
        ("gaitbot walk --dry-run",
         "gaitbot walk --distance 1.0 --dry-run --record run.jsonl",
         "gaitbot walk --sim --distance 0.5")),
    "drive": CommandHelp(
        "drive the robot live from a keyboard, a gamepad, UDP, Foxglove or a commands file",
        "Plan each step from the latest velocity command while the robot walks, check every frame before it\n"
        "is sent, and stream it at the robot's frame rate (docs/driving.md). Ctrl-C stops stepping and\n"
        "stands; a second Ctrl-C hurries to the stop ramp.",
        ("gaitbot drive --robot op3 --dry-run --input commands:config/commands/drive-demo.jsonl",),
        ("gaitbot drive --robot op3 --input keyboard",)),
    "check": CommandHelp(
        "check a trajectory or a recorded run against the robot's limits",
        "Say joint by joint whether, and where, a trajectory or a bus recording breaks a position, tick,\n"
        "velocity or acceleration limit; for recordings also checksums, ids and frame timing.\n"
        "Exit 0 when everything holds, 1 when something breaks, 2 for unreadable input.",
        ("gaitbot generate --distance 0.5 -o walk.csv",
         "gaitbot check walk.csv",
         "gaitbot check --json walk.csv")),
    "eigen": CommandHelp(
        "eigen-gaits (Li et al. 2009): learn walks from examples, synthesise new ones",
        "Learn the main ways example walks differ (eigen-motions, by functional PCA) and synthesise new\n"
        "walks from them: at a step length between the examples', changing step length, or forced\n"
        "through a pose (docs/eigen-gaits.md).",
        ("gaitbot generate --steps 0.03,0.03,0.03,0.03,0.03,0.03 -o ex_0.03.npz",
         "gaitbot generate --steps 0.07,0.07,0.07,0.07,0.07,0.07 -o ex_0.07.npz",
         "gaitbot eigen fit ex_0.03.npz ex_0.07.npz -o model.npz",
         "gaitbot eigen synth model.npz --step-length 0.05 -o walk.csv")),
    "eigen fit": CommandHelp(
        "fit an eigen-gait model to example walks",
        "Cut each example walk into cycles (left heel strike to left heel strike), align them in time,\n"
        "reduce the poses by PCA, fit each channel with smooth functions and keep the eigen-motions that\n"
        "explain most of the variance. The examples are walks of one robot (--robot), with the joints it walks\n"
        "with; the model remembers its joints, the leg it learnt and the robot it is for.",
        ("gaitbot generate --steps 0.03,0.03,0.03,0.03,0.03,0.03 -o ex_0.03.npz",
         "gaitbot generate --steps 0.07,0.07,0.07,0.07,0.07,0.07 -o ex_0.07.npz",
         "gaitbot eigen fit ex_0.03.npz ex_0.07.npz -o model.npz")),
    "eigen synth": CommandHelp(
        "synthesise a walk from an eigen-gait model",
        "Make a walk from the model: at --step-length, changing to --to-step-length, or passing through\n"
        "--pose-deg at --pose-time. It starts and ends standing and is checked like gaitbot walk checks it\n"
        "(exit 1, with the file written, if it breaks a limit or would tip the robot). Only for the robot the\n"
        "model was fitted for.",
        ("gaitbot generate --steps 0.03,0.03,0.03,0.03,0.03,0.03 -o ex_0.03.npz",
         "gaitbot generate --steps 0.07,0.07,0.07,0.07,0.07,0.07 -o ex_0.07.npz",
         "gaitbot eigen fit ex_0.03.npz ex_0.07.npz -o model.npz",
         "gaitbot eigen synth model.npz --step-length 0.05 --cycles 2 -o walk.csv")),
    "record": CommandHelp(
        "record a motion made by hand: torque off, positions read to a trajectory CSV",
        "Turn torque off (after asking), read every servo's position at the robot's frame rate while you\n"
        "move the legs, and write them as a trajectory, flushed row by row. Ctrl-C ends it (exit 0).",
        ("gaitbot record --dry-run --duration 2 --yes -o demo.csv",)),
    "scan": CommandHelp(
        "list every servo that answers, at every baud rate",
        "Ping every id at every baud rate of the configured protocol (or --baud) and list each servo that\n"
        "answers: id, baud rate, model, firmware, present position (ticks and as its joint's angle), input\n"
        "voltage, temperature, load, torque and hardware errors in words; then the configured joints that\n"
        "did not answer. Reads only; a progress bar on a terminal. Exit 0 when every configured joint\n"
        "answered as configured, else 1.",
        ("gaitbot scan --dry-run",
         "gaitbot scan --robot ax12a-biped --dry-run --json")),
    "setup": CommandHelp(
        "give new servos, one at a time, the config's ids and baud rate",
        "For each joint (or each --joint), asks you to connect only that joint's servo, finds it at any id\n"
        "and any baud rate its model can run at, and writes the joint's id and the config's baud rate\n"
        "(torque off, the Feetech EEPROM lock, ID, Baud Rate: nothing else), then reads them back. Refuses\n"
        "(exit 2, nothing written) when more than one servo answers or the servo is not the config's model\n"
        "(docs/bring-up.md).",
        ("gaitbot setup --help",),
        ("gaitbot setup --robot config/xl430-biped.toml --port /dev/ttyUSB0",
         "gaitbot setup --robot ax12a-biped --joint knee_pitch_left --yes --reply-timeout-ms 5")),
    "calibrate": CommandHelp(
        "measure each joint's zero tick and direction into a calibration file",
        "Torque off; you hold the robot in its zero pose (legs straight, feet flat) and press Enter: the\n"
        "present positions become the zero ticks. Then, joint by joint, you bend the joint in its positive\n"
        "direction (told in words) and press Enter: the sign of the change is its direction, the size is\n"
        "checked against the configured limits. Writes the calibration file where every command finds it\n"
        "and applies it on top of the config: <config stem>.calibration.toml beside your config, or in this\n"
        "folder for a shipped robot (or -o FILE, then --calibration FILE). Writes only Torque Enable = 0 to\n"
        "the servos (docs/bring-up.md).",
        ("gaitbot calibrate --help",),
        ("gaitbot calibrate --robot robots/mybot.toml",
         "gaitbot walk --robot robots/mybot.toml --distance 0.5   # applies robots/mybot.calibration.toml")),
    "robot": CommandHelp(
        "a new robot config, or a robot config to and from URDF and MJCF (the field's robot descriptions)",
        "Start a new robot from a complete commented template (robot new), export a robot config as URDF or\n"
        "MJCF for the tools the field looks at robots with (RViz, Foxglove, MuJoCo's viewer, PlaCo), or import a\n"
        "robot's URDF or MJCF as a config draft (docs/robot-description.md).",
        ("gaitbot robot new mybot --legs 12 -o mybot.toml",
         "gaitbot robot export op3 --urdf op3.urdf --mjcf op3.xml",
         "gaitbot robot import op3.urdf --like config/op3.toml -o mine.toml")),
    "robot new": CommandHelp(
        "write a new robot's config: a complete commented template that walks as it is",
        "A made-up robot of the usual size (220 mm legs, Dynamixel X servos) with 6 joints (hip, knee and ankle\n"
        "pitch: it walks on a boom) or 12 (hip yaw, roll, pitch, knee, ankle pitch, roll: it balances). It plans,\n"
        "generates, checks and simulates as it is; every value only your robot can give is marked FILL IN, and\n"
        "[robot] draft keeps the hardware commands from using it until you delete that line (docs/robot-config.md).",
        ("gaitbot robot new mybot --legs 12 -o mybot.toml",
         "gaitbot generate --robot mybot.toml --distance 0.3 -o mybot-walk.csv",
         "gaitbot check mybot-walk.csv")),
    "robot export": CommandHelp(
        "write a robot config as URDF and/or MJCF",
        "Links, joints (axes, the config's limits), masses, centres of mass and inertias, the feet as boxes,\n"
        "held joints fixed at their hold angles. The MJCF is the simulated robot itself (gaitbot walk --sim's\n"
        "model); frame names in docs/robot-description.md.",
        ("gaitbot robot export op3 --urdf op3.urdf",
         "gaitbot robot export ax12a-biped --urdf ax12a.urdf --mjcf ax12a.xml")),
    "robot import": CommandHelp(
        "read a URDF or MJCF as a robot config draft",
        "Find the legs' joints (by name, or --map), check their axes and signs by forward kinematics, measure\n"
        "the legs and sum every link's mass, centre of mass and inertia into gaitbot's links; the bus, servos,\n"
        "ids and gait come from --like CONFIG, or are placeholders and the draft says so ([robot] draft: the\n"
        "hardware commands refuse it until it is checked). Prints the joint mapping to confirm. A leg that is\n"
        "not 6 (or 3 pitch) hinges in a chain is refused (exit 2).",
        ("gaitbot robot export op3 --urdf op3.urdf",
         "gaitbot robot import op3.urdf --like config/op3.toml -o mine.toml",
         "gaitbot robot import op3.urdf -o draft.toml",
         "gaitbot plan --robot mine.toml --distance 0.3")),
}
