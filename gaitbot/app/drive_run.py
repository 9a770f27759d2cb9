"""``gaitbot drive`` (its run; the options are in gaitbot.app.drive): the live walk, steered from a keyboard, a gamepad, UDP datagrams or a commands file.

The frame source (gaitbot.drive.frames) plans each step from the latest command and checks every frame
before it goes out; the walk session streams it exactly as ``gaitbot walk`` streams a planned walk (the
LimitGuard, --record, the health read-back, the stop ramp on a bus fault). The first Ctrl-C or SIGTERM
stops stepping, closes the feet and stands (exit 130 or 143); a second one hurries to the session's stop
ramp. docs/driving.md.
"""

from __future__ import annotations

import json
import math
import signal
import sys
import threading

from gaitbot.app.feel_options import fall_dict, fall_line, feedback_mode, make_feedback
from gaitbot.app.hardware import refuse_port_in_dry_run, serial_port, warn_about_latency
from gaitbot.app.options import UsageError, load_robot
from gaitbot.app.outputs import output_path
from gaitbot.app.sim_options import DEFAULT_PUSH_AT_S, check_sim_model, foreign_model, parse_push
from gaitbot.app.view_options import FOXGLOVE_INPUT, drive_input, open_drive_view
from gaitbot.bus.factory import guarded, make_robot_bus
from gaitbot.bus.recording import BusRecorder
from gaitbot.drive.frames import DriveFrames, command_limits
from gaitbot.errors import UserError
from gaitbot.inputs.open import open_source
from gaitbot.robot.calibration import standing_ticks
from gaitbot.robot.calibration_file import sent_calibration
from gaitbot.robot.gains import gain_writes
from gaitbot.robot.steered_walk import footstep_planner
from gaitbot.robot.walk_settings import joint_limits_ticks
from gaitbot.stream.clock import MonotonicClock, VirtualClock
from gaitbot.stream.health import HealthMonitor
from gaitbot.stream.session import walk_session
from gaitbot.stream.signals import Terminated

MAX_TIME_S = 24 * 3600.0


def _check_args(args) -> None:
    if args.sim and (args.dry_run or args.port or args.realtime):
        raise UsageError("--sim: give --sim alone (not with --dry-run, --port or --realtime)")
    if args.max_time is not None and not (math.isfinite(args.max_time) and 0 < args.max_time <= MAX_TIME_S):
        raise UsageError(f"--max-time must be more than 0 and at most {MAX_TIME_S:g} seconds, got {args.max_time!r}")
    for flag in ("record", "record_commands"):
        if getattr(args, flag):
            output_path(getattr(args, flag), f"--{flag.replace('_', '-')}", args)
    if not args.sim:
        for flag in ("push", "push_at", "imu_fault", "sim_model", "sim_map"):
            if getattr(args, flag, None) is not None:
                raise UsageError(f"--{flag.replace('_', '-')}: only with --sim (a simulated drive)")
    args.push, args.push_direction_deg = parse_push(args.push)
    if args.push_at is not None and not (math.isfinite(args.push_at) and 0 <= args.push_at <= MAX_TIME_S):
        raise UsageError(f"--push-at must be seconds from the start, 0 to {MAX_TIME_S:g}, got {args.push_at!r}")
    if args.push_at is not None and args.push is None:
        raise UsageError("--push-at: give the push too (--push IMPULSE[@DIRECTION])")
    check_sim_model(args)


class GracefulSignals:
    """First SIGINT/SIGTERM: ask the drive to stop stepping and stand; the second raises as the session expects."""

    def __init__(self, frames: DriveFrames) -> None:
        self.frames = frames
        self.first: int | None = None
        self._old: dict = {}

    def handler(self, signum, _frame) -> None:
        if self.first is None:
            self.first = signum
            self.frames.stop_requested = True
            return
        raise Terminated(f"received signal {signum}") if signum == signal.SIGTERM else KeyboardInterrupt

    def __enter__(self):
        if threading.current_thread() is threading.main_thread():
            self._old = {s: signal.signal(s, self.handler) for s in (signal.SIGINT, signal.SIGTERM)}
        return self

    def __exit__(self, *exc) -> None:
        for signum, old in self._old.items():
            signal.signal(signum, old)


def _say(text: str) -> None:
    print(("\n" if sys.stderr.isatty() else "") + f"drive: {text}", file=sys.stderr, flush=True)


