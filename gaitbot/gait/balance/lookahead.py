"""The balanced walker's online preview stages (a part of gaitbot.gait.balance.walker.BalancedWalker).

The first preview stage runs horizon + 1 frames ahead of the output and places the body for each frame's
CoM (the float code); the second stage previews the multibody ZMP's error computed from those placements.
A step appended while walking changes the reference over the horizon: the first stage reruns from the next
output frame (``_replan_lookahead``), and its body placements are redone at once (vectorised) or spread
over the next frames (``work``). Behind the output, the plan's per-frame stores are dropped (``_trim``), so
a walk of any length holds bounded memory. State lives on the walker (BalancedWalker.__init__, ``_prime``).
"""

from __future__ import annotations

import numpy as np

from gaitbot.gait.balance.flat_foot_body import FlatFootBody
from gaitbot.gait.balance.placement import (MAX_PLACEMENT_ITERATIONS, PLACEMENT_TOLERANCE_M, SLOPE_PROBE_M,
                                            multibody_zmp)
from gaitbot.gait.balance.preview import FloatPreview

SPREAD_FRAMES = 6
"""Body placements ``BalancedWalker.work`` redoes per call by default (the float code: ~0.1 ms each on the
development machine): a replan of the 1 s preview horizon is spread over ~11 frames."""
VECTORISED_FRAMES = 16
"""From this many frames on, a re-placement runs vectorised (numpy) rather than frame by frame in floats."""
STORED_FRAMES = 1200
"""The online walker keeps its plan's per-frame arrays from KEPT_FRAMES behind the output frame on, and drops
the older ones whenever that reaches this many frames: a drive of any length holds bounded memory."""
KEPT_FRAMES = 32
RESERVE_FRAMES = 256
"""The second stage's per-frame stores grow by this many frames at a time."""


