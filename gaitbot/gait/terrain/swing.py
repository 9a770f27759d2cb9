"""The swing foot of a terrain step: a world path from rest at lift-off to rest at landing.

Path. The foot goes up, over and down: it first rises straight (``HOLD`` of the path has no
forward motion), travels forward, and sets down straight, so a toe next to a riser or a
heel just past a nose never cuts the corner. The level change happens while over the higher
surface: a rising foot reaches its new level before it travels (``LEVEL``), a falling one leaves
it only when it has arrived. The sole levels out from its lift-off pitch early and lands flat. On
top of that a lift, smooth and zero at both ends, is the least that keeps the sole

- ``clearance`` above every tread edge it passes over (anywhere in the swing: what the course asks),
- ``clearance`` above the surface under heel and toe wherever the foot moves forward
  (CLEARANCE_WINDOW, the path between the two HOLDs: the rule every swing keeps, flat or terrain,
  docs/gait.md; the lift is whole there, LIFT_RISE = HOLD),
- above the terrain everywhere.

The lift's shape follows time as well as the path (``lift_shape``): a timing that holds the foot back
still lifts it off the ground at once (with a quarter-cycle hold-back on the path alone, a foot spent
the first fifth of its swing within 0.2 mm of the ground).

The sole height at every sample is linear in the lift, so the least lift is found exactly on a fine
sampling (aiming 2% high keeps the frames between samples clear too).

Timing. The path is a curve in sigma in [0, 1]; the foot's progress along it over the swing's
time share s is sigma = warp(s), a cubic Bezier with Bernstein coefficients (0, c1, c2, 1),
0 <= c1 <= c2 <= 1, so monotone (the foot never goes back). (1/3, 2/3) is the identity; smaller
coefficients hold the foot back and let it catch up late (a leading foot waiting for the pelvis to
rise before it reaches onto a stair), larger ones send it ahead early (a trailing foot keeping up
with the pelvis). The path starts and ends with zero tangent, so the foot is at rest at lift-off
and landing whatever the warp.

Ankle. Keeping the sole level can bend the ankle past its range where a flexed knee leans the
shank far back, so once a pelvis path is given (``fitted``) the sole tips where it must, the
ankle angle saturating smoothly inside its range, and an extra lift (found the same way as the
lift) keeps the tipped sole clear. The run chooses the warp and the pelvis with this fitted foot
(step.py ``feasible_warp``), and ``finalize`` fixes both for the frames.
"""

from __future__ import annotations

from collections.abc import Callable
from functools import lru_cache

import numpy as np

from ..geometry import LegGeometry, foot_points, leg_ik
from ..walk_segments import GaitGenerationError
from ..smooth import plateau, smootherstep, smoothstep
from .model import Terrain

HOLD = 0.2  # share of the path at each end with no horizontal motion (straight up, straight down)
LEVEL = 0.45  # a rising foot reaches the new level by this share; a falling one leaves it this late
LIFT_RISE = HOLD  # the lift rises over this share of the path (and falls over the last): whole before the foot moves on
PITCH_SHARE = 0.3  # the sole levels out over this share of the path (and tips to its landing pitch)
TIP_RISE = 0.1  # the ankle's tipping fades in over this share of the path (none at lift-off and landing)
CLEARANCE_WINDOW = (HOLD, 1.0 - HOLD)  # the path's forward part: the whole sole keeps the clearance there
AIM = 1.02  # aim this much above the clearance (frames fall between the samples)
SAMPLES = 801
FIT_ROUNDS = 12  # rounds of tip-then-lift for a tipped sole (the tip grows with the lift; it settles in a few)
ANKLE_SPARE_RAD = np.radians(1.0)  # the swing ankle keeps this far from its limits
ANKLE_SOFT_RAD = np.radians(10.0)  # its saturation starts this far inside the range
_C = (0.0, 1 / 3, 2 / 3, 1.0)
WARPS = tuple(sorted(((a, b) for a in _C for b in _C if a <= b),
                     key=lambda w: abs(w[0] - 1 / 3) + abs(w[1] - 2 / 3)))  # nearest the identity first
IDENTITY = (1 / 3, 2 / 3)


def warp(s, c1: float, c2: float):
    """sigma(s): the cubic Bezier with Bernstein coefficients (0, c1, c2, 1) on s in [0, 1]."""
    s = np.clip(np.asarray(s, dtype=float), 0.0, 1.0)
    return 3 * c1 * s * (1 - s) ** 2 + 3 * c2 * s * s * (1 - s) + s**3


@lru_cache(maxsize=16)
def warp_table(s_to: float, samples: int) -> np.ndarray:
    """sigma for every one of WARPS (rows) at ``samples`` swing time shares from 0 to s_to (read-only)."""
    s = np.linspace(0.0, s_to, samples)
    table = np.stack([warp(s, *w) for w in WARPS])
    table.setflags(write=False)
    return table


