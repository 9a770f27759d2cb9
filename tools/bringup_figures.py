#!/usr/bin/env python3
"""The figures of docs/bring-up.md, drawn with matplotlib:

    python tools/bringup_figures.py zero-pose docs/zero-pose.png
    python tools/bringup_figures.py health RUN.jsonl docs/health-walk.png

``zero-pose``: the pose ``gaitbot calibrate`` asks for (legs straight, feet flat, torso upright) as stick
figures from the side and the front, next to each pitch joint bent in its positive direction (hip flexion
swings the thigh forward, knee flexion bends the knee, ankle flexion lifts the toes: docs/gait-model.md).
Drawn to the default robot's leg (config/xl430-biped.toml).

``health``: the temperature and input voltage of every servo as a walk read them (the health blocks in a
bus recording, decoded by gaitbot.check.health), with the robot's warning and stop thresholds.
"""

from __future__ import annotations

import math
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # run from a source checkout too

import matplotlib  # noqa: E402

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

from gaitbot.robot.config import load_robot_config, resolve_config  # noqa: E402


def leg_points(g, hip_x: float, hip_y: float, hip: float, knee: float, ankle: float):
    """Hip, knee, ankle, heel, toe of a planar leg (angles in radians, flexion positive; x forward, y up)."""
    thigh = hip  # from the downward vertical, forward positive
    shank = hip - knee
    knee_xy = (hip_x + g.thigh_m * math.sin(thigh), hip_y - g.thigh_m * math.cos(thigh))
    ankle_xy = (knee_xy[0] + g.shank_m * math.sin(shank), knee_xy[1] - g.shank_m * math.cos(shank))
    foot = shank + ankle  # sole angle from the horizontal, toe up positive
    down = (ankle_xy[0] + g.ankle_height_m * math.sin(foot), ankle_xy[1] - g.ankle_height_m * math.cos(foot))
    heel = (down[0] - g.heel_back_m * math.cos(foot), down[1] - g.heel_back_m * math.sin(foot))
    toe = (down[0] + (g.foot_m - g.heel_back_m) * math.cos(foot), down[1] + (g.foot_m - g.heel_back_m) * math.sin(foot))
    return [(hip_x, hip_y), knee_xy, ankle_xy, down, heel, toe]


def draw_side(ax, g, hip=0.0, knee=0.0, ankle=0.0, title="", ghost=False):
    height = g.thigh_m + g.shank_m + g.ankle_height_m
    points = leg_points(g, 0.0, height, math.radians(hip), math.radians(knee), math.radians(ankle))
    straight = leg_points(g, 0.0, height, 0.0, 0.0, 0.0)
    if ghost:
        xs, ys = zip(*straight[:4])
        ax.plot(xs, ys, color="0.8", lw=3, zorder=1)
        ax.plot([straight[4][0], straight[5][0]], [straight[4][1], straight[5][1]], color="0.8", lw=3, zorder=1)
    ax.plot([0, 0], [height, height + 0.12], color="k", lw=6, solid_capstyle="round")  # torso
    xs, ys = zip(*points[:4])
    ax.plot(xs, ys, color="tab:blue", lw=3, marker="o", ms=5)
    ax.plot([points[4][0], points[5][0]], [points[4][1], points[5][1]], color="tab:blue", lw=3)
    ax.axhline(0, color="0.5", lw=1)
    ax.set_title(title, fontsize=9)
    ax.set_aspect("equal")
    ax.set_xlim(-0.16, 0.22)
    ax.set_ylim(-0.02, height + 0.15)
    ax.axis("off")


