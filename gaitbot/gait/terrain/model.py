"""The terrain: flat treads over a ground at height 0, as a piecewise-constant height profile.

A course lists treads (start, length, height). Ground outside the listed treads is at height 0,
so the profile is a sequence of *surfaces* (flat pieces) covering the whole x axis: the treads,
and ground pieces before, between and after them. Heights are piecewise constant; at an edge
(where two surfaces meet) the height is the higher of the two, so a foot point exactly over an
edge counts as over the higher surface.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import cached_property

import numpy as np

MIN_GAP_M = 1e-3  # a gap between treads narrower than this is almost surely a typo (treads meant to touch)


class TerrainError(ValueError):
    """A terrain description is unusable; ``field`` names the offending entry (e.g. ``tread[2].length_m``)."""

    def __init__(self, field: str, reason: str) -> None:
        self.field = field
        self.reason = " ".join(str(reason).split())
        super().__init__(f"{field}: {self.reason}")


@dataclass(frozen=True)
class Tread:
    """One flat tread: x from start_m to start_m + length_m at height_m (metres)."""

    start_m: float
    length_m: float
    height_m: float

    @property
    def end_m(self) -> float:
        return self.start_m + self.length_m


@dataclass(frozen=True)
class Surface:
    """A flat piece of the profile. ``tread`` is the 1-based tread number, or 0 for the ground."""

    start: float  # may be -inf
    end: float  # may be +inf
    height: float
    tread: int

    def describe(self) -> str:
        where = f"x {self.start:.3f} to {self.end:.3f} m" if math.isfinite(self.start) and math.isfinite(self.end) else (
            f"x up to {self.end:.3f} m" if math.isfinite(self.end) else f"x from {self.start:.3f} m")
        name = f"tread {self.tread}" if self.tread else "ground"
        return f"{name} ({where}, height {self.height:.3f} m)"


@dataclass(frozen=True)
class Terrain:
    treads: tuple[Tread, ...]

    def __post_init__(self) -> None:
        for i, t in enumerate(self.treads, start=1):
            for name in ("start_m", "length_m", "height_m"):
                value = getattr(t, name)
                if not isinstance(value, (int, float)) or isinstance(value, bool) or not math.isfinite(value):
                    raise TerrainError(f"tread[{i}].{name}", f"must be a finite number of metres, got {value!r}")
            if t.length_m <= 0:
                raise TerrainError(f"tread[{i}].length_m", f"must be positive, got {t.length_m!r}")
        order = sorted(range(len(self.treads)), key=lambda i: self.treads[i].start_m)
        for a, b in zip(order, order[1:]):
            ta, tb = self.treads[a], self.treads[b]
            if tb.start_m < ta.end_m - 1e-9:
                raise TerrainError(f"tread[{b + 1}].start_m", f"{tb.start_m:g} m overlaps tread {a + 1} "
                                   f"(x {ta.start_m:g} to {ta.end_m:g} m)")
            gap = tb.start_m - ta.end_m
            if 1e-9 < gap < MIN_GAP_M:
                raise TerrainError(f"tread[{b + 1}].start_m", f"leaves a {gap * 1000:.2g} mm gap after tread {a + 1}: "
                                   f"make them touch (start_m = {ta.end_m:g}) or leave a real gap")

    @cached_property
    def surfaces(self) -> tuple[Surface, ...]:
        pieces: list[Surface] = []
        x = -math.inf
        for i, t in sorted(enumerate(self.treads, start=1), key=lambda it: it[1].start_m):
            if t.start_m > x + 1e-9:
                pieces.append(Surface(x, t.start_m, 0.0, 0))
            pieces.append(Surface(t.start_m, t.end_m, float(t.height_m), i))
            x = t.end_m
        pieces.append(Surface(x, math.inf, 0.0, 0))
        merged: list[Surface] = []
        for s in pieces:  # a zero-height tread touching the ground is one surface with it
            if merged and merged[-1].height == s.height and abs(merged[-1].end - s.start) < 1e-9:
                prev = merged.pop()
                s = Surface(prev.start, s.end, s.height, prev.tread or s.tread)
            merged.append(s)
        return tuple(merged)

    def edges(self) -> list[tuple[float, float]]:
        """(x, top height) of every place where the height changes."""
        s = self.surfaces
        return [(a.end, max(a.height, b.height)) for a, b in zip(s, s[1:])]

    @cached_property
    def _bounds(self) -> np.ndarray:
        return np.array([p.end for p in self.surfaces[:-1]])

    @cached_property
    def _heights(self) -> np.ndarray:
        return np.array([p.height for p in self.surfaces])

    def surface_index(self, x) -> np.ndarray:
        """Index into ``surfaces`` of the surface holding x (within 1e-12 m of an edge: the higher one)."""
        x = np.asarray(x, dtype=float)
        bounds, heights = self._bounds, self._heights
        left = np.searchsorted(bounds, x - 1e-12, side="left")
        right = np.searchsorted(bounds, x + 1e-12, side="right")
        return np.where(heights[right] > heights[left], right, left)

    def height_at(self, x) -> np.ndarray:
        return self._heights[self.surface_index(x)]

    def max_height(self, x0: float, x1: float) -> float:
        """Highest surface over the closed interval [x0, x1]."""
        lo, hi = min(x0, x1), max(x0, x1)
        return max(p.height for p in self.surfaces if p.end >= lo and p.start <= hi)

    def level_between(self, x0: float, x1: float) -> bool:
        """True if the whole closed interval [x0, x1] lies on one surface (no edge)."""
        lo, hi = min(x0, x1), max(x0, x1)
        return sum(1 for p in self.surfaces if p.end > lo and p.start < hi) == 1 and not any(
            lo < e < hi for e, _ in self.edges())
