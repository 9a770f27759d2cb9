"""The USB-serial adapter's latency timer, read from Linux sysfs: a slow one delays every servo reply."""

from __future__ import annotations

import os


def latency_timer_warning(port_name: str, sysfs_root: str = "/sys") -> str | None:
    """A one-line warning if the USB-serial adapter of ``port_name`` buffers reads for over 1 ms.

    FTDI adapters (``/dev/ttyUSB*``) hold received bytes for their latency timer, 16 ms by
    default. Every servo reply then arrives up to 16 ms late, which is a whole frame at 60 Hz.
    Returns None when the timer is 1 ms or less, or when it cannot be read (not Linux, not a
    usb-serial device, no such port). Symlinks such as ``/dev/serial/by-id/...`` are resolved.
    ``sysfs_root`` is for tests.
    """
    device = os.path.basename(os.path.realpath(port_name))
    path = os.path.join(sysfs_root, "bus", "usb-serial", "devices", device, "latency_timer")
    try:
        with open(path, encoding="ascii") as f:
            latency_ms = int(f.read().strip())
    except (OSError, ValueError):
        return None
    if latency_ms <= 1:
        return None
    return (f"{port_name}: USB latency timer is {latency_ms} ms, so every servo read waits up to "
            f"{latency_ms} ms (about {latency_ms / (1000 / 60):.1f} frames at 60 Hz); lower it with "
            f"`echo 1 | sudo tee {path}` or permanently with a udev rule such as "
            '`ACTION=="add", SUBSYSTEM=="usb-serial", DRIVER=="ftdi_sio", ATTR{latency_timer}="1"`')