def zero_pose(out: Path) -> None:
    robot = load_robot_config(resolve_config("xl430-biped"))
    g = robot.geometry
    fig, axes = plt.subplots(1, 5, figsize=(12, 4.2))
    draw_side(axes[0], g, title="zero pose, from the side:\nlegs straight, feet flat,\ntorso upright")
    # front view: both legs straight down, hips apart, feet flat
    ax = axes[1]
    height = g.thigh_m + g.shank_m + g.ankle_height_m
    half = g.hip_width_m / 2
    ax.plot([-half, half], [height, height], color="k", lw=6, solid_capstyle="round")
    ax.plot([0, 0], [height, height + 0.12], color="k", lw=6, solid_capstyle="round")
    for x in (-half, half):
        ax.plot([x, x, x], [height, height - g.thigh_m, g.ankle_height_m], color="tab:blue", lw=3, marker="o", ms=5)
        ax.plot([x - 0.025, x + 0.025], [0, 0], color="tab:blue", lw=4)
    ax.axhline(0, color="0.5", lw=1)
    ax.set_title("zero pose, from the front:\nlegs parallel, soles flat\non the floor", fontsize=9)
    ax.set_aspect("equal")
    ax.set_xlim(-0.16, 0.16)
    ax.set_ylim(-0.02, height + 0.15)
    ax.axis("off")
    draw_side(axes[2], g, hip=30, title="hip_pitch positive:\n\"swing the thigh forward\"", ghost=True)
    draw_side(axes[3], g, hip=15, knee=40, ankle=25, title="knee_pitch positive:\n\"bend the knee\"", ghost=True)
    draw_side(axes[4], g, ankle=25, title="ankle_pitch positive:\n\"lift the toes\"", ghost=True)
    for ax in axes[2:]:
        ax.annotate("forward", xy=(0.2, 0.01), xytext=(0.1, 0.01), fontsize=7, color="0.4",
                    arrowprops=dict(arrowstyle="->", color="0.4"))
    fig.suptitle("gaitbot calibrate: hold the zero pose, then bend each joint its positive way (left leg shown; "
                 "the right leg the same, mirrored)", fontsize=10)
    fig.tight_layout(rect=(0, 0, 1, 0.9))
    fig.savefig(out, dpi=110)


def health(recording: Path, out: Path) -> None:
    from gaitbot.app.options import load_robot
    from gaitbot.check.health import health_report
    from gaitbot.check.recording import read_log, robot_for_recording
    from gaitbot.robot.health import health_thresholds
    from gaitbot.servos import wire

    robot = robot_for_recording(recording, None, lambda name: load_robot(name))
    _header, packets, _notes = read_log(recording)
    names = {j.id: j.name for j in robot.joints}
    thresholds = health_thresholds(robot)
    readings = []
    report = health_report(packets, wire.framing_for(robot.bus.backend, robot.bus.protocol), robot.models_by_id,
                           thresholds, names, collect=readings)
    fig, (top, bottom) = plt.subplots(2, 1, figsize=(8, 5), sharex=True)
    for servo_id, name in names.items():
        mine = [r for r in readings if r.reading.servo_id == servo_id]
        if not mine:
            continue
        t = [r.t_s for r in mine]
        top.plot(t, [r.reading.temperature_c for r in mine], label=f"{servo_id} {name}", lw=1.5)
        bottom.plot(t, [r.reading.voltage_v for r in mine], lw=1.5)
    first = thresholds[robot.joints[0].id]
    top.axhline(first.warn_temperature_c, color="orange", ls="--", lw=1, label="warning")
    top.axhline(first.stop_temperature_c, color="red", ls="--", lw=1, label="stop")
    bottom.axhline(first.warn_voltage_v, color="orange", ls="--", lw=1)
    bottom.axhline(first.stop_voltage_v, color="red", ls="--", lw=1)
    top.set_ylabel("temperature (°C)")
    bottom.set_ylabel("input voltage (V)")
    bottom.set_xlabel("time since the recording started (s)")
    top.legend(fontsize=7, ncol=3)
    top.set_title(f"{recording.name}: {report.n_readings} health reads, one servo a frame ({robot.name})", fontsize=10)
    fig.tight_layout()
    fig.savefig(out, dpi=110)


def main(argv: list[str]) -> int:
    if len(argv) == 2 and argv[0] == "zero-pose":
        zero_pose(Path(argv[1]))
    elif len(argv) == 3 and argv[0] == "health":
        health(Path(argv[1]), Path(argv[2]))
    else:
        print(__doc__, file=sys.stderr)
        return 2
    print(f"wrote {argv[-1]}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
