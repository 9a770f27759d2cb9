"""A timed commands file played on the drive's clock: how tests and scripted demos drive the robot."""

from __future__ import annotations

import bisect
from pathlib import Path

from gaitbot.gait.steer.command import STILL, TimedCommand, read_commands
from gaitbot.inputs.source import Reading


class ScriptedSource:
    """Each entry holds from its time until the next; a ``stop`` entry ends the drive. Without a stop entry the
    last command holds until Ctrl-C."""

    name = "commands"

    def __init__(self, commands: list[TimedCommand]) -> None:
        self.commands = commands
        self._times = [c.t_s for c in commands]

    @classmethod
    def from_file(cls, path: str | Path) -> "ScriptedSource":
        return cls(read_commands(path))

    def poll(self, now_s: float) -> Reading:
        k = bisect.bisect_right(self._times, now_s) - 1
        if k < 0:
            return Reading(STILL)
        entry = self.commands[k]
        if entry.stop:
            return Reading(STILL, end=True)
        return Reading(entry.command)

    def close(self) -> None:
        pass
