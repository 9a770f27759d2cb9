"""``gaitbot plot``: a trajectory as one picture a person can read at a glance.

Three panels. Joint angles against time, heel strikes marked by lines a reader can see, the legend
outside the plot so it hides no curve. Foot clearance against time: each foot's distance from its sole
to the nearest ground, treads and risers alike, so the trace is continuous where a foot passes over a
kerb's edge (a height above "the ground under the foot" jumps there, as that ground does), with the
configured clearance as a line. Stick figures of the walk in the world, a few poses only (at heel
strikes, at most MAX_POSES), the far leg paler, over the ground or the terrain and the footholds.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from gaitbot.gait.footfall import CONTACT_TOL_FRACTION, heel_strikes_from_heights
from gaitbot.gait.geometry import LegGeometry, leg_points
from gaitbot.gait.joints import LEG_JOINT_KINDS, PITCH_JOINTS, SIDES
from gaitbot.gait.trajectory import HeelStrike, Trajectory

_COLOURS = {"left": "tab:blue", "right": "tab:red"}
MAX_POSES = 16  # stick figures drawn at most (evenly chosen among the heel strikes)
#: Which way each joint kind's angle grows (gaitbot/gait/joints.py gives the signs).
JOINT_SENSE = {"hip_yaw": "toe out", "hip_roll": "abduction", "hip_pitch": "flexion", "knee_pitch": "flexion",
               "ankle_pitch": "flexion", "ankle_roll": "hip roll's sense"}
GROUND = "saddlebrown"


def _world_points(geometry: LegGeometry, trajectory: Trajectory, side: int):
    q = trajectory.angles_of(PITCH_JOINTS)[:, 3 * side:3 * side + 3]
    knee, ankle, heel, toe = leg_points(geometry, q[:, 0], q[:, 1], q[:, 2])
    root = trajectory.root_xz_m
    return root, knee + root, ankle + root, heel + root, toe + root


def ground_profile(terrain, x_lo: float, x_hi: float) -> np.ndarray:
    """The ground as a polyline (k, 2) from x_lo to x_hi: treads and the risers between them (flat: y = 0)."""
    if terrain is None:
        return np.array([[x_lo, 0.0], [x_hi, 0.0]])
    points = []
    for surface in terrain.surfaces:
        a, b = max(surface.start, x_lo), min(surface.end, x_hi)
        if a < b:
            points += [[a, surface.height], [b, surface.height]]
    return np.array(points)


def _point_segment_distance(p, a, b):
    """Distance from points p (n, 2) to segments a-b (n, 2)."""
    ab = b - a
    length2 = np.maximum((ab * ab).sum(axis=-1), 1e-300)
    u = np.clip(((p - a) * ab).sum(axis=-1) / length2, 0.0, 1.0)
    return np.hypot(*(p - a - u[..., None] * ab).T)


def sole_clearance(heel, toe, profile: np.ndarray) -> np.ndarray:
    """Per frame, the distance from the sole (segment heel-toe) to the ground polyline; 0 where they touch."""
    n = len(heel)
    best = np.full(n, np.inf)
    for a, b in zip(profile[:-1], profile[1:]):
        a_, b_ = np.broadcast_to(a, (n, 2)), np.broadcast_to(b, (n, 2))
        d = np.minimum.reduce([_point_segment_distance(heel, a_, b_), _point_segment_distance(toe, a_, b_),
                               _point_segment_distance(a_, heel, toe), _point_segment_distance(b_, heel, toe)])
        best = np.minimum(best, d)
    return best


def _foot_lows(geometry: LegGeometry, trajectory: Trajectory, terrain=None) -> dict[str, np.ndarray]:
    """Lowest sole point of each foot above the ground under it, metres (heel strikes are read from these)."""
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


def _mark_strikes(ax, heel_strikes, label: bool) -> None:
    for i, strike in enumerate(heel_strikes):
        ax.axvline(strike.t_s, color=_COLOURS[strike.leg], lw=1.0, ls="--", alpha=0.75, zorder=0,
                   label=f"{strike.leg} heel strike" if label and strike.leg not in
                   {h.leg for h in heel_strikes[:i]} else None)


def plot_trajectory(trajectory: Trajectory, geometry: LegGeometry, out: Path, clearance: float = 0.0,
                    title: str = "", terrain=None) -> None:
    """``terrain`` (a gaitbot.gait.terrain.model.Terrain), when given, is drawn under the walk; clearances
    are then measured to the terrain and footholds sit on their treads."""
    import matplotlib.pyplot as plt

    fig = trajectory_figure(trajectory, geometry, clearance, title, terrain)
    fig.savefig(out, dpi=100)
    plt.close(fig)


def trajectory_figure(trajectory: Trajectory, geometry: LegGeometry, clearance: float = 0.0, title: str = "",
                      terrain=None):
    """The picture of ``plot_trajectory`` as a matplotlib figure (the caller closes it)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    t = trajectory.t_s
    heel_strikes = trajectory.heel_strikes or _detected_heel_strikes(geometry, trajectory,
                                                                     _foot_lows(geometry, trajectory, terrain))
    fig = plt.figure(figsize=(13, 10), constrained_layout=True)
    grid = fig.add_gridspec(3, 1, height_ratios=[1.2, 0.8, 1.1])
    ax_angles, ax_feet, ax_stick = (fig.add_subplot(grid[i]) for i in range(3))
    ax_feet.sharex(ax_angles)

    for i, name in enumerate(trajectory.joints):
        side = "left" if name.endswith("left") else "right"
        style = {"hip": "-", "knee": "--", "ankle": ":"}[name.split("_")[0]]
        if "_pitch" not in name:
            style = "-."  # roll and yaw
        ax_angles.plot(t, np.degrees(trajectory.angles_rad[:, i]), style, color=_COLOURS[side], lw=1.3,
                       label=name.replace("_pitch", "").replace("_", " "))
    _mark_strikes(ax_angles, heel_strikes, label=True)
    ax_angles.set_ylabel("joint angle (deg, flexion +)")
    ax_angles.legend(fontsize=8, loc="upper left", bbox_to_anchor=(1.005, 1.0), borderaxespad=0.0)
    ax_angles.set_title(f"{title}  {len(t)} frames, {t[-1]:.2f} s, "
                        f"{trajectory.root_m[-1, 0] - trajectory.root_m[0, 0]:.3f} m")
    ax_angles.grid(alpha=0.3)

    xs = np.concatenate([_world_points(geometry, trajectory, side)[k][:, 0] for side in (0, 1) for k in (3, 4)])
    profile = ground_profile(terrain, float(xs.min()) - 0.1, float(xs.max()) + 0.1)
    for side, name in ((0, "left"), (1, "right")):
        _, _, _, heel, toe = _world_points(geometry, trajectory, side)
        ax_feet.plot(t, 1000 * sole_clearance(heel, toe, profile), color=_COLOURS[name], lw=1.3, label=f"{name} foot")
    if clearance > 0:
        ax_feet.axhline(1000 * clearance, color="k", ls=":", lw=1.0, label=f"clearance {1000 * clearance:.0f} mm")
    _mark_strikes(ax_feet, heel_strikes, label=False)
    ax_feet.set_ylabel("sole to ground (mm)" if terrain is None else "sole to terrain (mm)\ntreads and risers")
    ax_feet.set_xlabel("time (s)")
    ax_feet.legend(fontsize=8, loc="upper left", bbox_to_anchor=(1.005, 1.0), borderaxespad=0.0)
    ax_feet.grid(alpha=0.3)

    strikes = [int(round(h.t_s / (t[1] - t[0]))) for h in heel_strikes]
    marks = sorted({0, *strikes, len(t) - 1})
    frames = [marks[int(round(i))] for i in np.linspace(0, len(marks) - 1, min(MAX_POSES, len(marks)))]
    for side, name, alpha in ((1, "right", 0.95), (0, "left", 0.45)):  # the far (left) leg paler, drawn behind
        root, knee, ankle, heel, toe = _world_points(geometry, trajectory, side)
        for k in frames:
            xs_ = [root[k, 0], knee[k, 0], ankle[k, 0], heel[k, 0], toe[k, 0], ankle[k, 0]]
            ys_ = [root[k, 1], knee[k, 1], ankle[k, 1], heel[k, 1], toe[k, 1], ankle[k, 1]]
            ax_stick.plot(xs_, ys_, color=_COLOURS[name], lw=1.4, alpha=alpha, solid_joinstyle="round")
    ax_stick.plot(trajectory.root_m[:, 0], trajectory.root_m[:, 2], color="k", lw=0.8, label="hip path")
    bottom = float(profile[:, 1].min()) - 0.02
    ax_stick.fill_between(profile[:, 0], profile[:, 1], bottom, color=GROUND, alpha=0.25, lw=0)
    ax_stick.plot(profile[:, 0], profile[:, 1], color=GROUND, lw=1.5, label="ground" if terrain is None else "terrain")
    ground = (lambda x: float(terrain.height_at(x))) if terrain is not None else (lambda x: 0.0)  # noqa: E731
    for leg in ("left", "right"):
        xs_ = [h.x_m for h in heel_strikes if h.leg == leg]
        ax_stick.plot(xs_, [ground(x) for x in xs_], ls="none", marker="^", color=_COLOURS[leg], ms=8,
                      label=f"{leg} foothold")
    ax_stick.set_ylim(bottom, None)
    ax_stick.set_aspect("equal")
    ax_stick.set_xlabel(f"x (m): poses at {len(frames)} heel strikes (right leg dark, left pale)")
    ax_stick.set_ylabel("z (m)")
    ax_stick.legend(fontsize=8, loc="upper left", bbox_to_anchor=(1.005, 1.0), borderaxespad=0.0)
    return fig


