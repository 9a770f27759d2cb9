"""``gaitbot walk``: a walk streamed to the robot, the mock bus (``--dry-run``) or the simulated robot (``--sim``).

The robot loaded once, the walk planned once (gaitbot.app.planned_walk), the preflight check (nothing
moves if any frame breaks a limit), then the walk session (gaitbot.stream.session.WalkSession) on a bus
behind the LimitGuard; docs/bus-faults.md says what happens when the bus fails.
"""

from __future__ import annotations

import math
import sys

from gaitbot.app.arguments import add_command, bus_options, check_walk_source, walk_options
from gaitbot.app.feel_options import (add_feedback_option, fall_dict, fall_line, feedback_choice, feedback_mode,
                                      make_feedback)
from gaitbot.app.hardware import refuse_port_in_dry_run, serial_port, warn_about_latency
from gaitbot.app.file_robot import robot_for_walk
from gaitbot.app.options import UsageError, check_rate_option, check_reply_timeout, file_option
from gaitbot.app.planned_walk import PlannedWalk, clearance_hint, planned_walk
from gaitbot.app.outputs import output_path
from gaitbot.app.progress import callback, progress
from gaitbot.app.sim_options import (add_push_phase_option, add_sim_model_options, check_push_phase,
                                     check_sim_model, foreign_model, parse_push)
from gaitbot.app.view_options import add_view_options, open_view
from gaitbot.bus.factory import guarded, make_robot_bus
from gaitbot.bus.recording import BusRecorder, RecordingFailed
from gaitbot.check.preflight import LimitBroken, preflight  # noqa: F401 (LimitBroken: walk's refusal)
from gaitbot.errors import UserError
from gaitbot.robot.balanced_walk import BalancedPlan
from gaitbot.robot.calibration import standing_ticks, trajectory_ticks
from gaitbot.robot.calibration_file import sent_calibration
from gaitbot.robot.gains import gain_notes, gain_writes
from gaitbot.robot.walk_settings import joint_limits_ticks
from gaitbot.sim import import_mujoco
from gaitbot.sim.model3d import TorsoSupport
from gaitbot.sim.video import check_video_path
from gaitbot.stream.clock import MonotonicClock, VirtualClock
from gaitbot.stream.health import HealthMonitor
from gaitbot.stream.session import SessionLimits, WalkSession


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


def add_parser(subparsers):
    p = add_command(subparsers, "walk")
    walk_options(p, demo=True)
    p.add_argument("--trajectory", metavar="FILE", help="walk a trajectory file (.csv/.npz: gaitbot generate, "
                   "eigen synth, record) instead of --steps/--distance; it streams at its own frame rate, on the "
                   "robot it was made for unless --robot says (the same one)")
    bus_options(p, "use the mock bus under the real SDK: no hardware, and every packet exactly as a real walk sends it")
    p.add_argument("--realtime", action="store_true",
                   help="--dry-run: pace it at the real frame rate (default: a simulated clock, as fast as it goes)")
    p.add_argument("--record", metavar="FILE", help="write every bus packet to this .jsonl file (gaitbot check reads it)")
    p.add_argument("--sim", action="store_true",
                   help="walk the simulated robot (MuJoCo) and measure whether it really walks")
    p.add_argument("--boom", action="store_true",
                   help="the robot walks on a boom: accept a walk that would tip a free-standing robot (with --sim: "
                   "the simulated torso rides a boom, sliding forward and up, pitch held)")
    p.add_argument("--free-pitch", action="store_true", help="--sim: the boom, with the torso free to pitch on it")
    add_sim_model_options(p)  # --push, --imu-fault, --imu-seed, --sim-model, --sim-map (gaitbot.app.sim_options)
    add_push_phase_option(p)
    add_feedback_option(p)  # --feedback (gaitbot.app.feel_options)
    p.add_argument("--video", metavar="FILE", help="--sim: render the walk to walk.gif or walk.mp4 (three-quarter view)")
    p.add_argument("--json", action="store_true", help="--sim: print the measurements as one JSON object")
    add_view_options(p)  # --mcap, --foxglove (gaitbot.app.view_options)
    return p


def check_arguments(parser, args) -> None:
    """One source of steps; on the mock bus or the simulated robot none walks the demo."""
    check_walk_source(parser, args, demo=args.dry_run or args.sim)


