"""``gaitbot record``: wiring from arguments to a bus, a question, and a trajectory CSV (gaitbot/stream/record.py).

What a sample becomes (:class:`TrajectorySink`): ticks -> joint angles through the robot's
calibration (the exact inverse of the map a walk uses) -> the root from foot contact
(gait/footfall.py ``ContactRoot``: the lower foot is taken as standing on flat ground, so the
file walks like the walker's and eigen-synthesised walks do) -> one CSV row, written and flushed
at once (gait/trajectory.py ``CsvTrajectoryWriter``).

A hand can move a leg anywhere: positions outside a joint's limits are recorded as read, with a
warning the first time each joint leaves its limits and a summary at the end. ``gaitbot check``
reports them as errors (exit 1), ``gaitbot walk --trajectory`` refuses such a file before anything
moves, and ``gaitbot eigen fit`` learns from it but warns, since walks synthesised near it may be
refused in turn.
"""

from __future__ import annotations

import math
import sys
from pathlib import Path

import numpy as np

from gaitbot.app.arguments import add_command, bus_options, robot_options
from gaitbot.app.hardware import refuse_port_in_dry_run, serial_port
from gaitbot.app.options import UsageError, check_reply_timeout, load_robot
from gaitbot.app.outputs import output_path
from gaitbot.bus.factory import make_robot_bus
from gaitbot.gait.footfall import ContactRoot
from gaitbot.gait.joints import PITCH_JOINTS
from gaitbot.gait.trajectory import CsvTrajectoryWriter
from gaitbot.robot.calibration import ticks_to_angles
from gaitbot.robot.config import RobotConfig
from gaitbot.robot.gains import gain_notes, gain_writes
from gaitbot.robot.origin import origin_for
from gaitbot.robot.walk_settings import leg_geometry
from gaitbot.stream.clock import MonotonicClock, VirtualClock
from gaitbot.stream.health import HealthMonitor
from gaitbot.stream.record import record_session

QUESTION = "Turn torque off on {n} servos? The legs will go limp. [y/N] "


class LimitWatch:
    """Joints seen outside their limits while recording: warn once per joint, summarise at the end."""

    def __init__(self, config: RobotConfig, warn) -> None:
        self.names = [j.name for j in config.joints]
        self.low = np.array([j.min_deg for j in config.joints])
        self.high = np.array([j.max_deg for j in config.joints])
        self.warn = warn
        self.outside: dict[str, list] = {}  # joint -> [samples outside, worst excess deg, worst value deg, t_s]

    def see(self, t_s: float, angles_deg: np.ndarray) -> None:
        excess = np.maximum(self.low - angles_deg, angles_deg - self.high)
        for j in np.flatnonzero(excess > 0):
            name = self.names[j]
            seen = self.outside.get(name)
            if seen is None:
                self.warn(f"t={t_s:.3f} s: {name} at {angles_deg[j]:.1f} deg is outside its limits "
                          f"{self.low[j]:g} to {self.high[j]:g} deg (recorded as read)")
                seen = self.outside[name] = [0, 0.0, 0.0, t_s]
            seen[0] += 1
            if excess[j] > seen[1]:
                seen[1:] = [float(excess[j]), float(angles_deg[j]), t_s]

    def summary(self) -> list[str]:
        return [f"{name} outside its limits in {n} samples, worst {value:.1f} deg at t={t:.3f} s"
                for name, (n, _, value, t) in self.outside.items()]


class TrajectorySink:
    """Samples of ticks (the config's joint order) -> rows of a trajectory CSV (see the module docstring)."""

    def __init__(self, config: RobotConfig, path: Path, warn, status=None) -> None:
        self.config = config
        self.path = path
        self.status = status  # called with (samples, t_s) after each sample, for a live status line
        self.limits = LimitWatch(config, warn)
        self.writer: CsvTrajectoryWriter | None = None
        self.root: ContactRoot | None = None
        self.last_root_m = np.zeros(2)
        names = config.walking_joint_names
        self._pitch_columns = [names.index(n) for n in PITCH_JOINTS]  # the contact model's legs

    def open(self) -> None:
        self.writer = CsvTrajectoryWriter(self.path, self.config.walking_joint_names,
                                          origin_for(self.config, ground_known=False))  # the ground is not known
        self.root = ContactRoot(leg_geometry(self.config))

    def add(self, t_s: float, ticks: np.ndarray) -> None:
        angles_rad = ticks_to_angles(self.config, ticks)
        moving = angles_rad[: self.config.calibration.n_walking]
        self.last_root_m = self.root.update(moving[self._pitch_columns])
        # the contact model's root is the hip point; the robot's root may sit above the hips
        lift = self.config.geometry.hip_below_root_m
        self.writer.write(t_s, moving, (self.last_root_m[0], 0.0, self.last_root_m[1] + lift))
        self.limits.see(t_s, np.degrees(angles_rad))
        if self.status is not None:
            self.status(self.writer.rows, t_s)

    def sync(self) -> None:
        self.writer.sync()

    def close(self) -> None:
        self.writer.close()