def _status_line(frames: DriveFrames, health: HealthMonitor):
    """On a terminal: command, planned speed, steps and servo health, twice a second; nothing in a pipe."""
    if not sys.stderr.isatty():
        return None
    last = {"k": 0, "pose": (0.0, 0.0, 0.0)}

    def on_frame(k: int, stats) -> None:
        if k % 30:
            return
        x, y, _ = frames.walk_pose()
        px, py, _ = last["pose"]
        speed = math.hypot(x - px, y - py) / max(1e-9, (k - last["k"]) * frames.period_s) if k else 0.0
        last.update(k=k, pose=(x, y, 0.0))
        c = frames.command
        servo = health.status or "servos ok"
        print(f"\rcommand ({c.vx_m_s:+.3f} m/s, {c.vy_m_s:+.3f} m/s, {c.wz_deg_s:+.1f} deg/s)  speed {speed:.3f} m/s  "
              f"steps {frames.log.steps}  {servo}  ", end="", file=sys.stderr, flush=True)

    return on_frame


def run(args) -> int:
    drive_input(args)  # --input left out: foxglove with --foxglove, else keyboard
    _check_args(args)
    refuse_port_in_dry_run(args)
    config = load_robot(args.robot, getattr(args, "calibration", None))
    if config.steer is None:
        raise UsageError(f"--robot {args.robot or config.name}: {config.name} has no [steer] table: it cannot be driven")
    if getattr(args, "feedback", None) == "step":
        raise UsageError("--feedback step: the live drive does not move its footholds yet; use full")
    if getattr(args, "feedback", None) == "zmp":
        raise UsageError("--feedback zmp: the live drive does not feed its preview controller yet; use full")
    mode = feedback_mode(args, config)  # refused (one line) before anything is opened; no IMU: said once
    step_s = footstep_planner(config).step_s
    top, bottom = command_limits(config.steer, step_s)
    view = open_drive_view(args, config)  # --mcap, --foxglove (gaitbot.app.view_options)
    try:
        commands_out = (open(args.record_commands, "w", encoding="utf-8")  # noqa: SIM115
                        if args.record_commands else None)
        source = view.teleop if args.input == FOXGLOVE_INPUT else open_source(args.input, top, bottom)
        try:
            return _drive(args, config, source, commands_out, mode, view)
        finally:
            source.close()
            if commands_out is not None:
                commands_out.close()
    finally:
        if view is not None:
            view.close()


def _drive(args, config, source, commands_out, mode: str, view=None) -> int:
    def on_command(timed) -> None:
        if commands_out is not None:
            commands_out.write(timed.to_json() + "\n")
            commands_out.flush()

    frames = DriveFrames(config, source, max_time_s=args.max_time, say=_say, on_command=on_command)
    sim = None
    if args.sim:
        sim = _sim_walk(args, config, frames)
    hardware = not (args.dry_run or args.sim)
    port = serial_port(config, args.port, dry_run=not hardware)
    clock = MonotonicClock() if (hardware or args.realtime or args.input != "commands" and
                                 not args.input.startswith("commands:")) else VirtualClock()
    if hardware:
        warn_about_latency(port)
    recorder = None
    if args.record:
        recorder = BusRecorder(args.record, robot=config.name, joints={j.name: j.id for j in config.joints},
                               clock=clock.now, rate_hz=1.0 / frames.period_s, calibration=sent_calibration(config))
    try:
        bus = (guarded(config, sim.make_bus(_from_zero(clock), recorder)) if sim is not None else
               make_robot_bus(config, port, dry_run=args.dry_run, recorder=recorder,
                              reply_timeout_ms=args.reply_timeout_ms, clock=clock.now))
    except OSError as exc:
        raise UsageError(f"--record {args.record}: cannot write the recording ({exc.strerror or exc})") from None
    velocity, acceleration = joint_limits_ticks(config)
    health = HealthMonitor.for_robot(config, _say, clock.now)
    feedback = make_feedback(config, mode, bus, clock, frames.period_s, sim)
    try:
        with GracefulSignals(frames) as signals:
            result = walk_session(bus, config.ids, frames, standing_ticks(config), max_velocity_ticks_per_s=velocity,
                                  max_accel_ticks_per_s2=acceleration, period_s=frames.period_s, clock=clock,
                                  torque_off_on_exit=config.bus.torque_off_on_exit,
                                  on_frame=_on_frame(view, frames, health, clock, sim, feedback), handle_sigterm=False,
                                  setup_writes=gain_writes(config), health=health, feedback=feedback)
    finally:
        if recorder is not None:
            recorder.close()
    if sys.stderr.isatty():
        print(file=sys.stderr)
    return _report(args, config, frames, result, signals.first, sim, feedback)


def _on_frame(view, frames: DriveFrames, health: HealthMonitor, clock, sim=None, feedback=None):
    """The status line, and the view's telemetry when --mcap or --foxglove is on (the IMU's readings when the
    drive's feedback reads one)."""
    status = _status_line(frames, health)
    return status if view is None else view.attach(frames, health, not isinstance(clock, VirtualClock), status,
                                                   feedback=feedback, sim_robot=sim.robot if sim is not None else None)


