#!/usr/bin/env python3
"""From a box of servos to a walking robot on the servo emulator, every step as a person takes it:

    python tools/bringup_journey.py --robot xl430-biped [--folder bringup-journey] [--seed 0]

1. the emulator holds factory-fresh servos, one connected at a time, kept in ``chain.json`` (``--state``);
2. ``gaitbot setup`` asks for each servo in turn; Enter in the emulator plugs in the next (the person's
   hand), and once more after the last connects the whole chain;
3. ``gaitbot scan`` finds every servo of the config at its id and rate;
4. the emulator is stopped and started again with the same ``chain.json``: the same servos, and
   ``--hand-calibrate`` standing in for the person who holds the robot and bends its joints;
5. ``gaitbot calibrate`` writes the calibration where every command finds it, and ``gaitbot walk`` walks.

Each command is printed as typed (``$ gaitbot ...``) with what it printed; the commands run in ``--folder``.
At the end the calibration is compared with how the emulated robot was built (each horn a few degrees off
the config's zero: gaitbot.app.emulator_hand.mounting_zero_ticks): exit 0 when every step did what it should
and the calibration found the build's zero ticks and the config's directions, 1 otherwise.
"""

from __future__ import annotations

import argparse
import os
import signal
import subprocess
import sys
import threading
from pathlib import Path

CHECKOUT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(CHECKOUT))  # run from a source checkout too

from gaitbot.app.emulator_hand import mounting_zero_ticks  # noqa: E402
from gaitbot.robot.calibration_file import calibration_path_for, read_calibration  # noqa: E402
from gaitbot.robot.config import load_robot_config, resolve_config  # noqa: E402

STEP_TIMEOUT_S = 300.0
#: The commands run this checkout's gaitbot, as this script does.
ENV = {**os.environ, "PYTHONPATH": os.pathsep.join(p for p in (str(CHECKOUT), os.environ.get("PYTHONPATH")) if p)}
SEARCH_TIMEOUT = ["--reply-timeout-ms", "5"]  # setup: one servo on the line; the emulator answers within a ms or two
#: scan: six servos answer a broadcast ping in turn, and a busy host can hold the emulator's next reply back
#: longer than 5 ms, which would end the listening early (docs/bring-up.md): a 50 ms quiet window.
SCAN_TIMEOUT = ["--reply-timeout-ms", "50"]
#: A busy host delays the emulator's replies for reasons no servo has (docs/bring-up.md): the walk and
#: the calibration wait longer for each status packet.
BUSY_HOST_TIMEOUT = ["--reply-timeout-ms", "250"]


class Emulator:
    """tools/servo_emulator.py in the background: its pty path, Enter on its standard input, Ctrl-C."""

    def __init__(self, folder: Path, *args: str) -> None:
        print(f"$ python tools/servo_emulator.py {' '.join(args)}    # in another terminal", flush=True)
        self.proc = subprocess.Popen([sys.executable, "-m", "gaitbot.app.emulator", *args], cwd=folder,
                                     stdin=subprocess.PIPE, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                                     env=ENV)
        self.path = self.proc.stdout.readline().strip()
        if not self.path:
            raise RuntimeError(f"the emulator did not start: {self.proc.stderr.read().strip()}")
        self.said(lambda line: "Ctrl-C to stop" in line)
        if "--one-at-a-time" in args:
            self.said(lambda line: "connected" in line)  # the first servo

    def said(self, until) -> str:
        """Its messages (stderr), echoed, up to the first for which ``until(line)`` holds."""
        for line in self.proc.stderr:
            print(f"  [emulator] {line.rstrip()}", flush=True)
            if until(line):
                return line
        raise RuntimeError("the emulator stopped")

    def enter(self) -> str:
        """Enter in the emulator's terminal: the next servo plugged in (or, after the last, all of them)."""
        self.proc.stdin.write("\n")
        self.proc.stdin.flush()
        return self.said(lambda line: "connected" in line)

    def stop(self) -> None:
        self.proc.send_signal(signal.SIGINT)
        try:
            self.proc.wait(timeout=10)
        except subprocess.TimeoutExpired:
            self.proc.kill()
            self.proc.wait()


