"""The commands of a steered walk over time, drawn under its balance picture (gaitbot.plot.balance).

Times are the walk's: the command clock starts when the robot starts stepping (docs/steering.md), after the
rise, the crouch and the start pause, COMMAND_CLOCK_START_S into the walk.
"""

from __future__ import annotations

import numpy as np

from gaitbot.gait.balance.step_plan import RISE_S, SETTLE_S, START_PAUSE_S

COMMAND_CLOCK_START_S = RISE_S + SETTLE_S + START_PAUSE_S


def draw_commands(ax, commands, end_s: float) -> None:
    """vx, vy (m/s, left axis) and wz (deg/s, right axis) as steps over the walk's time; the stop marked."""
    times, vx, vy, wz = [], [], [], []
    stop = None
    for c in commands:
        if c.stop:
            stop = c.t_s + COMMAND_CLOCK_START_S
            continue
        times.append(c.t_s + COMMAND_CLOCK_START_S)
        vx.append(c.command.vx_m_s)
        vy.append(c.command.vy_m_s)
        wz.append(c.command.wz_deg_s)
    last = stop if stop is not None else end_s
    t = np.array(times + [last])
    for values, label, colour in ((vx, "vx (m/s)", "tab:blue"), (vy, "vy (m/s)", "tab:green")):
        ax.step(t, values + values[-1:], where="post", color=colour, lw=1.2, label=label)
    turn = ax.twinx()
    turn.step(t, wz + wz[-1:], where="post", color="tab:red", lw=1.2, label="wz (deg/s)")
    turn.set_ylabel("wz (deg/s)")
    if stop is not None:
        ax.axvline(stop, color="k", lw=0.8, ls="--", label="stop")
    ax.set_xlim(0.0, end_s)
    ax.set_ylabel("vx, vy (m/s)")
    ax.set_xlabel(f"time (s); the commands' clock starts at {COMMAND_CLOCK_START_S:.1f} s, when stepping starts")
    lines = ax.get_legend_handles_labels()
    more = turn.get_legend_handles_labels()
    ax.legend(lines[0] + more[0], lines[1] + more[1], ncol=4, fontsize=8, loc="upper right")
    ax.grid(alpha=0.3)