class Lookahead:
    """The online preview stages of BalancedWalker (a mixin: it uses the walker's plan and state)."""

    def _trim(self) -> None:
        """Once STORED_FRAMES have gathered behind the output, drop the plan's frames (and the second stage's
        errors and points) more than KEPT_FRAMES behind it."""
        if self._k - self._base < STORED_FRAMES:
            return
        cut = self._k - KEPT_FRAMES
        d = cut - self._base
        if d <= 0:
            return
        closed = self._ext is self._arrays
        self._arrays = {key: a[d:].copy() for key, a in self._arrays.items()}
        self._ext = self._arrays if closed else {key: a[d:].copy() for key, a in self._ext.items()}
        self._zmp_padded = self._zmp_padded[d:].copy()
        self._err = self._err[d:].copy()
        self._pts = self._pts[d:].copy()
        self._base = cut

    def _prime(self) -> None:
        self._flat = FlatFootBody(self.body)
        self._stage1 = FloatPreview(self.gains, self._arrays["zmp"][0])
        self._stage2 = FloatPreview(self.gains, np.zeros(2))
        self._s1_next = 0
        self._s1_offset = tuple(self.standing_offset)
        self._s1_com, self._s1_snapshot, self._s1_offsets = {}, {}, {}
        self._err, self._err_next = np.zeros((256, 2)), 0  # the second stage's errors, from frame _base on
        self._pts = np.zeros((256, len(self.whole.point_masses_kg), 3))  # the first stage's link points, too
        self._offset = tuple(self.standing_offset)
        self._previous_offset = None
        self._point_shares = self._shares_of_points()
        self._primed = True

    def _shares_of_points(self) -> np.ndarray:
        """(13, 2): how far each link point (torso, legs) moves in x and in y per metre the whole CoM moves,
        the feet standing (the walking crouch, measured once: ~1.25 for the torso, 0 for the feet)."""
        ankles = np.repeat(self._arrays["ankles"][:1], 3, 0)
        root = np.repeat([[*(self._arrays["zmp"][0] + self.standing_offset), self.planner.walk_root_z]], 3, 0)
        root[1, 0] += SLOPE_PROBE_M
        root[2, 1] += SLOPE_PROBE_M
        points = self.whole.link_points(root, self.whole.legs(root, ankles))
        com = self.whole.com(root, ankles)
        return np.column_stack([(points[1, :, 0] - points[0, :, 0]) / (com[1, 0] - com[0, 0]),
                                (points[2, :, 1] - points[0, :, 1]) / (com[2, 1] - com[0, 1])])

    def _stage1_until(self, j: int) -> None:
        """Run the first preview stage and place the body up to frame j (clamped to the last frame)."""
        stop = min(j, self._last_frame())
        if self._s1_next > stop:
            return
        first = self._s1_next
        self._run_stage1(first, stop)
        for i in range(first, stop + 1):
            self._place_stage1(i, extrapolated(self._s1_offset, self._s1_offsets.get(i - 2)))
        self._s1_next = stop + 1

    def _run_stage1(self, first: int, last: int) -> None:
        """The first preview stage's recursion over frames first..last (its state at ``first`` given): each
        frame's CoM and the state before it (from which a replan restarts)."""
        b = self._base
        stage = self._stage1
        padded = self._zmp_padded
        sums = stage.preview_sums(padded, first - b, last - first + 1).tolist()
        refs = padded[first - b:last - b + 1].tolist()
        for n, i in enumerate(range(first, last + 1)):
            self._s1_snapshot[i] = stage.state
            self._s1_com[i] = stage.com
            (rx, ry), (px, py) = refs[n], sums[n]
            stage.step(rx, ry, px, py)

    def _place_stage1(self, i: int, guess) -> None:
        """Place the body (the float code) for the first stage's CoM at frame i."""
        com = self._s1_com[i]
        yaws = self._yaws_at(i)
        root, q, _ = self._flat.place(com[0], com[1], self._ext_at("ankles", i), float(self._ext_at("root_z", i)),
                                      guess[0], guess[1], self.com_slope, PLACEMENT_TOLERANCE_M,
                                      MAX_PLACEMENT_ITERATIONS, yaws)
        self._s1_offset = (root[0] - com[0], root[1] - com[1])
        self._s1_offsets[i] = self._s1_offset
        self._reserve(i)
        self._pts[i - self._base] = self._flat.world_points(root, q, yaws)

    def _reserve(self, j: int) -> None:
        """Room in the per-frame stores (errors, points) up to frame j + 1."""
        need = j - self._base + 2
        if len(self._err) < need:
            more = max(RESERVE_FRAMES, need - len(self._err))
            self._err = np.concatenate([self._err, np.zeros((more, 2))])
            self._pts = np.concatenate([self._pts, np.zeros((more,) + self._pts.shape[1:])])

    def _replan_lookahead(self, spread: bool = False) -> None:
        """A step appended while walking: rerun the first stage from the next output frame with the new
        reference (it had previewed the provisional close-and-stand), and re-place the body for those
        frames: at once (vectorised), or with ``spread`` over the next frames (``work``); the second
        stage's errors are recomputed from the new placements."""
        k = self._k
        if k not in self._s1_snapshot:
            return
        self._stage1.restore(self._s1_snapshot[k])
        end = min(self._s1_next - 1, self._last_frame())
        frames = range(k, end + 1)
        before = np.array([self._s1_com[i] for i in frames])
        self._run_stage1(k, end)
        self._pending = (k, end)
        if not spread:
            self.work(end - k + 1)
            return
        # Until work() re-places them, the frames' link points move with their CoM's change as the standing
        # pose's do (_point_shares): the second stage sees the new plan's CoM with the old plan's legs.
        moved = np.array([self._s1_com[i] for i in frames]) - before
        self._pts[k - self._base:end - self._base + 1, :, :2] += moved[:, None, :] * self._point_shares
        self._refresh_errors(k, end)

    def work(self, frames: int | None = None) -> int:
        """Redo up to ``frames`` (default SPREAD_FRAMES) of the body placements a spread append left
        pending, nearest first; returns how many are still pending. Call it once a frame, before
        ``next_frame``: a step appended with ``spread=True`` reruns the first preview stage's recursion at
        once (cheap) but re-places the body for the new CoM of each frame of the horizon only here; until
        then a frame ahead keeps its previous placement shifted by its CoM's change, which only feeds the
        second stage's multibody ZMP error (the old plan's leg motion on the new plan's CoM, for a few
        frames). The frames handed out are always placed for the new CoM (placed when handed out)."""
        if self._pending is None:
            return 0
        first, end = self._pending
        first = max(first, self._k)
        last = min(end, first + (SPREAD_FRAMES if frames is None else frames) - 1)
        if first <= last:
            self._replace(first, last)
        self._pending = (last + 1, end) if last < end else None
        return self.pending_frames

    def _replace(self, first: int, last: int) -> None:
        """Re-place the body for the first stage's (new) CoM at frames first..last, and refresh the second
        stage's errors around them (those already computed; the later ones are computed when needed)."""
        if last - first + 1 >= VECTORISED_FRAMES:
            frames = range(first, last + 1)
            coms = np.array([self._s1_com[i] for i in frames])
            idx = np.minimum(np.arange(first, last + 1) - self._base, len(self._ext["zmp"]) - 1)
            guess = np.array([self._s1_offsets.get(i, self._s1_offset) for i in frames])
            yaw = self._ext["yaw"][idx] if self._ext["yaw"][idx].any() else None
            root, q, _ = self.whole.place(coms, self._ext["ankles"][idx], self._ext["root_z"][idx], guess,
                                          self.com_slope, yaw)
            points = self.whole.link_points(root, q, yaw)
            self._pts[first - self._base:last - self._base + 1] = points
            for n, i in enumerate(frames):
                self._s1_offsets[i] = tuple(root[n, :2] - coms[n])
        else:
            for i in range(first, last + 1):
                self._place_stage1(i, self._s1_offsets.get(i, self._s1_offset))
        if last >= self._s1_next - 1:
            self._s1_offset = self._s1_offsets[last]
        else:
            self._s1_offset = self._s1_offsets.get(self._s1_next - 1, self._s1_offset)
        self._refresh_errors(max(self._k, first - 1), last + 1)

    def _refresh_errors(self, first: int, last: int) -> None:
        """The second stage's multibody ZMP error at frames first..last, those already computed."""
        last = min(last, self._err_next - 1, self._last_frame())
        if first <= last:
            self._errors(first, last)

    def _errors(self, first: int, last: int) -> None:
        """Multibody (point-mass) ZMP minus the reference at frames first..last (at most the last frame), at
        once: the points of frames first - 1..last + 1 (the walk's ends repeated, as the offline padding)."""
        end = self._last_frame()
        b = self._base
        window = self._pts[max(first - 1, 0) - b:min(last + 1, end) - b + 1]
        if first == 0:
            window = np.concatenate([window[:1], window])
        if last == end:
            window = np.concatenate([window, window[-1:]])
        zmp = multibody_zmp(window, self.whole.point_masses_kg, 1.0 / self.rate_hz)
        self._err[first - b:last - b + 1] = zmp - self._ext["zmp"][first - b:last - b + 1]

    def _zmp_errors_until(self, j: int) -> None:
        """Multibody ZMP errors for the frames up to j not computed yet (frames past the end: the last
        frame's, as the offline padding)."""
        if self._err_next > j:
            return
        b = self._base
        self._reserve(j)
        last = self._last_frame()
        if self._err_next <= min(j, last):
            self._errors(self._err_next, min(j, last))
        if j > last:
            self._err[max(self._err_next, last + 1) - b:j - b + 1] = self._err[last - b]
        self._err_next = j + 1


def extrapolated(offset, previous) -> tuple[float, float]:
    """The next frame's root - CoM offset guessed from the last two (the placement then needs 2 to 3
    iterations instead of 4 to 5)."""
    if previous is None:
        return offset
    return 2 * offset[0] - previous[0], 2 * offset[1] - previous[1]
