"""Foothold planner: where each heel goes, every foot fully on one surface with a margin.

A foothold is a heel x. The foot covers [heel, heel + foot]; it must lie on one surface with
``margin`` to spare at both ends. A step (heel strike to heel strike) is at most ``flat_max_step``
when both footholds are on the same surface (the flat walker takes it, within the Boulic model's
range) and at most ``terrain_max_step`` when it goes to another surface; the rise between two
footholds, and anything standing between them above the higher one, is at most ``max_rise``.

Among the feasible plans it takes the fewest steps, and among those the most even (dynamic
programming on a 1 mm grid of heel positions: cost 1 per step plus a small penalty for
straying from a preferred step length). A course that cannot be walked raises CourseError
saying where and why.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .model import Surface, Terrain

GRID_M = 5e-3
PREFERRED_SHARE = 0.85  # preferred step: this share of the longest allowed
EVENNESS = 0.3  # weight of the squared relative deviation from the preferred step


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
    flat_max_step: float
    terrain_max_step: float
    max_rise: float
    max_travel: float  # longest swing of one foot, lift-off to landing (heel to heel)


def admissible(terrain: Terrain, heel_x, limits: FootholdLimits) -> np.ndarray:
    """True where a heel at x puts the whole foot on one surface with the margin at both ends."""
    heel_x = np.asarray(heel_x, dtype=float)
    surfaces = terrain.surfaces
    idx = terrain.surface_index(heel_x)
    starts = np.array([s.start for s in surfaces])[idx]
    ends = np.array([s.end for s in surfaces])[idx]
    tol = 1e-9
    return (heel_x >= starts + limits.margin - tol) & (heel_x + limits.foot + limits.margin <= ends + tol)


def _pair_tables(terrain: Terrain, limits: FootholdLimits):
    """For each pair of surfaces (i <= j): the rise, the obstacle height between, and whether it is allowed."""
    s = terrain.surfaces
    h = np.array([p.height for p in s])
    n = len(s)
    rise = np.abs(h[None, :] - h[:, None])
    obstacle = np.zeros((n, n))
    for i in range(n):
        for j in range(i + 2, n):
            obstacle[i, j] = max(0.0, h[i + 1:j].max() - max(h[i], h[j]))
    ok = (rise <= limits.max_rise + 1e-12) & (obstacle <= limits.max_rise + 1e-12)
    return rise, obstacle, ok


def plan_footholds(terrain: Terrain, start: float, end: float, limits: FootholdLimits) -> list[Foothold]:
    """Footholds from the first step to the last (the start, where both heels stand, excluded).

    The last foothold is the first admissible heel position at or past ``end``. Dynamic
    programming over states (rear heel, stance heel) on a GRID_M lattice: a step lands at most
    the longest step ahead of the stance heel and at most ``max_travel`` ahead of where the
    swinging foot lifted off. A zero step (the trailing foot closing beside the leading one) is
    allowed, so stairs whose going exceeds half the travel are climbed one tread at a time."""
    surfaces = terrain.surfaces
    reach = max(limits.flat_max_step, limits.terrain_max_step)
    n = int(np.ceil((end - start + 4 * reach + limits.foot) / GRID_M)) + 1
    xs = start + GRID_M * np.arange(n)
    ok_pos = admissible(terrain, xs, limits)
    if not ok_pos[0]:
        sf = surfaces[int(terrain.surface_index(start))]
        raise CourseError(f"course.start_m: the feet at x = {start:g} m are not fully on one surface with the "
                          f"margin {limits.margin:g} m (on {sf.describe()}; foot {limits.foot:g} m long)")
    beyond = np.nonzero(ok_pos & (xs >= end - 1e-9))[0]
    if len(beyond) == 0:
        raise CourseError(f"course.end_m: no surface at or past x = {end:g} m holds a foot")
    target = int(beyond[0])
    surf = terrain.surface_index(xs)
    heights = np.array([p.height for p in surfaces])
    _, _, pair_ok = _pair_tables(terrain, limits)
    w = int(np.floor(reach / GRID_M + 1e-9))
    travel_w = int(np.floor(limits.max_travel / GRID_M + 1e-9))
    flat_w = int(np.floor(limits.flat_max_step / GRID_M + 1e-9))  # on one level the flat walker's swing is two steps
    # cost[j, d]: best cost with the stance heel at j and the rear heel at j - d
    cost = np.full((target + w + 2, w + 1), np.inf)
    back = np.full((target + w + 2, w + 1), -1, dtype=int)
    cost[0, 0] = 0.0
    d_rear = np.arange(w + 1)[:, None]  # rear offset behind the stance heel
    ahead = np.arange(w + 1)[None, :]  # next heel ahead of the stance heel
    for j, zero_only in ((j, z) for j in range(target) for z in (True, False)):
        row = cost[j].copy()
        if not np.isfinite(row).any() or not ok_pos[j]:
            continue
        k = j + ahead  # (1, w+1)
        k_ok = (k <= target)
        kk = np.minimum(k, target)
        rear = np.maximum(j - d_rear, 0)
        step = ahead * GRID_M
        same = surf[kk] == surf[j]
        longest = np.where(same, limits.flat_max_step, limits.terrain_max_step)
        lo1, hi1 = np.minimum(surf[j], surf[kk]), np.maximum(surf[j], surf[kk])
        lo2, hi2 = np.minimum(surf[rear], surf[kk]), np.maximum(surf[rear], surf[kk])
        valid = (k_ok & ok_pos[kk] & (step <= longest + 1e-9) & pair_ok[lo1, hi1] & pair_ok[lo2, hi2]
                 & ((k - rear <= travel_w) | (same & (surf[rear] == surf[j]) & (k - rear <= 2 * flat_w)))
                 & np.isfinite(row)[:, None] & ~((ahead == 0) & (d_rear == 0)) & ((ahead == 0) | (not zero_only)))
        pref = PREFERRED_SHARE * longest
        c = row[:, None] + 1.0 + EVENNESS * np.where(ahead > 0, ((step - pref) / pref) ** 2, 0.5)
        c = np.where(valid, c, np.inf)
        best_d = np.argmin(c, axis=0)  # per next heel
        best = c[best_d, np.arange(w + 1)]
        for a in np.nonzero(np.isfinite(best))[0]:
            knext = j + a
            if best[a] < cost[knext, a]:
                cost[knext, a], back[knext, a] = best[a], best_d[a]
    final = cost[target].copy()
    final[np.arange(w + 1) > travel_w] = np.inf  # the closing step must reach too
    if not np.isfinite(final).any():
        raise CourseError(_why_blocked(terrain, xs[:target + 1], ok_pos[:target + 1],
                                       np.where(np.isfinite(cost[:target + 1]).any(axis=1), 0.0, np.inf), limits))
    j, d = target, int(np.argmin(final))
    path = [j]
    while j != 0:
        j, d = j - d, int(back[j, d])
        path.append(j)
    path.reverse()
    return [Foothold(float(xs[j]), float(heights[surf[j]]), int(surf[j])) for j in path[1:]]


def _why_blocked(terrain: Terrain, xs, ok_pos, cost, limits: FootholdLimits) -> str:
    surfaces = terrain.surfaces
    reached = np.nonzero(np.isfinite(cost))[0]
    r = int(reached[-1])
    here: Surface = surfaces[int(terrain.surface_index(xs[r]))]
    ahead = np.nonzero(ok_pos & (np.arange(len(xs)) > r) & (terrain.surface_index(xs) != terrain.surface_index(xs[r])))[0]
    where = f"cannot walk past x = {xs[r]:.3f} m (last reachable heel, on {here.describe()})"
    if len(ahead) == 0:
        return f"{where}: no surface ahead holds a foot ({limits.foot:g} m plus margins {limits.margin:g} m)"
    a = int(ahead[0])
    there = surfaces[int(terrain.surface_index(xs[a]))]
    rise = there.height - here.height
    if abs(rise) > limits.max_rise:
        kind = "rise" if rise > 0 else "drop"
        return (f"{where}: the next surface that holds a foot, {there.describe()}, is a {kind} of {abs(rise):.3f} m, "
                f"more than the leg can step (max_rise_m {limits.max_rise:.3f} m)")
    between = [s for s in surfaces if s.start >= here.end - 1e-12 and s.end <= there.start + 1e-12]
    tall = [s for s in between if s.height - max(here.height, there.height) > limits.max_rise]
    if tall:
        return (f"{where}: {tall[0].describe()} stands {tall[0].height - max(here.height, there.height):.3f} m above "
                f"its neighbours, more than the leg can step over (max_rise_m {limits.max_rise:.3f} m)")
    gap = xs[a] - xs[r]
    return (f"{where}: the nearest foothold beyond, on {there.describe()}, is {gap:.3f} m ahead, longer than "
            f"the longest step {limits.terrain_max_step:.3f} m (surfaces between are too short for a "
            f"{limits.foot:g} m foot with {limits.margin:g} m margins)")
