"""Foothold planner: where each heel goes, every foot fully on one surface with a margin.

A foothold is a heel x. The foot covers [heel, heel + foot]; it must lie on one surface with
``margin`` to spare at both ends. Steps where the rear, stance and target footholds share one
surface are the flat walker's, at most ``flat_max_step`` long. Every other step, and the swing that
makes it (lift-off to landing), stays within the leg's step envelope (envelope.py): no longer than
``step_limit`` of its rise, and nothing between standing higher above the higher end than the
largest rise. A zero step (the trailing foot closing beside the leading one) is allowed, so steep
or short treads are taken one at a time (step-to); a shuffle (a very short step, under
SHUFFLE_SHARE of a flat step) is not, as a step off the flat or right before one: it would swing
the trailing foot further than a closing step does, for nothing.

Among the feasible plans it takes the fewest steps, and among those the most even: dynamic
programming over (rear heel, stance heel) on candidate heel positions (a GRID_M lattice plus both
ends of every surface's admissible stretch, so a tread barely longer than a foot is never missed),
cost 1 per step plus a small penalty for straying from the flat walker's preferred step (a larger
one for a step off the flat longer than that: the edge of the envelope is for ditches and stairs
that need it, not for saving a step on easy ground). A course
that cannot be walked raises CourseError saying where and why (course_problems names the first
tread the envelope rules out before any planning).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .envelope import StepEnvelope, course_problems
from .model import Terrain

GRID_M = 5e-3
PREFERRED_SHARE = 0.85  # preferred step: this share of the flat walker's longest
EVENNESS = 0.3  # weight of the squared relative deviation from the preferred step
LONG_TERRAIN_STEP = 1.0  # ... for a step off the flat longer than preferred: taken only where it saves a step and more
SHUFFLE_SHARE = 0.3  # a step off the flat is a closing step (0) or at least this share of the flat walker's longest


class CourseError(ValueError):
    """The course cannot be walked by this leg; the message says where and why."""


@dataclass(frozen=True)
class Foothold:
    heel_x: float
    height: float
    surface: int  # index into terrain.surfaces


@dataclass(frozen=True)
class FootholdLimits:
    foot: float  # heel to toe, metres
    margin: float
    flat_max_step: float  # a step with all three footholds on one surface (the flat walker's)
    envelope: StepEnvelope  # every other step


def admissible(terrain: Terrain, heel_x, limits: FootholdLimits) -> np.ndarray:
    """True where a heel at x puts the whole foot on one surface with the margin at both ends."""
    heel_x = np.asarray(heel_x, dtype=float)
    surfaces = terrain.surfaces
    idx = terrain.surface_index(heel_x)
    starts = np.array([s.start for s in surfaces])[idx]
    ends = np.array([s.end for s in surfaces])[idx]
    tol = 1e-9
    return (heel_x >= starts + limits.margin - tol) & (heel_x + limits.foot + limits.margin <= ends + tol)


def candidates(terrain: Terrain, start: float, stop: float, limits: FootholdLimits) -> np.ndarray:
    """Admissible heel positions from ``start`` to ``stop``: a GRID_M lattice and both ends of every
    surface's admissible stretch."""
    xs = [start + GRID_M * np.arange(int(np.ceil((stop - start) / GRID_M)) + 1)]
    for s in terrain.surfaces:
        lo, hi = s.start + limits.margin, s.end - limits.margin - limits.foot
        xs.append(np.array([v for v in (lo, hi) if np.isfinite(v) and start <= v <= stop]))
    xs = np.unique(np.round(np.concatenate(xs), 9))
    return xs[admissible(terrain, xs, limits)]


def _obstacles(terrain: Terrain) -> np.ndarray:
    """obstacle[i, j]: how far the highest surface strictly between surfaces i < j stands above both."""
    h = np.array([p.height for p in terrain.surfaces])
    n = len(h)
    out = np.zeros((n, n))
    for i in range(n):
        for j in range(i + 2, n):
            out[i, j] = out[j, i] = max(0.0, h[i + 1:j].max() - max(h[i], h[j]))
    return out


