"""Spread the walker's replan over frames: the one spike of a live drive.

A step appended while walking makes the balanced walker rerun its first preview stage from the next
output frame and re-place the body for every frame of the preview horizon at once
(BalancedWalker._replan_lookahead: ~4-7 ms on the development machine, over a 60 Hz frame's share on a
Raspberry Pi). Here the cheap part (the preview recursion: the new CoM of every frame) runs at once, and
the body placements, which only feed the second stage's multibody ZMP error, are redone CHUNK_FRAMES at a
time, nearest first, one chunk per frame from the frame after; the frames not yet re-placed keep their previous placement
meanwhile (the error of a slightly older plan, far ahead in the horizon, for a few frames). The walk's
frames themselves are always placed for the new CoM (BalancedWalker._balance_frame).
"""

from __future__ import annotations

import numpy as np

from gaitbot.gait.balance.placement import multibody_zmp

CHUNK_FRAMES = 6


class SpreadReplan:
    """Installs itself on a BalancedWalker; call ``work()`` once a frame before ``next_frame``."""

    def __init__(self, walker) -> None:
        self.walker = walker
        self.pending: list[int] = []
        self.coms: dict[int, np.ndarray] = {}
        walker._replan_lookahead = self.replan

    def replan(self) -> None:
        w = self.walker
        k = w._k
        if k not in w._s1_snapshot:
            return
        state, error_sum = w._s1_snapshot[k]
        w._stage1.state, w._stage1.error_sum = state.copy(), error_sum.copy()
        end = min(w._s1_next - 1, w._last_frame())
        horizon = w.gains.horizon_frames
        for i in range(k, end + 1):
            w._s1_snapshot[i] = (w._stage1.state.copy(), w._stage1.error_sum.copy())
            w._s1_com[i] = w._stage1.state[0].copy()
            w._stage1.step(w._zmp_padded[i], w._zmp_padded[i + 1:i + 1 + horizon])
        self.pending = list(range(k, end + 1))  # re-placed from the next frame on

    def work(self) -> None:
        """Re-place the nearest CHUNK_FRAMES frames still pending (those already handed out are dropped)."""
        w = self.walker
        self.pending = [i for i in self.pending if i >= w._k and i in w._s1_com]
        if not self.pending:
            return
        chunk, self.pending = self.pending[:CHUNK_FRAMES], self.pending[CHUNK_FRAMES:]
        idx = np.minimum(np.array(chunk), len(w._ext["zmp"]) - 1)
        coms = np.array([w._s1_com[i] for i in chunk])
        guess = np.array([w._s1_offsets.get(i, w._s1_offset) for i in chunk])
        yaw = w._ext["yaw"][idx] if w._ext["yaw"][idx].any() else None
        root, q, _ = w.whole.place(coms, w._ext["ankles"][idx], w._ext["root_z"][idx], guess, w.com_slope, yaw)
        points = w.whole.link_points(root, q, yaw)
        for n, i in enumerate(chunk):
            w._s1_points[i] = points[n]
            w._s1_offsets[i] = tuple(root[n, :2] - coms[n])
        self._refresh_errors(range(max(w._k, chunk[0] - 1), chunk[-1] + 2))

    def _refresh_errors(self, frames) -> None:
        """The second stage's multibody ZMP error at the frames whose neighbourhood was re-placed (those
        already computed; later ones are computed when first needed, from the new points)."""
        w = self.walker
        last = w._last_frame()
        masses, dt = w.whole.point_masses_kg, 1.0 / w.rate_hz
        for i in frames:
            if i >= w._err_next or i > last:
                break
            window = np.stack([w._points(i - 1 if i > 0 else 0), w._points(i), w._points(i + 1 if i < last else i)])
            w._err[i] = multibody_zmp(window, masses, dt)[0] - w._ext_at("zmp", i)
