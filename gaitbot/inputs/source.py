"""What every command source gives the drive loop each frame, the watchdog, and ``--input`` parsing."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Protocol

from gaitbot.errors import UserError
from gaitbot.gait.steer.command import STILL, VelocityCommand

WATCHDOG_S = 0.5  # a network or gamepad source silent this long stops the walk (to standing)


class InputError(UserError, ValueError):
    """An ``--input`` that cannot be opened (a bad spec, a port in use, no gamepad)."""


@dataclass
class Reading:
    """A source's state after a poll: the command in force (the last one holds), whether the user asked to end
    the drive, and any messages for the user (each said once by the source)."""

    command: VelocityCommand = STILL
    end: bool = False
    messages: list[str] = field(default_factory=list)


class CommandSource(Protocol):
    """Polled once a frame; never blocks."""

    name: str

    def poll(self, now_s: float) -> Reading:
        """The state at ``now_s`` (seconds on the drive's clock, from its start)."""

    def close(self) -> None:
        """Give back what the source holds (terminal mode, socket, device)."""


class Watchdog:
    """Silence detector: ``expired`` once ``limit_s`` has passed since the last ``feed``.

    Why: a network sender or a wireless gamepad can vanish mid-walk; the walk must then come to standing
    rather than keep obeying the last command for ever."""

    def __init__(self, limit_s: float = WATCHDOG_S) -> None:
        self.limit_s = limit_s
        self.last_fed_s: float | None = None
        self._said = False

    def feed(self, now_s: float) -> None:
        self.last_fed_s = now_s
        self._said = False

    def expired(self, now_s: float) -> bool:
        return self.last_fed_s is not None and now_s - self.last_fed_s > self.limit_s

    def stand_if_silent(self, command: VelocityCommand, now_s: float, reading: Reading, silence: str) -> VelocityCommand:
        """The command in force: STILL once a moving command has gone unfed past the limit, said once a silence
        (``silence``: what fell silent, e.g. "udp: no command")."""
        if command.is_still or not self.expired(now_s):
            return command
        if not self._said:
            reading.messages.append(f"{silence} for {self.limit_s:g} s: standing")
            self._said = True
        return STILL