def plan_footholds(terrain: Terrain, start: float, end: float, limits: FootholdLimits) -> list[Foothold]:
    """Footholds from the first step to the last (the start, where both heels stand, excluded).

    The last foothold is the first admissible heel position at or past ``end``."""
    env = limits.envelope
    if not admissible(terrain, np.array([start]), limits)[0]:
        sf = terrain.surfaces[int(terrain.surface_index(start))]
        raise CourseError(f"course.start_m: the feet at x = {start:g} m are not fully on one surface with the "
                          f"margin {limits.margin:g} m (on {sf.describe()}; foot {limits.foot:g} m long)")
    problem = course_problems(terrain, start, end, limits.foot, limits.margin, env)
    if problem:
        raise CourseError(problem)
    reach = max(limits.flat_max_step, env.longest)
    xs = candidates(terrain, start, end + 2 * reach + limits.foot, limits)
    beyond = np.nonzero(xs >= end - 1e-9)[0]
    if len(beyond) == 0:
        raise CourseError(f"course.end_m: no surface at or past x = {end:g} m holds a foot")
    target = int(beyond[0])
    xs = xs[:target + 1]
    n = len(xs)
    surf = terrain.surface_index(xs)
    heights = np.array([p.height for p in terrain.surfaces])
    obstacle = _obstacles(terrain)
    limit = np.array([[env.step_limit(b - a) for b in heights] for a in heights])  # [from surface, to surface]
    # cost[j][m]: best cost with the stance heel at j and the rear heel at j - m (m = 0: side by side)
    window = int(max(np.searchsorted(xs, xs + 2 * reach + 1e-9) - np.arange(n))) + 1
    cost = np.full((n, window), np.inf)
    back = np.full((n, window), -1, dtype=int)
    cost[0, 0] = 0.0
    for j in range(target):
        for zero_only in (True, False):  # zero steps first: their states (j, j) step on from j too
            row = cost[j].copy()
            if not np.isfinite(row).any():
                continue
            m = np.arange(window)
            rear = j - m
            live = np.isfinite(row) & (rear >= 0)
            k_hi = int(np.searchsorted(xs, xs[j] + reach + 1e-9))
            ks = np.arange(j, min(k_hi, target + 1)) if not zero_only else np.array([j])
            if len(ks) == 0 or not live.any():
                continue
            r = np.where(live, rear, 0)[:, None]  # (window, 1)
            k = ks[None, :]  # (1, K)
            step, travel = xs[k] - xs[j], xs[k] - xs[r]
            same = (surf[r] == surf[j]) & (surf[j] == surf[k])
            flat_ok = same & (step <= limits.flat_max_step + 1e-9) & (travel <= 2 * limits.flat_max_step + 1e-9)
            terrain_ok = ((step <= limit[surf[j], surf[k]] + 1e-9) & (travel <= limit[surf[r], surf[k]] + 1e-9)
                          & (obstacle[surf[j], surf[k]] <= env.max_rise + 1e-12)
                          & (obstacle[surf[r], surf[k]] <= env.max_rise + 1e-12))
            short = SHUFFLE_SHARE * limits.flat_max_step
            shuffle = (step > 1e-9) & (step < short)
            came_shuffling = (xs[j] - xs[r] > 1e-9) & (xs[j] - xs[r] < short)  # (window, 1)
            valid = (live[:, None] & (flat_ok | (~same & terrain_ok & ~shuffle & ~came_shuffling))
                     & ~((k == j) & (r == j)))
            pref = PREFERRED_SHARE * limits.flat_max_step
            weight = np.where(~same & (step > pref), LONG_TERRAIN_STEP, EVENNESS)
            c = row[:, None] + 1.0 + weight * np.where(step > 0, ((step - pref) / pref) ** 2, 0.5)
            c = np.where(valid, c, np.inf)
            best_m = np.argmin(c, axis=0)
            best = c[best_m, np.arange(len(ks))]
            for col in np.nonzero(np.isfinite(best))[0]:
                kk = int(ks[col])
                mm = kk - j
                if mm < window and best[col] < cost[kk, mm]:
                    cost[kk, mm], back[kk, mm] = best[col], best_m[col]
    if not np.isfinite(cost[target]).any():
        raise CourseError(_why_blocked(terrain, xs, cost))
    j, m = target, int(np.argmin(cost[target]))
    path = [j]
    while j != 0:
        j, m = j - m, int(back[j, m])
        path.append(j)
    path.reverse()
    return [Foothold(float(xs[j]), float(heights[surf[j]]), int(surf[j])) for j in path[1:]]


def _why_blocked(terrain: Terrain, xs, cost) -> str:
    """Where the plan stops (course_problems found nothing: a combination of steps the planner cannot chain)."""
    reached = np.nonzero(np.isfinite(cost).any(axis=1))[0]
    r = int(reached[-1])
    here = terrain.surfaces[int(terrain.surface_index(xs[r]))]
    return (f"cannot walk past x = {xs[r]:.3f} m (last reachable heel, on {here.describe()}): no sequence of steps "
            f"within this leg's envelope reaches further")
