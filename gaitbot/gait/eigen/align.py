"""Li et al. 2009 section 3 (1)-(2): resampling cycles to a common length, and DTW alignment to a reference.

A cycle is given as ``n`` frames at phases ``0, 1/n, ..., (n-1)/n`` of its duration (periodic: the
frame at phase 1 is the next cycle's first). ``resample_cycle`` brings it to ``samples`` frames at
``s = k / samples`` by linear interpolation (periodic) or ``linspace(0, 1, samples)`` (non-periodic).

DTW (dynamic time warping) matches each frame of an example to frames of the reference, inside a
Sakoe-Chiba band so a cycle is never warped by more than ``band`` of its length, with both ends
matched to both ends. The alignment is kept as a *warp* ``h``: the aligned example at reference
phase ``s`` is the original at phase ``h(s)`` (monotone, h(0) = 0, h(1) = 1). The model keeps
the warps, so a synthesised cycle can be played back in real time (Li et al. 2009 section 6 (1)).
"""

from __future__ import annotations

import numpy as np


def sample_phases(samples: int, periodic: bool) -> np.ndarray:
    return np.arange(samples) / samples if periodic else np.linspace(0.0, 1.0, samples)


def interpolate_cycle(frames: np.ndarray, phases, periodic: bool) -> np.ndarray:
    """Frames (n, d) of a cycle at ``phases`` in [0, 1] (linear interpolation)."""
    frames = np.asarray(frames, dtype=float)
    n = len(frames)
    if periodic:
        grid = np.arange(n + 1) / n
        data = np.vstack([frames, frames[:1]])
        phases = np.mod(phases, 1.0)
    else:
        grid = np.linspace(0.0, 1.0, n)
        data = frames
    return np.column_stack([np.interp(phases, grid, data[:, j]) for j in range(data.shape[1])])


def resample_cycle(frames: np.ndarray, samples: int, periodic: bool = True) -> np.ndarray:
    return interpolate_cycle(frames, sample_phases(samples, periodic), periodic)


def dtw_path(reference: np.ndarray, example: np.ndarray, band: float) -> list[tuple[int, int]]:
    """Optimal monotone matching of frames (Euclidean pose distance) inside a band; both ends matched."""
    n, m = len(reference), len(example)
    cost = np.linalg.norm(reference[:, None, :] - example[None, :, :], axis=-1)
    width = max(1, int(np.ceil(band * max(n, m))))
    i_idx, j_idx = np.indices((n, m))
    cost = np.where(np.abs(i_idx * (m - 1) / max(n - 1, 1) - j_idx) <= width, cost, np.inf)
    acc = np.full((n + 1, m + 1), np.inf)
    acc[0, 0] = 0.0
    for i in range(1, n + 1):
        row = cost[i - 1]
        prev = acc[i - 1]
        # diagonal and vertical moves at once, then the horizontal moves as a running minimum
        best = np.minimum(prev[:-1], prev[1:]) + row
        current = np.empty(m + 1)
        current[0] = np.inf
        running = np.inf
        for j in range(m):
            running = min(best[j], running + row[j])
            current[j + 1] = running
        acc[i] = current
    path = [(n - 1, m - 1)]
    i, j = n, m
    while (i, j) != (1, 1):
        moves = ((acc[i - 1, j - 1], i - 1, j - 1), (acc[i - 1, j], i - 1, j), (acc[i, j - 1], i, j - 1))
        _, i, j = min(moves, key=lambda item: item[0])
        path.append((i - 1, j - 1))
    return path[::-1]


def warp_from_path(path, n_ref: int, n_example: int) -> np.ndarray:
    """Warp h at the reference's sample phases: mean matched example phase, made strictly increasing."""
    sums = np.zeros(n_ref)
    counts = np.zeros(n_ref)
    for i, j in path:
        sums[i] += j
        counts[i] += 1
    h = sums / counts / n_example
    # a staircase path gives repeated values: smooth by a 3-tap filter and force monotone increase
    if n_ref > 2:
        h[1:-1] = (h[:-2] + 2 * h[1:-1] + h[2:]) / 4.0
    h[0] = 0.0
    return np.maximum.accumulate(h)


def align_to_reference(reference: np.ndarray, example: np.ndarray, band: float, periodic: bool = True):
    """Return (aligned example at the reference's phases, warp h at those phases)."""
    path = dtw_path(reference, example, band)
    h = warp_from_path(path, len(reference), len(example))
    if not periodic:
        h = h * len(example) / max(len(example) - 1, 1)
    return interpolate_cycle(example, h, periodic), h