def ask_torque_off(n: int) -> bool:
    """The question on the terminal; anything but y/yes (or end of input) is no."""
    try:
        answer = input(QUESTION.format(n=n))
    except EOFError:
        print(file=sys.stderr)  # end the prompt's line
        return False
    return answer.strip().lower() in ("y", "yes")


def _check_output(out: Path) -> None:
    if out.suffix != ".csv":
        raise UsageError(f"-o {out}: a recording is written as it is read, in the trajectory CSV format: "
                         f"the file must end in .csv")


#: The longest recording by hand one --duration may ask for (a day); without --duration: until Ctrl-C.
MAX_DURATION_S = 86_400.0


def samples_for(duration_s: float | None, rate_hz: float) -> int | None:
    """Samples in ``duration_s`` at ``rate_hz`` (None: until Ctrl-C); a file needs at least 2."""
    if duration_s is None:
        return None
    if not (math.isfinite(duration_s) and 0 < duration_s <= MAX_DURATION_S):
        raise UsageError(f"--duration must be a number of seconds within 0..{MAX_DURATION_S:g}, got {duration_s!r}")
    n = int(round(duration_s * rate_hz))
    if n < 2:
        raise UsageError(f"--duration {duration_s:g} s holds fewer than 2 samples at {rate_hz:g} Hz "
                         f"(a trajectory needs 2); give at least {2 / rate_hz:.3g} s")
    return n


def _status_line(rate_hz: float):
    """On a terminal, the samples so far, rewritten in place twice a second; else nothing."""
    if not sys.stderr.isatty():
        return None
    every = max(1, int(rate_hz / 2))

    def show(samples: int, t_s: float) -> None:
        if samples % every == 0:
            sys.stderr.write(f"\rrecording: {samples} samples, {t_s:.1f} s (Ctrl-C to stop)   ")
            sys.stderr.flush()

    return show


def add_parser(subparsers):
    p = add_command(subparsers, "record")
    robot_options(p, "robot config: a .toml path or a shipped name (default xl430-biped)")
    p.add_argument("-o", "--output", required=True, help="trajectory CSV, written as it is read, e.g. demo.csv")
    p.add_argument("--duration", type=float, metavar="S", help="seconds to record (default: until Ctrl-C)")
    p.add_argument("--yes", action="store_true", help="turn torque off without asking")
    p.add_argument("--hold", action="store_true", help="at the end, hold the last pose (torque on) instead of "
                   "leaving torque off")
    bus_options(p, "record from the mock bus (needs --duration)")
    return p


def run(args) -> int:
    refuse_port_in_dry_run(args)
    config = load_robot(args.robot, getattr(args, "calibration", None))
    out = Path(args.output)
    _check_output(out)
    output_path(out, "-o", args)
    rate_hz = config.gait.rate_hz
    if args.dry_run and args.duration is None:
        raise UsageError("--dry-run needs --duration (a dry run has no hand on the legs and no Ctrl-C to wait for)")
    n_samples = samples_for(args.duration, rate_hz)
    check_reply_timeout(args.reply_timeout_ms)
    port = serial_port(config, args.port, args.dry_run)
    bus = make_robot_bus(config, port, dry_run=args.dry_run, reply_timeout_ms=args.reply_timeout_ms)

    def warn(text: str) -> None:
        print(f"warning: {text}", file=sys.stderr)

    sink = TrajectorySink(config, out, warn, _status_line(rate_hz))
    confirm = (lambda n: True) if args.yes else ask_torque_off
    clock = VirtualClock() if args.dry_run else MonotonicClock()
    if n_samples is None:
        print(f"recording at {rate_hz:g} Hz until Ctrl-C", file=sys.stderr)
    if args.hold:
        for note in gain_notes(config):
            print(f"note: {note}", file=sys.stderr)
    health = HealthMonitor.for_robot(config, warn, clock.now)
    result = record_session(bus, config.ids, 1.0 / rate_hz, sink, confirm=confirm, n_samples=n_samples, clock=clock,
                            hold_at_end=args.hold, setup_writes=gain_writes(config), health=health)
    if sink.status is not None and sink.writer is not None:
        sys.stderr.write("\n")
    for note in bus.open_notes:
        print(f"note: {note}", file=sys.stderr)
    for line in sink.limits.summary():
        warn(line)
    if result.outcome != "declined" and sink.writer is not None:
        rows = sink.writer.rows
        usable = "" if rows >= 2 else " (fewer than 2: not a readable trajectory)"
        print(f"wrote {out}: {rows} samples{usable}, {rows / rate_hz:.2f} s at {rate_hz:g} Hz; root from foot "
              f"contact, {sink.last_root_m[0]:.4f} m travelled")
        print(result.timing.summary(simulated_clock=args.dry_run))
    if health.summary():
        print(health.summary())
    mode = "dry run (mock bus, simulated clock)" if args.dry_run else f"{config.bus.backend} on {port}"
    print(f"{config.name}: {mode}. {result.message()}")
    return result.exit_code
