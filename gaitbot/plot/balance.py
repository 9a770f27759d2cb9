"""``gaitbot plot`` for a 3D walk: where the robot stands and why it does not fall, at a glance.

Three panels: the joint angles against time (left leg solid, right leg dashed), a top view of the
footprints with the support polygons, the ZMP path and the centre of mass's path (check/balance.py
computes them from the robot's mass model, as ``gaitbot check`` does), and the torso's roll, pitch
and yaw against time (zero where the gait keeps the torso upright).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from gaitbot.check.balance import balance_trace
from gaitbot.check.preflight import robot_angles_deg
from gaitbot.gait.joints import LEG_JOINT_KINDS
from gaitbot.gait.trajectory import Trajectory
from gaitbot.robot.config import RobotConfig
from gaitbot.plot.steer import draw_commands

_COLOURS = {"left": "tab:blue", "right": "tab:red"}
_KIND_COLOURS = dict(zip(LEG_JOINT_KINDS, ("tab:gray", "tab:purple", "tab:blue", "tab:orange", "tab:green",
                                           "tab:brown")))


def _footprints(trace, side: str) -> list[np.ndarray]:
    """The sole outlines (4, 2) where the foot stood flat on the ground, each place once."""
    corners = trace.soles[side]
    flat = np.all(np.abs(corners[:, :, 2]) < 1e-3, axis=1)
    seen, out = set(), []
    for k in np.flatnonzero(flat):
        key = tuple(np.round(corners[k, :, :2].mean(axis=0), 3))
        if key not in seen:
            seen.add(key)
            out.append(corners[k, :, :2])
    return out


def plot_balance(trajectory: Trajectory, config: RobotConfig, out: Path, title: str = "", commands=None) -> None:
    """Joint angles, the top view (footprints as the forward kinematics turns them, CoM, ZMP, support) and
    the torso's attitude where the walk turns it (a torso held upright throughout gets no empty panel, the
    top view's title says so); with ``commands`` (a steered walk's timed commands) a panel of them."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.patches import Polygon

    trace = balance_trace(config, trajectory, robot_angles_deg(config, trajectory))
    t = trajectory.t_s
    rpy = None if trajectory.torso_rpy_rad is None else np.degrees(trajectory.torso_rpy_rad)
    turns = rpy is not None and bool(np.any(np.abs(rpy) > 1e-9))
    heights = [1.0, 1.3] + [0.6] * turns + [0.6] * (commands is not None)
    fig = plt.figure(figsize=(12, 4.4 + 2.6 * len(heights)), constrained_layout=True)
    grid = fig.add_gridspec(len(heights), 1, height_ratios=heights)
    ax_angles, ax_top = fig.add_subplot(grid[0]), fig.add_subplot(grid[1])
    if commands is not None:
        draw_commands(fig.add_subplot(grid[len(heights) - 1]), commands, float(t[-1]))

    for i, name in enumerate(trajectory.joints):
        kind, side = name.rsplit("_", 1)
        ax_angles.plot(t, np.degrees(trajectory.angles_rad[:, i]), "-" if side == "left" else "--",
                       color=_KIND_COLOURS[kind], lw=1.1, label=kind if side == "left" else None)
    for strike in trajectory.heel_strikes:
        ax_angles.axvline(strike.t_s, color=_COLOURS[strike.leg], lw=0.8, alpha=0.6)
    ax_angles.set_ylabel("joint angle (deg)")
    ax_angles.set_xlabel("time (s); left leg solid, right dashed; vertical lines: heel strikes")
    ax_angles.legend(ncol=6, fontsize=8, loc="lower center", bbox_to_anchor=(0.5, 1.0), frameon=False)
    ax_angles.grid(alpha=0.3)
    ax_angles.set_title(f"{title}  {config.name}: {len(t)} frames, {t[-1]:.2f} s, "
                        f"{trajectory.root_m[-1, 0] - trajectory.root_m[0, 0]:.3f} m", pad=22)

    for side in ("left", "right"):
        for outline in _footprints(trace, side):
            ax_top.add_patch(Polygon(outline, closed=True, facecolor=_COLOURS[side], alpha=0.15,
                                     edgecolor=_COLOURS[side], lw=0.8))
    single = [k for k, hull in enumerate(trace.support) if len(hull) == 4]
    double = [k for k, hull in enumerate(trace.support) if len(hull) > 4]
    for frames, style in ((single[::12], ":"), (double[::12], "-")):
        for k in frames:
            hull = trace.support[k]
            ax_top.plot(*np.vstack([hull, hull[:1]]).T, style, color="0.5", lw=0.6)
    ax_top.plot(trace.com_m[:, 0], trace.com_m[:, 1], color="k", lw=1.2, label="centre of mass")
    ax_top.plot(trace.zmp_m[:, 0], trace.zmp_m[:, 1], color="tab:green", lw=1.2, label="ZMP")
    outside = trace.margin_m < 0
    if outside.any():
        ax_top.plot(trace.zmp_m[outside, 0], trace.zmp_m[outside, 1], "x", color="crimson", ms=5,
                    label=f"ZMP outside the support ({outside.sum()} frames)")
    ax_top.plot([], [], ":", color="0.5", lw=0.6, label="support polygon (one foot)")
    ax_top.plot([], [], "-", color="0.5", lw=0.6, label="support polygon (both feet)")
    ax_top.set_aspect("equal", adjustable="datalim")
    ax_top.set_xlabel("x forward (m)")
    ax_top.set_ylabel("y left (m)")
    k = int(np.argmin(trace.margin_m))
    ax_top.set_title(f"top view: footprints (left blue, right red); least ZMP margin "
                     f"{1e3 * trace.margin_m[k]:.1f} mm at t={t[k]:.2f} s"
                     + ("" if turns else "; the torso stays upright throughout"), fontsize=10)
    ax_top.legend(fontsize=8, loc="upper left", ncol=3)
    ax_top.grid(alpha=0.3)

    if turns:
        ax_torso = fig.add_subplot(grid[2])
        for j, (name, colour) in enumerate((("roll", "tab:purple"), ("pitch", "tab:orange"), ("yaw", "tab:gray"))):
            ax_torso.plot(t, rpy[:, j], color=colour, lw=1.2, label=name)
        ax_torso.set_ylabel("torso (deg)")
        ax_torso.set_xlabel("time (s)")
        ax_torso.legend(ncol=3, fontsize=8, loc="upper right")
        ax_torso.grid(alpha=0.3)
    fig.savefig(out, dpi=110)
    plt.close(fig)
