"""gaitbot benchmarks: prints figures for this machine (the README quotes them).

    python tools/bench.py                 # all sections
    python tools/bench.py gait            # walker: online per frame, offline frames/s, RV solve
    python tools/bench.py stream          # 60 s real-time dry run of the default robot on the mock bus
    python tools/bench.py stream --seconds 10
    python tools/bench.py session         # CPU per frame of a whole dry-run walk session (virtual clock)
    python tools/bench.py sim             # real-time factor of `gaitbot walk --sim` (the sim extra)
    python tools/bench.py terrain         # 10 stairs planned and generated; grid search on the examples

Figures are medians/percentiles of repeated measurements with time.perf_counter; nothing here
is asserted (timed tests are flaky on shared machines).
"""

from __future__ import annotations

import argparse
import os
import platform
import sys
import time

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), os.pardir))

from gaitbot.app.progress import progress  # noqa: E402
from gaitbot.gait import TABLE1_LEG, OnlineWalker, generate_walk  # noqa: E402
from gaitbot.gait.step_length import StepLengthInverse, boulic_step_length, step_length_to_rv_bisection  # noqa: E402


def machine() -> str:
    return f"{platform.machine()}, {os.cpu_count()} cores, Python {platform.python_version()}, {platform.platform()}"


def _us(values) -> str:
    values = np.asarray(values) * 1e6
    return f"median {np.median(values):.1f} us, p99 {np.percentile(values, 99):.1f} us, max {values.max():.1f} us"


def bench_gait() -> None:
    from gaitbot.robot.config import default_config_path, load_robot_config
    from gaitbot.robot.walk_settings import leg_geometry, walk_settings

    config = load_robot_config(default_config_path())
    geometry, settings = leg_geometry(config), walk_settings(config)
    rng = np.random.default_rng(1)
    steps = rng.uniform(0.3, 1.0, 100) * config.gait.max_step_m

    # online: append steps while consuming frames, timing each next_frame and each append_step
    walker = OnlineWalker(geometry, settings)
    frame_times, append_times = [], []
    queue = list(steps)
    while True:
        if queue and len(walker._frames) < walker.ctx.step_frames:
            t0 = time.perf_counter()
            walker.append_step(queue.pop(0))
            append_times.append(time.perf_counter() - t0)
        if not queue and not walker.finished:
            walker.finish()
        t0 = time.perf_counter()
        frame = walker.next_frame()
        frame_times.append(time.perf_counter() - t0)
        if frame is None:
            break
    print("walker, online (default robot, 100 random steps):")
    print(f"  next_frame per frame: {_us(frame_times)} over {len(frame_times)} frames")
    print(f"  append_step (plans a whole step, {walker.ctx.step_frames} frames): {_us(append_times)}")
    amortised = (sum(frame_times) + sum(append_times)) / len(frame_times)
    print(f"  amortised work per frame (planning included): {amortised * 1e6:.1f} us")

    # offline: whole trajectories, vectorised per segment
    best = np.inf
    for _ in range(3):
        t0 = time.perf_counter()
        trajectory = generate_walk(geometry, steps, settings)
        best = min(best, time.perf_counter() - t0)
    print(f"walker, offline: {len(trajectory)} frames in {best * 1e3:.1f} ms = {len(trajectory) / best:,.0f} frames/s")

    # step length -> RV: fast inverse vs the paper's bisection, Table 1 leg
    inverse = StepLengthInverse.build(TABLE1_LEG)
    targets = np.linspace(0.0, 0.75, 200)
    fast_times, errors, agree = [], [], []
    for sl in targets:
        t0 = time.perf_counter()
        rv = inverse.rv(sl)
        fast_times.append(time.perf_counter() - t0)
        errors.append(abs(boulic_step_length(TABLE1_LEG, rv)[0] - sl))
        rv_ref, _ = step_length_to_rv_bisection(TABLE1_LEG, sl, tolerance=1e-13)
        agree.append(abs(rv - rv_ref))
    bisect_times = []
    for sl in targets[::10]:
        t0 = time.perf_counter()
        step_length_to_rv_bisection(TABLE1_LEG, sl, tolerance=0.01)
        bisect_times.append(time.perf_counter() - t0)
    print("step length -> RV (Table 1 leg, 200 targets on [0, 0.75]):")
    print(f"  fast inverse: {_us(fast_times)}; |SL(rv) - SL*| max {max(errors):.2e} leg lengths;"
          f" |rv - bisection(1e-13)| max {max(agree):.2e}")
    print(f"  paper's bisection (tolerance 0.01): {_us(bisect_times)}")


def frame_counter(bar):
    """A Streamer's on_frame that moves the bar now and then (a bar drawn every frame would cost the loop)."""
    def on_frame(k: int, stats) -> None:
        if k % 30 == 0:
            bar.update(k + 1 - bar.n)
    return on_frame


