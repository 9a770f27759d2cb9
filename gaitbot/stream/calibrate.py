"""Calibrating a robot by hand: torque off, the zero pose read, then each joint bent in its positive direction.

The stream room's vocabulary (servo ids, ticks, a Bus); the words and the file are the caller's
(gaitbot/app/calibrate.py). Sequence (:func:`calibrate_session`): open, ping every joint's servo and read
where it is (a missing servo stops here, nothing written), check each servo's model number against the
config, ``confirm`` torque off, torque off (the only write), ``ask`` for the zero pose and read every
servo: those ticks are the zero ticks; then for each joint ``ask`` that it be bent in its positive
direction and read every servo again: the sign of the joint's change is its direction, the size the range
moved. Joints bent at earlier steps may be held or let back; another joint that is neither is reported. Every step reads each servo exactly once, so a scripted hand (the emulator's, one sample per read
cycle) gives the same answer whatever the timing. Torque stays off at the end.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass

from gaitbot.bus.base import Bus
from gaitbot.errors import UserError
from gaitbot.stream.session import prepare

#: A bend smaller than this (degrees) is taken for a joint that was not moved.
MIN_BEND_DEG = 5.0
#: Another joint moving more than this (degrees) during a bend is reported: was the right joint bent?
OTHERS_STILL_DEG = 3.0


class CalibrationStopped(UserError):
    """The calibration cannot go on (a joint was not bent, a servo is not the config's model, no answer on
    standard input); nothing was written to a file. One line, exit 2: the person can fix it and run again."""


@dataclass(frozen=True)
class CalibrationJoint:
    """A joint to calibrate: its name, servo id, model (a ServoModel) and configured limits (degrees)."""

    name: str
    id: int
    model: object
    min_deg: float
    max_deg: float


@dataclass(frozen=True)
class JointResult:
    """One joint as measured: zero tick, direction (+1/-1), how far it was bent (degrees), and notes."""

    name: str
    id: int
    model_name: str
    zero_tick: int
    direction: int
    moved_deg: float
    notes: tuple[str, ...] = ()


def tick_delta(model, before: int, after: int) -> int:
    """``after - before`` in ticks; on a full-circle encoder the short way round the seam."""
    delta = int(after) - int(before)
    if model.wraps:
        half = model.resolution_ticks // 2
        delta = (delta + half) % model.resolution_ticks - half
    return delta


def calibrate_session(bus: Bus, joints: Sequence[CalibrationJoint], *, ask: Callable[[str, str], None],
                      confirm: Callable[[int], bool], words: Callable[[str], str]) -> list[JointResult] | None:
    """Run the calibration (module docstring). ``ask(step, text)`` waits for the person (step "zero" or a
    joint name); ``confirm(n)`` asks whether n servos may go limp (False: nothing written, None returned);
    ``words(joint)`` says how to move a joint positively. Raises CalibrationStopped, or the bus's errors."""
    ids = [j.id for j in joints]
    bus.open()
    try:
        prepare(bus, ids)
        numbers = bus.model_numbers
        for j in joints:
            number = numbers.get(j.id)
            if number is not None and number != j.model.model_number:
                raise CalibrationStopped(f"servo {j.id} ({j.name}) reports model number {number}, but the config "
                                         f"says {j.model.name} ({j.model.model_number}); is it the right servo?")
        if not confirm(len(ids)):
            return None
        bus.set_torque(ids, False)
        ask("zero", "")
        zero = bus.read_present_ticks(ids)
        results = []
        before = zero
        for j in joints:
            ask(j.name, words(j.name))
            bent = bus.read_present_ticks(ids)
            results.append(_judge(j, joints, zero, before, bent))
            before = bent
        return results
    finally:
        bus.close()


def _degrees(joint: CalibrationJoint, before: int, after: int) -> float:
    return abs(tick_delta(joint.model, before, after)) / (joint.model.ticks_per_rad * math.pi / 180.0)


def _judge(j: CalibrationJoint, joints: Sequence[CalibrationJoint], zero: dict[int, int], before: dict[int, int],
           bent: dict[int, int]) -> JointResult:
    """Direction and range of ``j`` from the zero pose to ``bent``. Another joint is said to have moved only when
    it is neither where the last step left it (held bent, as the prompt allows) nor back at zero."""
    model = j.model
    ticks_per_deg = model.ticks_per_rad * math.pi / 180.0
    delta = tick_delta(model, zero[j.id], bent[j.id])
    moved_deg = abs(delta) / ticks_per_deg
    if moved_deg < MIN_BEND_DEG:
        raise CalibrationStopped(f"{j.name} (servo {j.id}) moved only {moved_deg:.1f} deg (at least {MIN_BEND_DEG:g} "
                                 "needed to tell its direction): bend it further and run gaitbot calibrate again")
    notes = []
    for other in joints:
        if other.id != j.id:
            from_zero = _degrees(other, zero[other.id], bent[other.id])
            from_before = _degrees(other, before[other.id], bent[other.id])
            if min(from_zero, from_before) > OTHERS_STILL_DEG:
                notes.append(f"{other.name} moved {from_before:.1f} deg too while {j.name} was bent")
    if moved_deg > j.max_deg + OTHERS_STILL_DEG:
        notes.append(f"bent {moved_deg:.1f} deg, past its configured max_deg {j.max_deg:g}: the joint reaches further "
                     "than the config lets it walk (fine), or the zero pose was not straight")
    return JointResult(j.name, j.id, model.name, int(zero[j.id]), 1 if delta > 0 else -1, moved_deg, tuple(notes))
