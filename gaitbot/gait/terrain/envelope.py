"""What one step of a leg can do between two surfaces: the envelope the planner and the course check share.

Three numbers per robot, measured by ``tools/terrain_envelope.py`` (it walks stairs, kerbs and
ditches with the generator itself and bisects) and kept in the robot config's ``[terrain]``
table:

- ``max_rise``: the highest step up between surfaces a foot stands on (stairs up at the shortest
  going, a kerb);
- ``max_drop``: the deepest step down;
- ``max_gap``: the widest stretch of ground no foot can stand on (a ditch, or treads too short for
  a foot) stepped over between two surfaces at one level.

From them, the longest heel-to-heel step between two surfaces ``rise`` apart (``step_limit``):
``reference_step + max_gap`` on the level, falling to ``reference_step`` at the largest rise or
drop as (1 - rise / largest)^2 (a long step and a large rise together ask for both the reach and
the lift: measured, that falls faster than linearly), where ``reference_step`` is the shortest
step from one tread to the next (a foot plus its margin at both ends, with the margin the
envelope was measured at). The same limit holds for a
swing from lift-off to landing, so steep steps are taken one at a time (step-to), as a small
child climbs stairs.

``course_problems`` reads a course the way the planner will walk it and names the first tread
(or piece of ground) the leg cannot manage and why, so that a course is refused before any
planning with one line saying where; a course it accepts is one the planner can walk.
"""

from __future__ import annotations

from dataclasses import dataclass

from .model import Surface, Terrain

REFERENCE_MARGIN_M = 0.01  # the margin (heel and toe from a tread's edges) envelopes are measured at
DEFAULT_SHARE = 0.08  # a robot without a measured envelope: rise, drop and gap of this many leg lengths


@dataclass(frozen=True)
class StepEnvelope:
    """A leg's step envelope in metres (see the module docstring)."""

    max_rise: float
    max_drop: float
    max_gap: float
    reference_step: float  # foot + 2 * REFERENCE_MARGIN_M
    who: str = "this leg"  # for messages: "max 0.045 m for xl430-biped"

    @classmethod
    def for_foot(cls, foot: float, max_rise: float, max_drop: float, max_gap: float,
                 who: str = "this leg") -> StepEnvelope:
        return cls(max_rise, max_drop, max_gap, foot + 2 * REFERENCE_MARGIN_M, who)

    @classmethod
    def default(cls, foot: float, leg_length: float, who: str = "this leg") -> StepEnvelope:
        """For a robot whose envelope was never measured: DEFAULT_SHARE leg lengths each way."""
        share = DEFAULT_SHARE * leg_length
        return cls.for_foot(foot, share, share, share, who)

    def step_limit(self, rise: float) -> float:
        """Longest heel-to-heel step (or swing) between surfaces ``rise`` apart (up positive); -1 if the rise
        itself is beyond the envelope."""
        top = self.max_rise if rise > 0 else self.max_drop
        size = abs(rise)
        if size > top + 1e-12:
            return -1.0
        share = size / top if size > 0 else 0.0
        return self.reference_step + self.max_gap * (1.0 - share) ** 2

    @property
    def longest(self) -> float:
        return self.reference_step + self.max_gap


def holds_foot(surface: Surface, foot: float, margin: float) -> bool:
    """Whether a whole foot fits on the surface with ``margin`` to spare at both ends."""
    return surface.end - surface.start >= foot + 2 * margin - 1e-9


def course_problems(terrain: Terrain, start: float, end: float, foot: float, margin: float,
                    envelope: StepEnvelope) -> str | None:
    """The first place between ``start`` and ``end`` the leg cannot step, as ``<where>: <why>``; None if none.

    Surfaces that hold a foot are stood on; everything between two of them is stepped over. Between
    consecutive ones the step must be within the envelope: the rise or drop, the width stepped over
    (plus a foot and its margins) against ``step_limit``, and nothing in between standing higher
    above the higher of the two than the largest rise."""
    surfaces = terrain.surfaces
    stood = [i for i, s in enumerate(surfaces) if holds_foot(s, foot, margin) and s.end > start and s.start < end + foot]
    for a, b in zip(stood, stood[1:]):
        here, there = surfaces[a], surfaces[b]
        if there.start > end + foot + margin:
            break
        where = _name(there, surfaces, b)
        rise = there.height - here.height
        between = surfaces[a + 1:b]
        short = [s for s in between if s.tread]
        too_short = (f"; {_names(short)} before it {'is' if len(short) == 1 else 'are'} too short to stand on "
                     f"(a foot needs {foot + 2 * margin:.4g} m)") if short else ""
        if rise > envelope.max_rise + 1e-12:
            return (f"{where}: rise {rise:.4g} m exceeds what this leg can step (max {envelope.max_rise:.4g} m "
                    f"for {envelope.who}){too_short}")
        if -rise > envelope.max_drop + 1e-12:
            return (f"{where}: drop {-rise:.4g} m exceeds what this leg can step down (max {envelope.max_drop:.4g} m "
                    f"for {envelope.who}){too_short}")
        if between:
            top = max(s.height for s in between) - max(here.height, there.height)
            if top > envelope.max_rise + 1e-12:
                tall = max(between, key=lambda s: s.height)
                return (f"{_name(tall, surfaces, surfaces.index(tall))}: stands {top:.4g} m above its neighbours, "
                        f"more than this leg can step over (max {envelope.max_rise:.4g} m for {envelope.who})")
        gap = there.start - here.end
        needed = gap + foot + 2 * margin
        limit = envelope.step_limit(rise)
        if needed > limit + 1e-9:
            what = "a gap" if gap > 1e-9 else "a step"
            return (f"{where}: {what} of {gap:.4g} m to step over at a rise of {rise:+.4g} m needs a step of "
                    f"{needed:.4g} m (heel to heel, margins {margin:g} m), longer than the {limit:.4g} m this leg "
                    f"can step there (widest gap on the level {envelope.max_gap:.4g} m for {envelope.who})"
                    f"{too_short}")
    return None


def _names(pieces) -> str:
    numbers = [p.tread for p in pieces]
    if len(numbers) == 1:
        return f"tread {numbers[0]}"
    if numbers == list(range(numbers[0], numbers[-1] + 1)):
        return f"treads {numbers[0]} to {numbers[-1]}"
    return "treads " + ", ".join(str(n) for n in numbers)


def _name(surface: Surface, surfaces, index: int) -> str:
    if surface.tread:
        return f"tread {surface.tread}"
    before = next((s.tread for s in reversed(surfaces[:index]) if s.tread), 0)
    return f"the ground after tread {before}" if before else "the ground"