def gaitbot(folder: Path, argv: list[str], answer=lambda line: None) -> tuple[int, str]:
    """Run a gaitbot command as typed; ``answer(line)`` is what the person types after each line it prints."""
    print(f"$ gaitbot {' '.join(argv)}", flush=True)
    proc = subprocess.Popen([sys.executable, "-m", "gaitbot", *argv], cwd=folder, stdin=subprocess.PIPE,
                            stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, env=ENV)
    watchdog = threading.Timer(STEP_TIMEOUT_S, proc.kill)
    watchdog.start()
    out = []
    try:
        for line in proc.stdout:
            out.append(line)
            print(f"  {line.rstrip()}", flush=True)
            reply = answer(line)
            if reply is not None:
                proc.stdin.write(reply)
                proc.stdin.flush()
        proc.stdin.close()
        proc.wait()
    finally:
        watchdog.cancel()
    return proc.returncode, "".join(out)


def set_up(folder: Path, robot: str, emulator: Emulator) -> int:
    """gaitbot setup, the person plugging in each servo when asked (Enter in the emulator's terminal)."""
    asked = {"n": 0}

    def answer(line: str):
        if not line.startswith("Connect only the servo for"):
            return None
        if asked["n"]:
            emulator.enter()  # unplug the servo just set up, plug in the next
        asked["n"] += 1
        return "\n"

    code, _ = gaitbot(folder, ["setup", "--robot", robot, "--port", emulator.path, *SEARCH_TIMEOUT], answer)
    return code


def journey(robot: str, folder: Path, seed: int = 0) -> list[str]:
    """Run every step; the problems found (none: the robot was brought up and walked)."""
    folder.mkdir(parents=True, exist_ok=True)
    config = load_robot_config(resolve_config(robot))
    state = "chain.json"
    problems = []
    emulator = Emulator(folder, "--robot", robot, "--factory-fresh", "--one-at-a-time", "--state", state)
    try:
        if set_up(folder, robot, emulator) != 0:
            return ["gaitbot setup did not set up every servo"]
        emulator.enter()  # once more after the last: the whole chain
        code, _ = gaitbot(folder, ["scan", "--robot", robot, "--port", emulator.path, *SCAN_TIMEOUT])
        if code != 0:
            problems.append("gaitbot scan did not find every servo of the config at its id and rate")
    finally:
        emulator.stop()
    emulator = Emulator(folder, "--robot", robot, "--state", state, "--hand-calibrate", "--seed", str(seed))
    try:
        code, _ = gaitbot(folder, ["calibrate", "--robot", robot, "--port", emulator.path, "--yes",
                                   *BUSY_HOST_TIMEOUT], lambda line: "\n" if line.rstrip().endswith("Press Enter.")
                          else None)
        if code != 0:
            return problems + ["gaitbot calibrate failed"]
        code, out = gaitbot(folder, ["walk", "--robot", robot, "--steps", "0.03,0.03", "--port", emulator.path,
                                     *BUSY_HOST_TIMEOUT])
        if code != 0 or "calibration" not in out:
            problems.append("gaitbot walk did not walk with the calibration")
    finally:
        emulator.stop()
    return problems + compare_with_build(config, folder / calibration_path_for(config.path), seed)


def compare_with_build(config, path: Path, seed: int) -> list[str]:
    """The calibration against the emulated build: its zero ticks, and the config's directions."""
    calibration = {j.id: j for j in read_calibration(path).joints}
    build = mounting_zero_ticks(config, seed)
    problems = [f"{j.name}: zero tick {calibration[j.id].zero_tick}, the build's is {build[j.id]}"
                for j in config.joints if calibration[j.id].zero_tick != build[j.id]]
    problems += [f"{j.name}: direction {calibration[j.id].direction:+d}, the config's is {j.direction:+d}"
                 for j in config.joints if calibration[j.id].direction != j.direction]
    offsets = [build[j.id] - j.zero_tick for j in config.joints]
    print(f"{path}: zero ticks {min(offsets):+d}..{max(offsets):+d} ticks off the config's, as the emulated robot "
          f"was built; directions as the config's" if not problems else f"{path}: does not match the build")
    return problems


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--robot", default="xl430-biped", help="robot config (path or shipped name)")
    parser.add_argument("--folder", default="bringup-journey", help="where the commands run and write their files")
    parser.add_argument("--seed", type=int, default=0, help="how the emulated robot was built (its horns' offsets)")
    args = parser.parse_args(argv)
    problems = journey(args.robot if not Path(args.robot).is_file() else str(Path(args.robot).resolve()),
                       Path(args.folder), args.seed)
    for problem in problems:
        print(f"problem: {problem}", file=sys.stderr)
    print("brought up and walked" if not problems else f"{len(problems)} problems")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
