"""The two-level grid search of seed 003 for a mid-double-support (MDS) pelvis point.

The region (a rectangle between two mid-stance points) is split into 5 x 5 cells and each cell
centre is scored; cells the legs cannot reach are skipped before scoring (a cheap test at the
MDS pose itself; a candidate that passes it but fails later scores inf). The best cell is split
5 x 5 again and scored the same way. The finest cells are 1/625 of the region, as in a full
25 x 25 search, but far fewer are scored: ``SearchResult`` counts them.

``brute_force`` scores every centre of an n x n grid over the same region: the reference the
two-level search is tested against.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

Region = tuple[float, float, float, float]  # x_lo, x_hi, y_lo, y_hi


@dataclass(frozen=True)
class SearchResult:
    point: tuple[float, float]
    cost: float
    evaluated: int  # cells scored in full
    pruned: int  # cells skipped as unreachable without scoring
    full_grid: int  # cells of the equivalent single-level search (625 for two levels of 5 x 5)
    centre_cost: float  # the cost of simply taking the middle of the region (inf if unreachable)


def cell_centres(region: Region, n: int) -> np.ndarray:
    x0, x1, y0, y1 = region
    xs = x0 + (np.arange(n) + 0.5) * (x1 - x0) / n
    ys = y0 + (np.arange(n) + 0.5) * (y1 - y0) / n
    gx, gy = np.meshgrid(xs, ys, indexing="ij")
    return np.column_stack([gx.ravel(), gy.ravel()])


def _score(points, cost: Callable, reachable: Callable):
    costs = np.full(len(points), np.inf)
    evaluated = pruned = 0
    for i, p in enumerate(points):
        if not reachable(p):
            pruned += 1
            continue
        evaluated += 1
        costs[i] = cost(p)
    return costs, evaluated, pruned


def two_level_search(region: Region, cost: Callable, reachable: Callable, n: int = 5, levels: int = 2) -> SearchResult:
    """Seed 003's search: ``cost(point)`` -> float (inf if infeasible), ``reachable(point)`` -> bool (cheap)."""
    x0, x1, y0, y1 = region
    evaluated = pruned = 0
    best_point, best_cost = None, np.inf
    current = region
    for _ in range(levels):
        points = cell_centres(current, n)
        costs, e, p = _score(points, cost, reachable)
        evaluated, pruned = evaluated + e, pruned + p
        k = int(np.argmin(costs))
        if not np.isfinite(costs[k]):
            break
        if costs[k] < best_cost:
            best_point, best_cost = points[k], float(costs[k])
        cx, cy = points[k]
        w, h = (current[1] - current[0]) / n, (current[3] - current[2]) / n
        current = (cx - w / 2, cx + w / 2, cy - h / 2, cy + h / 2)
    centre = np.array([(x0 + x1) / 2, (y0 + y1) / 2])
    centre_cost = float(cost(centre)) if reachable(centre) else np.inf
    point = (float(best_point[0]), float(best_point[1])) if best_point is not None else (np.nan, np.nan)
    return SearchResult(point, best_cost, evaluated, pruned, (n * n) ** levels, centre_cost)


def brute_force(region: Region, cost: Callable, reachable: Callable, n: int = 25) -> SearchResult:
    """Score every cell centre of an n x n grid over the region (the reference for tests and the bench)."""
    points = cell_centres(region, n)
    costs, evaluated, pruned = _score(points, cost, reachable)
    k = int(np.argmin(costs))
    x0, x1, y0, y1 = region
    centre = np.array([(x0 + x1) / 2, (y0 + y1) / 2])
    centre_cost = float(cost(centre)) if reachable(centre) else np.inf
    return SearchResult((float(points[k][0]), float(points[k][1])), float(costs[k]), evaluated, pruned, n * n,
                        centre_cost)
