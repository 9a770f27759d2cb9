"""``--input``: a command source by name (one entry per kind of source)."""

from __future__ import annotations

from gaitbot.gait.steer.command import VelocityCommand
from gaitbot.inputs.source import CommandSource, InputError


def open_source(spec: str, max_command: VelocityCommand, min_command: VelocityCommand) -> CommandSource:
    """``--input``: ``keyboard``, ``gamepad[:DEVICE]``, ``udp:[HOST:]PORT`` or ``commands:FILE``.

    max_command and min_command are the robot's most forward/left/counter-clockwise and most
    backward/right/clockwise command (the keyboard and the gamepad scale to them)."""
    kind, _, rest = spec.partition(":")
    if kind == "keyboard" and not rest:
        from gaitbot.inputs.keyboard import KeyboardSource
        return KeyboardSource.on_terminal(max_command, min_command)
    if kind == "gamepad":
        from gaitbot.inputs.gamepad import GamepadSource
        return GamepadSource.open(rest or None, max_command, min_command)
    if kind == "udp" and rest:
        from gaitbot.inputs.udp import UdpSource
        return UdpSource.bind(rest)
    if kind == "commands" and rest:
        from gaitbot.inputs.scripted import ScriptedSource
        return ScriptedSource.from_file(rest)
    raise InputError(f"--input: expected keyboard, gamepad[:DEVICE], udp:[HOST:]PORT or commands:FILE, got {spec!r}")
