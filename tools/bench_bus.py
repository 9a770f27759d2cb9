"""Highest frame rate the real bus backends sustain through a pty, beside the wire limits.

For each protocol, 6 and 12 servos: the real DynamixelBus / FeetechBus (vendor SDK PortHandler on
the emulator's pty, gaitbot.emulator on a thread, factory Return Delay Time) sends frames
back to back for ``--seconds``: goal sync writes only, then a sync write plus a read of every
servo (sync read where the protocol has one). Beside it, the wire limit from the packet sizes
(gaitbot.servos.budget.frame_budget: 10 bits a byte, plus one return delay per status packet) at
1 Mbaud and at 57,600 baud, without the 30 % margin the config check keeps.

    python tools/bench_bus.py              # about 20 s
    python tools/bench_bus.py --seconds 0.5
    python tools/bench_bus.py --markdown    # the wire limits of docs/benchmarks.md (tools/figures.py)

The pty does not pace bytes at the baud rate, so the measured rate is what the host (Python, the
SDK's polling receive loop, the emulator) sustains; the real bus is bounded by the wire column.
"""

from __future__ import annotations

import argparse
import os
import platform
import sys
import time

try:
    from gaitbot.servos.budget import frame_budget
except ImportError:  # run from a checkout without installing
    sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), os.pardir))
    from gaitbot.servos.budget import frame_budget

from gaitbot.app.emulator import PROTOCOLS
import gaitbot.emulator as se
from gaitbot.bus.factory import make_bus
from gaitbot.servos.models import servo_model


def measure(protocol: str, n_servos: int, read_back: bool, seconds: float) -> float:
    """Frames per second through the emulator's pty."""
    backend, version, name = PROTOCOLS[protocol]
    model = servo_model(name)
    models = {i: model for i in range(1, n_servos + 1)}
    with se.ServoEmulator(se.EmulatorConfig(backend, version, models)) as emulator:
        # throughput, not latency, is measured: the emulator's thread shares the GIL with the bus, so a busy
        # host can hold a reply past the SDK's 34 ms timeout; a generous timeout keeps that from ending the run
        bus = make_bus(backend, version, emulator.path, 1_000_000, models, interface="serial", reply_timeout_ms=500)
        with bus:
            ids = list(models)
            frames, start = 0, time.perf_counter()
            while time.perf_counter() - start < seconds:
                offset = (frames % 50) - 25
                bus.write_goal_ticks({i: model.centre_tick + offset for i in ids})
                if read_back:
                    bus.read_present_ticks(ids)
                frames += 1
            elapsed = time.perf_counter() - start
    return frames / elapsed


def wire_limit_hz(protocol: str, n_servos: int, baudrate: int, read_back: bool) -> float:
    backend, version, name = PROTOCOLS[protocol]
    return 1.0 / frame_budget(backend, version, name, n_servos, baudrate, read_back).wire_time_s


def wire_markdown() -> str:
    """The wire limits of each protocol (computed from packet sizes: no timing), as docs/benchmarks.md's table."""
    names = {"dxl2": "Dynamixel 2.0", "dxl1": "Dynamixel 1.0", "feetech-sts": "Feetech STS", "feetech-scs": "Feetech SCS"}
    lines = ["| protocol | servos | wire Hz at 1 Mbaud (w / w+r) | wire Hz at 57,600 (w / w+r) |", "|---|---|---|---|"]
    for protocol, name in names.items():
        for n in (6, 12):
            fast = [wire_limit_hz(protocol, n, 1_000_000, r) for r in (False, True)]
            slow = [wire_limit_hz(protocol, n, 57_600, r) for r in (False, True)]
            lines.append(f"| {name} | {n} | {fast[0]:.0f} / {fast[1]:.0f} | {slow[0]:.1f} / {slow[1]:.1f} |")
    return "<!-- figure bus-wire -->\n" + "\n".join(lines) + "\n<!-- /figure -->"


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seconds", type=float, default=1.0, help="seconds per measurement (default 1)")
    parser.add_argument("--markdown", action="store_true", help="print the wire limits as the docs' table")
    args = parser.parse_args(argv)
    if args.markdown:
        print(wire_markdown())
        return 0
    print(f"{platform.processor() or platform.machine()}, {os.cpu_count()} cores, Python {platform.python_version()}")
    print(f"{'protocol':12} {'servos':>6} {'frame':>13} {'pty Hz':>8} {'wire Hz 1M':>11} {'wire Hz 57600':>14}")
    for protocol in ("dxl2", "dxl1", "feetech-sts", "feetech-scs"):
        for n_servos in (6, 12):
            for read_back in (False, True):
                rate = measure(protocol, n_servos, read_back, args.seconds)
                what = "write+read" if read_back else "write"
                print(f"{protocol:12} {n_servos:6d} {what:>13} {rate:8.0f} "
                      f"{wire_limit_hz(protocol, n_servos, 1_000_000, read_back):11.0f} "
                      f"{wire_limit_hz(protocol, n_servos, 57_600, read_back):14.1f}", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
