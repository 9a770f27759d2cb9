"""Offline steering: timed commands -> the walk's footsteps (``--velocity``/``--duration``, ``--commands``).

The command clock starts when the robot starts stepping (the first step's weight shift; the rise and
crouch before it are not counted), so a command of v for S seconds asks for v S of travel. Each step is
planned from the command that holds when it starts (as a live drive plans each step from the latest
command); after the stop (a ``stop`` entry, or the end of ``--duration``) the planner slows down within
its change limits and closes the feet side by side. A still command that is not the last entry steps in
place until the next one.
"""

from __future__ import annotations

import bisect
from dataclasses import dataclass

from gaitbot.gait.steer.command import STILL, CommandError, TimedCommand, VelocityCommand
from gaitbot.gait.steer.planner import Footstep, FootstepPlanner, leading_side

OTHER = {"left": "right", "right": "left"}


@dataclass(frozen=True)
class CommandSchedule:
    """Timed commands ending in a stop (``end_s``): the command at any time of the command clock."""

    commands: tuple[TimedCommand, ...]
    end_s: float

    @classmethod
    def of(cls, commands, source: str) -> "CommandSchedule":
        """From parsed JSON Lines: the walk stops at the stop entry, or at a last still command."""
        commands = tuple(commands)
        last = commands[-1]
        if not (last.stop or last.command.is_still):
            raise CommandError(f"{source}: the last entry (t {last.t_s:g} s) keeps the robot moving; end the walk "
                               f"with a stop entry like {{\"t\": {last.t_s + 5:g}, \"stop\": true}}")
        return cls(tuple(c for c in commands if not c.stop), last.t_s)

    @classmethod
    def steady(cls, command: VelocityCommand, duration_s: float) -> "CommandSchedule":
        """``--velocity`` for ``--duration`` seconds, then stop."""
        return cls((TimedCommand(0.0, command),), duration_s)

    def at(self, t_s: float) -> VelocityCommand | None:
        """The command holding at t_s, or None from the stop on."""
        if t_s >= self.end_s:
            return None
        k = bisect.bisect_right([c.t_s for c in self.commands], t_s) - 1
        return STILL if k < 0 else self.commands[k].command


GAP_TOLERANCE_M = 1e-4
"""A planned step's soles may come this much closer than min_gap_m (float noise of the swept gap)."""


def plan_footsteps(planner: FootstepPlanner, schedule: CommandSchedule, first_step_s: float, step_s: float,
                   max_steps: int) -> list[Footstep]:
    """Every step of a walk under ``schedule``: the first lasts ``first_step_s`` (its double support shifts
    the weight), the others ``step_s``; the walk ends when the stop has brought the feet side by side.
    More than ``max_steps`` steps is refused (bounded work whatever the file asks)."""
    steps: list[Footstep] = []
    t_s, side = 0.0, None
    while True:
        command = schedule.at(t_s)
        stopped = command is None
        if stopped and planner.standing():
            return steps
        if len(steps) >= max_steps:
            raise CommandError(f"the commands ask for more than the {max_steps} steps one walk may have "
                               f"(the stop comes at {schedule.end_s:g} s)")
        command = STILL if stopped else command
        side = leading_side(command) if side is None else OTHER[side]
        step = planner.next_step(command, side)
        if step.gap_m < planner.limits.min_gap_m - GAP_TOLERANCE_M:  # the planner's last resort came too close
            raise CommandError(f"step {len(steps) + 1} (at {t_s:.2f} s) would bring the soles {step.gap_m * 1e3:.1f} mm "
                               f"apart, closer than the robot's [steer] min_gap_m ({planner.limits.min_gap_m * 1e3:g} mm)")
        steps.append(step)
        t_s += first_step_s if len(steps) == 1 else step_s