#: A joint whose mean cycle and eigen-motions stay within this many degrees of a constant is not drawn
#: (a hip yaw a straight walk never turns): the title says so instead.
STILL_JOINT_DEG = 1e-6


def eigen_model_columns(model, mean_deg: np.ndarray, deltas_deg) -> tuple[list, list]:
    """The columns of the model picture: one per joint kind the model moves (LEG_JOINT_KINDS order), each
    drawing that joint of both legs, and the joints left out because they do not move ((name, angle))."""
    kinds, still = [], []
    for kind in LEG_JOINT_KINDS:
        names = [f"{kind}_{side}" for side in SIDES if f"{kind}_{side}" in model.joints]
        if not names:
            continue
        moving = False
        for name in names:
            c = model.joints.index(name)
            span = np.ptp(mean_deg[:, c]) + max((np.abs(d[:, c]).max() for d in deltas_deg), default=0.0)
            if span > STILL_JOINT_DEG:
                moving = True
            else:
                still.append((name, float(mean_deg[0, c])))
        if moving:
            kinds.append(kind)
    return kinds, still


def plot_eigen_model(model_path, out: Path, n_show: int = 3) -> None:
    """Eigen-motions of an eigen-gait model (Li et al. 2009 Fig. 3): per eigen-motion (rows), each joint's mean
    cycle (solid) and mean +- 2 sqrt(eigenvalue) times the eigen-motion (dashed +, dotted -), one column
    per joint kind the model moves, both legs in each. A joint that does not move in any example is left
    out and named in the title with its angle."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from gaitbot.gait.eigen import EigenGaitModel

    model = EigenGaitModel.load(model_path)
    k = min(n_show, len(model.eigenvalues))
    s = np.linspace(0.0, 1.0, 201)
    mean = np.degrees(model.poses(s, np.zeros(0)))
    deltas = [2.0 * np.sqrt(model.eigenvalues[i]) * np.degrees(model.eigen_motion(s, i)) for i in range(k)]
    kinds, still = eigen_model_columns(model, mean, deltas)
    columns = max(1, len(kinds))
    fig, axes = plt.subplots(k, columns, figsize=(13 * max(1.0, columns / 3), 3.2 * k + 0.6), sharex=True,
                             squeeze=False, constrained_layout=True)
    share = model.variance_explained
    for i in range(k):
        delta = deltas[i]
        for j, kind in enumerate(kinds):
            joint = kind.replace("_pitch", "").replace("_", " ")
            ax = axes[i, j]
            for side, colour in ((0, "tab:blue"), (1, "tab:red")):
                name = f"{kind}_{SIDES[side]}"
                if name not in model.joints:
                    continue
                c = model.joints.index(name)
                ax.plot(100 * s, mean[:, c], color=colour, lw=1.5, label=f"{joint} {SIDES[side]} mean")
                ax.plot(100 * s, mean[:, c] + delta[:, c], "--", color=colour, lw=1.0)
                ax.plot(100 * s, mean[:, c] - delta[:, c], ":", color=colour, lw=1.0)
            ax.grid(alpha=0.3)
            if i == 0:
                ax.set_title(f"{joint} (deg, {JOINT_SENSE[kind]} +)")
            if j == 0:
                kept = " (kept)" if i < model.n_components else ""
                ax.set_ylabel(f"eigen-motion {i + 1}{kept}\n{100 * share[i]:.1f}% of variance")
            if i == k - 1:
                ax.set_xlabel("aligned cycle phase (%), 0 = left heel strike")
    from matplotlib.lines import Line2D

    handles = [Line2D([], [], color="tab:blue", lw=1.5, label="left leg"),
               Line2D([], [], color="tab:red", lw=1.5, label="right leg"),
               Line2D([], [], color="k", lw=1.5, label="mean cycle"),
               Line2D([], [], color="k", lw=1.0, ls="--", label="mean + 2 sd x eigen-motion"),
               Line2D([], [], color="k", lw=1.0, ls=":", label="mean - 2 sd x eigen-motion")]
    fig.legend(handles=handles, loc="outside lower center", ncol=5, fontsize=9)
    labels = ", ".join(f"{v:g}" for v in sorted(set(np.round(model.labels, 4))))
    title = (f"{Path(str(model_path)).name}: the eigen-motions of {len(model.labels)} example cycles, step "
             f"lengths {labels} m")
    if still:
        title += ("\nnot drawn, still in every example: "
                  + ", ".join(f"{name} ({round(value, 6) + 0.0:g} deg)" for name, value in still))
    fig.suptitle(title, fontsize=10)
    fig.savefig(out, dpi=100)
    plt.close(fig)
