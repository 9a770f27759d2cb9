"""What each subcommand does, given parsed arguments. Returns the process exit status."""

from __future__ import annotations

import json
import math
import sys
from pathlib import Path

from gaitbot.bus.budget import check_rate
from gaitbot.bus.factory import make_bus
from gaitbot.bus.guard import LimitGuard
from gaitbot.bus.recording import BusRecorder
from gaitbot.clock import MonotonicClock, VirtualClock
from gaitbot.gait.trajectory import Trajectory
from gaitbot.robot.calibration import angles_to_ticks, standing_ticks, tick_limits
from gaitbot.session import (UsageError, gain_notes, gain_writes, gait_source, joint_limits_ticks, load_robot,
                             plan_summary, preflight, trajectory_for_robot)
from gaitbot.stream import latency_timer_warning, walk_session


def _plan_terrain(args) -> int:
    from gaitbot.session import terrain_plan_summary

    source, walk, _ = trajectory_for_robot(args)
    plan = terrain_plan_summary(source, walk)
    if args.json:
        print(json.dumps(plan, indent=2))
        return 0
    print(f"{'step':>4} {'leg':>5} {'length m':>9} {'start s':>8} {'end s':>7} {'foothold m':>10} {'height m':>8} "
          f"{'method':>8} {'lift m':>7}")
    for s in plan["steps"]:
        label = "close" if s["closing"] else str(s["index"])
        print(f"{label:>4} {s['leg']:>5} {s['length_m']:9.4f} {s['start_s']:8.3f} {s['end_s']:7.3f} "
              f"{s['foothold_m']:10.4f} {s['height_m']:8.4f} {s['method']:>8} {s['lift_m']:7.4f}")
    for i, r in enumerate(plan["searches"], start=1):
        centre = f"{r['centre_cost']:.4g}" if r["centre_cost"] is not None else "unreachable"
        print(f"MDS {i}: pelvis at ({r['mds_m'][0]:.4f}, {r['mds_m'][1]:.4f}) m, cost {r['cost']:.4g} "
              f"(middle of the region: {centre}); {r['evaluated']} cells scored, {r['pruned']} skipped as "
              f"unreachable, of {r['full_grid']} in a full search")
    print(f"{plan['n_steps']} steps ({plan['n_terrain_steps']} on terrain), {plan['duration_s']:.2f} s, "
          f"{plan['n_frames']} frames; grid search scored {plan['cells_evaluated']} cells against "
          f"{plan['cells_full_search']} for full searches")
    return 0


def cmd_plan(args) -> int:
    if getattr(args, "terrain", None) is not None:
        return _plan_terrain(args)
    source, walker, _ = trajectory_for_robot(args)
    plan = plan_summary(source, walker)
    if args.json:
        print(json.dumps(plan, indent=2))
        return 0
    print(f"{'step':>4} {'leg':>5} {'length m':>9} {'RV':>7} {'start s':>8} {'end s':>7} {'foothold m':>10}")
    for s in plan["steps"] + ([plan["closing_step"]] if plan["closing_step"] else []):
        label = "close" if s["closing"] else str(s["index"])
        print(f"{label:>4} {s['leg']:>5} {s['length_m']:9.4f} {s['rv']:7.4f} {s['start_s']:8.3f} {s['end_s']:7.3f} "
              f"{s['foothold_m']:10.4f}")
    print(f"{plan['n_steps']} steps, {plan['total_distance_m']:.4f} m in {plan['duration_s']:.2f} s "
          f"(cycle {plan['cycle_s']:.4f} s, {plan['rate_hz']:g} Hz, reachable step 0 to "
          f"{plan['reachable_step_m'][1]:.4f} m, allowed up to {plan['max_step_m']:.4f} m)")
    return 0


def cmd_generate(args) -> int:
    out = Path(args.output)
    if out.suffix not in (".csv", ".npz"):
        raise UsageError(f"-o {out}: the output must end in .csv or .npz")
    _, walker, trajectory = trajectory_for_robot(args)
    trajectory.save(out)
    print(f"wrote {out}: {len(trajectory)} frames, {trajectory.t_s[-1]:.2f} s, "
          f"{len(walker.heel_strikes)} heel strikes, {trajectory.root_m[-1, 0] - trajectory.root_m[0, 0]:.4f} m")
    return 0


def cmd_plot(args) -> int:
    try:
        import matplotlib  # noqa: F401  (only plotting needs it: the `plot` extra)
    except ImportError:
        raise UsageError("plotting needs matplotlib: pip install 'gaitbot[plot]'") from None
    from gaitbot.plot import plot_trajectory

    if Path(args.file).suffix == ".npz":
        from gaitbot.gait.eigen import is_model_file

        if is_model_file(args.file):
            from gaitbot.plot import plot_eigen_model

            plot_eigen_model(args.file, Path(args.output))
            print(f"wrote {args.output}")
            return 0
    trajectory = Trajectory.load(args.file)
    source = gait_source(args)
    out = Path(args.output)
    terrain = None
    if getattr(args, "terrain", None) is not None:
        from gaitbot.terrain_file import load_course

        terrain = load_course(args.terrain).terrain
    plot_trajectory(trajectory, source.geometry, out, clearance=source.settings.clearance, title=Path(args.file).name,
                    terrain=terrain)
    print(f"wrote {out}")
    return 0


def _status_line(total: int, strikes, rate_hz: float):
    """A cheap live status line: frame, step and late frames, rewritten in place on a terminal."""
    out = sys.stderr
    if not out.isatty():
        return None
    times = [h.t_s for h in strikes]

    def on_frame(k: int, stats) -> None:
        if k % 6:
            return
        step = sum(1 for t in times if t <= k / rate_hz)
        out.write(f"\rframe {k + 1}/{total}  step {step}/{len(times)}  late {stats.late_frames}   ")
        out.flush()

    return on_frame


