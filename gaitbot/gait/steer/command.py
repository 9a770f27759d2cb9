"""A velocity command (vx, vy in m/s, wz in deg/s, in the robot's frame) and its timed form.

One format for every source of commands: ``--velocity VX,VY,WZ``, a ``--commands`` JSON Lines file
(``{"t": 0.0, "vx": 0.1, "vy": 0.0, "wz": 0.0}``, or ``{"t": 8.0, "stop": true}``), and what
``gaitbot drive`` records of its live input. Reading is bounded (file size, line count, magnitudes)
whatever the file asks for, and every refusal names the file, the line and the field.
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass
from pathlib import Path
from typing import IO, Iterable

from gaitbot.errors import UserError

MAX_COMMANDS_FILE_BYTES = 4 * 1024 * 1024  # about 60,000 lines: hours of commands at 20 Hz
MAX_COMMAND_TIME_S = 24 * 3600.0
# Far beyond any small robot (the drive clips to the robot's [steer] limits); only absurd input is refused.
MAX_SPEED_M_S = 10.0
MAX_TURN_DEG_S = 3600.0


class CommandError(UserError, ValueError):
    """A command (argument, file line or datagram) that is not a finite, bounded velocity."""


@dataclass(frozen=True)
class VelocityCommand:
    """Walk at vx (forward), vy (left) in m/s and turn at wz (counter-clockwise seen from above) in deg/s."""

    vx_m_s: float = 0.0
    vy_m_s: float = 0.0
    wz_deg_s: float = 0.0

    @property
    def is_still(self) -> bool:
        """True when the command asks for no motion at all (the walk may stop stepping)."""
        return self.vx_m_s == 0.0 and self.vy_m_s == 0.0 and self.wz_deg_s == 0.0


STILL = VelocityCommand()


@dataclass(frozen=True)
class TimedCommand:
    """A command that holds from ``t_s`` (seconds from the start) until the next one; ``stop`` ends the walk
    (the feet brought side by side, weight between them)."""

    t_s: float
    command: VelocityCommand = STILL
    stop: bool = False

    def to_json(self) -> str:
        """The JSON Lines form (one line, no newline)."""
        if self.stop:
            return json.dumps({"t": self.t_s, "stop": True})
        c = self.command
        return json.dumps({"t": self.t_s, "vx": c.vx_m_s, "vy": c.vy_m_s, "wz": c.wz_deg_s})


def _bounded(value: object, name: str, limit: float, where: str) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise CommandError(f"{where}: {name} must be a number, got {value!r}")
    number = float(value)
    if not math.isfinite(number) or abs(number) > limit:
        raise CommandError(f"{where}: {name} must be finite and within +-{limit:g}, got {value!r}")
    return number


def velocity_from_mapping(fields: dict, where: str) -> VelocityCommand:
    """vx, vy (m/s) and wz (deg/s) from a JSON object; a missing field is 0."""
    return VelocityCommand(
        vx_m_s=_bounded(fields.get("vx", 0.0), "vx (m/s)", MAX_SPEED_M_S, where),
        vy_m_s=_bounded(fields.get("vy", 0.0), "vy (m/s)", MAX_SPEED_M_S, where),
        wz_deg_s=_bounded(fields.get("wz", 0.0), "wz (deg/s)", MAX_TURN_DEG_S, where),
    )


def parse_velocity(text: str, where: str = "--velocity") -> VelocityCommand:
    """``VX,VY,WZ`` (m/s, m/s, deg/s), as ``--velocity`` takes it."""
    parts = text.split(",")
    if len(parts) != 3:
        raise CommandError(f"{where}: expected VX,VY,WZ (m/s, m/s, deg/s), got {text!r}")
    try:
        values = [float(p) for p in parts]
    except ValueError:
        raise CommandError(f"{where}: expected three numbers VX,VY,WZ (m/s, m/s, deg/s), got {text!r}") from None
    return velocity_from_mapping(dict(zip(("vx", "vy", "wz"), values)), where)


_KNOWN_KEYS = frozenset({"t", "vx", "vy", "wz", "stop"})


def parse_command_line(line: str, where: str) -> TimedCommand:
    """One JSON Lines entry: ``{"t": S, "vx": .., "vy": .., "wz": ..}`` or ``{"t": S, "stop": true}``."""
    try:
        fields = json.loads(line)
    except (json.JSONDecodeError, RecursionError):
        raise CommandError(f"{where}: not a JSON object") from None
    if not isinstance(fields, dict):
        raise CommandError(f"{where}: expected a JSON object like {{\"t\": 0.0, \"vx\": 0.1}}")
    unknown = sorted(set(fields) - _KNOWN_KEYS)
    if unknown:
        raise CommandError(f"{where}: unknown field {unknown[0]!r} (allowed: t, vx, vy, wz, stop)")
    if "t" not in fields:
        raise CommandError(f"{where}: missing field 't' (seconds from the start)")
    t_s = _bounded(fields["t"], "t (s)", MAX_COMMAND_TIME_S, where)
    if t_s < 0:
        raise CommandError(f"{where}: t (s) must be >= 0, got {fields['t']!r}")
    stop = fields.get("stop", False)
    if not isinstance(stop, bool):
        raise CommandError(f"{where}: stop must be true or false, got {stop!r}")
    if stop:
        if any(k in fields for k in ("vx", "vy", "wz")):
            raise CommandError(f"{where}: a stop entry carries no vx, vy or wz")
        return TimedCommand(t_s=t_s, stop=True)
    return TimedCommand(t_s=t_s, command=velocity_from_mapping(fields, where))


def parse_commands(lines: Iterable[str], source: str) -> list[TimedCommand]:
    """Timed commands from JSON Lines (blank lines and lines starting with '#' skipped); times must not go back."""
    commands: list[TimedCommand] = []
    for number, line in enumerate(lines, start=1):
        text = line.strip()
        if not text or text.startswith("#"):
            continue
        timed = parse_command_line(text, f"{source} line {number}")
        if commands and timed.t_s < commands[-1].t_s:
            raise CommandError(f"{source} line {number}: t {timed.t_s:g} s is before the previous "
                               f"entry's {commands[-1].t_s:g} s (times must not go back)")
        if commands and commands[-1].stop:
            raise CommandError(f"{source} line {number}: an entry after the stop entry (the stop ends the walk)")
        commands.append(timed)
    if not commands:
        raise CommandError(f"{source}: no commands (expected JSON Lines like {{\"t\": 0.0, \"vx\": 0.1}})")
    return commands


def read_commands(path: str | Path) -> list[TimedCommand]:
    """A ``--commands`` file: a regular file of at most MAX_COMMANDS_FILE_BYTES, UTF-8 JSON Lines."""
    path = Path(path)
    try:
        if not path.is_file():
            raise CommandError(f"{path}: not a regular file (a JSON Lines file of timed commands)")
        if path.stat().st_size > MAX_COMMANDS_FILE_BYTES:
            raise CommandError(f"{path}: larger than {MAX_COMMANDS_FILE_BYTES // (1024 * 1024)} MB")
        text = path.read_text(encoding="utf-8")
    except UnicodeDecodeError:
        raise CommandError(f"{path}: not UTF-8 text (a JSON Lines file of timed commands)") from None
    except OSError as exc:
        raise CommandError(f"{path}: cannot read: {exc.strerror or exc}") from None
    return parse_commands(text.splitlines(), str(path))


def write_commands(stream: IO[str], commands: Iterable[TimedCommand]) -> None:
    """The JSON Lines form that read_commands reads back."""
    for timed in commands:
        stream.write(timed.to_json() + "\n")
