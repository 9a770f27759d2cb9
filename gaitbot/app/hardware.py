"""Opening the hardware from the command line: the serial port (it must exist) and its adapter's latency.

The bus itself, behind its LimitGuard, comes from gaitbot.bus.factory.make_robot_bus (written once,
used by walk, record and scan).
"""

from __future__ import annotations

import os
import sys
from pathlib import Path

from gaitbot.app.options import UsageError
from gaitbot.bus.serial_latency import latency_timer_warning
from gaitbot.robot.config import RobotConfig


def require_port(port: str) -> None:
    """A real run needs a serial device that exists and is a terminal (a USB adapter, a pty): say which one is
    missing, or what it is instead (/dev/null, a regular file, a folder), and how to list them, before anything
    else is done."""
    hint = "list them with: python -m serial.tools.list_ports -v; or try --dry-run"
    if not port or not port.strip():
        raise UsageError(f"--port: empty name ({hint})")
    if not Path(port).exists():
        raise UsageError(f"--port {port}: no such serial port ({hint})")
    if os.name != "posix":
        return
    if Path(port).is_dir():
        raise UsageError(f"--port {port}: is a directory, not a serial port ({hint})")
    try:
        fd = os.open(port, os.O_RDWR | os.O_NOCTTY | os.O_NONBLOCK)
    except OSError as exc:
        raise UsageError(f"--port {port}: cannot open ({exc.strerror or exc}; {hint})") from None
    try:
        is_terminal = os.isatty(fd)
    finally:
        os.close(fd)
    if not is_terminal:
        raise UsageError(f"--port {port}: not a serial port (not a terminal device) ({hint})")


def refuse_port_in_dry_run(args) -> None:
    """``--dry-run`` talks to the mock bus: a ``--port`` beside it would be silently ignored, so it is refused."""
    if getattr(args, "dry_run", False) and getattr(args, "port", None):
        raise UsageError(f"--port {args.port}: a dry run uses the mock bus, not a serial port; leave out --port "
                         f"or --dry-run")


def serial_port(config: RobotConfig, port: str | None, dry_run: bool) -> str:
    """``--port``, else the config's; outside a dry run it must exist."""
    port = port or config.bus.port
    if not dry_run and config.draft is not None:
        raise UsageError(f"{config.path}: robot.draft: a draft config ({config.draft}); the hardware needs a "
                         f"checked one (docs/robot-description.md)")
    if not dry_run:
        require_port(port)
    return port


def warn_about_latency(port: str) -> None:
    """One warning line on stderr when the port's USB adapter holds replies back (see serial_latency)."""
    warning = latency_timer_warning(port)
    if warning:
        print(f"warning: {warning}", file=sys.stderr)