def _from_zero(clock):
    """The clock as the simulation follows it: from 0 now (the real clock counts from the machine's start, and
    the physics, which starts at 0, would otherwise first simulate all that time)."""
    start_s = clock.now()
    return lambda: clock.now() - start_s


def _sim_walk(args, config, frames: DriveFrames):
    from gaitbot.sim.metrics import WalkPlan
    from gaitbot.sim.walk import Push, Pusher, SimWalk

    start = {name: 0.0 for name in config.walking_joint_names}
    plan = WalkPlan(distance_m=0.0, start_angles_rad=start, start_root_m=frames.start_root_m)
    sim = SimWalk(config, 1.0 / frames.period_s, plan, "free", foreign=foreign_model(args), imu_seed=args.imu_seed,
                  imu_fault=args.imu_fault)
    for note in getattr(sim.robot, "notes", ()):
        print(f"note: --sim-model: {note}", file=sys.stderr)
    if args.push is not None:  # a drive has no planned middle step: the push comes at --push-at
        at_s = DEFAULT_PUSH_AT_S if args.push_at is None else args.push_at
        sim.push = Push(args.push, at_s, 0, "", args.push_direction_deg)
        sim.robot.observers.append(Pusher(sim.push, sim.robot.frame_s))
    return sim


def _ending(outcome: str, result) -> str:
    """How the drive ended, in one sentence (a first signal is a drive that stood, not a session's abort)."""
    if result.outcome == "completed" and outcome in ("interrupted", "terminated"):
        how = "Ctrl-C" if outcome == "interrupted" else "SIGTERM"
        return "; ".join([f"Drive stopped by {how}: steps finished, feet closed, standing", *result.notes]) + "."
    if outcome == "refused":
        return ("Drive stopped: a frame (or a step, and the stop in its place) was refused before it was sent; "
                "ended standing.")
    if outcome == "fell":
        return "; ".join(["Drive stopped: the robot fell, stepping stopped and the CoM lowered", *result.notes]) + "."
    return result.message()


def _report(args, config, frames: DriveFrames, result, first_signal, sim, feedback) -> int:
    exit_code = result.exit_code
    outcome = result.outcome
    if outcome == "completed" and first_signal is not None:
        outcome, exit_code = ("terminated", 143) if first_signal == signal.SIGTERM else ("interrupted", 130)
    if outcome == "completed" and frames.log.ended_by_refusal:  # a step replaced by a stop alone is no failure
        outcome, exit_code = "refused", 1
    x, y, heading = frames.walk_pose()
    report = {"robot": config.name, "input": args.input, "outcome": outcome,
              "pose": {"x_m": x, "y_m": y, "heading_deg": math.degrees(heading)},
              "distance_m": frames.log.distance_m, "steps": frames.log.steps, "clipped": frames.log.clipped,
              "refused": frames.log.refused, "step_refusals": frames.log.step_refusals,
              "frames_clipped": frames.guard.clipped,
              "fell": outcome == "fell", "frames": frames.k, "feedback": feedback.mode if feedback else "none",
              "fall_noticed": fall_dict(result, sim.tilt_crossed_s(config.imu.fall_tilt_deg) if sim else None),
              "notes": list(result.notes), "error": str(result.error) if result.error else None}
    if sim is not None:
        measured = sim.report()
        report["planned_pose"] = report["pose"]
        report["pose"] = {"x_m": measured.distance_travelled_m, "y_m": measured.lateral_drift_m,
                          "heading_deg": measured.heading_deg}
        report["fell"] = measured.fell or report["fell"]
        report["fall_reason"] = measured.fall_reason or (str(result.error) if outcome == "fell" else None)
        report["fell_at_s"] = measured.fell_at_s
        report["fall_direction"] = measured.fall_direction
        report["push"] = sim.push.to_dict() if sim.push is not None else None
        report["worst_tilt_deg"] = max(measured.torso_roll_max_deg, measured.torso_pitch_max_deg)
        if measured.fell and exit_code == 0:
            exit_code = 1
    report["exit_status"] = exit_code
    if args.json:
        print(json.dumps(report, indent=2))
    else:
        p = report["pose"]
        print(f"{config.name}: drove {report['steps']} steps, {report['distance_m']:.3f} m; pose x {p['x_m']:.3f} m, "
              f"y {p['y_m']:.3f} m, heading {p['heading_deg']:.1f} deg{'; FELL' if report['fell'] else ''}. "
              f"{_ending(outcome, result)}")
        if fall_line(result, feedback):
            print(fall_line(result, feedback))
        elif report["fell"] and sim is not None:
            print(f"The robot fell {report['fall_direction']} at {report['fell_at_s']:.2f} s ({report['fall_reason']}).")
    return exit_code


__all__ = ["run", "UserError"]