def bench_stream(seconds: float) -> None:
    from gaitbot.bus.factory import make_bus
    from gaitbot.stream.clock import MonotonicClock
    from gaitbot.robot.calibration import trajectory_ticks
    from gaitbot.robot.config import default_config_path, load_robot_config
    from gaitbot.robot.walk_settings import leg_geometry, walk_settings
    from gaitbot.stream import Streamer

    config = load_robot_config(default_config_path())
    geometry, settings = leg_geometry(config), walk_settings(config)
    n_steps = int(seconds / (settings.cycle_s / 2)) + 2
    trajectory = generate_walk(geometry, [0.8 * config.gait.max_step_m] * n_steps, settings)
    frames = trajectory_ticks(config, trajectory)[: int(seconds * settings.rate_hz)]
    bus = make_bus(config.bus.backend, config.bus.protocol, "mock", config.bus.baudrate, config.models_by_id,
                   interface="dry-run")
    with bus, progress("streaming in real time", total=len(frames), unit="frame") as bar:
        stats = Streamer(bus, config.ids, 1.0 / settings.rate_hz, MonotonicClock(), frame_counter(bar)).run(frames)
    print(f"streaming, {len(frames) / settings.rate_hz:.0f} s real-time dry run at {settings.rate_hz:g} Hz "
          f"({config.name}, Dynamixel 2.0 packets on the mock bus):")
    print(f"  {stats.summary()}")
    half = 0.5 / settings.rate_hz
    verdict = "no frame" if stats.max_lateness_s <= half else "SOME frame"
    print(f"  {verdict} later than half a period ({half * 1e3:.1f} ms): worst {stats.max_lateness_s * 1e3:.3f} ms late")


def bench_session(repeats: int = 5) -> None:
    """CPU per frame of the whole 60 Hz path of a dry run: LimitGuard, goal sync write, the read-back of
    one servo, the SDK's packet code and the mock chain, on the virtual clock (no waiting)."""
    from gaitbot.bus.factory import make_robot_bus
    from gaitbot.robot.calibration import standing_ticks, trajectory_ticks
    from gaitbot.robot.config import default_config_path, load_robot_config
    from gaitbot.robot.gains import gain_writes
    from gaitbot.robot.walk_settings import joint_limits_ticks, leg_geometry, walk_settings
    from gaitbot.stream.clock import VirtualClock
    from gaitbot.stream.session import walk_session

    config = load_robot_config(default_config_path())
    trajectory = generate_walk(leg_geometry(config), [0.8 * config.gait.max_step_m] * 60, walk_settings(config))
    frames = trajectory_ticks(config, trajectory)
    velocity, acceleration = joint_limits_ticks(config)
    per_frame = []
    for _ in range(repeats):
        bus = make_robot_bus(config, "mock", dry_run=True)
        t0 = time.process_time()
        walk_session(bus, config.ids, frames, standing_ticks(config), max_velocity_ticks_per_s=velocity,
                     max_accel_ticks_per_s2=acceleration, period_s=1.0 / config.gait.rate_hz, clock=VirtualClock(),
                     setup_writes=gain_writes(config))
        per_frame.append((time.process_time() - t0) / len(frames))
    print(f"walk session, dry run of {len(frames)} frames ({config.name}, virtual clock; guard, goal sync write, "
          f"read-back of one servo, SDK and mock chain): CPU per frame best {min(per_frame) * 1e6:.0f} us, "
          f"median {np.median(per_frame) * 1e6:.0f} us over {repeats} runs")


def bench_sim(distance_m: float = 1.0, repeats: int = 3) -> None:
    """Real-time factor of `gaitbot walk --sim`: simulated seconds over wall seconds, for the whole
    command (planning, preflight, model build, the walk through the SDK packet code) and for the
    physics alone (the standing robot stepped for the same simulated time)."""
    import contextlib
    import io
    import json

    from gaitbot.sim.physics import SimRobot
    from gaitbot.app.cli import main as gaitbot_main
    from gaitbot.robot.config import load_robot_config, resolve_config

    print(f"simulated robot, `gaitbot walk --sim --distance {distance_m:g}` (median of {repeats} runs after a "
          f"warm-up run, which also builds the gait's step-length table):")
    for name in ("xl430-biped", "sts3215-biped", "ax12a-biped"):
        walls, report = [], {}
        for _ in range(repeats + 1):
            out = io.StringIO()
            t0 = time.perf_counter()
            with contextlib.redirect_stdout(out):
                gaitbot_main(["walk", "--sim", "--json", "--robot", name, "--distance", str(distance_m)])
            walls.append(time.perf_counter() - t0)
            report = json.loads(out.getvalue())
        walls = walls[1:]
        simulated = report["simulated_s"]
        robot = SimRobot(load_robot_config(resolve_config(name)), 60.0)
        for i in range(6):
            robot.set_torque(i, True)
        t0 = time.perf_counter()
        robot.advance_to(simulated)
        physics = time.perf_counter() - t0
        print(f"  {name}: {simulated:.1f} s simulated in {np.median(walls):.2f} s: {simulated / np.median(walls):.0f}x "
              f"real time (physics alone {simulated / physics:.0f}x; {robot.substeps} steps of "
              f"{robot.timestep_s * 1e3:.2f} ms per frame)")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("sections", nargs="*", default=["gait", "stream"], help="gait, stream, session, sim, terrain")
    parser.add_argument("--seconds", type=float, default=60.0, help="length of the streaming run")
    args = parser.parse_args()
    print(f"machine: {machine()}")
    for section in args.sections:
        if section == "gait":
            bench_gait()
        elif section == "stream":
            bench_stream(args.seconds)
        elif section == "session":
            bench_session()
        elif section == "sim":
            bench_sim()
        elif section == "terrain":  # tools/bench_terrain.py
            sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
            import bench_terrain

            bench_terrain.main([])
        else:
            parser.error(f"unknown section {section!r} (gait, stream, session, sim, terrain)")


if __name__ == "__main__":
    main()
