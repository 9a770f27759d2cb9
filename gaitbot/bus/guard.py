"""The last line of defence: no goal outside a joint's limits ever reaches a servo.

Every trajectory is limit-checked before a walk starts, but a session also writes goals of its
own: the present pose before torque on, the ramp to the first pose, the braking stop. A servo
found outside its limits (a robot left in an odd pose) would make those leave the limits. This
layer checks every goal write against per-servo tick limits and raises before any byte is
sent; the session then stops as for any bus error. It is a plain bus layer (gaitbot.bus.base.BusLayer):
the same interface as any bus, and only the one goal-writing method of its own.
"""

from __future__ import annotations

from collections.abc import Mapping

from gaitbot.bus.base import Bus, BusError, BusLayer


class GoalOutsideLimits(BusError):
    """A goal write would move a servo outside its configured limits; nothing was sent."""


class LimitGuard(BusLayer):
    """A bus that refuses goal writes outside ``limits`` = {servo id: (lowest tick, highest tick)}.

    ``names`` (servo id -> joint name) only makes the message readable. Settings (``write_register``) are
    not goals: they pass, and the backend refuses a write to the goal or torque register.
    """

    def __init__(self, bus: Bus, limits: Mapping[int, tuple[int, int]], names: Mapping[int, str] | None = None) -> None:
        super().__init__(bus)
        self.limits = dict(limits)
        self.names = dict(names or {})

    def write_goal_ticks(self, goals: Mapping[int, int]) -> None:
        limits = self.limits
        for servo_id, tick in goals.items():
            low, high = limits.get(servo_id, (None, None))
            if low is None:
                raise GoalOutsideLimits(f"goal for servo {servo_id}, which has no configured limits; nothing sent",
                                        servo_id=servo_id)
            if not low <= tick <= high:
                name = self.names.get(servo_id, f"servo {servo_id}")
                raise GoalOutsideLimits(
                    f"refused a goal of {tick} ticks for {name} (servo {servo_id}), outside its limits {low}..{high} "
                    f"ticks; nothing sent. If the servo is there now, move the joint by hand inside its limits",
                    servo_id=servo_id)
        self.inner.write_goal_ticks(goals)
