"""The tests' own terrain profile, built from the treads independently of gaitbot's Terrain: ground at 0
outside the treads, neighbouring pieces of equal height merged into one surface."""

import numpy as np


def surface_pieces(treads):
    """[start, end, height] pieces covering the whole x axis, in order."""
    pieces, x = [], -np.inf
    for t in sorted(treads, key=lambda t: t.start_m):
        if t.start_m > x + 1e-9:
            pieces.append([x, t.start_m, 0.0])
        pieces.append([t.start_m, t.start_m + t.length_m, t.height_m])
        x = t.start_m + t.length_m
    pieces.append([x, np.inf, 0.0])
    merged = []
    for p in pieces:
        if merged and merged[-1][2] == p[2] and abs(merged[-1][1] - p[0]) < 1e-9:
            merged[-1][1] = p[1]
        else:
            merged.append(p)
    return merged


def height(pieces, x):
    """Terrain height under each x (at an edge: the higher side)."""
    out = np.zeros_like(x)
    for i, xi in enumerate(x):
        out[i] = max(h for s, e, h in pieces if s - 1e-12 <= xi <= e + 1e-12)
    return out
