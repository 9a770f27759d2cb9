"""The last line of defence: no goal outside a joint's limits ever reaches a servo.

Every trajectory is limit-checked before a walk starts, but a session also writes goals of its
own: the present pose before torque on, the ramp to the first pose, the braking stop. A servo
found outside its limits (a robot left in an odd pose) would make those leave the limits. This
wrapper checks every goal write against per-servo tick limits and raises before any byte is
sent; the session then stops as for any bus error. It is the one check of a goal on the 60 Hz path:
the limits lie inside the servos' tick ranges, so the backend does not check again.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping

from gaitbot.bus.base import Bus, BusError, ReadBack


class GoalOutsideLimits(BusError):
    """A goal write would move a servo outside its configured limits; nothing was sent."""


class LimitGuard(Bus):
    """A Bus that refuses goal writes outside ``limits`` = {servo id: (lowest tick, highest tick)}.

    ``names`` (servo id -> joint name) only makes the message readable.
    """

    def __init__(self, bus: Bus, limits: Mapping[int, tuple[int, int]], names: Mapping[int, str] | None = None) -> None:
        self.inner = bus
        self.limits = dict(limits)
        self.names = dict(names or {})

    def __getattr__(self, name: str):  # open_notes, port, ... of the wrapped bus
        return getattr(self.inner, name)

    def open(self) -> None:
        self.inner.open()

    def close(self) -> None:
        self.inner.close()

    def ping(self, servo_id: int) -> bool:
        return self.inner.ping(servo_id)

    def scan(self, ids: Iterable[int]) -> list[int]:
        return self.inner.scan(ids)

    def set_torque(self, ids: Iterable[int], enabled: bool) -> None:
        self.inner.set_torque(ids, enabled)

    def read_present_ticks(self, ids: Iterable[int]) -> dict[int, int]:
        return self.inner.read_present_ticks(ids)

    def read_health(self, servo_id: int):
        return self.inner.read_health(servo_id)

    def read_back(self, servo_id: int, budget_s: float) -> ReadBack:
        return self.inner.read_back(servo_id, budget_s)

    def set_read_back_blocks(self, blocks: dict[int, tuple[int, int]]) -> None:
        self.inner.set_read_back_blocks(blocks)

    def read_device(self, device_id: int, address: int, length: int, budget_s: float) -> bytes | None:
        return self.inner.read_device(device_id, address, length, budget_s)

    def write_register(self, ids: Iterable[int], address: int, length: int, value: int) -> None:
        """Settings are not goals: passed on (the backend refuses a write to the goal or torque register)."""
        self.inner.write_register(ids, address, length, value)

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
        self.inner.send_goal_ticks(goals)

    def send_goal_ticks(self, goals: Mapping[int, int]) -> None:
        self.write_goal_ticks(goals)
