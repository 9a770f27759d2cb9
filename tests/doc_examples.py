"""The commands the docs show, read from the pages and run as a user would (tests/docs/test_examples.py).

Rules (also in docs/command-line.md, for whoever writes a page):

- Commands live in fenced blocks marked ``sh``, one command a line, in the order a reader types them;
  each page runs in its own temporary folder holding links to the checkout's ``config``, ``tools`` and
  ``pyproject.toml`` (the commands name them as a user in the checkout would), with the test's Python first
  on PATH. Other fenced blocks are marked ``text``, ``toml`` or ``json`` and are not run.
- A command exits 0 unless its comment says ``exit N``. A comment that says ``Ctrl-C`` means the command
  runs until interrupted: it gets SIGINT after INTERRUPT_AFTER_S. Nothing it prints may be a traceback.
- A command that needs hardware (``gaitbot walk``, ``record`` or ``scan`` without ``--dry-run`` or ``--sim``)
  runs against the servo emulator (gaitbot.emulator) of its robot on a pty, given as ``--port``: the
  emulator answers as the servos do, through the same vendor SDKs. Such a command also gets
  ``--reply-timeout-ms 250`` unless it names one: the emulator shares a busy CI host with the suite, and a
  reply held up by the host is not what the text is about (faults are tests/app/test_emulator_e2e.py's).
  Questions are answered ``y``.
- ``<!-- setup: COMMAND -->`` before a block runs COMMAND first, unseen: files the text assumes exist.
- Installing (``python3 -m venv``, ``. .venv/bin/activate``, ``pip install``) is what the test environment
  already is (.ci/run makes it exactly so), and ``pytest`` is this suite: those parts of a line are not run
  again; the rest of the line is.
"""

from __future__ import annotations

import os
import re
import signal
import subprocess
import sys
import time
from contextlib import nullcontext
from dataclasses import dataclass
from pathlib import Path

from helpers import REPO_ROOT, emulator_for

INTERRUPT_AFTER_S = 3.0
COMMAND_TIMEOUT_S = 180.0
LINKED = ("config", "tools", "pyproject.toml")
FENCE = re.compile(r"^```(\w*)(.*)$")
SETUP = re.compile(r"<!--\s*setup:(.*?)-->", re.S)
INSTALL = re.compile(r"^(python3? -m venv\b|\. \S*activate$|source \S*activate$|pip install\b)")
HARDWARE = re.compile(r"^gaitbot (walk|record|scan)\b")
LANGUAGES = {"sh", "text", "toml", "json"}


@dataclass(frozen=True)
class Command:
    """One line of a ``sh`` block (or a setup comment): what runs, and what the text says of it."""

    page: str
    line: int
    text: str
    comment: str = ""
    setup: bool = False

    @property
    def expected_exit(self) -> int:
        found = re.search(r"\bexit (\d+)\b", self.comment)
        return int(found.group(1)) if found else 0

    @property
    def interrupted(self) -> bool:
        return "Ctrl-C" in self.comment

    def runnable(self) -> str:
        """The line without the installation steps and the test suite (see the module docstring)."""
        parts = [p.strip() for p in self.text.split("&&")]
        kept = [p for p in parts if not INSTALL.match(p) and not re.match(r"^pytest\b", p)]
        return " && ".join(kept)

    def __str__(self) -> str:
        return f"{self.page}:{self.line}: {self.text}"


def split_comment(line: str) -> tuple[str, str]:
    """``cmd  # comment`` -> (cmd, comment); a ``#`` inside quotes is not a comment."""
    in_single = in_double = False
    for i, ch in enumerate(line):
        if ch == "'" and not in_double:
            in_single = not in_single
        elif ch == '"' and not in_single:
            in_double = not in_double
        elif ch == "#" and not in_single and not in_double and (i == 0 or line[i - 1].isspace()):
            return line[:i].rstrip(), line[i + 1:].strip()
    return line.rstrip(), ""