def lift_shape(s, sigma, rise: float = LIFT_RISE):
    """The lift's shape at swing time share s and path position sigma: plateau(sigma, rise), except that it
    rises with whichever of time and path comes first and falls with whichever comes last. A timing that
    holds the foot back on its path (a warp below the identity) then still lifts it off the ground at once,
    and it waits in the air; where the foot moves forward (sigma in CLEARANCE_WINDOW) the shape is 1 either
    way. It is never below plateau(sigma), so a lift found on the path alone clears the ground in time too.
    The sole's tipping for the ankle fades in the same way (rise TIP_RISE), so that a foot lifted early is
    tipped early too."""
    s, sigma = np.asarray(s, dtype=float), np.asarray(sigma, dtype=float)
    return smoothstep(np.maximum(s, sigma) / rise) * smoothstep((1.0 - np.minimum(s, sigma)) / rise)


def smooth_clamp(x, lo: float, hi: float, soft: float = ANKLE_SOFT_RAD):
    """Identity inside [lo + soft, hi - soft]; beyond, approaches lo or hi smoothly (tanh), never reaching them."""
    x = np.asarray(x, dtype=float)
    a, b = hi - soft, lo + soft
    up = a + soft * np.tanh((x - a) / soft)
    down = b + soft * np.tanh((x - b) / soft)
    return np.where(x > a, up, np.where(x < b, down, x))


