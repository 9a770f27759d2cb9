"""``gaitbot walk``: a walk streamed to the robot, the mock bus (``--dry-run``) or the simulated robot (``--sim``).

The preflight check first (nothing moves if any frame breaks a limit), then the walk session on a
bus behind the LimitGuard; docs/bus-faults.md says what happens when the bus fails.
"""

from __future__ import annotations

import math
import sys

from gaitbot.app.hardware import refuse_port_in_dry_run, serial_port, warn_about_latency
from gaitbot.app.options import UsageError, check_rate_option, check_reply_timeout, load_robot
from gaitbot.app.outputs import output_path
from gaitbot.app.progress import callback, progress
from gaitbot.app.walks import trajectory_for_robot
from gaitbot.bus.factory import guarded, make_robot_bus
from gaitbot.bus.log import BusRecorder, RecordingFailed
from gaitbot.check.preflight import preflight
from gaitbot.errors import UserError
from gaitbot.robot.calibration import standing_ticks, trajectory_ticks
from gaitbot.robot.gains import gain_notes, gain_writes
from gaitbot.robot.walk_settings import joint_limits_ticks
from gaitbot.sim import import_mujoco
from gaitbot.sim.video import check_video_path
from gaitbot.stream.clock import MonotonicClock, VirtualClock
from gaitbot.stream.health import HealthMonitor
from gaitbot.stream.session import walk_session


class LimitBroken(UserError):
    """The walk breaks a limit of the robot (or would tip it over): refused before anything moves, in one line.
    The check failed, as ``gaitbot check`` fails on the same file: exit 1 (docs/command-line.md), not 2 (the
    input is readable)."""

    exit_status = 1


def _status(bar, strikes, rate_hz: float, health: HealthMonitor):
    """The walk's live status on the bar: step, late frames and the latest servo health warning (the bar
    itself counts frames)."""
    times = [h.t_s for h in strikes]

    def on_frame(k: int, stats) -> None:
        if k % 6:
            return
        step = sum(1 for t in times if t <= k / rate_hz)
        warning = f"; warning: {health.status}" if health.status else ""
        bar.update(k + 1 - bar.n)
        bar.set_postfix_str(f"step {step}/{len(times)}, {stats.late_frames} late{warning}; Ctrl-C stops safely",
                            refresh=False)

    return on_frame


def _warn_line(text: str) -> None:
    """A health warning the first time it happens: on its own line (a terminal's status line keeps the latest)."""
    prefix = "\n" if sys.stderr.isatty() else ""
    print(f"{prefix}warning: {text}", file=sys.stderr, flush=True)


def run(args) -> int:
    check_sim_arguments(args)
    refuse_port_in_dry_run(args)
    check_reply_timeout(args.reply_timeout_ms)
    config = load_robot(args.robot, getattr(args, "calibration", None))
    check_rate_option(config, args.rate)
    args.robot = str(config.path)
    source, walker, trajectory = trajectory_for_robot(args, goals=True)  # what the servos are sent
    planned = walker.walk.trajectory() if hasattr(walker, "walk") else trajectory  # what the body does
    report = preflight(config, trajectory, on_boom=args.boom, planned=planned)
    if not report.ok:
        raise LimitBroken(f"walk refused before anything moved: {report.first_error}")
    frames = trajectory_ticks(config, trajectory)
    straight = [name for name in config.walking_joint_names if name not in trajectory.joints]
    if straight:
        print(f"note: the trajectory does not move {', '.join(straight)}: held at 0 deg (straight)", file=sys.stderr)
    period = 1.0 / source.settings.rate_hz
    sim = None
    if args.sim:
        from gaitbot.sim.walk import SimWalk, walk_plan  # MuJoCo: only with --sim

        sim = SimWalk(config, source.settings.rate_hz, walk_plan(walker, planned), sim_support(args, config),
                      args.video, args.push)
    hardware = not (args.dry_run or args.sim)
    port = serial_port(config, args.port, dry_run=not hardware)
    clock = MonotonicClock() if (hardware or args.realtime) else VirtualClock()
    if hardware:
        warn_about_latency(port)
    recorder = None
    if args.record is not None:
        output_path(args.record, "--record", args)
        joints = {j.name: j.id for j in config.joints}
        recorder = BusRecorder(args.record, robot=config.name, joints=joints, clock=clock.now,
                               rate_hz=source.settings.rate_hz)
    try:  # the recording's header is written here, before anything is sent
        if sim is not None:
            bus = guarded(config, sim.make_bus(clock.now, recorder))
        else:
            bus = make_robot_bus(config, port, dry_run=args.dry_run, recorder=recorder,
                                 reply_timeout_ms=args.reply_timeout_ms)
    except (OSError, RecordingFailed) as exc:
        if recorder is None:
            raise
        reason = exc.strerror if isinstance(exc, OSError) and exc.strerror else exc
        if isinstance(exc, RecordingFailed) and isinstance(exc.__cause__, OSError):
            reason = exc.__cause__.strerror or exc.__cause__
        raise UsageError(f"--record {args.record}: cannot write the recording ({reason}); nothing was sent") from None
    if getattr(args, "demo", False):  # said once every input was found good: a refusal stays one line (exit 2)
        print(f"note: no --steps, --distance, --terrain or --trajectory: walking the demo, --distance "
              f"{args.distance:g}", file=sys.stderr)
    velocity, acceleration = joint_limits_ticks(config)
    for note in gain_notes(config):
        print(f"note: {note}", file=sys.stderr)
    health = HealthMonitor.for_robot(config, _warn_line, clock.now)
    what = "simulating" if sim is not None else "walking"
    try:
        with progress(what, total=len(frames), unit="frame") as bar:
            result = walk_session(bus, config.ids, frames, standing_ticks(config), max_velocity_ticks_per_s=velocity,
                                  max_accel_ticks_per_s2=acceleration, period_s=period, clock=clock,
                                  torque_off_on_exit=config.bus.torque_off_on_exit,
                                  on_frame=_status(bar, walker.heel_strikes, source.settings.rate_hz, health),
                                  setup_writes=gain_writes(config), health=health)
    finally:
        if recorder is not None:
            recorder.close()
    for note in getattr(bus, "open_notes", []):
        print(f"note: {note}", file=sys.stderr)
    if sim is not None and args.json:
        return _sim_exit(_sim_report(sim, True, result.outcome, args.video), result.exit_code)
    if sim is not None:
        torso = {"free": "free-floating torso", "boom": "torso on a boom, pitch held",
                 "boom-pitch": "torso on a boom, free to pitch"}[sim.robot.support]
        mode = (f"simulated robot (MuJoCo; {config.bus.backend} packets on a simulated bus, simulated clock; "
                f"{torso})")
    elif not args.dry_run:
        mode = f"{config.bus.backend} on {port}"
    elif args.realtime:
        mode = "dry run (mock bus, paced in real time)"
    else:
        mode = "dry run (mock bus, simulated clock; --realtime paces it)"
    if config.calibration_file is not None:
        print(f"note: calibration {config.calibration_file} applied", file=sys.stderr)
    print(f"{config.name}: {mode}: {len(walker.planned_steps)} heel strikes, "
          f"{trajectory.root_m[-1, 0] - trajectory.root_m[0, 0]:.3f} m planned. {result.message()}")
    if result.walk_stats is not None:
        print(result.walk_stats.summary(simulated_clock=isinstance(clock, VirtualClock)))
    if health.summary():
        print(health.summary())
    if args.record:
        print(f"recording: {args.record}")
    if sim is not None:
        report = _sim_report(sim, False, result.outcome, args.video)
        if report.fell:
            print(f"The robot fell {report.fall_direction} at {report.fell_at_s:.2f} s ({report.fall_reason}).")
        return _sim_exit(report, result.exit_code)
    return result.exit_code