def run(args) -> int:
    check_sim_arguments(args)
    refuse_port_in_dry_run(args)
    check_reply_timeout(args.reply_timeout_ms)
    config = robot_for_walk(args)
    check_rate_option(config, args.rate)
    feedback_choice(args, config)  # refused here, before any note (the open-loop note comes once all is checked)
    walk = planned_walk(args, config)
    check_stepping(args, config, walk)
    report = preflight(config, walk.goals, on_boom=args.boom, planned=walk.planned)
    if not report.ok:
        raise LimitBroken(f"walk refused before anything moved: {report.first_error}{clearance_hint(walk.source)}")
    frames = trajectory_ticks(config, walk.goals)
    straight = [name for name in config.walking_joint_names if name not in walk.goals.joints]
    if straight:
        print(f"note: the trajectory does not move {', '.join(straight)}: held at 0 deg (straight)", file=sys.stderr)
    sim = None
    if args.sim:
        from gaitbot.sim.walk import SimWalk, walk_plan  # MuJoCo: only with --sim

        sim = SimWalk(config, walk.rate_hz, walk_plan(walk.plan, walk.planned), sim_support(args, config),
                      args.video, args.push, args.push_direction_deg, foreign_model(args), args.imu_seed,
                      args.imu_fault, getattr(args, "push_phase", None))
        for note in getattr(sim.robot, "notes", ()):
            print(f"note: --sim-model: {note}", file=sys.stderr)
    hardware = not (args.dry_run or args.sim)
    port = serial_port(config, args.port, dry_run=not hardware)
    clock = MonotonicClock() if (hardware or args.realtime) else VirtualClock()
    if hardware:
        warn_about_latency(port)
    recorder = _recorder(args, config, clock, walk.rate_hz)
    bus = _open_bus(args, config, port, sim, clock, recorder)
    if getattr(args, "demo", False):  # said once every input was found good: a refusal stays one line (exit 2)
        print(f"note: no --steps, --distance, --terrain or --trajectory: walking the demo, --distance "
              f"{args.distance:g}", file=sys.stderr)
    walk.say_notes()  # the planner's (a gentler or slower walk than asked), now that every check passed
    for note in gain_notes(config):
        print(f"note: {note}", file=sys.stderr)
    health = HealthMonitor.for_robot(config, _warn_line, clock.now)
    velocity, acceleration = joint_limits_ticks(config)
    feedback = make_feedback(config, feedback_mode(args, config), bus, clock, 1.0 / walk.rate_hz, sim)
    session = WalkSession(bus, config.ids, standing_ticks(config),
                          SessionLimits(velocity, acceleration, 1.0 / walk.rate_hz), clock=clock,
                          torque_off_on_exit=config.bus.torque_off_on_exit, setup_writes=gain_writes(config),
                          health=health, feedback=feedback)
    view = stepping = None
    try:
        view = open_view(args, config, walk.goals, walk.planned, health, not isinstance(clock, VirtualClock),
                         feedback, sim.robot if sim is not None else None)
        with progress("simulating" if sim is not None else "walking", total=len(frames), unit="frame") as bar:
            status = _status(bar, walk.heel_strikes, walk.rate_hz, health)
            stepping = stepping_source(walk, config, feedback)
            result = session.run(stepping or frames, view.chain(status) if view else status)
    finally:
        if recorder is not None:
            recorder.close()
        if view is not None:
            view.close()
    for note in bus.open_notes:
        print(f"note: {note}", file=sys.stderr)
    if sim is not None and stepping is not None and stepping.stepping:
        sim.extra["capture_steps"] = stepping.log.summary()
        sim.extra["capture_pauses_s"] = [round(t_s, 4) for t_s in stepping.log.paused_s]
    if sim is not None and stepping is not None and stepping.correction is not None:
        sim.extra["zmp_correction"] = stepping.correction_log.summary()
    return _report(args, config, walk, result, sim, port, clock, health, feedback)


def check_stepping(args, config, walk) -> None:
    """``--feedback step`` needs a balanced walk of planned steps (not a file or a steered walk) and the
    robot's ``[steer]`` limits (how far a foothold may move); else one line, exit 2."""
    mode = getattr(args, "feedback", None)
    if mode == "zmp" and type(walk.plan) is not BalancedPlan:
        raise UsageError("--feedback zmp: only a balanced walk of --steps or --distance is walked online")
    if mode != "step":
        return
    if config.steer is None:
        raise UsageError(f"--feedback step: robot {config.name} has no [steer] limits (how far a step may move)")
    if type(walk.plan) is not BalancedPlan:  # a steered walk's plan is another class: its steps are commands
        raise UsageError("--feedback step: only a balanced walk of --steps or --distance moves its footholds")