def fenced_blocks(path: Path) -> list[tuple[int, str, list[str]]]:
    """(first line number, language, lines) of every fenced block of a page."""
    blocks, current = [], None
    for number, line in enumerate(path.read_text().splitlines(), start=1):
        match = FENCE.match(line)
        if current is None and match:
            current = (number + 1, match.group(1), [])
        elif current is not None and line.startswith("```"):
            blocks.append(current)
            current = None
        elif current is not None:
            current[2].append(line)
    assert current is None, f"{path.name}: a fenced block is not closed"
    return blocks


def page_commands(path: Path) -> list[Command]:
    """Every command of a page in reading order, setup comments included."""
    text = path.read_text()
    events = []
    for match in SETUP.finditer(text):
        line = text.count("\n", 0, match.start()) + 1
        for k, command in enumerate(c.strip() for c in match.group(1).strip().splitlines()):
            events.append((line, k, Command(path.name, line, command, setup=True)))
    for first, language, lines in fenced_blocks(path):
        if language != "sh":
            continue
        for offset, line in enumerate(lines):
            command, comment = split_comment(line)
            if command:
                events.append((first + offset, 0, Command(path.name, first + offset, command, comment)))
    return [command for *_, command in sorted(events, key=lambda e: (e[0], e[1]))]


def prepare_folder(folder: Path) -> None:
    for name in LINKED:
        (folder / name).symlink_to(REPO_ROOT / name)


def environment() -> dict:
    env = dict(os.environ)
    env["PATH"] = f"{Path(sys.executable).parent}{os.pathsep}{env.get('PATH', '')}"
    env["MPLBACKEND"] = "Agg"
    env.pop("PYTHONPATH", None)
    return env


def hardware_robot(command: str) -> str | None:
    """The robot whose servos a command needs (``--robot``'s value, or the default), or None for none."""
    if not HARDWARE.match(command) or re.search(r"--(dry-run|sim)\b", command):
        return None
    found = re.search(r"--robot[= ](\S+)", command)
    return found.group(1) if found else "xl430-biped"


def with_port(command: str, port: str) -> str:
    if re.search(r"--port[= ]\S+", command):
        command = re.sub(r"--port[= ]\S+", f"--port {port}", command)
    else:
        command = f"{command} --port {port}"
    if "--reply-timeout-ms" not in command:
        command += " --reply-timeout-ms 250"
    return command


@dataclass(frozen=True)
class Outcome:
    command: Command
    ran: str
    status: int
    stdout: str
    stderr: str

    def problem(self) -> str | None:
        """Why this outcome is not what the text says, or None."""
        if "Traceback (most recent call last)" in self.stdout + self.stderr:
            return "printed a traceback"
        if self.status != self.command.expected_exit:
            return f"exit {self.status}, the text says {self.command.expected_exit}"
        return None

    def describe(self) -> str:
        return (f"{self.command}\n  ran: {self.ran}\n  {self.problem()}\n--- stdout\n{self.stdout[-3000:]}\n"
                f"--- stderr\n{self.stderr[-3000:]}")


def run_command(command: Command, folder: Path, log: Path) -> Outcome | None:
    """Run one command in ``folder`` as the module docstring says; None when nothing of it is left to run."""
    ran = command.runnable()
    if not ran:
        return None
    robot = hardware_robot(ran)
    if robot is not None:
        from gaitbot.robot.config import resolve_config

        emulator = emulator_for(resolve_config(robot) if not robot.endswith(".toml") else folder / robot, log)
    else:
        emulator = nullcontext()
    with emulator as chain:
        if chain is not None:
            ran = with_port(ran, chain.path)
        proc = subprocess.Popen(["bash", "-c", ran], cwd=folder, env=environment(), stdin=subprocess.PIPE,
                                stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, start_new_session=True)
        if command.interrupted:
            time.sleep(INTERRUPT_AFTER_S)
            os.killpg(proc.pid, signal.SIGINT)
        try:
            out, err = proc.communicate("y\n", timeout=COMMAND_TIMEOUT_S)
        except subprocess.TimeoutExpired:
            os.killpg(proc.pid, signal.SIGKILL)
            out, err = proc.communicate()
            err += f"\n(killed after {COMMAND_TIMEOUT_S:g} s)"
    return Outcome(command, ran, proc.returncode, out, err)
