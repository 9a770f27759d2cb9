"""The terminal's keyboard: arrow keys or WASD for forward and turn, Q/E sideways, +/- speed, space to stand.

Each of forward (W, up), backward (S, down), turn left (A, left), turn right (D, right), sideways left (Q)
and right (E) sets its axis to the current speed level; the opposite key sets that axis back to zero, so W
then A walks an arc and S then stops going forward. +/- change the speed level in tenths of the robot's
limits (10% to 100%, starting at 50%); space stands still. Ctrl-C keeps its usual meaning (stop and exit):
the terminal is put in cbreak mode, which keeps signals. The keys are read without blocking (select with a
zero timeout) and the terminal's mode is restored on close.
"""

from __future__ import annotations

import os
import select
import sys
from dataclasses import replace

from gaitbot.gait.steer.command import STILL, VelocityCommand
from gaitbot.inputs.source import InputError, Reading

# key -> (axis, sign): axis is a VelocityCommand field
_KEYS = {
    "w": ("vx_m_s", 1), "UP": ("vx_m_s", 1), "s": ("vx_m_s", -1), "DOWN": ("vx_m_s", -1),
    "a": ("wz_deg_s", 1), "LEFT": ("wz_deg_s", 1), "d": ("wz_deg_s", -1), "RIGHT": ("wz_deg_s", -1),
    "q": ("vy_m_s", 1), "e": ("vy_m_s", -1),
}
_ARROWS = {b"A": "UP", b"B": "DOWN", b"C": "RIGHT", b"D": "LEFT"}
MAX_READ_BYTES = 256  # per poll: a held key repeats at about 30 Hz, far below this


def split_keys(buffer: bytes) -> tuple[list[str], bytes]:
    """Keys from terminal bytes (arrows are ESC [ A..D), and the unfinished tail of an escape sequence."""
    keys: list[str] = []
    k = 0
    while k < len(buffer):
        byte = buffer[k:k + 1]
        if byte == b"\x1b":
            if len(buffer) - k < 3:
                return keys, buffer[k:]
            if buffer[k + 1:k + 2] in (b"[", b"O") and buffer[k + 2:k + 3] in _ARROWS:
                keys.append(_ARROWS[buffer[k + 2:k + 3]])
            k += 3
            continue
        keys.append(byte.decode("latin-1").lower())
        k += 1
    return keys, b""


class KeyboardSource:
    """Keys from a file descriptor (the terminal, or a pty in tests) turned into a held velocity command."""

    name = "keyboard"

    def __init__(self, fd: int, max_command: VelocityCommand, min_command: VelocityCommand,
                 restore=None) -> None:
        self.fd = fd
        self.max_command = max_command
        self.min_command = min_command
        self.level = 0.5
        self.signs = {"vx_m_s": 0, "vy_m_s": 0, "wz_deg_s": 0}
        self._pending = b""
        self._restore = restore

    @classmethod
    def on_terminal(cls, max_command: VelocityCommand, min_command: VelocityCommand) -> "KeyboardSource":
        """The controlling terminal's standard input in cbreak mode (restored by close)."""
        import termios
        import tty
        fd = sys.stdin.fileno() if sys.stdin is not None else -1
        if fd < 0 or not os.isatty(fd):
            raise InputError("--input keyboard: standard input is not a terminal (use udp:PORT or commands:FILE)")
        saved = termios.tcgetattr(fd)
        tty.setcbreak(fd)
        return cls(fd, max_command, min_command, restore=lambda: termios.tcsetattr(fd, termios.TCSADRAIN, saved))

    def press(self, key: str) -> None:
        """One key's effect on the held command."""
        if key in _KEYS:
            axis, sign = _KEYS[key]
            self.signs[axis] = 0 if self.signs[axis] == -sign else sign
        elif key == " ":
            self.signs = dict.fromkeys(self.signs, 0)
        elif key in ("+", "="):
            self.level = min(1.0, round(self.level + 0.1, 1))
        elif key in ("-", "_"):
            self.level = max(0.1, round(self.level - 0.1, 1))

    def command(self) -> VelocityCommand:
        """The held command: each axis at the speed level of its limit in the direction pressed."""
        values = {}
        for axis, sign in self.signs.items():
            limit = getattr(self.max_command if sign > 0 else self.min_command, axis)
            values[axis] = self.level * limit if sign else 0.0
        return replace(STILL, **values)

    def poll(self, now_s: float) -> Reading:
        while select.select([self.fd], [], [], 0)[0]:
            data = os.read(self.fd, MAX_READ_BYTES)
            if not data:
                break
            keys, self._pending = split_keys(self._pending + data)
            for key in keys:
                self.press(key)
            if len(data) < MAX_READ_BYTES:
                break
        return Reading(self.command())

    def close(self) -> None:
        if self._restore is not None:
            self._restore()
            self._restore = None