def stepping_source(walk, config, feedback):
    """The frames of ``--feedback step``: the plan's steps walked online, the next foothold moved to catch a
    push (gaitbot.drive.stepping); None for every other mode (the planned frames as they are)."""
    if feedback is None or feedback.mode not in ("step", "zmp"):
        return None
    from gaitbot.drive.stepping import SteppingFrames

    zmp = feedback.mode == "zmp"
    return SteppingFrames(config, walk.plan, feedback.estimate, lambda: feedback.active, stepping=not zmp,
                          correction=zmp)


def _recorder(args, config, clock, rate_hz: float) -> BusRecorder | None:
    """The ``--record`` file's writer (its header is written when the bus opens), if asked."""
    if args.record is None:
        return None
    output_path(args.record, "--record", args)
    joints = {j.name: j.id for j in config.joints}
    return BusRecorder(args.record, robot=config.name, joints=joints, clock=clock.now, rate_hz=rate_hz,
                       calibration=sent_calibration(config))


def _open_bus(args, config, port: str, sim, clock, recorder: BusRecorder | None):
    """The robot's bus behind its guard: the simulated robot's, the mock's or the serial port's. A recording
    that cannot be written is refused here, before anything is sent."""
    try:  # the recording's header is written here, before anything is sent
        if sim is not None:
            return guarded(config, sim.make_bus(clock.now, recorder))
        return make_robot_bus(config, port, dry_run=args.dry_run, recorder=recorder,
                              reply_timeout_ms=args.reply_timeout_ms, clock=clock.now)
    except (OSError, RecordingFailed) as exc:
        if recorder is None:
            raise
        reason = exc.strerror if isinstance(exc, OSError) and exc.strerror else exc
        if isinstance(exc, RecordingFailed) and isinstance(exc.__cause__, OSError):
            reason = exc.__cause__.strerror or exc.__cause__
        raise UsageError(f"--record {args.record}: cannot write the recording ({reason}); nothing was sent") from None
def _report(args, config, walk: PlannedWalk, result, sim, port: str, clock, health: HealthMonitor,
            feedback) -> int:
    """What the walk did, on stdout (or the simulation's measurements as JSON), and the exit status."""
    if sim is not None:
        sim.extra["feedback"] = feedback.mode if feedback is not None else "none"
        if feedback is not None:
            sim.extra["feedback_servo_error_deg"] = round(feedback.servo_error_deg, 3)
            sim.extra["feedback_roll_attitude_gain"] = round(config.imu.roll_gain(feedback.servo_error_deg), 4)
            least = feedback.least_load_g  # the walk's margin to [fall] load_lost_g (docs/feedback.md, "A fall")
            sim.extra["imu_least_load_g"] = None if least is None else round(least, 3)
        sim.extra["fall_noticed"] = fall_dict(result, sim.tilt_crossed_s(config.imu.fall_tilt_deg))
    if sim is not None and args.json:
        return _sim_exit(_sim_report(sim, True, result.outcome, args.video), result.exit_code)
    if sim is not None:
        torso = {TorsoSupport.FREE: "free-floating torso", TorsoSupport.BOOM: "torso on a boom, pitch held",
                 TorsoSupport.BOOM_PITCH: "torso on a boom, free to pitch"}[sim.robot.support]
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
    root = walk.goals.root_m
    print(f"{config.name}: {mode}: {len(walk.planned_steps)} heel strikes, "
          f"{root[-1, 0] - root[0, 0]:.3f} m planned. {result.message()}")
    if result.walk_stats is not None:
        print(result.walk_stats.summary(simulated_clock=isinstance(clock, VirtualClock)))
    if fall_line(result, feedback):
        print(fall_line(result, feedback))
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


def sim_support(args, config) -> TorsoSupport:
    """How the simulated torso is held: free-floating unless --boom or --free-pitch asks for the boom (or the
    config says the robot walks on one, ``[robot] boom = true``)."""
    if args.free_pitch:
        return TorsoSupport.BOOM_PITCH
    return TorsoSupport.BOOM if (args.boom or config.boom) else TorsoSupport.FREE


def check_sim_arguments(args) -> None:
    """Refuse what a simulated walk cannot honour, and a missing MuJoCo, before any work is done."""
    sim = getattr(args, "sim", False)
    if not sim:
        check_push_phase(args)
        for flag in ("free_pitch", "push", "video", "json", "sim_model", "sim_map", "imu_fault"):
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
    args.push, args.push_direction_deg = parse_push(getattr(args, "push", None))
    if args.push is not None and (getattr(args, "boom", False) or getattr(args, "free_pitch", False)):
        raise UsageError("--push: a sideways push needs a free-floating torso (the boom holds it sideways)")
    check_push_phase(args)
    check_sim_model(args)
    import_mujoco()
    if getattr(args, "video", None):
        check_video_path(args.video)