def _require_port(port: str) -> None:
    """A real run needs a serial device that exists: say which one is missing and how to list them."""
    if not Path(port).exists():
        raise UsageError(f"--port {port}: no such serial port (list them with: python -m serial.tools.list_ports -v; "
                         f"or try --dry-run)")


def _check_rate_override(config, rate) -> None:
    if rate is None:
        return
    if not (math.isfinite(rate) and rate > 0):
        raise UsageError(f"--rate must be a positive frame rate in Hz, got {rate!r}")
    try:
        check_rate(rate, config.bus.backend, config.bus.protocol, config.joints[0].model, len(config.joints),
                   config.bus.baudrate, read_back=True)
    except ValueError as exc:
        raise UsageError(f"--rate {rate:g}: {exc}") from None


def cmd_walk(args) -> int:
    from gaitbot.sim_walk import check_sim_arguments

    check_sim_arguments(args)
    config = load_robot(args.robot)
    _check_rate_override(config, args.rate)
    args.robot = str(config.path)
    source, walker, trajectory = trajectory_for_robot(args)
    report = preflight(config, trajectory)
    if not report.ok:
        raise UsageError(f"walk refused before anything moved: {report.first_error}")
    frames = angles_to_ticks(config, trajectory.angles_rad)
    period = 1.0 / source.settings.rate_hz
    sim = None
    if args.sim:
        from gaitbot.sim_walk import SimWalk, walk_plan

        sim = SimWalk(config, source.settings.rate_hz, walk_plan(walker, trajectory), args.free_pitch, args.video)
    hardware = not (args.dry_run or args.sim)
    port = args.port or config.bus.port
    if hardware:
        _require_port(port)
    clock = MonotonicClock() if (hardware or args.realtime) else VirtualClock()
    if hardware:
        warning = latency_timer_warning(port)
        if warning:
            print(f"warning: {warning}", file=sys.stderr)
    recorder = None
    if args.record:
        joints = {j.name: j.id for j in config.joints}
        recorder = BusRecorder(args.record, robot=config.name, joints=joints, clock=clock.now)
    if args.reply_timeout_ms is not None and not (math.isfinite(args.reply_timeout_ms) and args.reply_timeout_ms > 0):
        raise UsageError(f"--reply-timeout-ms must be a positive number of milliseconds, got {args.reply_timeout_ms!r}")
    if sim is not None:
        bus = sim.make_bus(clock, recorder)
    else:
        bus = make_bus(config.bus.backend, config.bus.protocol, port, config.bus.baudrate, config.models_by_id,
                       dry_run=args.dry_run, recorder=recorder, reply_timeout_ms=args.reply_timeout_ms)
    bus = LimitGuard(bus, tick_limits(config), {j.id: j.name for j in config.joints})
    velocity, acceleration = joint_limits_ticks(config)
    for note in gain_notes(config):
        print(f"note: {note}", file=sys.stderr)
    try:
        result = walk_session(bus, config.ids, frames, standing_ticks(config), max_velocity_ticks_per_s=velocity,
                              max_accel_ticks_per_s2=acceleration, period_s=period, clock=clock,
                              torque_off_on_exit=config.bus.torque_off_on_exit,
                              on_frame=_status_line(len(frames), walker.heel_strikes, source.settings.rate_hz),
                              setup_writes=gain_writes(config))
    finally:
        if recorder is not None:
            recorder.close()
    for note in getattr(bus, "open_notes", []):
        print(f"note: {note}", file=sys.stderr)
    if sys.stderr.isatty():
        sys.stderr.write("\n")
    if sim is not None and args.json:
        sim.print_report(True, result.outcome)
        return result.exit_code
    if sim is not None:
        mode = (f"simulated robot (MuJoCo; {config.bus.backend} packets on a simulated bus, simulated clock; "
                f"torso {'free to pitch' if args.free_pitch else 'on a boom, pitch held'})")
    elif not args.dry_run:
        mode = f"{config.bus.backend} on {port}"
    elif args.realtime:
        mode = "dry run (mock bus, paced in real time)"
    else:
        mode = "dry run (mock bus, simulated clock: timing figures are exact by construction; --realtime paces it)"
    print(f"{config.name}: {mode}: {len(walker.planned_steps)} heel strikes, "
          f"{trajectory.root_m[-1, 0] - trajectory.root_m[0, 0]:.3f} m planned. {result.message()}")
    if result.walk_stats is not None:
        print(result.walk_stats.summary())
    if args.record:
        print(f"recording: {args.record}")
    if sim is not None:
        sim.print_report(False, result.outcome)
    return result.exit_code


def cmd_scan(args) -> int:
    config = load_robot(args.robot)
    port = args.port or config.bus.port
    if not args.dry_run:
        _require_port(port)
    ids = range(0, 253) if args.all else config.ids
    names = {j.id: j.name for j in config.joints}
    bus = make_bus(config.bus.backend, config.bus.protocol, port, config.bus.baudrate, config.models_by_id,
                   dry_run=args.dry_run)
    with bus:
        found = bus.scan(ids)
    for servo_id in ids if not args.all else found:
        state = "answers" if servo_id in found else "MISSING"
        print(f"id {servo_id:3d}  {names.get(servo_id, '(not in config)'):20s} {state}")
    missing = [i for i in config.ids if i not in found]
    return 1 if missing else 0


def cmd_check(args) -> int:
    from gaitbot.check_command import run_check

    return run_check(args)


def cmd_record(args) -> int:
    from gaitbot.record_command import run_record

    return run_record(args)


def cmd_eigen(args) -> int:
    from gaitbot.eigen_command import run_eigen

    return run_eigen(args)
