"""The two-level grid search of Zhang 2008 for a mid-double-support (MDS) pelvis point.

The region (a rectangle between two mid-stance points) is split into 5 x 5 cells and each cell
centre is scored; cells the legs cannot reach are skipped before scoring (a cheap test at the
MDS pose itself; a candidate that passes it but fails later scores inf). The best cell is split
5 x 5 again and scored the same way (and, where the best of those lies on the cell's edge, the
cell across that edge once: see ``two_level_search``). The finest cells are 1/625 of the region,
as in a full 25 x 25 search, but far fewer are scored: ``SearchResult`` counts them.

``brute_force`` scores every centre of an n x n grid over the same region: the reference the
two-level search is tested against.

Both take ``cost`` and ``reachable`` on arrays of points, (m, 2) -> (m,): a level's cells are tested and
scored together, so a search costs a few array computations per level rather than one per cell (the
terrain walker's cost builds a pelvis path per cell and checks its legs over every sample).
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
    ok = np.asarray(reachable(points), dtype=bool)
    if ok.any():
        costs[ok] = cost(points[ok])
    return costs, int(ok.sum()), int((~ok).sum())


def _centre_cost(region: Region, cost: Callable, reachable: Callable) -> float:
    x0, x1, y0, y1 = region
    centre = np.array([[(x0 + x1) / 2, (y0 + y1) / 2]])
    return float(cost(centre)[0]) if reachable(centre)[0] else np.inf


def two_level_search(region: Region, cost: Callable, reachable: Callable, n: int = 5, follow: int = 1) -> SearchResult:
    """Zhang's search: ``cost(points)`` -> (m,) floats (inf where infeasible), ``reachable(points)`` -> (m,)
    bools (cheap), for points (m, 2).

    Level one scores the n x n cell centres of the region; level two splits the best cell n x n
    again and scores those. Where the best of the second level lies in the outer ring of its cell,
    the optimum may sit just across that edge (it often does: the best pelvis point presses against
    the boundary of what the legs can reach, where a first-level centre sees nothing), so the
    neighbouring cell across it is split and scored too, at most ``follow`` times. The finest cells
    are 1/(n^4) of the region, as in a full n^2 x n^2 search; far fewer are scored."""
    x0, x1, y0, y1 = region
    w, h = (x1 - x0) / n, (y1 - y0) / n
    points = cell_centres(region, n)
    costs, evaluated, pruned = _score(points, cost, reachable)
    k = int(np.argmin(costs))
    best_point, best_cost = points[k], float(costs[k])
    if np.isfinite(best_cost):
        queue, seen = [divmod(k, n)], set()
        while queue:
            i, j = queue.pop(0)
            if (i, j) in seen:
                continue
            seen.add((i, j))
            sub = cell_centres((x0 + i * w, x0 + (i + 1) * w, y0 + j * h, y0 + (j + 1) * h), n)
            sub_costs, e, p = _score(sub, cost, reachable)
            evaluated, pruned = evaluated + e, pruned + p
            m = int(np.argmin(sub_costs))
            if sub_costs[m] < best_cost:
                best_point, best_cost = sub[m], float(sub_costs[m])
                a, b = divmod(m, n)
                for across in ((i + (a == n - 1) - (a == 0), j), (i, j + (b == n - 1) - (b == 0))):
                    if across != (i, j) and 0 <= across[0] < n and 0 <= across[1] < n and follow > 0:
                        queue.append(across)
                        follow -= 1
    point = (float(best_point[0]), float(best_point[1])) if np.isfinite(best_cost) else (np.nan, np.nan)
    return SearchResult(point, best_cost, evaluated, pruned, n ** 4, _centre_cost(region, cost, reachable))


def brute_force(region: Region, cost: Callable, reachable: Callable, n: int = 25) -> SearchResult:
    """Score every cell centre of an n x n grid over the region (the reference for tests and the bench)."""
    points = cell_centres(region, n)
    costs, evaluated, pruned = _score(points, cost, reachable)
    k = int(np.argmin(costs))
    return SearchResult((float(points[k][0]), float(points[k][1])), float(costs[k]), evaluated, pruned, n * n,
                        _centre_cost(region, cost, reachable))
