"""The pelvis of a run of consecutive terrain steps (Zhang 2008): Bezier segments through MS and MDS points.

Knots, in time order: the hand-over from the segment before (position and velocity, so joint
velocities stay continuous), then per step its mid-double-support point (MDS, lowest, chosen by the
two-level grid search) and its mid-stance point (MS, highest, at mid-swing), and a hand-over point
at the run's last heel strike, from which the next segment takes over.

- MS: the highest pelvis point at mid-swing from which both legs fit (``legs.LegRange`` with a
  spare margin), no higher than the stance knee bent MS_KNEE_RAD (MS_KNEE_DOWN_RAD on a step
  down), preferring a point midway between the stance ankle and the middle of the swing path; a
  few such candidates, tried in turn (``_ms_candidates``). On level ground that is Zhang's MS;
  on a stair it drops or moves where the swing foot still lies far behind or below.
- MDS: Zhang's search over the region between the two neighbouring knots (``_mds_region``),
  scoring a cell by the supporting legs' weighted squared joint accelerations over the two Bezier
  segments it shapes (``MdsProblem``); a cell whose MDS pose the legs cannot reach is skipped,
  and a cell whose path leaves the legs' ranges or moves the pelvis backward scores INFEASIBLE
  and more the further it is from feasible.
- Velocities at MS and MDS: vertical 0 (they are the extremes of height), horizontal the
  Fritsch-Butland mean of the neighbouring slopes, which keeps every segment's x monotone.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, replace

import numpy as np

from ..walk_segments import GaitContext, GaitGenerationError, crouch_leg_scale
from .legs import LegRange
from .pelvis import Knot, PelvisPath
from .search import Region, SearchResult, brute_force, two_level_search
from .step import TerrainStepSegment

MS_KNEE_RAD = np.radians(15.0)  # the pelvis at mid-stance is no higher than this stance knee bend allows ...
MS_KNEE_DOWN_RAD = np.radians(8.0)  # ... or this one on a step down, where a high pelvis lets the foot behind lift
MS_X_WEIGHT = 1.0  # how much pelvis height a knot gives up per metre nearer its preferred x
KNOT_SPARE_RAD = np.radians(5.0)  # MS and hand-over points keep this far inside the joint ranges
KNOT_MIN_KNEE_RAD = np.radians(15.0)  # ... and at least this knee bend, leaving the path room to move on
MDS_DEPTH_SHARE = 0.2  # the MDS region reaches this many leg lengths below the lower neighbour
MDS_ABOVE_SHARE = 0.05  # ... and this many above the higher one (a level pelvis inside the region, not on its edge)
REGION_GRID = 41  # the region is cropped to what the legs reach, found on this many points a side
COST_SAMPLES = 60
BACKWARD_TOL = 1e-9  # metres per sample the pelvis may move backward (rounding only)
INFEASIBLE = 1e9  # an infeasible cell scores this plus how far it is from feasible (any feasible cell scores less)
SWING_SPARE_RAD = np.radians(2.0)  # swing timings are chosen this far inside the ranges (frames fall between samples)


def monotone_slope(d0: float, d1: float) -> float:
    """Fritsch-Butland: the harmonic mean of two neighbouring slopes, 0 where they differ in sign.

    It is at most twice the smaller slope, so a cubic Hermite piece whose both end slopes come
    from it stays monotone."""
    if d0 * d1 <= 0.0:
        return 0.0
    return 2.0 * d0 * d1 / (d0 + d1)


def _slope(a: Knot, b: Knot) -> float:
    return (b.pos[0] - a.pos[0]) / (b.t - a.t)


@dataclass(frozen=True)
class MdsProblem:
    """One MDS point's search: the region and the functions Zhang's grid search needs.

    ``cost(points)`` is, per point (m, 2), the supporting legs' weighted squared joint accelerations
    (INFEASIBLE and more where the path is infeasible); ``reachable(points)`` the cheap test at the MDS
    pose itself."""

    step_index: int
    region: Region
    cost: Callable
    reachable: Callable

    def search(self) -> SearchResult:
        return _feasible_only(two_level_search(self.region, self.cost, self.reachable))

    def brute_force(self, n: int = 25) -> SearchResult:
        return _feasible_only(brute_force(self.region, self.cost, self.reachable, n))


def _feasible_only(result: SearchResult) -> SearchResult:
    """The search navigates by how far infeasible cells are from feasible; its report shows them as inf."""
    def clean(c):
        return c if c < INFEASIBLE else np.inf
    return replace(result, cost=clean(result.cost), centre_cost=clean(result.centre_cost))


@dataclass(frozen=True)
class RunReport:
    """What the grid search did for one MDS point of a run."""

    problem: MdsProblem
    result: SearchResult


class TerrainRun:
    """Consecutive terrain steps sharing one pelvis path.

    Order of work: step by step, an MS point (from a few candidates, see ``_ms_candidates``) together
    with the MDS point before it (each search also fixes the timing of the swing that ends inside its
    interval: see ``_search_mds``), then the hand-over point at the end together with the last
    swing's timing."""

    def __init__(self, ctx: GaitContext, legs: LegRange, weights, segments: list[TerrainStepSegment],
                 start_root, start_vel, t_start: float) -> None:
        self.ctx, self.legs, self.segments = ctx, legs, segments
        self.weights = np.asarray(weights, dtype=float)
        self.knot_legs = legs.with_spare(max(legs.spare, KNOT_SPARE_RAD), max(legs.min_knee, KNOT_MIN_KNEE_RAD))
        self.swing_legs = legs.with_spare(max(legs.spare, SWING_SPARE_RAD), legs.min_knee)
        self.reports: list[RunReport] = []
        self.warps: list = [None] * len(segments)  # each swing's timing, fixed by the search after it
        start = Knot(t_start, (float(start_root[0]), float(start_root[1])),
                     (float(start_vel[0]), float(start_vel[1])), "start")
        candidates = [self._ms_candidates(seg) for seg in segments]
        last = segments[-1]
        stance_end = last.stance_world(np.array([1.0]))[0]
        guess = Knot(float(last.time(1.0)), (0.5 * (stance_end[0] + last.landing[0]), 0.0), (0.0, 0.0), "end")
        self.knots = [start]
        for k in range(len(segments)):
            after = candidates[k + 1][0] if k + 1 < len(segments) else guess
            self.knots += self._mds_and_ms(k, self.knots[-1], candidates[k], after)
        self.knots.append(self._end_knot(self.knots[-1]))
        self.path = PelvisPath(self.knots)
        for seg, w in zip(segments, self.warps):
            seg.pelvis = self.path
            seg.finalize_swing(self._dense_warp(seg, w))

    def _dense_warp(self, seg: TerrainStepSegment, chosen):
        """The swing timing checked at every frame on the final path (the search samples more sparsely): the
        one chosen if it holds there, else the best at that density."""
        dense = seg.swing_frames()
        if chosen is not None and seg.feasible_warp(self.path, self.swing_legs, samples=dense, warps=(chosen,))[1] <= 0:
            return chosen
        return seg.feasible_warp(self.path, self.swing_legs, samples=dense)[0]

    # --- feet of the whole run -------------------------------------------------------------------
    def _feet(self, t):
        """World poses (n, 3) of both feet (as left, right), and whether each supports, at times t."""
        t = np.atleast_1d(np.asarray(t, dtype=float))
        left, right = np.empty((len(t), 3)), np.empty((len(t), 3))
        sup_l, sup_r = np.zeros(len(t), bool), np.zeros(len(t), bool)
        for seg in self.segments:
            inside = (t >= seg.t0 - 1e-12) & (t <= seg.t0 + seg.duration + 1e-12)
            if not inside.any():
                continue
            stance, other, other_sup = seg.feet_world((t[inside] - seg.t0) / seg.duration)
            if seg.state.stance_left:
                left[inside], right[inside], sup_l[inside], sup_r[inside] = stance, other, True, other_sup
            else:
                right[inside], left[inside], sup_r[inside], sup_l[inside] = stance, other, True, other_sup
        return left, right, sup_l, sup_r

    def _supports_excess(self, roots, feet):
        """How far each pelvis path, sampled at ``roots`` (m, n, 2), is from feasible for the supporting feet
        (0 if they all fit): each supporting foot within its leg's reach and ranges, and the pelvis never
        turning back (it may still be moving backward at the start, as handed over, but once it moves
        forward it keeps doing so: no loops). Returns (m,) excesses and the legs' angles (left, right),
        each (m, n, 3)."""
        left, right, sup_l, sup_r = feet
        m, n = roots.shape[:2]
        total = np.zeros(m)
        for i, path in enumerate(roots):
            dx = np.diff(path[:, 0])
            forward = np.nonzero(dx >= 0.0)[0]
            total[i] = float(-np.minimum(dx[forward[0]:] + BACKWARD_TOL, 0.0).sum()) if len(forward) else 0.0
        total /= self.ctx.geometry.leg_length
        angles = []
        for pose, sup in ((left, sup_l), (right, sup_r)):
            excess, q = self.legs.check(np.tile(pose, (m, 1)), roots.reshape(-1, 2))
            total += [float(row[sup].sum()) for row in excess.reshape(m, n)]  # row by row: the same bits in any batch
            angles.append(q.reshape(m, n, 3))
        return total, angles

    # --- knots ---------------------------------------------------------------------------------------
    def _ms_candidates(self, seg: TerrainStepSegment) -> list[Knot]:
        """Zhang's MS at mid-swing: the highest point from which the stance leg reaches its foot and the
        swing leg some point of its path with room to spare. Where along x: first choice midway between
        the stance ankle and the middle of the swing path (over the stance foot when the feet pass each
        other, as on flat ground; ahead of it on a step-to's leading step, behind on its closing step),
        then over the stance ankle, then ahead of it (a closing step down, whose pelvis must be well
        forward by the leading foot's landing). Velocities are set when the point is chosen."""
        g = self.ctx.geometry
        u = (1.0 + seg.u_ds) / 2.0
        t = float(seg.time(u))
        stance = seg.stance_world(np.array([u]))[0]
        middle = seg.swing.path(np.array([0.5]), lift=True)[0]
        lo_x, hi_x = min(stance[0], middle[0]) - 0.5 * g.foot, max(stance[0], middle[0]) + 0.5 * g.foot
        down = min(seg.landing[1], seg.swing.start[1]) < stance[1] - 1e-9 or seg.swing.start[1] > stance[1] + 1e-9
        knee = MS_KNEE_DOWN_RAD if down else MS_KNEE_RAD
        y_top = stance[1] + g.leg_length * crouch_leg_scale(g, knee)
        legs = self.knot_legs.with_spare(self.knot_legs.spare, min(self.knot_legs.min_knee, knee))
        gx, gy = np.meshgrid(np.linspace(lo_x, hi_x, 45), y_top - np.linspace(0.0, 0.35 * g.leg_length, 141),
                             indexing="ij")
        roots = np.column_stack([gx.ravel(), gy.ravel()])
        n = len(roots)
        ok = legs.fits(np.repeat(stance[None], n, axis=0), roots)
        swing = np.zeros(n, bool)
        for pose in seg.swing.path(np.linspace(0.1, 0.9, 9), lift=True):
            swing |= legs.fits(np.repeat(pose[None], n, axis=0), roots, False)
        ok &= swing
        if not ok.any():
            raise GaitGenerationError(f"{seg.what}: no pelvis position at mid-stance lets both legs reach their "
                                      f"feet within the joint limits (rise or step too large for this leg)")
        out: list[Knot] = []
        for prefer in (0.5 * (stance[0] + middle[0]), stance[0], stance[0] + 0.5 * g.foot, middle[0]):
            score = np.where(ok, roots[:, 1] - MS_X_WEIGHT * np.abs(roots[:, 0] - prefer), -np.inf)
            best = roots[int(np.argmax(score))]
            if all(abs(best[0] - k.pos[0]) > 1e-3 * g.leg_length for k in out):
                out.append(Knot(t, (float(best[0]), float(best[1])), (0.0, 0.0), "MS"))
        return out

    def _mds_and_ms(self, k: int, prev: Knot, candidates: list[Knot], after: Knot) -> tuple[Knot, Knot]:
        """The MDS point of step k and the MS point after it: the first MS candidate (ahead of ``prev``) for
        which the MDS search finds a feasible cell. The MS velocity is the Fritsch-Butland mean of the
        slopes from ``prev`` and to ``after`` (the next step's first candidate, or the end)."""
        first_error = None
        for cand in candidates:
            if cand.pos[0] <= prev.pos[0]:
                continue
            ms = Knot(cand.t, cand.pos, (monotone_slope(_slope(prev, cand), _slope(cand, after)), 0.0), "MS")
            try:
                return self._search_mds(k, prev, ms), ms
            except GaitGenerationError as exc:
                first_error = first_error or exc
        raise first_error or GaitGenerationError(f"{self.segments[k].what}: the pelvis would have to move back")

    def _end_knot(self, last_ms: Knot) -> Knot:
        """Where the run hands over at its last heel strike: between the feet, as high as the legs allow
        over the whole last segment (from the last MS on, which no MDS search covers), where the last
        swing finds a timing that keeps its leg in range."""
        g = self.ctx.geometry
        seg = self.segments[-1]
        t_end = float(seg.time(1.0))
        stance, landed = seg.stance_world(np.array([1.0]))[0], seg.landing
        mid = 0.5 * (stance[0] + landed[0])
        y_top = max(stance[1], landed[1]) + g.leg_length * crouch_leg_scale(g, MS_KNEE_RAD)
        lo_x = last_ms.pos[0] + 1e-3 * g.leg_length
        hi_x = max(lo_x, max(stance[0], landed[0]) + 0.5 * g.foot)
        t = np.linspace(last_ms.t, t_end, COST_SAMPLES)
        feet = self._feet(t)
        xs, ys = np.linspace(lo_x, hi_x, 25), y_top - np.linspace(0.0, 0.35 * g.leg_length, 36)
        candidates = sorted(((y - MS_X_WEIGHT * abs(x - mid), x, y) for x in xs for y in ys), reverse=True)
        head = self.knots[:-1]
        handed = np.array([stance, landed])
        for _, x, y in candidates:
            end = Knot(t_end, (float(x), float(y)), (_slope(last_ms, Knot(t_end, (x, y), (0, 0), "")), 0.0), "end")
            if not self.knot_legs.fits(handed, np.array([[x, y], [x, y]])).all():
                continue  # the segment taking over (the flat walker, or the settle) wants room to move on
            if self._supports_excess(PelvisPath([last_ms, end])(t)[None], feet)[0][0] > 0.0:
                continue
            w, excess = seg.feasible_warp(PelvisPath([*head, last_ms, end]), self.swing_legs)
            if excess <= 0.0:
                self.warps[-1] = w
                return end
        raise GaitGenerationError(f"{seg.what}: no pelvis path from mid-stance to the heel strike lets both legs "
                                  f"reach their feet within the joint limits (rise or step too large for this leg)")

    # --- Zhang's search -------------------------------------------------------------------------
    def _mds_region(self, prev: Knot, nxt: Knot, at_mds):
        """Zhang's region between the two MS points (x between them, y from MDS_DEPTH_SHARE leg lengths
        below the lower up to MDS_ABOVE_SHARE above the higher: with bent knees the cheapest pelvis often
        barely dips, and a best point on the region's edge is one a grid of centres sees badly),
        cropped to the box around the part of it from which both legs reach their feet at the MDS
        instant (found on a fine grid), so that the 5 x 5 cells cover what can be reached; None if
        nothing can."""
        depth = MDS_DEPTH_SHARE * self.ctx.geometry.leg_length
        lo_x, hi_x = sorted((prev.pos[0], nxt.pos[0]))
        box = (lo_x, hi_x, min(prev.pos[1], nxt.pos[1]) - depth,
               max(prev.pos[1], nxt.pos[1]) + MDS_ABOVE_SHARE * self.ctx.geometry.leg_length)
        xs, ys = np.linspace(box[0], box[1], REGION_GRID), np.linspace(box[2], box[3], REGION_GRID)
        gx, gy = np.meshgrid(xs, ys, indexing="ij")
        roots = np.column_stack([gx.ravel(), gy.ravel()])
        ok = np.ones(len(roots), bool)
        for pose in at_mds[:2]:
            ok &= self.legs.fits(np.repeat(pose, len(roots), axis=0), roots)
        if not ok.any():
            return None
        pad_x, pad_y = xs[1] - xs[0], ys[1] - ys[0]
        inside = roots[ok]
        return (max(box[0], inside[:, 0].min() - pad_x), min(box[1], inside[:, 0].max() + pad_x),
                max(box[2], inside[:, 1].min() - pad_y), min(box[3], inside[:, 1].max() + pad_y))

    def _search_mds(self, k: int, prev: Knot, nxt: Knot) -> Knot:
        """MDS of step k by the two-level grid search between ``prev`` and ``nxt``.

        A cell is feasible if the supporting legs fit all along its two Bezier segments, the swing that
        ends inside them (the previous step's) finds a timing that keeps its leg in range over its whole
        swing, and the swing that starts inside them (this step's) finds one up to mid-swing. Its cost
        is Zhang's: the supporting legs' weighted squared joint accelerations. An infeasible cell
        scores INFEASIBLE scaled up by how far it is from feasible, so where the feasible set is a thin
        sliver the search still homes in on it. The chosen cell fixes the previous swing's timing."""
        seg = self.segments[k]
        before = self.segments[k - 1] if k > 0 else None
        t_mds = float(seg.time(seg.u_ds / 2.0))
        at_mds = self._feet(np.array([t_mds]))
        region = self._mds_region(prev, nxt, at_mds)
        if region is None:
            raise GaitGenerationError(f"{seg.what}: no pelvis point in double support lets both legs reach their "
                                      f"feet within the joint limits (rise or step too large for this leg)")
        t = np.linspace(prev.t, nxt.t, COST_SAMPLES)
        dt = t[1] - t[0]
        feet = self._feet(t)
        left, right, sup_l, sup_r = feet
        head = self.knots[:-1]
        w = self.weights

        def knot(p) -> Knot:
            v = monotone_slope((p[0] - prev.pos[0]) / (t_mds - prev.t), (nxt.pos[0] - p[0]) / (nxt.t - t_mds))
            return Knot(t_mds, (float(p[0]), float(p[1])), (v, 0.0), "MDS")

        def reachable(points) -> np.ndarray:
            return self.legs.fits(at_mds[0], points) & self.legs.fits(at_mds[1], points)

        def swings_excess(paths: list[PelvisPath]) -> np.ndarray:
            total = np.zeros(len(paths))
            for swing, s_to in ((seg, 0.5), (before, 1.0)):
                if swing is not None:
                    times = swing.swing_times(s_to)
                    hips = np.stack([path(times) for path in paths])
                    total += [excess for _, excess in swing.feasible_warps(hips, self.swing_legs, s_to)]
            return total

        def cost(points) -> np.ndarray:
            paths = [PelvisPath([*head, prev, knot(p), nxt]) for p in points]
            excess, angles = self._supports_excess(np.stack([path(t) for path in paths]), feet)
            excess += swings_excess(paths)
            totals = np.zeros(len(paths))
            for q, sup in zip(angles, (sup_l, sup_r)):
                excess += self.legs.motion_excess(q, dt, np.broadcast_to(sup, q.shape[:2]))
                for i, qi in enumerate(q):  # path by path: a cell scores the same bits in any batch
                    acc = (qi[2:] - 2 * qi[1:-1] + qi[:-2]) / dt**2
                    totals[i] += float(((acc**2 @ w) * sup[1:-1]).sum() * dt)
            return np.where(excess > 0.0, INFEASIBLE * (1.0 + excess), totals)

        problem = MdsProblem(k, region, cost, reachable)
        result = problem.search()
        if not np.isfinite(result.cost):
            raise GaitGenerationError(f"{seg.what}: no pelvis height in double support lets both legs reach "
                                      f"their feet within the joint limits (rise or step too large for this leg)")
        self.reports.append(RunReport(problem, result))
        chosen = knot(result.point)
        if before is not None:
            self.warps[k - 1] = before.feasible_warp(PelvisPath([*head, prev, chosen, nxt]), self.swing_legs)[0]
        return chosen