def _sim_report(sim, as_json: bool, outcome: str, video: str | None):
    with progress(f"writing {video}" if video else "measuring", unit="frame") as bar:
        return sim.print_report(as_json, outcome, callback(bar))


def _sim_exit(report, session_exit: int) -> int:
    """A simulated robot that fell failed its walk: exit 1 (docs/command-line.md), whatever the session says."""
    return 1 if report.fell and session_exit == 0 else session_exit


def sim_support(args, config) -> str:
    """How the simulated torso is held: free-floating unless --boom or --free-pitch asks for the boom (or the
    config says the robot walks on one, ``[robot] boom = true``)."""
    if args.free_pitch:
        return "boom-pitch"
    return "boom" if (args.boom or config.boom) else "free"


MAX_PUSH_NS = 20.0
"""The largest --push (N s): far beyond what knocks over any small humanoid (docs/simulation.md)."""


def check_sim_arguments(args) -> None:
    """Refuse what a simulated walk cannot honour, and a missing MuJoCo, before any work is done."""
    sim = getattr(args, "sim", False)
    if not sim:
        for flag in ("free_pitch", "push", "video", "json"):
            if getattr(args, flag, None):
                raise UsageError(f"--{flag.replace('_', '-')}: only with --sim (a simulated walk)")
        return
    refused = {"dry_run": "give --sim or --dry-run, not both",
               "port": "a simulated walk has no serial port",
               "realtime": "a simulated walk runs on the simulated clock, as fast as the CPU allows",
               "terrain": "the simulated floor is flat; terrain courses are not simulated yet",
               "reply_timeout_ms": "a simulated walk has no serial port",
               "trajectory": "the measurements need the walker's plan (swing times, footholds): give --steps or --distance",
               **{leg: "the simulated robot is built from the robot config: give the leg in a config file"
                  for leg in ("thigh", "shank", "foot")}}
    for flag, why in refused.items():
        if getattr(args, flag, None):
            raise UsageError(f"--{flag.replace('_', '-')}: {why}")
    push = getattr(args, "push", None)
    if push is not None:
        if not (math.isfinite(push) and push != 0 and abs(push) <= MAX_PUSH_NS):
            raise UsageError(f"--push must be a non-zero impulse of at most {MAX_PUSH_NS:g} N s (positive to the left), "
                             f"got {push!r}")
        if getattr(args, "boom", False) or getattr(args, "free_pitch", False):
            raise UsageError("--push: a sideways push needs a free-floating torso (the boom holds it sideways)")
    import_mujoco()
    if getattr(args, "video", None):
        check_video_path(args.video)
