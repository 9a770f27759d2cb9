"""The soles as rectangles on the floor, and the gap between two of them (metres).

Why: a turn or a sidestep must never make the feet touch. The planner checks, for every step, the gap
between the stance sole and the swing sole along the swing's whole path in the plane (its ankle point
on the straight line to the foothold, its yaw a fixed function of how far along it is:
gaitbot.gait.balance.step_plan.swing_yaw_share), sampled at SWEEP_SAMPLES points; ``gaitbot check``
measures the same gap on any trajectory from the soles' corners. The gap of two convex polygons that do
not overlap is the least distance from a corner of one to an edge of the other; overlapping ones get a
negative gap. Plain floats (no numpy): the planner runs this per step on a live walk's frame budget.
"""

from __future__ import annotations

import math

from gaitbot.gait.balance.step_plan import swing_yaw_share
from gaitbot.gait.balance.zmp_reference import FootPlacement
from gaitbot.gait.body import SIDE_SIGN, BodyGeometry

SWEEP_SAMPLES = 11
"""Poses of the swing checked, evenly in the share of the way (between them the sole moves < 1 mm per
cm of step and < 0.2 deg per degree of turn)."""


def sole_box(geometry: BodyGeometry, foot: FootPlacement) -> list[tuple[float, float]]:
    """The sole's four corners on the floor, counter-clockwise (front left first)."""
    fwd = geometry.foot_m / 2 - geometry.heel_back_m
    left = SIDE_SIGN[foot.side] * geometry.sole_outward_m
    half_l, half_w = geometry.foot_m / 2, geometry.foot_width_m / 2
    c, s = math.cos(foot.yaw_rad), math.sin(foot.yaw_rad)
    out = []
    for a, b in ((1, 1), (-1, 1), (-1, -1), (1, -1)):
        u, v = fwd + a * half_l, left + b * half_w
        out.append((foot.x_m + c * u - s * v, foot.y_m + s * u + c * v))
    return out


def _point_segment(px, py, ax, ay, bx, by) -> float:
    ex, ey = bx - ax, by - ay
    t = ((px - ax) * ex + (py - ay) * ey) / (ex * ex + ey * ey)
    t = 0.0 if t < 0.0 else 1.0 if t > 1.0 else t
    return math.hypot(ax + t * ex - px, ay + t * ey - py)


def _edges(poly) -> list[tuple[float, float, float, float, float]]:
    """Each edge of a polygon as (ax, ay, ex, ey, |e|): its start and its vector."""
    n = len(poly)
    out = []
    for k in range(n):
        (ax, ay), (bx, by) = poly[k], poly[(k + 1) % n]
        out.append((ax, ay, bx - ax, by - ay, math.hypot(bx - ax, by - ay)))
    return out


def _depth(px, py, poly) -> float:
    """How far (px, py) lies inside a counter-clockwise convex polygon (<= 0: outside or on its edge)."""
    return min((ex * (py - ay) - ey * (px - ax)) / length for ax, ay, ex, ey, length in _edges(poly))


def _deepest(points, edges) -> tuple[float, bool]:
    """The deepest of ``points`` inside the polygon of ``edges`` (as _depth), and whether all of them lie
    strictly outside one of its edges (then the polygons are apart: no edges cross)."""
    deepest = -math.inf
    for px, py in points:
        depth = math.inf
        for ax, ay, ex, ey, length in edges:
            d = (ex * (py - ay) - ey * (px - ax)) / length
            if d < depth:
                depth = d
        if depth > deepest:
            deepest = depth
    apart = any(all(ex * (py - ay) - ey * (px - ax) < -COLLINEAR_M2 for px, py in points)
                for ax, ay, ex, ey, _ in edges)
    return deepest, apart


COLLINEAR_M2 = 1e-15
"""Orientations (twice a triangle's area, m^2) below this count as collinear: side by side soles' toe
edges lie on one line, and rounding must not make them cross."""


def _cross(p, q) -> bool:
    """Whether an edge of p crosses an edge of q (properly: collinear touching does not count)."""
    def side(a, b, c) -> int:
        o = (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])
        return 0 if abs(o) < COLLINEAR_M2 else (1 if o > 0 else -1)
    for i in range(len(p)):
        a, b = p[i], p[(i + 1) % len(p)]
        for j in range(len(q)):
            c, d = q[j], q[(j + 1) % len(q)]
            if side(a, b, c) * side(a, b, d) < 0 and side(c, d, a) * side(c, d, b) < 0:
                return True
    return False


def polygon_gap(p, q, p_edges=None) -> float:
    """Least distance between convex counter-clockwise polygons p and q (lists of (x, y)); negative if
    they overlap (minus the deepest corner's depth; edges crossing with no corner inside: 0).
    p_edges: p's _edges when the caller has them (a sweep against one stance sole)."""
    ep = _edges(p) if p_edges is None else p_edges
    eq = _edges(q)
    deep_p, apart_q = _deepest(p, eq)
    deep_q, apart_p = _deepest(q, ep)
    depth = max(deep_p, deep_q)
    if depth > 0:
        return -depth
    gap = math.inf
    for points, edges in ((p, eq), (q, ep)):
        for x, y in points:
            for ax, ay, ex, ey, _ in edges:
                t = ((x - ax) * ex + (y - ay) * ey) / (ex * ex + ey * ey)
                t = 0.0 if t < 0.0 else 1.0 if t > 1.0 else t
                d = math.hypot(ax + t * ex - x, ay + t * ey - y)
                if d < gap:
                    gap = d
    return 0.0 if not (apart_p or apart_q) and _cross(p, q) else gap


def sole_gap_m(geometry: BodyGeometry, a: FootPlacement, b: FootPlacement) -> float:
    """The gap between two feet's soles on the floor (m; negative: they overlap)."""
    return polygon_gap(sole_box(geometry, a), sole_box(geometry, b))


def between(old: FootPlacement, new: FootPlacement, share: float) -> FootPlacement:
    """The swing foot's pose ``share`` of the way from ``old`` to ``new`` (yaw by swing_yaw_share)."""
    w = float(swing_yaw_share(share))
    return FootPlacement(new.side, old.x_m + share * (new.x_m - old.x_m), old.y_m + share * (new.y_m - old.y_m),
                         old.yaw_rad + w * (new.yaw_rad - old.yaw_rad))


def swept_gap_m(geometry: BodyGeometry, stance: FootPlacement, old: FootPlacement, new: FootPlacement) -> float:
    """The least gap between the stance sole and the swing sole along the swing's path."""
    return swept_gap_where(geometry, stance, old, new)[0]


def swept_gap_where(geometry: BodyGeometry, stance: FootPlacement, old: FootPlacement,
                    new: FootPlacement) -> tuple[float, float]:
    """(the least gap along the swing's path, the share of the way where it is least)."""
    box = sole_box(geometry, stance)
    edges = _edges(box)
    return min((polygon_gap(box, sole_box(geometry, between(old, new, k / (SWEEP_SAMPLES - 1))), edges),
                k / (SWEEP_SAMPLES - 1)) for k in range(SWEEP_SAMPLES))
