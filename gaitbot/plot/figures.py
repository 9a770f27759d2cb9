"""``gaitbot plot``: a trajectory as one picture a person can read at a glance.

Three panels sharing the time axis where it makes sense: joint angles against time (heel strikes
marked), foot heights against time (lowest sole point of each foot, with the clearance line), and
a stick-figure strip of the walk in the world with the footholds marked.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from gaitbot.gait.footfall import CONTACT_TOL_FRACTION, heel_strikes_from_heights
from gaitbot.gait.geometry import LegGeometry, leg_points
from gaitbot.gait.joints import PITCH_JOINTS
from gaitbot.gait.trajectory import HeelStrike, Trajectory

_COLOURS = {"left": "tab:blue", "right": "tab:red"}


def _world_points(geometry: LegGeometry, trajectory: Trajectory, side: int):
    q = trajectory.angles_of(PITCH_JOINTS)[:, 3 * side:3 * side + 3]
    knee, ankle, heel, toe = leg_points(geometry, q[:, 0], q[:, 1], q[:, 2])
    root = trajectory.root_xz_m
    return root, knee + root, ankle + root, heel + root, toe + root


def _foot_heights(geometry: LegGeometry, trajectory: Trajectory, terrain=None) -> dict[str, np.ndarray]:
    """Lowest sole point of each foot above the ground (or the terrain under it), metres."""
    lows = {}
    for side, name in ((0, "left"), (1, "right")):
        _, _, _, heel, toe = _world_points(geometry, trajectory, side)
        if terrain is not None:
            lows[name] = np.minimum(heel[:, 1] - terrain.height_at(heel[:, 0]), toe[:, 1] - terrain.height_at(toe[:, 0]))
        else:
            lows[name] = np.minimum(heel[:, 1], toe[:, 1])
    return lows


def _detected_heel_strikes(geometry: LegGeometry, trajectory: Trajectory, lows) -> tuple[HeelStrike, ...]:
    """Heel strikes of a file that carries none (CSV, recordings): footfall.py's rule on the feet's
    heights above the ground under them (the same rule ``gaitbot eigen fit`` cuts cycles with)."""
    heel_x = np.column_stack([_world_points(geometry, trajectory, side)[3][:, 0] for side in (0, 1)])
    heights = np.column_stack([lows["left"], lows["right"]])
    return tuple(heel_strikes_from_heights(trajectory.t_s, heights, heel_x, CONTACT_TOL_FRACTION * geometry.leg_length))


def plot_trajectory(trajectory: Trajectory, geometry: LegGeometry, out: Path, clearance: float = 0.0,
                    title: str = "", terrain=None) -> None:
    """``terrain`` (a gaitbot.gait.terrain.model.Terrain), when given, is drawn under the walk; foot heights
    are then measured from the terrain under each foot and footholds sit on their treads."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    t = trajectory.t_s
    lows = _foot_heights(geometry, trajectory, terrain)
    heel_strikes = trajectory.heel_strikes or _detected_heel_strikes(geometry, trajectory, lows)
    fig = plt.figure(figsize=(12, 9), constrained_layout=True)
    grid = fig.add_gridspec(3, 1, height_ratios=[1.2, 0.8, 1.0])
    ax_angles, ax_feet, ax_stick = (fig.add_subplot(grid[i]) for i in range(3))

    for i, name in enumerate(trajectory.joints):
        side = "left" if name.endswith("left") else "right"
        style = {"hip": "-", "knee": "--", "ankle": ":"}[name.split("_")[0]]
        if "_pitch" not in name:
            style = "-."  # roll and yaw
        ax_angles.plot(t, np.degrees(trajectory.angles_rad[:, i]), style, color=_COLOURS[side], lw=1.2,
                       label=name.replace("_pitch", ""))
    for strike in heel_strikes:
        ax_angles.axvline(strike.t_s, color=_COLOURS[strike.leg], lw=0.5, alpha=0.4)
    ax_angles.set_ylabel("joint angle (deg, flexion +)")
    ax_angles.legend(ncol=6, fontsize=8, loc="upper center")
    ax_angles.set_title(f"{title}  {len(t)} frames, {t[-1]:.2f} s, {trajectory.root_m[-1, 0] - trajectory.root_m[0, 0]:.3f} m"
                        f"  (vertical lines: heel strikes)")
    ax_angles.grid(alpha=0.3)

    for name, low in lows.items():
        above = " above the terrain" if terrain is not None else ""
        ax_feet.plot(t, 1000 * low, color=_COLOURS[name], label=f"{name} foot lowest point{above}")
    if clearance > 0:
        ax_feet.axhline(1000 * clearance, color="k", ls="--", lw=0.8, label=f"clearance {1000 * clearance:.0f} mm")
    ax_feet.set_ylabel("foot height (mm)")
    ax_feet.set_xlabel("time (s)")
    ax_feet.legend(fontsize=8, loc="upper right")
    ax_feet.grid(alpha=0.3)

    strikes = [int(round(h.t_s / (t[1] - t[0]))) for h in heel_strikes]
    marks = [0, *strikes, len(t) - 1]
    frames = sorted({*marks, *((a + b) // 2 for a, b in zip(marks, marks[1:]))})
    for side, name in ((0, "left"), (1, "right")):
        root, knee, ankle, heel, toe = _world_points(geometry, trajectory, side)
        for k in frames:
            xs = [root[k, 0], knee[k, 0], ankle[k, 0], heel[k, 0], toe[k, 0], ankle[k, 0]]
            ys = [root[k, 1], knee[k, 1], ankle[k, 1], heel[k, 1], toe[k, 1], ankle[k, 1]]
            ax_stick.plot(xs, ys, color=_COLOURS[name], lw=1.0, alpha=0.7)
    ax_stick.plot(trajectory.root_m[:, 0], trajectory.root_m[:, 2], color="k", lw=0.8, label="hip path")
    ground = (lambda x: float(terrain.height_at(x))) if terrain is not None else (lambda x: 0.0)  # noqa: E731
    for strike in heel_strikes:
        ax_stick.plot([strike.x_m], [ground(strike.x_m)], marker="^", color=_COLOURS[strike.leg], ms=8)
    if terrain is None:
        ax_stick.axhline(0.0, color="saddlebrown", lw=1.5)
    else:
        x0, x1 = ax_stick.get_xlim()
        px, py = [], []
        for surface in terrain.surfaces:
            a, b = max(surface.start, x0), min(surface.end, x1)
            if a < b:
                px += [a, b]
                py += [surface.height, surface.height]
        ax_stick.plot(px, py, color="saddlebrown", lw=1.5, label="terrain")
    ax_stick.set_aspect("equal")
    ax_stick.set_xlabel("x (m)   poses at each heel strike and mid-step; triangles: planned footholds (blue left, red right)")
    ax_stick.set_ylabel("y (m)")
    ax_stick.legend(fontsize=8, loc="upper left")
    fig.savefig(out, dpi=110)
    plt.close(fig)


def plot_eigen_model(model_path, out: Path, n_show: int = 3) -> None:
    """Eigen-motions of an eigen-gait model (seed 004 Fig. 3): per eigen-motion, each joint's mean
    cycle (solid) and mean +- 2 sqrt(eigenvalue) times the eigen-motion (dashed +, dotted -)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from gaitbot.gait.eigen import EigenGaitModel

    model = EigenGaitModel.load(model_path)
    k = min(n_show, len(model.eigenvalues))
    s = np.linspace(0.0, 1.0, 201)
    mean = np.degrees(model.poses(s, np.zeros(0)))
    fig, axes = plt.subplots(k, 3, figsize=(13, 3.2 * k + 0.6), sharex=True, squeeze=False, constrained_layout=True)
    share = model.variance_explained
    for i in range(k):
        delta = 2.0 * np.sqrt(model.eigenvalues[i]) * np.degrees(model.eigen_motion(s, i))
        for j, joint in enumerate(("hip", "knee", "ankle")):
            ax = axes[i, j]
            for side, colour in ((0, "tab:blue"), (1, "tab:red")):
                c = 3 * side + j
                ax.plot(100 * s, mean[:, c], color=colour, lw=1.5, label=f"{joint} {'left' if side == 0 else 'right'} mean")
                ax.plot(100 * s, mean[:, c] + delta[:, c], "--", color=colour, lw=1.0)
                ax.plot(100 * s, mean[:, c] - delta[:, c], ":", color=colour, lw=1.0)
            ax.grid(alpha=0.3)
            if i == 0:
                ax.set_title(f"{joint} (deg, flexion +)")
            if j == 0:
                kept = " (kept)" if i < model.n_components else ""
                ax.set_ylabel(f"eigen-motion {i + 1}{kept}\n{100 * share[i]:.1f}% of variance")
            if i == k - 1:
                ax.set_xlabel("aligned cycle phase (%), 0 = left heel strike")
            if i == 0 and j == 2:
                ax.legend(fontsize=7, loc="best")
    labels = ", ".join(f"{v:g}" for v in sorted(set(np.round(model.labels, 4))))
    fig.suptitle(f"{Path(str(model_path)).name}: mean cycle (solid), mean + 2 sd x eigen-motion (dashed), "
                 f"mean - 2 sd (dotted); {len(model.labels)} cycles, step lengths {labels} m", fontsize=9)
    fig.savefig(out, dpi=100)
    plt.close(fig)