class SwingPath:
    """A swing foot's path in the world: ankle (x, y) and sole pitch.

    ``start`` and ``end`` are (ankle x, ankle y, pitch) at lift-off and at landing; ``ankle_range``
    the ankle's limits in radians (lo, hi)."""

    def __init__(self, geometry: LegGeometry, terrain: Terrain, start, end, clearance: float,
                 ankle_range: tuple[float, float], what: str) -> None:
        self.g, self.terrain, self.clearance, self.what = geometry, terrain, clearance, what
        self.start, self.end = np.asarray(start, float), np.asarray(end, float)
        self.ankle_lo, self.ankle_hi = ankle_range[0] + ANKLE_SPARE_RAD, ankle_range[1] - ANKLE_SPARE_RAD
        lo_x = min(self.start[0], self.end[0]) - geometry.heel_back - 1e-9
        hi_x = max(self.start[0], self.end[0]) + geometry.toe_forward + 1e-9
        self.edges_passed = [(x, top) for x, top in terrain.edges() if lo_x < x < hi_x]
        self.warp = IDENTITY
        self.extra = 0.0
        self._pelvis: Callable | None = None
        self._cache: dict = {}
        self.lift = 0.0
        sigma = np.linspace(0.0, 1.0, SAMPLES)
        self.lift = self._least_lift(sigma, self.path(sigma, lift=False))

    # --- the path --------------------------------------------------------------------------------
    def path(self, sigma, lift: bool = True):
        """The level-sole path at sigma: (n, 3); with ``lift`` the lift included."""
        s = np.atleast_1d(np.asarray(sigma, dtype=float))
        p0, p1 = self.start, self.end
        x = p0[0] + (p1[0] - p0[0]) * smootherstep((s - HOLD) / (1.0 - 2.0 * HOLD))
        level = smootherstep(s / LEVEL) if p1[1] > p0[1] else smootherstep((s - 1.0 + LEVEL) / LEVEL)
        y = p0[1] + (p1[1] - p0[1]) * level
        pitch = (p0[2] * (1.0 - smootherstep(s / PITCH_SHARE))
                 + p1[2] * smootherstep((s - 1.0 + PITCH_SHARE) / PITCH_SHARE))
        pose = np.column_stack([x, y, pitch])
        if lift:
            pose[:, 1] += self.lift * plateau(s, LIFT_RISE)
        return pose

    def _need(self, sigma, pose) -> np.ndarray:
        """How much higher each sample's sole must be to keep the clearances (<= 0 where it is clear)."""
        g, cl = self.g, self.clearance
        heel, toe = foot_points(g, pose[:, :2], pose[:, 2])
        inside = (sigma >= CLEARANCE_WINDOW[0]) & (sigma <= CLEARANCE_WINDOW[1])
        aim = cl * AIM + 1e-6 * g.leg_length
        aim_window = np.where(inside, aim, 0.0)
        need = np.maximum(self.terrain.height_at(heel[:, 0]) + aim_window - heel[:, 1],
                          self.terrain.height_at(toe[:, 0]) + aim_window - toe[:, 1])
        span = toe[:, 0] - heel[:, 0]
        safe_span = np.where(np.abs(span) > 1e-12, span, 1.0)
        for x, top in self.edges_passed:
            over = (heel[:, 0] <= x) & (x <= toe[:, 0]) & (np.abs(span) > 1e-12)
            sole_y = heel[:, 1] + (x - heel[:, 0]) / safe_span * (toe[:, 1] - heel[:, 1])
            need = np.where(over, np.maximum(need, top + aim - sole_y), need)
        return need

    def _least_lift(self, sigma, pose) -> float:
        """The least lift (times plateau(sigma)) that clears ``pose``; an error where a lift cannot help."""
        need = self._need(sigma, pose)
        shape = plateau(sigma, LIFT_RISE)
        usable = shape > 1e-9
        if ((need > 1e-9 * self.g.leg_length) & ~usable).any():
            raise GaitGenerationError(f"{self.what}: the swing foot would touch the terrain where it cannot be lifted")
        short = (need > 0) & usable
        return max(0.0, float((need[short] / shape[short]).max())) if short.any() else 0.0

    # --- the foot for a pelvis -------------------------------------------------------------------
    def fitted(self, s, sigma, roots, extra=None, paths: int = 1):
        """The foot at swing time shares s (n,) and path positions sigma (w, n) (one row per timing) with the hip
        at ``roots`` (paths * w, n, 2: every timing for each of ``paths`` hip paths, path after path): the sole
        tipped where a level one would take the ankle out of its range, lifted by ``extra`` (paths * w,) more
        or, if None, by the least extra that keeps the tipped sole clear, found here per row of samples (each
        row one timing; a path's timings settle together, as if it were fitted alone). Returns
        (poses (paths * w, n, 3), extra (paths * w,))."""
        sigma = np.atleast_2d(np.asarray(sigma, dtype=float))
        w, n = sigma.shape
        rows = paths * w
        flat_sigma = np.tile(sigma.ravel(), paths)
        roots = np.asarray(roots, dtype=float).reshape(rows * n, 2)
        base, fade, shape = self._along(s, sigma)
        if paths > 1:
            base, fade, shape = np.tile(base, (paths, 1)), np.tile(fade, paths), np.tile(shape, paths)
        pose = base.copy()
        usable = (shape > 1e-9).reshape(rows, n)
        lift = np.zeros(rows) if extra is None else np.broadcast_to(np.asarray(extra, dtype=float), (rows,))
        settling = np.ones(paths, bool)
        for round_ in range(1 if extra is not None else FIT_ROUNDS):
            pose[:, 1] = base[:, 1] + np.repeat(lift, n) * shape
            rel = pose[:, :2] - roots
            d = np.maximum(np.hypot(rel[:, 0], rel[:, 1]), 1e-12)
            q = leg_ik(self.g, rel * np.minimum(1.0, self.g.leg_length * (1 - 1e-9) / d)[:, None], base[:, 2])
            shank = q[:, 0] - q[:, 1]
            tipped = shank + smooth_clamp(base[:, 2] - shank, self.ankle_lo, self.ankle_hi)
            pose[:, 2] = base[:, 2] + fade * (tipped - base[:, 2])
            if extra is not None:
                break  # given the extra lift
            if round_ == 0:  # no tipping needed: no extra lift either
                settling &= np.abs(pose[:, 2] - base[:, 2]).reshape(paths, w * n).max(axis=1) >= 1e-12
            if not settling.any():
                break
            probe = pose.copy()
            probe[:, 1] = base[:, 1]
            need = self._need(flat_sigma, probe) / np.where(shape > 1e-9, shape, 1.0)
            ratio = np.where(usable, need.reshape(rows, n), 0.0)
            needed = np.maximum(ratio.max(axis=1), 0.0)
            settling &= ~np.all((needed <= lift + 1e-7 * self.g.leg_length).reshape(paths, w), axis=1)
            if not settling.any():
                break  # the tip at this lift is cleared by it: settled
            # the tip grows with the lift: go up to meet it
            lift = np.where(np.repeat(settling, w), np.maximum(lift, needed) + 1e-6 * self.g.leg_length, lift)
        pose[:, 1] = base[:, 1] + np.repeat(lift, n) * shape
        return pose.reshape(rows, n, 3), lift

    def _along(self, s, sigma):
        """The lifted level-sole path, the tip's fade and the lift's shape (``lift_shape``) at time shares s and
        path positions sigma (flattened); cached for the read-only tables the run asks about again and again
        (``warp_table``, whose rows share one s)."""
        key = id(sigma) if not sigma.flags.writeable else None
        if key is not None and key in self._cache:
            return self._cache[key]
        flat = sigma.ravel()
        times = np.broadcast_to(np.asarray(s, dtype=float), sigma.shape).ravel()
        shape = lift_shape(times, flat)
        base = self.path(flat, lift=False)
        base[:, 1] += self.lift * shape
        out = (base, lift_shape(times, flat, TIP_RISE), shape)
        if key is not None:
            self._cache[key] = out
        return out

    def finalize(self, warp_coeffs, pelvis_at: Callable) -> None:
        """Fix the timing and the pelvis (``pelvis_at(s)`` -> hip positions at swing time shares s) and find
        the extra lift for the tipped sole on a fine sampling."""
        self.warp = tuple(warp_coeffs)
        s = np.linspace(0.0, 1.0, SAMPLES)
        self._pelvis = pelvis_at
        self.extra = float(self.fitted(s, warp(s, *self.warp)[None], pelvis_at(s)[None])[1][0])

    def __call__(self, s):
        """The foot at swing time share s: (n, 3). Before ``finalize``, the level-sole path, identity timing."""
        s = np.atleast_1d(np.asarray(s, dtype=float))
        sigma = warp(s, *self.warp)
        if self._pelvis is None:
            return self.path(sigma)
        return self.fitted(s, sigma[None], self._pelvis(s)[None], self.extra)[0][0]

    @property
    def total_lift(self) -> float:
        return self.lift + self.extra
