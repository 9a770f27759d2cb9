"""Recording by hand, measured against the servo emulator (docs/recording.md).

    python tools/bench_record.py               # step lengths read back, and real-time read timing (30 s)
    python tools/bench_record.py --markdown    # the read-back figure of docs/recording.md (tools/figures.py)

Read back: the emulator's hand plays walker walks of 0.03, 0.06 and 0.09 m steps on the default robot's
servos (torque off); ``record_session`` reads them through the vendor SDK on the emulator's pty, one sample
per read cycle on a simulated clock (deterministic whatever the host's timing), writes the trajectory CSV
(the root rebuilt from foot contact), and the step lengths are read from the recorded files as
``gaitbot eigen fit`` reads them. Timing: ``gaitbot record --duration 10`` on each shipped robot's emulated
servos in real time: how late reads started and how long they took (machine-dependent).
"""

from __future__ import annotations

import argparse
import re
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from gaitbot.app.options import load_robot  # noqa: E402
from gaitbot.app.progress import progress  # noqa: E402
from gaitbot.app.record import TrajectorySink  # noqa: E402
import gaitbot.emulator as se  # noqa: E402
from gaitbot.bus.factory import make_bus  # noqa: E402
from gaitbot.gait import generate_walk  # noqa: E402
from gaitbot.gait.eigen import cycles_from_trajectory, walk_label  # noqa: E402
from gaitbot.gait.trajectory import Trajectory  # noqa: E402
from gaitbot.robot.calibration import angles_to_ticks  # noqa: E402
from gaitbot.robot.walk_settings import leg_geometry, walk_settings  # noqa: E402
from gaitbot.stream.clock import VirtualClock  # noqa: E402
from gaitbot.stream.record import record_session  # noqa: E402

STEPS_M = (0.03, 0.06, 0.09)
ROBOTS = ("xl430-biped", "ax12a-biped", "sts3215-biped")
REPLY_TIMEOUT_MS = 1000  # a busy host (the emulator shares the GIL) must not turn a slow reply into a failure


def record_walk(config, step: float, out: Path) -> Trajectory:
    """A six-step walker walk played by the emulator's hand and recorded through the SDK (simulated clock)."""
    walk = generate_walk(leg_geometry(config), [step] * 6, walk_settings(config))
    ticks = angles_to_ticks(config, walk.angles_rad)
    hand = se.Hand({j.id: ticks[:, c].tolist() for c, j in enumerate(config.joints)}, None)
    chain = se.EmulatorConfig(config.bus.backend, config.bus.protocol, config.models_by_id, config.bus.baudrate,
                              se.Faults(), hand=hand)
    with se.ServoEmulator(chain) as emulator:
        bus = make_bus(config.bus.backend, config.bus.protocol, emulator.path, config.bus.baudrate,
                       config.models_by_id, interface="serial", reply_timeout_ms=REPLY_TIMEOUT_MS)
        result = record_session(bus, config.ids, 1.0 / config.gait.rate_hz, TrajectorySink(config, out, lambda t: None),
                                confirm=lambda n: True, n_samples=len(ticks), clock=VirtualClock())
    if result.outcome != "completed":
        raise RuntimeError(result.message())
    return Trajectory.load(out)


def read_back() -> list[float]:
    config = load_robot("xl430-biped")
    labels = []
    with tempfile.TemporaryDirectory() as folder, progress("recording walks", total=len(STEPS_M), unit="walk") as bar:
        for step in STEPS_M:
            recorded = record_walk(config, step, Path(folder) / f"rec_{step}.csv")
            labels.append(walk_label(cycles_from_trajectory(recorded, leg_geometry(config))))
            bar.update(1)
    return labels


def markdown(labels: list[float]) -> str:
    errors = [abs(label - step) / step for label, step in zip(labels, STEPS_M)]
    text = (f"the step lengths read back from the three recorded walks ({', '.join(f'{s:g}' for s in STEPS_M)} m) "
            f"are within {100 * max(errors):.1f}% ({', '.join(f'{v:.4f}' for v in labels)} m)")
    return f"<!-- figure record-readback -->\n{text}\n<!-- /figure -->"


def real_time(name: str, seconds: float = 10.0) -> str:
    """``gaitbot record`` for ``seconds`` on the emulated servos of robot ``name``: its timing line."""
    config = load_robot(name)
    with tempfile.TemporaryDirectory() as folder, se.ServoEmulator(se.EmulatorConfig(
            config.bus.backend, config.bus.protocol, config.models_by_id, config.bus.baudrate)) as emulator:
        proc = subprocess.run([sys.executable, "-m", "gaitbot", "record", "--robot", name, "--yes", "--duration",
                               str(seconds), "--port", emulator.path, "-o", str(Path(folder) / "r.csv")],
                              capture_output=True, text=True, cwd=ROOT)
    found = re.search(r"^Read .*$", proc.stdout, re.M)
    return found.group(0) if found else f"failed ({proc.returncode}): {proc.stderr.strip()[-300:]}"


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--markdown", action="store_true", help="print the docs' figure (tools/figures.py)")
    args = parser.parse_args(argv)
    labels = read_back()
    if args.markdown:
        print(markdown(labels))
        return 0
    print(f"xl430-biped, step lengths read back from recorded walks: "
          f"{', '.join(f'{s:g} m -> {v:.4f} m' for s, v in zip(STEPS_M, labels))} "
          f"(worst {100 * max(abs(v - s) / s for s, v in zip(STEPS_M, labels)):.1f}%)")
    for name in ROBOTS:
        print(f"{name}: {real_time(name)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
